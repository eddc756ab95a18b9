//! When a status report carries GRBL 1.1's occasional fields: the work coordinate offset
//! (`WCO:`) and the overrides (`Ov:`).
//!
//! As GRBL does, each goes out on the first report after it changes, and again every
//! [`WCO_REFRESH_BUSY_REPORTS`] / [`OV_REFRESH_BUSY_REPORTS`] reports while the machine moves
//! or every [`WCO_REFRESH_IDLE_REPORTS`] / [`OV_REFRESH_IDLE_REPORTS`] while it waits, so that a
//! sender that connects late learns them within a few seconds of polling. `Ov:` never shares a
//! report with `WCO:`: it waits for the next one, keeping reports short.

/// Reports between two `WCO:` fields while the machine moves, and while it waits (GRBL's).
pub const WCO_REFRESH_BUSY_REPORTS: u8 = 30;
pub const WCO_REFRESH_IDLE_REPORTS: u8 = 10;
/// Reports between two `Ov:` fields while the machine moves, and while it waits (GRBL's).
pub const OV_REFRESH_BUSY_REPORTS: u8 = 20;
pub const OV_REFRESH_IDLE_REPORTS: u8 = 10;

/// The occasional fields' countdowns, and what they last showed.
#[derive(Clone, Copy, Debug, Default)]
pub struct Refresh {
    /// Reports still to go without `WCO:` / `Ov:`; 0: the next one carries it.
    wco_after: u8,
    ov_after: u8,
    wco_shown: Option<[f32; 2]>,
    ov_shown: Option<[u8; 3]>,
}

/// Which occasional fields the next report carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Occasional {
    pub wco: bool,
    pub overrides: bool,
}

impl Refresh {
    /// Everything goes out on the first report.
    pub const fn new() -> Self {
        Refresh { wco_after: 0, ov_after: 0, wco_shown: None, ov_shown: None }
    }

    /// The fields of the next report, with the offset `wco_mm` and the overrides `overrides`
    /// as they are now, while the machine moves (`busy`) or waits.
    pub fn next(&mut self, wco_mm: [f32; 2], overrides: [u8; 3], busy: bool) -> Occasional {
        if self.wco_shown != Some(wco_mm) {
            self.wco_after = 0;
        }
        if self.ov_shown != Some(overrides) {
            self.ov_after = 0;
        }
        let wco = self.wco_after == 0;
        if wco {
            self.wco_after = if busy { WCO_REFRESH_BUSY_REPORTS } else { WCO_REFRESH_IDLE_REPORTS } - 1;
            self.wco_shown = Some(wco_mm);
            // `Ov:` due now waits for the next report.
            self.ov_after = self.ov_after.max(1);
        } else {
            self.wco_after -= 1;
        }
        let ov = self.ov_after == 0;
        if ov {
            self.ov_after = if busy { OV_REFRESH_BUSY_REPORTS } else { OV_REFRESH_IDLE_REPORTS } - 1;
            self.ov_shown = Some(overrides);
        } else {
            self.ov_after -= 1;
        }
        Occasional { wco, overrides: ov }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    const PLAIN: [u8; 3] = [100, 100, 100];

    /// The report indices (from 0) that carry each field over `n` reports.
    fn when(refresh: &mut Refresh, n: usize, busy: bool) -> (Vec<usize>, Vec<usize>) {
        let (mut wco, mut ov) = (Vec::new(), Vec::new());
        for i in 0..n {
            let o = refresh.next([1.0, 2.0], PLAIN, busy);
            if o.wco {
                wco.push(i);
            }
            if o.overrides {
                ov.push(i);
            }
        }
        (wco, ov)
    }

    #[test]
    fn wco_first_then_ov_then_each_at_its_refresh_rate() {
        let mut r = Refresh::new();
        let (wco, ov) = when(&mut r, 45, false);
        assert_eq!(wco, [0, 10, 20, 30, 40]);
        assert_eq!(ov, [1, 11, 21, 31, 41]);
        let mut r = Refresh::new();
        let (wco, ov) = when(&mut r, 65, true);
        assert_eq!(wco, [0, 30, 60]);
        assert_eq!(ov, [1, 21, 41, 61]);
    }

    #[test]
    fn a_change_goes_out_on_the_next_report() {
        let mut r = Refresh::new();
        when(&mut r, 5, false);
        assert_eq!(r.next([1.0, 2.0], PLAIN, false), Occasional { wco: false, overrides: false });
        assert_eq!(r.next([0.0, 2.0], PLAIN, false), Occasional { wco: true, overrides: false });
        assert_eq!(r.next([0.0, 2.0], PLAIN, false), Occasional { wco: false, overrides: false });
        assert_eq!(r.next([0.0, 2.0], [120, 100, 100], false), Occasional { wco: false, overrides: true });
        assert_eq!(r.next([0.0, 2.0], [120, 100, 100], false), Occasional { wco: false, overrides: false });
        // Both at once: `WCO:` now, `Ov:` on the report after.
        assert_eq!(r.next([5.0, 2.0], PLAIN, false), Occasional { wco: true, overrides: false });
        assert_eq!(r.next([5.0, 2.0], PLAIN, false), Occasional { wco: false, overrides: true });
    }
}

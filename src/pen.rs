//! The pen lift: an RC servo that holds the pen up or down, and which moves need the pen where.
//! Pure logic; the servo task drives the servo's PWM from [`Machine::pen`](crate::machine::Machine::pen)
//! and counts the settle time, the motion task changes the pen only at rest and starts no pulse
//! before the pen has settled.
//!
//! `$213` says how the pen is lifted ([`PenLift`]): not at all (no pen servo: the pen is
//! always down, as on a plotter with a fixed pen), by `M3`/`M4` (down) and `M5` (up), or by
//! itself as well: up for rapid moves (`G0`), down for every drawing move (`G1`–`G3` and the
//! curve commands).

use crate::settings::Settings;

/// The RC servo's frame: one pulse every 20 ms (50 Hz).
pub const PEN_SERVO_PERIOD_US: u32 = 20_000;

/// Where the pen is held.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Pen {
    Up,
    Down,
}

/// How the pen is lifted (`$213`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PenLift {
    /// No pen servo: nothing lifts the pen.
    None,
    /// `M3`/`M4` lower it, `M5` raises it.
    Spindle,
    /// As [`PenLift::Spindle`], and each move sets it: up for rapids, down for drawing.
    Auto,
}

impl PenLift {
    /// The mode `$213` names.
    pub fn of(settings: &Settings) -> PenLift {
        match settings.pen_lift {
            0 => PenLift::None,
            1 => PenLift::Spindle,
            _ => PenLift::Auto,
        }
    }
}

/// The servo pulse that holds `pen`, µs.
pub fn pulse_us(settings: &Settings, pen: Pen) -> u32 {
    match pen {
        Pen::Up => settings.pen_up_us,
        Pen::Down => settings.pen_down_us,
    }
}

/// Where a move needs the pen, a rapid (`G0`) or not, with the spindle (`M3`/`M4`) on or not;
/// `None` when nothing lifts the pen.
pub fn for_move(settings: &Settings, rapid: bool, spindle_on: bool) -> Option<Pen> {
    match PenLift::of(settings) {
        PenLift::None => None,
        PenLift::Auto if rapid => Some(Pen::Up),
        PenLift::Auto => Some(Pen::Down),
        PenLift::Spindle => Some(if spindle_on { Pen::Down } else { Pen::Up }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_mode_puts_the_pen_where_a_move_needs_it() {
        let mode = |pen_lift| Settings { pen_lift, ..Settings::default() };
        assert_eq!(for_move(&mode(0), true, true), None, "no pen servo");
        assert_eq!(for_move(&mode(1), true, true), Some(Pen::Down), "M3: down, rapid or not");
        assert_eq!(for_move(&mode(1), false, false), Some(Pen::Up), "M5: up, drawing or not");
        assert_eq!(for_move(&mode(2), true, true), Some(Pen::Up), "auto: rapids travel up");
        assert_eq!(for_move(&mode(2), false, false), Some(Pen::Down), "auto: drawing moves draw");
        let s = Settings::default();
        assert_eq!((pulse_us(&s, Pen::Up), pulse_us(&s, Pen::Down)), (1_000, 2_000));
    }
}

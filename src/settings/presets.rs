//! Named speed sets for the pens a plotter carries: the default feed, the axes' top speeds and
//! their accelerations. Picking one (on the keypad) writes those five settings at once; the
//! others stay as they are.

use super::Settings;

/// A named set of speeds and accelerations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum SpeedPreset {
    /// A technical pen: slow and gentle, so the ink keeps up and the tip never skips.
    FinePen,
    /// A felt tip: the default settings.
    FeltTip,
    /// Quick drafts with a ballpoint, at the default pulse rate's limit (100 steps/mm).
    FastDraft,
}

impl SpeedPreset {
    /// In menu order: `1` picks the first.
    pub const ALL: [SpeedPreset; 3] = [SpeedPreset::FinePen, SpeedPreset::FeltTip, SpeedPreset::FastDraft];

    /// Default feed ($203), top speed of both axes ($110, $111), in mm/min, and their
    /// acceleration ($120, $121), in mm/s².
    pub const fn speeds(self) -> (f32, f32, f32) {
        match self {
            SpeedPreset::FinePen => (1_200.0, 3_000.0, 250.0),
            SpeedPreset::FeltTip => (3_000.0, 6_000.0, 500.0),
            SpeedPreset::FastDraft => (6_000.0, 12_000.0, 1_500.0),
        }
    }

    /// The settings it writes, as `($ number, value)`.
    pub const fn changes(self) -> [(u16, f32); 5] {
        let (feed, rate, accel) = self.speeds();
        [(203, feed), (110, rate), (111, rate), (120, accel), (121, accel)]
    }

    /// True when `settings` hold this preset's values.
    pub fn is_set(self, settings: &Settings) -> bool {
        self.changes().iter().all(|&(id, value)| settings.get(id) == Ok(value))
    }

    /// Position in [`SpeedPreset::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_preset_writes_its_speeds_and_nothing_else() {
        for preset in SpeedPreset::ALL {
            let mut s = Settings::default();
            s.set_all(&preset.changes()).unwrap();
            assert!(preset.is_set(&s), "{preset:?}");
            assert_eq!(SpeedPreset::ALL.iter().filter(|p| p.is_set(&s)).count(), 1, "{preset:?}");
            let (feed, rate, accel) = preset.speeds();
            let expected = Settings {
                default_feed_mm_per_min: feed,
                max_rate_mm_per_min: [rate; 2],
                accel_mm_per_s2: [accel; 2],
                ..Settings::default()
            };
            assert_eq!(s, expected, "{preset:?}");
        }
        assert!(SpeedPreset::FeltTip.is_set(&Settings::default()));
    }

    #[test]
    fn fast_draft_stays_within_the_default_pulse_rate() {
        let s = Settings::default();
        let (_, rate, _) = SpeedPreset::FastDraft.speeds();
        assert!(rate / 60.0 * s.steps_per_mm[0] <= s.max_pulse_rate_hz);
    }
}

//! GRBL 1.1's overrides: the feed, rapid and spindle percentages a sender changes with realtime
//! bytes while a job runs, and what each of those bytes does to them.
//!
//! The feed override scales feed motion (G1-G3, the plotter's curves, keypad drawings), the rapid
//! override scales rapids (G0, G28, G30); jogs take neither. The planner applies both to the
//! motion already queued (see [`crate::motion::planner::Planner::set_overrides`]); the machine's limits
//! still cap every speed. The plotter has no spindle: its override is kept and reported, and acts
//! on nothing. As in GRBL, every override is back at 100 % after a reset.

/// Slowest and fastest feed and spindle overrides, percent (GRBL's).
pub const OVERRIDE_MIN_PERCENT: u8 = 10;
pub const OVERRIDE_MAX_PERCENT: u8 = 200;
/// Feed and spindle overrides: the coarse and the fine step, percent (GRBL's).
pub const OVERRIDE_COARSE_STEP_PERCENT: u8 = 10;
pub const OVERRIDE_FINE_STEP_PERCENT: u8 = 1;
/// An override that leaves the speed as programmed, percent.
pub const OVERRIDE_NONE_PERCENT: u8 = 100;
/// The rapid override's settings below full speed, percent (GRBL's).
pub const RAPID_OVERRIDE_HALF_PERCENT: u8 = 50;
pub const RAPID_OVERRIDE_QUARTER_PERCENT: u8 = 25;

/// The override percentages in force.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Overrides {
    /// Feed motion, 10 to 200 %.
    pub feed_percent: u8,
    /// Rapids: 25, 50 or 100 %.
    pub rapid_percent: u8,
    /// The spindle's (reported only), 10 to 200 %.
    pub spindle_percent: u8,
}

impl Default for Overrides {
    fn default() -> Self {
        Overrides::NONE
    }
}

/// What one override byte asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum OverrideCommand {
    /// 0x90 to 0x94: set the feed override to 100 %, or change it by this many percent.
    FeedReset,
    Feed(i8),
    /// 0x95 to 0x97: set the rapid override to this many percent.
    Rapid(u8),
    /// 0x99 to 0x9D: set the spindle override to 100 %, or change it by this many percent.
    SpindleReset,
    Spindle(i8),
}

impl OverrideCommand {
    /// The override command `byte` stands for, if any (GRBL 1.1's extended realtime bytes).
    pub const fn from_byte(byte: u8) -> Option<OverrideCommand> {
        const COARSE: i8 = OVERRIDE_COARSE_STEP_PERCENT as i8;
        const FINE: i8 = OVERRIDE_FINE_STEP_PERCENT as i8;
        Some(match byte {
            0x90 => OverrideCommand::FeedReset,
            0x91 => OverrideCommand::Feed(COARSE),
            0x92 => OverrideCommand::Feed(-COARSE),
            0x93 => OverrideCommand::Feed(FINE),
            0x94 => OverrideCommand::Feed(-FINE),
            0x95 => OverrideCommand::Rapid(OVERRIDE_NONE_PERCENT),
            0x96 => OverrideCommand::Rapid(RAPID_OVERRIDE_HALF_PERCENT),
            0x97 => OverrideCommand::Rapid(RAPID_OVERRIDE_QUARTER_PERCENT),
            0x99 => OverrideCommand::SpindleReset,
            0x9A => OverrideCommand::Spindle(COARSE),
            0x9B => OverrideCommand::Spindle(-COARSE),
            0x9C => OverrideCommand::Spindle(FINE),
            0x9D => OverrideCommand::Spindle(-FINE),
            _ => return None,
        })
    }
}

/// `percent` changed by `by`, kept within [`OVERRIDE_MIN_PERCENT`]..=[`OVERRIDE_MAX_PERCENT`].
const fn stepped(percent: u8, by: i8) -> u8 {
    let next = percent as i16 + by as i16;
    if next < OVERRIDE_MIN_PERCENT as i16 {
        OVERRIDE_MIN_PERCENT
    } else if next > OVERRIDE_MAX_PERCENT as i16 {
        OVERRIDE_MAX_PERCENT
    } else {
        next as u8
    }
}

impl Overrides {
    /// Everything at 100 %: speeds as programmed.
    pub const NONE: Overrides = Overrides {
        feed_percent: OVERRIDE_NONE_PERCENT,
        rapid_percent: OVERRIDE_NONE_PERCENT,
        spindle_percent: OVERRIDE_NONE_PERCENT,
    };

    /// The overrides after `command`.
    pub const fn after(self, command: OverrideCommand) -> Overrides {
        let mut next = self;
        match command {
            OverrideCommand::FeedReset => next.feed_percent = OVERRIDE_NONE_PERCENT,
            OverrideCommand::Feed(by) => next.feed_percent = stepped(self.feed_percent, by),
            OverrideCommand::Rapid(percent) => next.rapid_percent = percent,
            OverrideCommand::SpindleReset => next.spindle_percent = OVERRIDE_NONE_PERCENT,
            OverrideCommand::Spindle(by) => next.spindle_percent = stepped(self.spindle_percent, by),
        }
        next
    }

    /// Feed, rapid and spindle, percent, as `Ov:` reports them.
    pub const fn percents(self) -> [u8; 3] {
        [self.feed_percent, self.rapid_percent, self.spindle_percent]
    }

    /// Packed into one word (feed, rapid, spindle from the low byte up), to share it atomically.
    pub const fn to_bits(self) -> u32 {
        u32::from_le_bytes([self.feed_percent, self.rapid_percent, self.spindle_percent, 0])
    }

    /// What [`Self::to_bits`] packed.
    pub const fn from_bits(bits: u32) -> Overrides {
        let [feed_percent, rapid_percent, spindle_percent, _] = bits.to_le_bytes();
        Overrides { feed_percent, rapid_percent, spindle_percent }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn after(bytes: &[u8]) -> Overrides {
        bytes.iter().fold(Overrides::NONE, |o, &b| o.after(OverrideCommand::from_byte(b).unwrap()))
    }

    #[test]
    fn feed_steps_and_stays_within_10_to_200_percent() {
        assert_eq!(after(&[0x92]).feed_percent, 90);
        assert_eq!(after(&[0x91, 0x93, 0x93]).feed_percent, 112);
        assert_eq!(after(&[0x94; 3]).feed_percent, 97);
        assert_eq!(after(&[0x91; 15]).feed_percent, 200);
        assert_eq!(after(&[0x92; 15]).feed_percent, 10);
        assert_eq!(after(&[0x92; 15]).after(OverrideCommand::Feed(-1)).feed_percent, 10);
        assert_eq!(after(&[0x92, 0x92, 0x90]).feed_percent, 100);
        assert_eq!(after(&[0x92]).percents(), [90, 100, 100], "only the feed changes");
    }

    #[test]
    fn rapid_takes_three_settings_and_spindle_only_its_own_value() {
        assert_eq!(after(&[0x96]).percents(), [100, 50, 100]);
        assert_eq!(after(&[0x97]).percents(), [100, 25, 100]);
        assert_eq!(after(&[0x97, 0x95]).percents(), [100, 100, 100]);
        assert_eq!(after(&[0x9B, 0x9D]).percents(), [100, 100, 89]);
        assert_eq!(after(&[0x9A; 12]).spindle_percent, 200);
        assert_eq!(after(&[0x9A, 0x99]).spindle_percent, 100);
    }

    #[test]
    fn only_grbls_override_bytes_are_override_commands() {
        for byte in [0x8F, 0x98, 0x9E, 0x9F, 0xA0, 0xA1, b'?'] {
            assert_eq!(OverrideCommand::from_byte(byte), None, "{byte:#x}");
        }
        let o = after(&[0x92, 0x96, 0x9C]);
        assert_eq!(Overrides::from_bits(o.to_bits()), o);
    }
}

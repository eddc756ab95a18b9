//! The run LED and the buzzer: the LED lights while a drawing runs or holds, the buzzer beeps
//! once when a drawing ends and three times when an alarm is raised. Pure logic over the run
//! state and a millisecond clock; the servo task samples it and drives the pins. `$214` and
//! `$215` switch them off.

use crate::settings::Settings;
use crate::status::RunState;

/// The buzzer's patterns, as (on, off) pairs of milliseconds: one beep when a drawing ends,
/// three on an alarm.
pub const DONE_BEEP_MS: &[(u32, u32)] = &[(150, 0)];
pub const ALARM_BEEPS_MS: &[(u32, u32)] = &[(100, 100), (100, 100), (100, 0)];

/// What the LED and the buzzer do, from the run states seen.
#[derive(Clone, Copy, Debug, Default)]
pub struct Signals {
    last: RunState,
    /// The pattern sounding and when it began.
    beeping: Option<(&'static [(u32, u32)], u32)>,
}

impl Signals {
    /// Takes the run state at `now_ms` (a wrapping clock); whether the LED and the buzzer are on.
    pub fn update(&mut self, now_ms: u32, state: RunState, settings: &Settings) -> (bool, bool) {
        let pattern = match (self.last, state) {
            (RunState::Run | RunState::Hold, RunState::Idle) => Some(DONE_BEEP_MS),
            (last, RunState::Alarm) if last != RunState::Alarm => Some(ALARM_BEEPS_MS),
            _ => None,
        };
        self.last = state;
        if let Some(p) = pattern {
            self.beeping = Some((p, now_ms));
        }
        let mut buzzer = false;
        if let Some((pattern, since)) = self.beeping {
            let mut t = now_ms.wrapping_sub(since);
            let mut sounding = None;
            for &(on, off) in pattern {
                if t < on {
                    sounding = Some(true);
                    break;
                }
                if t < on + off {
                    sounding = Some(false);
                    break;
                }
                t -= on + off;
            }
            match sounding {
                Some(on) => buzzer = on,
                None => self.beeping = None,
            }
        }
        let led = matches!(state, RunState::Run | RunState::Hold);
        (led && settings.run_led, buzzer && settings.buzzer)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    #[test]
    fn the_led_follows_the_drawing_and_the_buzzer_beeps_at_its_end_and_on_an_alarm() {
        let s = Settings::default();
        let mut sig = Signals::default();
        assert_eq!(sig.update(0, RunState::Idle, &s), (false, false));
        assert_eq!(sig.update(10, RunState::Run, &s), (true, false));
        assert_eq!(sig.update(20, RunState::Hold, &s), (true, false));
        // The drawing ends: one beep of 150 ms.
        assert_eq!(sig.update(1_000, RunState::Idle, &s), (false, true));
        assert_eq!(sig.update(1_149, RunState::Idle, &s), (false, true));
        assert_eq!(sig.update(1_150, RunState::Idle, &s), (false, false));
        // A jog ends without a beep; an alarm gives three.
        sig.update(2_000, RunState::Jog, &s);
        assert_eq!(sig.update(2_100, RunState::Idle, &s), (false, false));
        let beeps: Vec<bool> = (0..6).map(|k| sig.update(3_000 + k * 100, RunState::Alarm, &s).1).collect();
        assert_eq!(beeps, [true, false, true, false, true, false]);
        // Switched off, neither sounds nor lights.
        let off = Settings { run_led: false, buzzer: false, ..Settings::default() };
        let mut sig = Signals::default();
        sig.update(0, RunState::Run, &off);
        assert_eq!(sig.update(10, RunState::Run, &off), (false, false));
        assert_eq!(sig.update(20, RunState::Idle, &off), (false, false));
    }
}

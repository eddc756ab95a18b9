//! When the drivers' servo-on (SON) goes off for standing still (`$1`), and when the drivers
//! count as ready once it is on again (`$209`). Pure logic over a millisecond clock; the servo
//! task samples it and drives the pin.

use crate::settings::{SERVO_ALWAYS_ON, Settings};

/// Since when the machine stands still, and since when SON is high.
#[derive(Clone, Copy, Debug, Default)]
pub struct ServoEnable {
    still_since: Option<u32>,
    on_since: Option<u32>,
}

impl ServoEnable {
    /// At `now_ms` (a wrapping clock), the machine standing still or not: true once it has
    /// stood still for `$1` ms (never with `$1` at [`SERVO_ALWAYS_ON`]).
    pub fn idle_off(&mut self, now_ms: u32, still: bool, settings: &Settings) -> bool {
        self.still_since = if still { self.still_since.or(Some(now_ms)) } else { None };
        settings.servo_idle_delay_ms != SERVO_ALWAYS_ON
            && self.still_since.is_some_and(|t| now_ms.wrapping_sub(t) >= settings.servo_idle_delay_ms)
    }

    /// True while SON is high.
    pub fn is_on(&self) -> bool {
        self.on_since.is_some()
    }

    /// SON is `on` at `now_ms`: whether the drivers hold their axes (on for `$209` ms).
    pub fn ready(&mut self, now_ms: u32, on: bool, settings: &Settings) -> bool {
        self.on_since = if on { self.on_since.or(Some(now_ms)) } else { None };
        self.on_since.is_some_and(|t| now_ms.wrapping_sub(t) >= settings.servo_enable_delay_ms)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn son_goes_off_after_the_idle_delay_and_is_ready_after_the_enable_delay() {
        let s = Settings { servo_idle_delay_ms: 100, servo_enable_delay_ms: 30, ..Settings::default() };
        let mut e = ServoEnable::default();
        assert!(!e.idle_off(0, true, &s));
        assert!(!e.ready(0, true, &s) && e.is_on());
        assert!(e.ready(30, true, &s));
        assert!(!e.idle_off(99, true, &s));
        assert!(e.idle_off(100, true, &s));
        assert!(!e.ready(100, false, &s) && !e.is_on());
        assert!(!e.idle_off(150, false, &s), "moving again");
        assert!(!e.ready(150, true, &s));
        assert!(e.ready(180, true, &s));
        let always = Settings::default();
        assert!(!ServoEnable::default().idle_off(u32::MAX, true, &always), "$1=255 keeps them on");
    }
}

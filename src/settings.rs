//! Machine settings: every rate, limit and timing the user may tune, with its range and unit.
//!
//! Settings are numbered like GRBL's `$` settings where GRBL has an equivalent, so existing
//! senders show them correctly; the plotter's own settings use numbers GRBL leaves free.
//! A value outside its range is refused with [`SettingError`] and changes nothing.

use crate::method::Method;

/// Why a setting was not changed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum SettingError {
    /// No setting has this number.
    Unknown,
    /// The value is outside the setting's range (or not a finite number).
    OutOfRange,
}

/// Identifies one setting: its `$` number, name, unit and range.
#[derive(Clone, Copy, Debug)]
pub struct SettingInfo {
    pub id: u16,
    pub name: &'static str,
    pub unit: &'static str,
    pub min: f32,
    pub max: f32,
}

/// Highest pulse rate the firmware drives: the drivers' own limit (EP3L class, open collector:
/// 200 kpps, a period of at least 5 µs).
pub const MAX_PULSE_RATE_HZ: f32 = 200_000.0;

/// Longest input debounce (`$206`): a switch held this long is no bounce.
pub const INPUT_DEBOUNCE_MAX_MS: u32 = 100;

/// Every setting, in `$$` listing order.
pub const SETTING_INFO: &[SettingInfo] = &[
    SettingInfo { id: 0, name: "pulse width", unit: "us", min: 2.5, max: 100.0 },
    SettingInfo { id: 3, name: "direction invert mask", unit: "mask", min: 0.0, max: 3.0 },
    SettingInfo {
        id: 5,
        name: "limit pins invert (0 normally open, 1 normally closed)",
        unit: "bool",
        min: 0.0,
        max: 1.0,
    },
    SettingInfo {
        id: 10,
        name: "status report (1 machine position, +2 buffer state)",
        unit: "mask",
        min: 0.0,
        max: 3.0,
    },
    SettingInfo { id: 11, name: "junction deviation", unit: "mm", min: 0.0, max: 5.0 },
    SettingInfo { id: 21, name: "hard limits", unit: "bool", min: 0.0, max: 1.0 },
    SettingInfo { id: 100, name: "x steps per mm", unit: "step/mm", min: 1.0, max: 200.0 },
    SettingInfo { id: 101, name: "y steps per mm", unit: "step/mm", min: 1.0, max: 200.0 },
    SettingInfo { id: 110, name: "x max rate", unit: "mm/min", min: 1.0, max: 60_000.0 },
    SettingInfo { id: 111, name: "y max rate", unit: "mm/min", min: 1.0, max: 60_000.0 },
    SettingInfo { id: 120, name: "x acceleration", unit: "mm/s^2", min: 1.0, max: 10_000.0 },
    SettingInfo { id: 121, name: "y acceleration", unit: "mm/s^2", min: 1.0, max: 10_000.0 },
    SettingInfo { id: 130, name: "x max travel", unit: "mm", min: 1.0, max: 500.0 },
    SettingInfo { id: 131, name: "y max travel", unit: "mm", min: 1.0, max: 500.0 },
    SettingInfo { id: 200, name: "direction setup", unit: "us", min: 5.0, max: 100.0 },
    SettingInfo { id: 201, name: "start rate", unit: "mm/min", min: 1.0, max: 60_000.0 },
    SettingInfo { id: 202, name: "interpolation (0 classic, 1 diagonal)", unit: "method", min: 0.0, max: 1.0 },
    SettingInfo { id: 203, name: "default feed rate", unit: "mm/min", min: 1.0, max: 60_000.0 },
    SettingInfo { id: 204, name: "max function jump", unit: "mm", min: 0.01, max: 500.0 },
    SettingInfo { id: 205, name: "max pulse rate", unit: "Hz", min: 100.0, max: MAX_PULSE_RATE_HZ },
    SettingInfo { id: 206, name: "input debounce", unit: "ms", min: 0.0, max: INPUT_DEBOUNCE_MAX_MS as f32 },
    SettingInfo { id: 207, name: "driver alarm inputs", unit: "bool", min: 0.0, max: 1.0 },
    SettingInfo { id: 208, name: "emergency stop input", unit: "bool", min: 0.0, max: 1.0 },
];

/// The machine's settings. [`Settings::default`] suits an EP3L-class servo behind PC817
/// optocouplers on a lab board.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Width of the PULS pulse ($0).
    pub pulse_width_us: f32,
    /// Bit 0 inverts X's SIGN output, bit 1 Y's ($3).
    pub dir_invert_mask: u8,
    /// The limit switches are normally closed: pressed reads high ($5).
    pub limit_pins_invert: bool,
    /// What status reports show ($10): bit 0 set, the machine position (`MPos:`), clear, the
    /// work position (`WPos:`); bit 1, the buffer state (`Bf:`).
    pub status_report_mask: u8,
    /// GRBL's junction deviation for look-ahead at corners ($11).
    pub junction_deviation_mm: f32,
    /// A limit switch pressed while moving towards it stops the machine in an alarm ($21).
    pub hard_limits: bool,
    /// Steps per millimetre, X and Y ($100, $101).
    pub steps_per_mm: [f32; 2],
    /// Fastest travel per axis ($110, $111).
    pub max_rate_mm_per_min: [f32; 2],
    /// Acceleration per axis ($120, $121).
    pub accel_mm_per_s2: [f32; 2],
    /// Travel from the origin, either way, per axis ($130, $131).
    pub max_travel_mm: [f32; 2],
    /// SIGN must settle this long before a PULS edge ($200).
    pub dir_setup_us: f32,
    /// Speed at which motion starts and ends; servos stall above their start rate ($201).
    pub start_rate_mm_per_min: f32,
    /// Interpolation method ($202).
    pub method: Method,
    /// Feed rate used until a program or the menu gives one ($203).
    pub default_feed_mm_per_min: f32,
    /// A function y = f(x) jumping further than this between two samples ends with an error ($204).
    pub max_jump_mm: f32,
    /// Highest pulse frequency the drivers (and their optocouplers) take, per axis ($205).
    pub max_pulse_rate_hz: f32,
    /// How long a limit switch, driver alarm or emergency stop input must stay active to count
    /// ($206).
    pub input_debounce_ms: u32,
    /// The drivers' alarm outputs are wired: an alarm stops the machine and turns the servos
    /// off ($207).
    pub driver_alarm_input: bool,
    /// The emergency stop input is wired ($208).
    pub estop_input: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            pulse_width_us: 5.0,
            dir_invert_mask: 0,
            limit_pins_invert: false,
            status_report_mask: 1,
            junction_deviation_mm: 0.02,
            hard_limits: false,
            steps_per_mm: [100.0, 100.0],
            max_rate_mm_per_min: [6_000.0, 6_000.0],
            accel_mm_per_s2: [500.0, 500.0],
            max_travel_mm: [200.0, 200.0],
            dir_setup_us: 10.0,
            start_rate_mm_per_min: 300.0,
            method: Method::Diagonal,
            default_feed_mm_per_min: 3_000.0,
            max_jump_mm: 5.0,
            max_pulse_rate_hz: 20_000.0,
            input_debounce_ms: 2,
            driver_alarm_input: false,
            estop_input: false,
        }
    }
}

impl Settings {
    /// The current value of setting `id`.
    pub fn get(&self, id: u16) -> Result<f32, SettingError> {
        Ok(match id {
            0 => self.pulse_width_us,
            3 => self.dir_invert_mask as f32,
            5 => f32::from(u8::from(self.limit_pins_invert)),
            10 => self.status_report_mask as f32,
            11 => self.junction_deviation_mm,
            21 => f32::from(u8::from(self.hard_limits)),
            100 | 101 => self.steps_per_mm[(id - 100) as usize],
            110 | 111 => self.max_rate_mm_per_min[(id - 110) as usize],
            120 | 121 => self.accel_mm_per_s2[(id - 120) as usize],
            130 | 131 => self.max_travel_mm[(id - 130) as usize],
            200 => self.dir_setup_us,
            201 => self.start_rate_mm_per_min,
            202 => match self.method {
                Method::Classic => 0.0,
                Method::Diagonal => 1.0,
            },
            203 => self.default_feed_mm_per_min,
            204 => self.max_jump_mm,
            205 => self.max_pulse_rate_hz,
            206 => self.input_debounce_ms as f32,
            207 => f32::from(u8::from(self.driver_alarm_input)),
            208 => f32::from(u8::from(self.estop_input)),
            _ => return Err(SettingError::Unknown),
        })
    }

    /// Sets setting `id` to `value`; out of range, unknown or not finite changes nothing.
    pub fn set(&mut self, id: u16, value: f32) -> Result<(), SettingError> {
        let mut next = self.clone();
        next.assign(id, value)?;
        next.check()?;
        *self = next;
        Ok(())
    }

    /// Settings from one value per setting, in [`SETTING_INFO`] order (as the flash store keeps
    /// them): each must be in its range and all of them agree.
    pub fn from_values(values: impl IntoIterator<Item = f32>) -> Result<Settings, SettingError> {
        let mut settings = Settings::default();
        let mut values = values.into_iter();
        for info in SETTING_INFO {
            settings.assign(info.id, values.next().ok_or(SettingError::OutOfRange)?)?;
        }
        if values.next().is_some() {
            return Err(SettingError::OutOfRange);
        }
        settings.check()?;
        Ok(settings)
    }

    /// Every value, in [`SETTING_INFO`] order.
    pub fn values(&self) -> impl Iterator<Item = f32> + '_ {
        SETTING_INFO.iter().map(|info| self.get(info.id).unwrap_or(0.0))
    }

    /// Sets one field to `value` if it is in the setting's range, without the rules that tie
    /// settings together.
    fn assign(&mut self, id: u16, value: f32) -> Result<(), SettingError> {
        let info = SETTING_INFO.iter().find(|i| i.id == id).ok_or(SettingError::Unknown)?;
        if !value.is_finite() || value < info.min || value > info.max {
            return Err(SettingError::OutOfRange);
        }
        let whole = value == crate::math::floor(value);
        match id {
            0 => self.pulse_width_us = value,
            3 if whole => self.dir_invert_mask = value as u8,
            5 if whole => self.limit_pins_invert = value != 0.0,
            10 if whole => self.status_report_mask = value as u8,
            11 => self.junction_deviation_mm = value,
            21 if whole => self.hard_limits = value != 0.0,
            100 | 101 => self.steps_per_mm[(id - 100) as usize] = value,
            110 | 111 => self.max_rate_mm_per_min[(id - 110) as usize] = value,
            120 | 121 => self.accel_mm_per_s2[(id - 120) as usize] = value,
            130 | 131 => self.max_travel_mm[(id - 130) as usize] = value,
            200 => self.dir_setup_us = value,
            201 => self.start_rate_mm_per_min = value,
            202 if whole => self.method = if value == 0.0 { Method::Classic } else { Method::Diagonal },
            203 => self.default_feed_mm_per_min = value,
            204 => self.max_jump_mm = value,
            205 => self.max_pulse_rate_hz = value,
            206 if whole => self.input_debounce_ms = value as u32,
            207 if whole => self.driver_alarm_input = value != 0.0,
            208 if whole => self.estop_input = value != 0.0,
            _ => return Err(SettingError::OutOfRange),
        }
        Ok(())
    }

    /// Rules that tie settings together.
    fn check(&self) -> Result<(), SettingError> {
        let slowest_max = self.max_rate_mm_per_min[0].min(self.max_rate_mm_per_min[1]);
        let fits_in_period = self.pulse_width_us * 2.0 <= 1e6 / self.max_pulse_rate_hz;
        if self.start_rate_mm_per_min > slowest_max || !fits_in_period {
            return Err(SettingError::OutOfRange);
        }
        Ok(())
    }

    /// The travel limits ±`$130`, ±`$131` in steps: the lattice points the pen may reach.
    pub fn travel_steps(&self) -> [i32; 2] {
        [0, 1].map(|i| crate::math::floor(self.max_travel_mm[i] * self.steps_per_mm[i] + 1e-3) as i32)
    }

    /// Steps per millimetre on `axis`.
    pub fn steps_per_mm(&self, axis: crate::geom::Axis) -> f32 {
        self.steps_per_mm[axis.index()]
    }

    /// Millimetres to the nearest whole step on `axis`.
    pub fn mm_to_steps(&self, axis: crate::geom::Axis, mm: f32) -> i32 {
        crate::math::round(mm * self.steps_per_mm(axis)) as i32
    }

    /// Steps to millimetres on `axis`.
    pub fn steps_to_mm(&self, axis: crate::geom::Axis, steps: i32) -> f32 {
        steps as f32 / self.steps_per_mm(axis)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_listed_setting_reads_back_what_was_set() {
        for info in SETTING_INFO {
            let mut s = Settings::default();
            let v = s.get(info.id).unwrap();
            assert_eq!(s.set(info.id, v), Ok(()), "${} = {v}", info.id);
            assert_eq!(s, Settings::default());
        }
    }

    #[test]
    fn bad_values_change_nothing() {
        let mut s = Settings::default();
        assert_eq!(s.set(100, 0.0), Err(SettingError::OutOfRange));
        assert_eq!(s.set(100, f32::NAN), Err(SettingError::OutOfRange));
        assert_eq!(s.set(202, 0.5), Err(SettingError::OutOfRange));
        assert_eq!(s.set(999, 1.0), Err(SettingError::Unknown));
        // A start rate above the slowest axis' max rate would stall nothing but make no sense.
        assert_eq!(s.set(201, 7_000.0), Err(SettingError::OutOfRange));
        assert_eq!(s, Settings::default());
    }

    #[test]
    fn millimetres_round_to_the_nearest_step() {
        let s = Settings::default();
        assert_eq!(s.mm_to_steps(crate::geom::Axis::X, 10.0), 1000);
        assert_eq!(s.mm_to_steps(crate::geom::Axis::Y, -0.004), 0);
        assert_eq!(s.mm_to_steps(crate::geom::Axis::Y, -0.006), -1);
    }
}

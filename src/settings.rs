//! Machine settings: every rate, limit and timing the user may tune, with its range and unit.
//!
//! Settings are numbered like GRBL's `$` settings where GRBL has an equivalent, so existing
//! senders show them correctly; the plotter's own settings use numbers GRBL leaves free.
//! A value outside its range is refused with [`SettingError`] and changes nothing. [`presets`]
//! names sets of speeds the keypad writes at once.

pub mod presets;

use crate::motion::method::Method;
use crate::panel::language::Language;
use crate::unit::Unit;

/// Why a setting was not changed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum SettingError {
    /// No setting has this number.
    Unknown,
    /// The value is outside the setting's range (or not a finite number).
    OutOfRange,
    /// The change would leave the pen, inside the travel now, outside it (soft limits turned on,
    /// or the travel made smaller): every move would then be refused, even back inside.
    StrandsPen,
}

/// Identifies one setting: its `$` number, its unit and its range. Its name on the LCD is the
/// UI's ([`crate::panel::texts::SETTING_NAMES`]).
#[derive(Clone, Copy, Debug)]
pub struct SettingInfo {
    pub id: u16,
    pub unit: Unit,
    pub min: f32,
    pub max: f32,
}

/// Highest pulse rate the firmware drives: the drivers' own limit (EP3L class, open collector:
/// 200 kpps, a period of at least 5 µs).
pub const MAX_PULSE_RATE_HZ: f32 = 200_000.0;

/// Longest input debounce (`$206`): a switch held this long is no bounce.
pub const INPUT_DEBOUNCE_MAX_MS: u32 = 100;

/// `$1` at this value keeps the servos on for good, as GRBL's step idle delay does.
pub const SERVO_ALWAYS_ON: u32 = 255;

/// Longest wait for a driver to take SON before the first pulse (`$209`).
pub const SERVO_ENABLE_DELAY_MAX_MS: u32 = 1_000;

/// Without soft limits (`$20=0`) the pen may go this far either way from machine zero: no
/// drawing on a plotter reaches it, and the position counters and every interpolator's
/// arithmetic hold far more.
pub const UNCHECKED_TRAVEL_STEPS: i32 = 1 << 20;

/// The pulses an RC servo takes (`$210`, `$211`), µs.
pub const PEN_PULSE_MIN_US: u32 = 500;
pub const PEN_PULSE_MAX_US: u32 = 2_500;

/// Longest wait for the pen to settle (`$212`).
pub const PEN_SETTLE_MAX_MS: u32 = 2_000;

/// Highest S word `$30` and `$31` take (GRBL's spindle speeds are floats; a pen needs no more).
pub const SPINDLE_SPEED_MAX: f32 = 100_000.0;

/// The language of the LCD (`$216`), which the menu also switches.
pub const LANGUAGE_SETTING: u16 = 216;

/// Longest pause after each homing move for the switch to settle (`$26`).
pub const HOMING_DEBOUNCE_MAX_MS: u32 = 1_000;

/// Where a setting is kept, and so which values it takes: any number in its range, or a whole
/// one.
enum Field<'a> {
    Real(&'a mut f32),
    Whole(&'a mut u32),
    Mask(&'a mut u8),
    Flag(&'a mut bool),
    Method(&'a mut Method),
    Language(&'a mut Language),
}

/// Every setting, in `$$` listing order. On/off settings are 0 or 1. Their names are the
/// `Setting<id>` lines of `src/panel/texts.txt`.
pub const SETTING_INFO: &[SettingInfo] = &[
    SettingInfo { id: 0, unit: Unit::Us, min: 2.5, max: 100.0 },
    // 255 always on
    SettingInfo { id: 1, unit: Unit::Ms, min: 0.0, max: 255.0 },
    // PULS is active high: only 0 (see `step_invert_mask`)
    SettingInfo { id: 2, unit: Unit::Plain, min: 0.0, max: 0.0 },
    // bit 0 X, bit 1 Y
    SettingInfo { id: 3, unit: Unit::Plain, min: 0.0, max: 3.0 },
    // SON is active high: only 0 (see `son_invert`)
    SettingInfo { id: 4, unit: Unit::Plain, min: 0.0, max: 0.0 },
    // 0 normally open, 1 normally closed
    SettingInfo { id: 5, unit: Unit::Plain, min: 0.0, max: 1.0 },
    // no probe input: kept, no effect
    SettingInfo { id: 6, unit: Unit::Plain, min: 0.0, max: 1.0 },
    // 1 machine position, +2 buffer state
    SettingInfo { id: 10, unit: Unit::Plain, min: 0.0, max: 3.0 },
    SettingInfo { id: 11, unit: Unit::Mm, min: 0.0, max: 5.0 },
    // arcs are interpolated step by step: kept, no effect
    SettingInfo { id: 12, unit: Unit::Mm, min: 0.001, max: 1.0 },
    // 1: status and `$#` in inches
    SettingInfo { id: 13, unit: Unit::Plain, min: 0.0, max: 1.0 },
    SettingInfo { id: 20, unit: Unit::Plain, min: 0.0, max: 1.0 },
    SettingInfo { id: 21, unit: Unit::Plain, min: 0.0, max: 1.0 },
    SettingInfo { id: 22, unit: Unit::Plain, min: 0.0, max: 1.0 },
    // bit set: towards the min switch
    SettingInfo { id: 23, unit: Unit::Plain, min: 0.0, max: 3.0 },
    SettingInfo { id: 24, unit: Unit::MmPerMin, min: 1.0, max: 60_000.0 },
    SettingInfo { id: 25, unit: Unit::MmPerMin, min: 1.0, max: 60_000.0 },
    SettingInfo { id: 26, unit: Unit::Ms, min: 0.0, max: HOMING_DEBOUNCE_MAX_MS as f32 },
    SettingInfo { id: 27, unit: Unit::Mm, min: 0.1, max: 20.0 },
    SettingInfo { id: 29, unit: Unit::Us, min: 5.0, max: 100.0 },
    // the S of `M3 S` that puts the pen fully down, and fully up
    SettingInfo { id: 30, unit: Unit::Plain, min: 1.0, max: SPINDLE_SPEED_MAX },
    SettingInfo { id: 31, unit: Unit::Plain, min: 0.0, max: SPINDLE_SPEED_MAX },
    // 1: the pen up for G0 and down for G1-G3 while M3/M4 is on
    SettingInfo { id: 32, unit: Unit::Plain, min: 0.0, max: 1.0 },
    SettingInfo { id: 100, unit: Unit::StepsPerMm, min: 1.0, max: 200.0 },
    SettingInfo { id: 101, unit: Unit::StepsPerMm, min: 1.0, max: 200.0 },
    SettingInfo { id: 110, unit: Unit::MmPerMin, min: 1.0, max: 60_000.0 },
    SettingInfo { id: 111, unit: Unit::MmPerMin, min: 1.0, max: 60_000.0 },
    SettingInfo { id: 120, unit: Unit::MmPerS2, min: 1.0, max: 10_000.0 },
    SettingInfo { id: 121, unit: Unit::MmPerS2, min: 1.0, max: 10_000.0 },
    SettingInfo { id: 130, unit: Unit::Mm, min: 1.0, max: 500.0 },
    SettingInfo { id: 131, unit: Unit::Mm, min: 1.0, max: 500.0 },
    SettingInfo { id: 200, unit: Unit::Us, min: 5.0, max: 100.0 },
    SettingInfo { id: 201, unit: Unit::MmPerMin, min: 1.0, max: 60_000.0 },
    // 0 classic, 1 diagonal
    SettingInfo { id: 202, unit: Unit::Plain, min: 0.0, max: 1.0 },
    SettingInfo { id: 203, unit: Unit::MmPerMin, min: 1.0, max: 60_000.0 },
    SettingInfo { id: 204, unit: Unit::Mm, min: 0.01, max: 500.0 },
    SettingInfo { id: 205, unit: Unit::Hz, min: 100.0, max: MAX_PULSE_RATE_HZ },
    SettingInfo { id: 206, unit: Unit::Ms, min: 0.0, max: INPUT_DEBOUNCE_MAX_MS as f32 },
    SettingInfo { id: 207, unit: Unit::Plain, min: 0.0, max: 1.0 },
    SettingInfo { id: 208, unit: Unit::Plain, min: 0.0, max: 1.0 },
    SettingInfo { id: 209, unit: Unit::Ms, min: 0.0, max: SERVO_ENABLE_DELAY_MAX_MS as f32 },
    SettingInfo { id: 210, unit: Unit::Us, min: PEN_PULSE_MIN_US as f32, max: PEN_PULSE_MAX_US as f32 },
    SettingInfo { id: 211, unit: Unit::Us, min: PEN_PULSE_MIN_US as f32, max: PEN_PULSE_MAX_US as f32 },
    SettingInfo { id: 212, unit: Unit::Ms, min: 0.0, max: PEN_SETTLE_MAX_MS as f32 },
    // 0 none, 1 M3/M5, 2 also by itself: up for G0, down for drawing
    SettingInfo { id: 213, unit: Unit::Plain, min: 0.0, max: 2.0 },
    SettingInfo { id: 214, unit: Unit::Plain, min: 0.0, max: 1.0 },
    SettingInfo { id: 215, unit: Unit::Plain, min: 0.0, max: 1.0 },
    SettingInfo { id: 216, unit: Unit::Plain, min: 0.0, max: 1.0 },
];

/// The machine's settings. [`Settings::default`] suits an EP3L-class servo behind PC817
/// optocouplers on a lab board.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// Width of the PULS pulse ($0).
    pub pulse_width_us: f32,
    /// After this long at rest the servos go off (SON low) until the next move;
    /// [`SERVO_ALWAYS_ON`] keeps them on ($1).
    pub servo_idle_delay_ms: u32,
    /// GRBL's step pulse invert ($2), 0 only: PULS is active high. A fault (a panic, a
    /// HardFault, a reset) drives PULS and SON low by register writes that need nothing
    /// initialised, which stops the drivers only if both are active high. Taken at 0 for the
    /// senders that write every setting back.
    pub step_invert_mask: u8,
    /// Bit 0 inverts X's SIGN output, bit 1 Y's ($3).
    pub dir_invert_mask: u8,
    /// GRBL's step enable invert ($4), 0 only: SON is active high, for the reason given at
    /// `step_invert_mask`.
    pub son_invert: bool,
    /// The limit switches are normally closed: pressed reads high ($5).
    pub limit_pins_invert: bool,
    /// GRBL's probe pin invert ($6): kept, no effect; the plotter has no probe input.
    pub probe_invert: bool,
    /// What status reports show ($10): bit 0 set, the machine position (`MPos:`), clear, the
    /// work position (`WPos:`); bit 1, the buffer state (`Bf:`).
    pub status_report_mask: u8,
    /// GRBL's junction deviation for look-ahead at corners ($11).
    pub junction_deviation_mm: f32,
    /// GRBL's arc tolerance ($12): kept, no effect; arcs are interpolated step by step on the
    /// lattice, never cut into chords.
    pub arc_tolerance_mm: f32,
    /// Status reports and `$#` in inches ($13).
    pub report_inches: bool,
    /// Drawings and jogs that would leave the travel are refused ($20).
    pub soft_limits: bool,
    /// A limit switch pressed while moving towards it stops the machine in an alarm ($21).
    pub hard_limits: bool,
    /// `$H` finds the limit switches and sets machine zero; the machine powers on locked until
    /// it is homed or unlocked ($22).
    pub homing: bool,
    /// Bit 0 homes X, bit 1 Y, towards its min switch; clear, towards its max switch ($23).
    pub homing_dir_mask: u8,
    /// Slow approach that locates the switch ($24).
    pub homing_locate_mm_per_min: f32,
    /// Fast approach that seeks the switch, and the pull-offs ($25).
    pub homing_seek_mm_per_min: f32,
    /// Pause after each homing move for the switch to settle ($26).
    pub homing_debounce_ms: u32,
    /// How far homing backs off the switch it found ($27).
    pub homing_pull_off_mm: f32,
    /// The S word of `M3 S…` that puts the pen fully down ($30, GRBL's max spindle speed), and
    /// the one that holds it up ($31, the min): the pen servo's pulse goes from `$210` at `$31`
    /// to `$211` at `$30`, in proportion.
    pub spindle_max: f32,
    pub spindle_min: f32,
    /// GRBL's laser mode ($32): with a pen lift, the pen is up for rapids (G0) and down for
    /// drawing moves while M3/M4 is on, as a laser is off in rapids.
    pub laser_mode: bool,
    /// Steps per millimetre, X and Y ($100, $101).
    pub steps_per_mm: [f32; 2],
    /// Fastest travel per axis ($110, $111).
    pub max_rate_mm_per_min: [f32; 2],
    /// Acceleration per axis ($120, $121).
    pub accel_mm_per_s2: [f32; 2],
    /// Travel from the origin, either way, per axis ($130, $131).
    pub max_travel_mm: [f32; 2],
    /// SIGN must settle this long before a pulse's leading edge ($200).
    pub dir_setup_us: f32,
    /// SIGN must stay this long after a pulse's trailing edge before it changes ($29; grblHAL
    /// numbers its step pulse delay so).
    pub dir_hold_us: f32,
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
    /// After SON goes high, the driver takes this long to hold its axis: the first pulse waits
    /// for it ($209).
    pub servo_enable_delay_ms: u32,
    /// The pen servo's pulse that holds the pen up, and down ($210, $211).
    pub pen_up_us: u32,
    pub pen_down_us: u32,
    /// How long the pen takes to get where it was sent: no pulse goes out before ($212).
    pub pen_settle_ms: u32,
    /// How the pen is lifted, see [`crate::machine_io::pen::PenLift`] ($213).
    pub pen_lift: u8,
    /// The run LED lights while a drawing runs ($214).
    pub run_led: bool,
    /// The buzzer beeps at the end of a drawing and on an alarm ($215).
    pub buzzer: bool,
    /// The language of the LCD: 0 English, 1 中文 ($216).
    pub language: Language,
}

/// Equal when every setting has the same value: one comparison through the settings table
/// rather than one per field.
impl PartialEq for Settings {
    fn eq(&self, other: &Self) -> bool {
        self.values().eq(other.values())
    }
}

impl Default for Settings {
    fn default() -> Self {
        DEFAULT_SETTINGS
    }
}

/// [`Settings::default`], one copy in flash for every caller.
const DEFAULT_SETTINGS: Settings = Settings {
    pulse_width_us: 5.0,
    servo_idle_delay_ms: SERVO_ALWAYS_ON,
    step_invert_mask: 0,
    dir_invert_mask: 0,
    son_invert: false,
    limit_pins_invert: false,
    probe_invert: false,
    status_report_mask: 1,
    junction_deviation_mm: 0.02,
    arc_tolerance_mm: 0.002,
    report_inches: false,
    soft_limits: true,
    hard_limits: false,
    homing: false,
    homing_dir_mask: 3,
    homing_locate_mm_per_min: 100.0,
    homing_seek_mm_per_min: 1_000.0,
    homing_debounce_ms: 250,
    homing_pull_off_mm: 1.0,
    spindle_max: 1_000.0,
    spindle_min: 0.0,
    laser_mode: false,
    steps_per_mm: [100.0, 100.0],
    max_rate_mm_per_min: [6_000.0, 6_000.0],
    accel_mm_per_s2: [500.0, 500.0],
    max_travel_mm: [200.0, 200.0],
    dir_setup_us: 5.0,
    dir_hold_us: 5.0,
    start_rate_mm_per_min: 300.0,
    method: Method::Diagonal,
    default_feed_mm_per_min: 3_000.0,
    max_jump_mm: 5.0,
    max_pulse_rate_hz: 20_000.0,
    input_debounce_ms: 2,
    driver_alarm_input: false,
    estop_input: false,
    servo_enable_delay_ms: 50,
    pen_up_us: 1_000,
    pen_down_us: 2_000,
    pen_settle_ms: 200,
    pen_lift: 0,
    run_led: true,
    buzzer: true,
    language: Language::English,
};

impl Settings {
    /// The current value of setting `id`.
    pub fn get(&self, id: u16) -> Result<f32, SettingError> {
        Ok(match self.clone().field(id).ok_or(SettingError::Unknown)? {
            Field::Real(v) => *v,
            Field::Whole(v) => *v as f32,
            Field::Mask(v) => f32::from(*v),
            Field::Flag(v) => f32::from(u8::from(*v)),
            Field::Method(Method::Classic) => 0.0,
            Field::Method(Method::Diagonal) => 1.0,
            Field::Language(Language::English) => 0.0,
            Field::Language(Language::Chinese) => 1.0,
        })
    }

    /// True when setting `id` takes whole numbers only (a count, a bit mask, a choice).
    pub fn is_whole(&self, id: u16) -> bool {
        !matches!(self.clone().field(id), Some(Field::Real(_)) | None)
    }

    /// The field that holds setting `id`.
    fn field(&mut self, id: u16) -> Option<Field<'_>> {
        Some(match id {
            0 => Field::Real(&mut self.pulse_width_us),
            1 => Field::Whole(&mut self.servo_idle_delay_ms),
            2 => Field::Mask(&mut self.step_invert_mask),
            3 => Field::Mask(&mut self.dir_invert_mask),
            4 => Field::Flag(&mut self.son_invert),
            5 => Field::Flag(&mut self.limit_pins_invert),
            6 => Field::Flag(&mut self.probe_invert),
            10 => Field::Mask(&mut self.status_report_mask),
            11 => Field::Real(&mut self.junction_deviation_mm),
            12 => Field::Real(&mut self.arc_tolerance_mm),
            13 => Field::Flag(&mut self.report_inches),
            20 => Field::Flag(&mut self.soft_limits),
            21 => Field::Flag(&mut self.hard_limits),
            22 => Field::Flag(&mut self.homing),
            23 => Field::Mask(&mut self.homing_dir_mask),
            24 => Field::Real(&mut self.homing_locate_mm_per_min),
            25 => Field::Real(&mut self.homing_seek_mm_per_min),
            26 => Field::Whole(&mut self.homing_debounce_ms),
            27 => Field::Real(&mut self.homing_pull_off_mm),
            29 => Field::Real(&mut self.dir_hold_us),
            30 => Field::Real(&mut self.spindle_max),
            31 => Field::Real(&mut self.spindle_min),
            32 => Field::Flag(&mut self.laser_mode),
            100 | 101 => Field::Real(&mut self.steps_per_mm[usize::from(id - 100)]),
            110 | 111 => Field::Real(&mut self.max_rate_mm_per_min[usize::from(id - 110)]),
            120 | 121 => Field::Real(&mut self.accel_mm_per_s2[usize::from(id - 120)]),
            130 | 131 => Field::Real(&mut self.max_travel_mm[usize::from(id - 130)]),
            200 => Field::Real(&mut self.dir_setup_us),
            201 => Field::Real(&mut self.start_rate_mm_per_min),
            202 => Field::Method(&mut self.method),
            203 => Field::Real(&mut self.default_feed_mm_per_min),
            204 => Field::Real(&mut self.max_jump_mm),
            205 => Field::Real(&mut self.max_pulse_rate_hz),
            206 => Field::Whole(&mut self.input_debounce_ms),
            207 => Field::Flag(&mut self.driver_alarm_input),
            208 => Field::Flag(&mut self.estop_input),
            209 => Field::Whole(&mut self.servo_enable_delay_ms),
            210 => Field::Whole(&mut self.pen_up_us),
            211 => Field::Whole(&mut self.pen_down_us),
            212 => Field::Whole(&mut self.pen_settle_ms),
            213 => Field::Mask(&mut self.pen_lift),
            214 => Field::Flag(&mut self.run_led),
            215 => Field::Flag(&mut self.buzzer),
            LANGUAGE_SETTING => Field::Language(&mut self.language),
            _ => return None,
        })
    }

    /// Sets setting `id` to `value`; out of range, unknown or not finite changes nothing.
    pub fn set(&mut self, id: u16, value: f32) -> Result<(), SettingError> {
        self.set_all(&[(id, value)])
    }

    /// Sets every `(id, value)` of `changes`, or, if one is refused or they leave the settings
    /// disagreeing, none.
    pub fn set_all(&mut self, changes: &[(u16, f32)]) -> Result<(), SettingError> {
        let mut next = *self;
        for &(id, value) in changes {
            next.assign(id, value)?;
        }
        next.check()?;
        *self = next;
        Ok(())
    }

    /// [`set_all`](Self::set_all), refusing ([`SettingError::StrandsPen`]) a change after which
    /// the pen at `pen` would lie outside the travel it lies inside now.
    pub fn set_all_around(&mut self, changes: &[(u16, f32)], pen: crate::geom::Point) -> Result<(), SettingError> {
        let mut next = *self;
        next.set_all(changes)?;
        if next.strands(pen) && !self.strands(pen) {
            return Err(SettingError::StrandsPen);
        }
        *self = next;
        Ok(())
    }

    /// Whether `pen` lies outside the travel ([`travel_steps`](Self::travel_steps)).
    pub fn strands(&self, pen: crate::geom::Point) -> bool {
        let [lx, ly] = self.travel_steps();
        !(-lx..=lx).contains(&pen.x) || !(-ly..=ly).contains(&pen.y)
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
        match self.field(id).ok_or(SettingError::Unknown)? {
            Field::Real(v) => *v = value,
            _ if !whole => return Err(SettingError::OutOfRange),
            Field::Whole(v) => *v = value as u32,
            Field::Mask(v) => *v = value as u8,
            Field::Flag(v) => *v = value != 0.0,
            Field::Method(v) => *v = if value == 0.0 { Method::Classic } else { Method::Diagonal },
            Field::Language(v) => *v = if value == 0.0 { Language::English } else { Language::Chinese },
        }
        Ok(())
    }

    /// Rules that tie settings together.
    fn check(&self) -> Result<(), SettingError> {
        match self.disagreeing() {
            Some(_) => Err(SettingError::OutOfRange),
            None => Ok(()),
        }
    }

    /// The two settings that disagree, if any: a start rate (`$201`) above the slower axis' top
    /// speed (`$110` or `$111`), a pulse (`$0`) too wide for the pulse rate (`$205`), or the S
    /// that holds the pen up (`$31`) not below the one that puts it down (`$30`).
    pub fn disagreeing(&self) -> Option<[u16; 2]> {
        let [x, y] = self.max_rate_mm_per_min;
        let (slowest_id, slowest_max) = if x <= y { (110, x) } else { (111, y) };
        if self.start_rate_mm_per_min > slowest_max {
            return Some([201, slowest_id]);
        }
        if !self.pulse_fits_in_period() {
            return Some([0, 205]);
        }
        if self.spindle_min >= self.spindle_max {
            return Some([31, 30]);
        }
        None
    }

    /// The two settings `changes` (each in its range) would leave disagreeing, if any: why
    /// [`set_all`](Self::set_all) refuses them.
    pub fn clash(&self, changes: &[(u16, f32)]) -> Option<[u16; 2]> {
        let mut next = *self;
        for &(id, value) in changes {
            next.assign(id, value).ok()?;
        }
        next.disagreeing()
    }

    /// True when a pulse of `$0` and as long again with PULS low fit in one period of `$205`,
    /// in whole step ticks as the step timer counts them: what caps `$205` (at 2.5 µs, 200 kHz).
    pub fn pulse_fits_in_period(&self) -> bool {
        let width_ticks = crate::geom::us_to_ticks(self.pulse_width_us);
        let period_ticks = crate::math::ceil(crate::geom::TICK_HZ as f32 / self.max_pulse_rate_hz) as u32;
        2 * width_ticks <= period_ticks
    }

    /// The travel limits in steps, either way from machine zero: the lattice points the pen may
    /// reach. With soft limits (`$20`) those of `$130`, `$131`: the pen stays inside the travel
    /// (homing, `$22`, puts machine zero in its middle); without, [`UNCHECKED_TRAVEL_STEPS`].
    /// The one travel check: the drawing builder, the curves' guard and the jogs all use it.
    pub fn travel_steps(&self) -> [i32; 2] {
        if !self.soft_limits {
            return [UNCHECKED_TRAVEL_STEPS; 2];
        }
        self.configured_travel_steps()
    }

    /// `$130`, `$131` in steps, soft limits or not.
    pub fn configured_travel_steps(&self) -> [i32; 2] {
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
    fn set_all_changes_everything_or_nothing() {
        let mut s = Settings::default();
        // $201 above the new $110 leaves them disagreeing: nothing changes.
        assert_eq!(s.set_all(&[(203, 1000.0), (110, 200.0)]), Err(SettingError::OutOfRange));
        assert_eq!(s, Settings::default());
        assert_eq!(s.set_all(&[(203, 1000.0), (110, 4000.0)]), Ok(()));
        assert_eq!((s.default_feed_mm_per_min, s.max_rate_mm_per_min), (1000.0, [4000.0, 6000.0]));
    }

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
    fn a_clash_names_the_two_settings_that_disagree() {
        let s = Settings::default();
        assert_eq!(s.clash(&[(201, 7_000.0)]), Some([201, 110]));
        assert_eq!(s.clash(&[(111, 3_000.0), (201, 4_000.0)]), Some([201, 111]), "the slower axis");
        assert_eq!(s.clash(&[(0, 100.0)]), Some([0, 205]));
        assert_eq!(s.clash(&[(201, 500.0)]), None, "they agree");
        assert_eq!(s.clash(&[(100, 0.0)]), None, "out of range: no clash");
    }

    #[test]
    fn millimetres_round_to_the_nearest_step() {
        let s = Settings::default();
        assert_eq!(s.mm_to_steps(crate::geom::Axis::X, 10.0), 1000);
        assert_eq!(s.mm_to_steps(crate::geom::Axis::Y, -0.004), 0);
        assert_eq!(s.mm_to_steps(crate::geom::Axis::Y, -0.006), -1);
    }
}

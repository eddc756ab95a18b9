//! The keypad menu: a state machine from key events to machine actions.
//!
//! [`Menu::handle`] takes one [`KeyEvent`] with the machine's status and settings and returns
//! one [`MenuAction`]; it never reads a clock and never waits. What the screen shows is read
//! back from the menu (see [`crate::ui::screen`]); the menu does not draw.
//!
//! Keys:
//!
//! - Mode list: `1`..`7` enter a mode; `A`/`B` move the cursor up/down (they repeat when held,
//!   stopping at the ends); `#` enters the mode under the cursor.
//! - Everywhere: `D` goes back to the mode list; while the machine moves (run, hold, jog) `D`
//!   aborts instead, and while a keypad jog is held it stops the jog. `C` holds a running job
//!   and resumes a held one. While a job runs or is held, every other key is ignored.
//! - Number fields: digits; `*` decimal point; `A` sign; `B` deletes the last character (held,
//!   it repeats but stays in the field; pressed on an empty field it goes back to the previous
//!   field); `C` clears the field; `#` checks the value and moves on, and on the last field
//!   starts the job. A value that is refused shows why and stays for correction.
//! - Jog: hold `1`-`4`, `6`-`9` to move (see [`JOG_KEYS`]); releasing the key stops.
//!
//! Every keypad drawing starts at the pen and is typed relative to it: a line is typed as its
//! offset (dX, dY) from the pen; curves are placed as described in [`crate::ui::curves`]. So
//! that "the pen" is where the job will really start, the menu starts a job only while the
//! machine is idle with nothing queued.

use core::ops::RangeInclusive;

use crate::geom::{Axis, Point, Step};
use crate::job::{Control, Feed, Job, Shape};
use crate::keypad::{Key, KeyEvent};
use crate::settings::Settings;
use crate::status::{RunState, Status};
use crate::ui::curves::{
    CircleParams, CurveJob, CurveParams, EllipseParams, Extent, FunctionParams, FunctionPreset, SineParams,
};
use crate::ui::entry::{EntryError, NumberEntry};

/// Line: offset of the end point from the pen, per axis.
pub const LINE_DELTA_RANGE_MM: RangeInclusive<f32> = -1000.0..=1000.0;
/// Circle: radius.
pub const CIRCLE_RADIUS_RANGE_MM: RangeInclusive<f32> = 0.1..=500.0;
/// Ellipse: semi-axes along X (a) and Y (b).
pub const ELLIPSE_SEMI_AXIS_RANGE_MM: RangeInclusive<f32> = 0.1..=500.0;
/// Circle and ellipse: angle of the pen on the curve, seen from the centre.
pub const ARC_START_RANGE_DEG: RangeInclusive<f32> = -360.0..=360.0;
/// Circle and ellipse: angle turned, positive counter-clockwise; 0 (or empty) is a full turn.
pub const ARC_SWEEP_RANGE_DEG: RangeInclusive<f32> = -360.0..=360.0;
/// Sine: amplitude (negative starts downwards).
pub const SINE_AMPLITUDE_RANGE_MM: RangeInclusive<f32> = -250.0..=250.0;
/// Sine: length of one wave along X.
pub const SINE_PERIOD_RANGE_MM: RangeInclusive<f32> = 1.0..=1000.0;
/// Sine: phase at the pen.
pub const SINE_PHASE_RANGE_DEG: RangeInclusive<f32> = -360.0..=360.0;
/// Sine: length along X (negative draws towards −X; never 0).
pub const SINE_LENGTH_RANGE_MM: RangeInclusive<f32> = -1000.0..=1000.0;
/// Function: x0 and x1 of y = f(x).
pub const FUNCTION_X_RANGE_MM: RangeInclusive<f32> = -1000.0..=1000.0;

/// Most fields one form has.
pub const FORM_MAX_FIELDS: usize = 4;

/// The eight jog keys, around `5` as they sit on the keypad (`2` is above `5`): `2` is +Y, `8`
/// −Y, `4` −X, `6` +X, and `1`, `3`, `7`, `9` the diagonals.
pub const JOG_KEYS: [(u8, Step); 8] = [
    (2, Step::YP),
    (8, Step::YN),
    (4, Step::XN),
    (6, Step::XP),
    (1, Step::new(-1, 1)),
    (3, Step::new(1, 1)),
    (7, Step::new(-1, -1)),
    (9, Step::new(1, -1)),
];

/// The jog direction of a key; `None` for keys that do not jog.
pub fn jog_step(key: Key) -> Option<Step> {
    match key {
        Key::Digit(d) => JOG_KEYS.iter().find(|(k, _)| *k == d).map(|&(_, s)| s),
        _ => None,
    }
}

/// What the menu asks the machine to do.
// A started job carries its shape by value (no heap).
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum MenuAction {
    None,
    /// Queue a job.
    Start(Job),
    /// Queue a curve, starting at the pen (circle, ellipse, sine, function).
    StartCurve(CurveJob),
    /// Hold, resume or abort the motion in progress.
    Control(Control),
    /// Start jogging in one of the 8 step directions until [`MenuAction::JogStop`].
    JogStart(Step),
    JogStop,
}

/// A top-level mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Mode {
    Jog,
    Line,
    Circle,
    Ellipse,
    Sine,
    Function,
    Settings,
}

impl Mode {
    /// Every mode, in menu order: `1` picks the first.
    pub const ALL: [Mode; 7] =
        [Mode::Jog, Mode::Line, Mode::Circle, Mode::Ellipse, Mode::Sine, Mode::Function, Mode::Settings];

    /// Screen title.
    pub const fn title(self) -> &'static str {
        match self {
            Mode::Jog => "JOG",
            Mode::Line => "LINE",
            Mode::Circle => "CIRCLE/ARC",
            Mode::Ellipse => "ELLIPSE",
            Mode::Sine => "SINE",
            Mode::Function => "FUNCTION",
            Mode::Settings => "SETTINGS",
        }
    }

    /// Entry in the mode list.
    pub const fn label(self) -> &'static str {
        match self {
            Mode::Jog => "Jog",
            Mode::Line => "Line",
            Mode::Circle => "Circle/arc",
            Mode::Ellipse => "Ellipse",
            Mode::Sine => "Sine wave",
            Mode::Function => "Function y=f(x)",
            Mode::Settings => "Settings",
        }
    }

    /// Position in [`Mode::ALL`].
    pub fn index(self) -> usize {
        Mode::ALL.iter().position(|&m| m == self).unwrap_or(0)
    }

    /// The fields of the mode's form; empty for modes without one.
    pub const fn fields(self) -> &'static [Field] {
        match self {
            Mode::Line => LINE_FIELDS,
            Mode::Circle => CIRCLE_FIELDS,
            Mode::Ellipse => ELLIPSE_FIELDS,
            Mode::Sine => SINE_FIELDS,
            Mode::Function => FUNCTION_FIELDS,
            Mode::Jog | Mode::Settings => &[],
        }
    }
}

/// Unit of a number field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Unit {
    Mm,
    Deg,
}

impl Unit {
    pub const fn symbol(self) -> &'static str {
        match self {
            Unit::Mm => "mm",
            Unit::Deg => "deg",
        }
    }
}

/// A number to type: its name, unit, range, and what an empty field means.
#[derive(Clone, Debug, PartialEq)]
pub struct NumberField {
    pub label: &'static str,
    pub unit: Unit,
    pub range: RangeInclusive<f32>,
    /// Used when `#` confirms an empty field; `None`: a value is required.
    pub default: Option<f32>,
    pub zero_allowed: bool,
    /// One line of help shown under the field.
    pub hint: &'static str,
}

impl NumberField {
    /// The value of `entry` for this field, checked.
    pub fn value(&self, entry: &NumberEntry) -> Result<f32, UiError> {
        let v = match entry.value().map_err(UiError::Entry)? {
            Some(v) => v,
            None => self.default.ok_or(UiError::Empty)?,
        };
        if !v.is_finite() || !self.range.contains(&v) {
            return Err(UiError::OutOfRange { min: *self.range.start(), max: *self.range.end(), unit: self.unit });
        }
        if v == 0.0 && !self.zero_allowed {
            return Err(UiError::Zero);
        }
        Ok(v)
    }
}

/// One field of a form.
#[derive(Clone, Debug, PartialEq)]
pub enum Field {
    Number(NumberField),
    /// Choice of a [`FunctionPreset`]: `1`..`5` pick, `A`/`B` step, `#` confirms.
    Preset,
}

const HINT_NUMBER: &str = "#ok *. A- Bdel Dback";

const fn mm(label: &'static str, range: RangeInclusive<f32>, zero_allowed: bool, hint: &'static str) -> Field {
    Field::Number(NumberField { label, unit: Unit::Mm, range, default: None, zero_allowed, hint })
}

const fn deg(label: &'static str, range: RangeInclusive<f32>, hint: &'static str) -> Field {
    Field::Number(NumberField { label, unit: Unit::Deg, range, default: Some(0.0), zero_allowed: true, hint })
}

const LINE_FIELDS: &[Field] = &[
    mm("dX", LINE_DELTA_RANGE_MM, true, "X offset from the pen"),
    mm("dY", LINE_DELTA_RANGE_MM, true, "Y offset from the pen"),
];
const CIRCLE_FIELDS: &[Field] = &[
    mm("Radius", CIRCLE_RADIUS_RANGE_MM, false, HINT_NUMBER),
    deg("Start", ARC_START_RANGE_DEG, "Pen angle, empty = 0"),
    deg("Sweep", ARC_SWEEP_RANGE_DEG, "0/empty = full, -=CW"),
];
const ELLIPSE_FIELDS: &[Field] = &[
    mm("a (X)", ELLIPSE_SEMI_AXIS_RANGE_MM, false, "Semi-axis along X"),
    mm("b (Y)", ELLIPSE_SEMI_AXIS_RANGE_MM, false, "Semi-axis along Y"),
    deg("Start", ARC_START_RANGE_DEG, "Pen angle, empty = 0"),
    deg("Sweep", ARC_SWEEP_RANGE_DEG, "0/empty = full, -=CW"),
];
const SINE_FIELDS: &[Field] = &[
    mm("Amplitude", SINE_AMPLITUDE_RANGE_MM, true, HINT_NUMBER),
    mm("Period", SINE_PERIOD_RANGE_MM, false, "One wave along X"),
    deg("Phase", SINE_PHASE_RANGE_DEG, "Empty = 0"),
    mm("Length", SINE_LENGTH_RANGE_MM, false, "Along X, - = leftwards"),
];
const FUNCTION_FIELDS: &[Field] = &[
    Field::Preset,
    mm("x0", FUNCTION_X_RANGE_MM, true, "Start x (at the pen)"),
    mm("x1", FUNCTION_X_RANGE_MM, true, "End x"),
];

/// Why the menu refused a key or a job; shown until the next key.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum UiError {
    Entry(EntryError),
    /// `#` on an empty field that has no default.
    Empty,
    OutOfRange {
        min: f32,
        max: f32,
        unit: Unit,
    },
    /// Zero where the field needs a length.
    Zero,
    /// A function's x1 equals its x0.
    SameEnds,
    /// The function is undefined somewhere between x0 and x1.
    Domain,
    /// A sine rises faster between two steps than the max function jump (`$204`) allows.
    TooSteep,
    /// The drawing would leave the travel area ($130, $131).
    Travel,
    /// The machine is moving or has jobs queued.
    Busy,
    /// An alarm locks motion.
    Alarm,
}

/// A keypad jog in progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ActiveJog {
    /// The key being held.
    pub key: Key,
    pub step: Step,
}

/// The form of a drawing mode: which field is being typed and what was typed so far.
#[derive(Clone, Debug, PartialEq)]
pub struct Form {
    mode: Mode,
    field: usize,
    entries: [NumberEntry; FORM_MAX_FIELDS],
    preset: FunctionPreset,
}

impl Form {
    fn new(mode: Mode) -> Self {
        Form {
            mode,
            field: 0,
            entries: [const { NumberEntry::new() }; FORM_MAX_FIELDS],
            preset: FunctionPreset::Parabola,
        }
    }

    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Index of the field being typed.
    pub fn field_index(&self) -> usize {
        self.field
    }

    /// The field being typed.
    pub fn field(&self) -> Option<&'static Field> {
        self.mode.fields().get(self.field)
    }

    /// The text of the field being typed.
    pub fn entry(&self) -> &NumberEntry {
        &self.entries[self.field.min(FORM_MAX_FIELDS - 1)]
    }

    /// The function chosen (function mode).
    pub fn preset(&self) -> FunctionPreset {
        self.preset
    }

    fn press(&mut self, key: Key, repeated: bool, status: &Status, settings: &Settings) -> Result<MenuAction, UiError> {
        let Some(field) = self.field() else { return Ok(MenuAction::None) };
        let entry = &mut self.entries[self.field.min(FORM_MAX_FIELDS - 1)];
        match (field, key) {
            (_, Key::Hash) => return self.confirm(status, settings),
            (Field::Preset, Key::Digit(d)) => {
                if let Some(&p) = (d as usize).checked_sub(1).and_then(|i| FunctionPreset::ALL.get(i)) {
                    self.preset = p;
                }
            }
            (Field::Preset, Key::A) => self.preset = FunctionPreset::ALL[self.preset.index().saturating_sub(1)],
            (Field::Preset, Key::B) => {
                self.preset = FunctionPreset::ALL[(self.preset.index() + 1).min(FunctionPreset::ALL.len() - 1)]
            }
            (Field::Number(_), Key::Digit(d)) => entry.push_digit(d).map_err(UiError::Entry)?,
            (Field::Number(_), Key::Star) => entry.push_point().map_err(UiError::Entry)?,
            (Field::Number(_), Key::A) => entry.toggle_sign(),
            (Field::Number(_), Key::B) => {
                let deleted = entry.backspace();
                // An empty field gives way to the previous one, on a fresh press only.
                if !deleted && !repeated && self.field > 0 {
                    self.field -= 1;
                }
            }
            (Field::Number(_), Key::C) => entry.clear(),
            _ => {}
        }
        Ok(MenuAction::None)
    }

    /// `#`: checks the field, then moves on or, after the last one, builds the job.
    fn confirm(&mut self, status: &Status, settings: &Settings) -> Result<MenuAction, UiError> {
        if let Some(Field::Number(spec)) = self.field() {
            spec.value(self.entry())?;
        }
        if self.field + 1 < self.mode.fields().len() {
            self.field += 1;
            return Ok(MenuAction::None);
        }
        let action = self.build(status, settings)?;
        *self = Form { preset: self.preset, ..Form::new(self.mode) };
        Ok(action)
    }

    /// The checked value of number field `i`.
    fn number(&self, i: usize) -> Result<f32, UiError> {
        match (self.mode.fields().get(i), self.entries.get(i)) {
            (Some(Field::Number(spec)), Some(entry)) => spec.value(entry),
            _ => Err(UiError::Empty),
        }
    }

    /// A full or partial turn: 0 means a full counter-clockwise turn.
    fn sweep(&self, i: usize) -> Result<f32, UiError> {
        let sweep = self.number(i)?;
        Ok(if sweep == 0.0 { 360.0 } else { sweep })
    }

    /// The typed curve (every mode but line).
    pub fn curve(&self) -> Result<CurveParams, UiError> {
        Ok(match self.mode {
            Mode::Circle => CurveParams::Circle(CircleParams {
                radius_mm: self.number(0)?,
                start_deg: self.number(1)?,
                sweep_deg: self.sweep(2)?,
            }),
            Mode::Ellipse => CurveParams::Ellipse(EllipseParams {
                a_mm: self.number(0)?,
                b_mm: self.number(1)?,
                start_deg: self.number(2)?,
                sweep_deg: self.sweep(3)?,
            }),
            Mode::Sine => CurveParams::Sine(SineParams {
                amplitude_mm: self.number(0)?,
                period_mm: self.number(1)?,
                phase_deg: self.number(2)?,
                length_mm: self.number(3)?,
            }),
            Mode::Function => {
                let (x0_mm, x1_mm) = (self.number(1)?, self.number(2)?);
                if x0_mm == x1_mm {
                    return Err(UiError::SameEnds);
                }
                CurveParams::Function(FunctionParams { preset: self.preset, x0_mm, x1_mm })
            }
            Mode::Jog | Mode::Line | Mode::Settings => return Err(UiError::Empty),
        })
    }

    /// The job the form describes, from the pen at `status.position`.
    fn build(&self, status: &Status, settings: &Settings) -> Result<MenuAction, UiError> {
        let feed = Feed::MmPerMin(settings.default_feed_mm_per_min);
        let start = status.position;
        let action = if self.mode == Mode::Line {
            let to = offset(start, self.number(0)?, self.number(1)?, settings);
            if !within_travel(to, settings) {
                return Err(UiError::Travel);
            }
            MenuAction::Start(Job::draw(Shape::Line { to }, feed))
        } else {
            let curve = self.curve()?;
            let extent = curve.extent().ok_or(UiError::Domain)?;
            if !extent_within_travel(start, &extent, settings) {
                return Err(UiError::Travel);
            }
            let job = CurveJob { start, curve, feed };
            if let Ok(Job { shape: Shape::Sine { amplitude_steps, omega_rad_per_step, .. }, .. }) = job.to_job(settings)
                && !crate::interp::sine::fits_jump_limit(amplitude_steps, omega_rad_per_step, settings)
            {
                return Err(UiError::TooSteep);
            }
            MenuAction::StartCurve(job)
        };
        match status.state {
            RunState::Alarm => Err(UiError::Alarm),
            RunState::Idle if status.queued_jobs == 0 => Ok(action),
            _ => Err(UiError::Busy),
        }
    }
}

/// `start` moved by (`dx_mm`, `dy_mm`), in steps.
fn offset(start: Point, dx_mm: f32, dy_mm: f32, settings: &Settings) -> Point {
    Point::new(
        start.x.saturating_add(settings.mm_to_steps(Axis::X, dx_mm)),
        start.y.saturating_add(settings.mm_to_steps(Axis::Y, dy_mm)),
    )
}

/// True when `p` is inside the travel area: |x|, |y| within max travel ($130, $131).
fn within_travel(p: Point, settings: &Settings) -> bool {
    Axis::ALL.into_iter().all(|axis| {
        let limit = settings.mm_to_steps(axis, settings.max_travel_mm[axis.index()]);
        let v = match axis {
            Axis::X => p.x,
            Axis::Y => p.y,
        };
        (-limit..=limit).contains(&v)
    })
}

/// True when a drawing covering `extent` from `start` stays inside the travel area.
fn extent_within_travel(start: Point, extent: &Extent, settings: &Settings) -> bool {
    within_travel(offset(start, extent.x_min_mm, extent.y_min_mm, settings), settings)
        && within_travel(offset(start, extent.x_max_mm, extent.y_max_mm, settings), settings)
}

/// What the menu shows.
#[derive(Clone, Debug, PartialEq)]
pub enum Screen {
    /// The mode list.
    Modes,
    Jog,
    Form(Form),
    /// Read-only list of the main settings, scrolled to `first_line`.
    Settings {
        first_line: usize,
    },
}

/// The keypad menu; see the module documentation.
#[derive(Clone, Debug, PartialEq)]
pub struct Menu {
    screen: Screen,
    /// Cursor in the mode list.
    selected: Mode,
    message: Option<UiError>,
    jog: Option<ActiveJog>,
}

impl Default for Menu {
    fn default() -> Self {
        Self::new()
    }
}

impl Menu {
    /// The mode list, cursor on the first mode.
    pub const fn new() -> Self {
        Menu { screen: Screen::Modes, selected: Mode::Jog, message: None, jog: None }
    }

    pub fn screen(&self) -> &Screen {
        &self.screen
    }

    /// The mode under the cursor of the mode list.
    pub fn selected(&self) -> Mode {
        self.selected
    }

    /// The error to show, if any.
    pub fn message(&self) -> Option<UiError> {
        self.message
    }

    /// The keypad jog in progress, if any.
    pub fn jog(&self) -> Option<ActiveJog> {
        self.jog
    }

    /// Shows why the job just confirmed could not start (the job queue was full, the curve
    /// could not be built).
    pub fn refuse(&mut self, why: UiError) {
        self.message = Some(why);
    }

    /// True while the machine's motion takes the keypad: only `C` and `D` act. A jog counts
    /// only outside the jog screen (inside it, the jog keys steer it).
    pub fn is_busy(&self, status: &Status) -> bool {
        match status.state {
            RunState::Run | RunState::Hold => true,
            RunState::Jog => self.screen != Screen::Jog,
            RunState::Idle | RunState::Alarm => false,
        }
    }

    /// Handles one key event.
    pub fn handle(&mut self, event: KeyEvent, status: &Status, settings: &Settings) -> MenuAction {
        let action = match event {
            KeyEvent::Press(key) => self.press(key, false, status, settings),
            KeyEvent::Repeat(key) if self.repeats(key, status) => self.press(key, true, status, settings),
            KeyEvent::Repeat(_) => MenuAction::None,
            KeyEvent::Release(key) => match self.jog {
                Some(jog) if jog.key == key => {
                    self.jog = None;
                    MenuAction::JogStop
                }
                _ => MenuAction::None,
            },
        };
        if action != MenuAction::None {
            debug!("menu: {:?}", action);
        }
        action
    }

    /// True when a held `key` repeats on the current screen: only moves through lists and
    /// deleting characters, never anything that starts motion or leaves a screen.
    fn repeats(&self, key: Key, status: &Status) -> bool {
        if self.is_busy(status) {
            return false;
        }
        match &self.screen {
            Screen::Modes | Screen::Settings { .. } => matches!(key, Key::A | Key::B),
            Screen::Form(form) => match form.field() {
                Some(Field::Preset) => matches!(key, Key::A | Key::B),
                Some(Field::Number(_)) => key == Key::B,
                None => false,
            },
            Screen::Jog => false,
        }
    }

    fn press(&mut self, key: Key, repeated: bool, status: &Status, settings: &Settings) -> MenuAction {
        self.message = None;
        if key == Key::D {
            if self.jog.take().is_some() {
                return MenuAction::JogStop;
            }
            if matches!(status.state, RunState::Run | RunState::Hold | RunState::Jog) {
                return MenuAction::Control(Control::Abort);
            }
            self.screen = Screen::Modes;
            return MenuAction::None;
        }
        match (key, status.state) {
            (Key::C, RunState::Run) => return MenuAction::Control(Control::Hold),
            (Key::C, RunState::Hold) => return MenuAction::Control(Control::Resume),
            _ if self.is_busy(status) => return MenuAction::None,
            _ => {}
        }
        let result = match &mut self.screen {
            Screen::Modes => {
                self.press_modes(key);
                Ok(MenuAction::None)
            }
            Screen::Settings { first_line } => {
                let last =
                    crate::ui::screen::SETTINGS_VIEW_LINES.saturating_sub(crate::ui::screen::SETTINGS_VISIBLE_LINES);
                match key {
                    Key::A => *first_line = first_line.saturating_sub(1),
                    Key::B => *first_line = (*first_line + 1).min(last),
                    _ => {}
                }
                Ok(MenuAction::None)
            }
            Screen::Jog => match jog_step(key) {
                Some(_) if status.state == RunState::Alarm => Err(UiError::Alarm),
                Some(step) => {
                    self.jog = Some(ActiveJog { key, step });
                    Ok(MenuAction::JogStart(step))
                }
                None => Ok(MenuAction::None),
            },
            Screen::Form(form) => form.press(key, repeated, status, settings),
        };
        result.unwrap_or_else(|e| {
            self.message = Some(e);
            MenuAction::None
        })
    }

    fn press_modes(&mut self, key: Key) {
        let last = Mode::ALL.len() - 1;
        match key {
            Key::Digit(d) => {
                if let Some(&mode) = (d as usize).checked_sub(1).and_then(|i| Mode::ALL.get(i)) {
                    self.enter(mode);
                }
            }
            Key::A => self.selected = Mode::ALL[self.selected.index().saturating_sub(1)],
            Key::B => self.selected = Mode::ALL[(self.selected.index() + 1).min(last)],
            Key::Hash => self.enter(self.selected),
            _ => {}
        }
    }

    fn enter(&mut self, mode: Mode) {
        self.selected = mode;
        self.screen = match mode {
            Mode::Jog => Screen::Jog,
            Mode::Settings => Screen::Settings { first_line: 0 },
            _ => Screen::Form(Form::new(mode)),
        };
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    fn key(ch: char) -> Key {
        match ch {
            '0'..='9' => Key::Digit(ch as u8 - b'0'),
            'A' => Key::A,
            'B' => Key::B,
            'C' => Key::C,
            'D' => Key::D,
            '*' => Key::Star,
            '#' => Key::Hash,
            _ => panic!("no key {ch}"),
        }
    }

    /// Presses each key of `keys` (spaces ignored); returns the actions other than `None`.
    fn type_keys(menu: &mut Menu, keys: &str, status: &Status) -> Vec<MenuAction> {
        keys.chars()
            .filter(|c| !c.is_whitespace())
            .map(|c| menu.handle(KeyEvent::Press(key(c)), status, &Settings::default()))
            .filter(|a| *a != MenuAction::None)
            .collect()
    }

    fn idle() -> Status {
        Status::default()
    }

    fn line(x: i32, y: i32) -> MenuAction {
        MenuAction::Start(Job::draw(Shape::Line { to: Point::new(x, y) }, Feed::MmPerMin(3_000.0)))
    }

    fn form(menu: &Menu) -> &Form {
        match menu.screen() {
            Screen::Form(f) => f,
            s => panic!("not a form: {s:?}"),
        }
    }

    #[test]
    fn line_mode_starts_a_line_in_steps() {
        let mut m = Menu::new();
        assert_eq!(type_keys(&mut m, "2 10# 5#", &idle()), [line(1000, 500)]);
        // The form is ready for the next line, empty.
        assert_eq!(form(&m).field_index(), 0);
        assert!(form(&m).entry().is_empty());
    }

    #[test]
    fn line_is_relative_to_the_pen() {
        let mut m = Menu::new();
        let status = Status { position: Point::new(200, -300), ..Status::default() };
        assert_eq!(type_keys(&mut m, "2 10# 5#", &status), [line(1200, 200)]);
    }

    #[test]
    fn backspace_sign_and_decimal_point() {
        let mut m = Menu::new();
        // "12" then delete the 2, point, 5, minus: -1.5 mm. Then 0.25 mm.
        assert_eq!(type_keys(&mut m, "2 12B*5A# *25#", &idle()), [line(-150, 25)]);
    }

    #[test]
    fn out_of_range_keeps_the_field_for_correction() {
        let mut m = Menu::new();
        assert_eq!(type_keys(&mut m, "2 2000#", &idle()), []);
        assert_eq!(m.message(), Some(UiError::OutOfRange { min: -1000.0, max: 1000.0, unit: Unit::Mm }));
        assert_eq!(form(&m).field_index(), 0);
        assert_eq!(form(&m).entry().digits(), "2000");
        // Any key clears the message; fix the value and go on.
        assert_eq!(type_keys(&mut m, "B#", &idle()), []);
        assert_eq!(m.message(), None);
        assert_eq!(type_keys(&mut m, "0#", &idle()), [line(20_000, 0)]);
    }

    #[test]
    fn empty_and_malformed_fields_are_refused() {
        let mut m = Menu::new();
        assert_eq!(type_keys(&mut m, "2#", &idle()), []);
        assert_eq!(m.message(), Some(UiError::Empty));
        assert_eq!(type_keys(&mut m, "A#", &idle()), []);
        assert_eq!(m.message(), Some(UiError::Entry(EntryError::NotANumber)));
        assert_eq!(type_keys(&mut m, "C12345678 9", &idle()), []);
        assert_eq!(m.message(), Some(UiError::Entry(EntryError::TooLong)));
        assert_eq!(form(&m).entry().digits(), "12345678");
    }

    #[test]
    fn beyond_travel_nothing_starts() {
        let mut m = Menu::new();
        // Pen at X 100 mm; 150 mm further is past the 200 mm travel.
        let status = Status { position: Point::new(10_000, 0), ..Status::default() };
        assert_eq!(type_keys(&mut m, "2 150# 0#", &status), []);
        assert_eq!(m.message(), Some(UiError::Travel));
        // The last field keeps its text; delete it, go back to dX and correct that.
        assert_eq!(form(&m).field_index(), 1);
        assert_eq!(form(&m).entry().digits(), "0");
        assert_eq!(type_keys(&mut m, "B B BBB 100# 0#", &status), [line(20_000, 0)]);
    }

    #[test]
    fn held_backspace_stays_in_its_field() {
        let mut m = Menu::new();
        let s = Settings::default();
        type_keys(&mut m, "2 7# 123", &idle());
        for _ in 0..10 {
            m.handle(KeyEvent::Repeat(Key::B), &idle(), &s);
        }
        assert_eq!(form(&m).field_index(), 1);
        assert!(form(&m).entry().is_empty());
        // A fresh press on the empty field goes back to dX, text intact.
        m.handle(KeyEvent::Press(Key::B), &idle(), &s);
        assert_eq!(form(&m).field_index(), 0);
        assert_eq!(form(&m).entry().digits(), "7");
        // The sign key does not repeat.
        m.handle(KeyEvent::Repeat(Key::A), &idle(), &s);
        assert!(!form(&m).entry().is_negative());
    }

    #[test]
    fn run_hold_resume_abort() {
        let mut m = Menu::new();
        type_keys(&mut m, "2 1", &idle());
        let run = Status { state: RunState::Run, ..Status::default() };
        let hold = Status { state: RunState::Hold, ..Status::default() };
        assert_eq!(type_keys(&mut m, "C", &run), [MenuAction::Control(Control::Hold)]);
        assert_eq!(type_keys(&mut m, "C", &hold), [MenuAction::Control(Control::Resume)]);
        // Digits and # do nothing while a job runs; D aborts and leaves the form as it was.
        assert_eq!(type_keys(&mut m, "5#", &run), []);
        assert_eq!(type_keys(&mut m, "D", &run), [MenuAction::Control(Control::Abort)]);
        assert_eq!(type_keys(&mut m, "D", &hold), [MenuAction::Control(Control::Abort)]);
        assert_eq!(form(&m).entry().digits(), "1");
        // Idle again: D goes back to the mode list.
        assert_eq!(type_keys(&mut m, "D", &idle()), []);
        assert_eq!(*m.screen(), Screen::Modes);
    }

    #[test]
    fn no_job_while_busy_or_in_alarm() {
        let mut m = Menu::new();
        let queued = Status { queued_jobs: 1, ..Status::default() };
        assert_eq!(type_keys(&mut m, "2 1# 1#", &queued), []);
        assert_eq!(m.message(), Some(UiError::Busy));
        let alarm = Status { state: RunState::Alarm, ..Status::default() };
        assert_eq!(type_keys(&mut m, "#", &alarm), []);
        assert_eq!(m.message(), Some(UiError::Alarm));
        assert_eq!(type_keys(&mut m, "#", &idle()), [line(100, 100)]);
    }

    #[test]
    fn jog_keys_start_and_stop_the_jog() {
        let mut m = Menu::new();
        let s = Settings::default();
        type_keys(&mut m, "1", &idle());
        assert_eq!(*m.screen(), Screen::Jog);
        let jogging = Status { state: RunState::Jog, ..Status::default() };
        for (k, step) in
            [(2, Step::YP), (8, Step::YN), (4, Step::XN), (6, Step::XP), (3, Step::new(1, 1)), (7, Step::new(-1, -1))]
        {
            assert_eq!(m.handle(KeyEvent::Press(Key::Digit(k)), &idle(), &s), MenuAction::JogStart(step));
            assert_eq!(m.handle(KeyEvent::Release(Key::Digit(k)), &jogging, &s), MenuAction::JogStop);
        }
        assert_eq!(m.handle(KeyEvent::Press(Key::Digit(5)), &idle(), &s), MenuAction::None);
        // Releasing a key other than the jogging one does not stop it.
        assert_eq!(m.handle(KeyEvent::Press(Key::Digit(1)), &idle(), &s), MenuAction::JogStart(Step::new(-1, 1)));
        assert_eq!(m.handle(KeyEvent::Release(Key::Digit(5)), &jogging, &s), MenuAction::None);
        // D while the key is held stops the jog; the late release then does nothing.
        assert_eq!(m.handle(KeyEvent::Press(Key::D), &jogging, &s), MenuAction::JogStop);
        assert_eq!(m.handle(KeyEvent::Release(Key::Digit(7)), &jogging, &s), MenuAction::None);
        // No jog in alarm.
        let alarm = Status { state: RunState::Alarm, ..Status::default() };
        assert_eq!(m.handle(KeyEvent::Press(Key::Digit(3)), &alarm, &s), MenuAction::None);
        assert_eq!(m.message(), Some(UiError::Alarm));
    }

    #[test]
    fn mode_list_by_digit_and_by_navigation() {
        let mut m = Menu::new();
        let s = Settings::default();
        m.handle(KeyEvent::Press(Key::A), &idle(), &s);
        assert_eq!(m.selected(), Mode::Jog, "stops at the top");
        m.handle(KeyEvent::Press(Key::B), &idle(), &s);
        m.handle(KeyEvent::Repeat(Key::B), &idle(), &s);
        assert_eq!(m.selected(), Mode::Circle);
        for _ in 0..20 {
            m.handle(KeyEvent::Repeat(Key::B), &idle(), &s);
        }
        assert_eq!(m.selected(), Mode::Settings, "stops at the bottom, no wrap");
        m.handle(KeyEvent::Press(Key::A), &idle(), &s);
        m.handle(KeyEvent::Press(Key::Hash), &idle(), &s);
        assert_eq!(form(&m).mode(), Mode::Function);
        type_keys(&mut m, "D 4", &idle());
        assert_eq!(form(&m).mode(), Mode::Ellipse);
        type_keys(&mut m, "D 7", &idle());
        assert_eq!(*m.screen(), Screen::Settings { first_line: 0 });
    }

    fn curve(action: &MenuAction) -> CurveParams {
        match action {
            MenuAction::StartCurve(job) => job.curve,
            a => panic!("not a curve: {a:?}"),
        }
    }

    #[test]
    fn circle_defaults_to_a_full_turn() {
        let mut m = Menu::new();
        let status = Status { position: Point::new(1000, 0), ..Status::default() };
        let actions = type_keys(&mut m, "3 10# # #", &status);
        assert_eq!(actions.len(), 1);
        assert_eq!(
            curve(&actions[0]),
            CurveParams::Circle(CircleParams { radius_mm: 10.0, start_deg: 0.0, sweep_deg: 360.0 })
        );
        let MenuAction::StartCurve(job) = &actions[0] else { unreachable!() };
        assert_eq!(job.start, Point::new(1000, 0));
        // A half turn clockwise from the top.
        let actions = type_keys(&mut m, "3# 90# A180#", &status);
        assert_eq!(
            curve(&actions[0]),
            CurveParams::Circle(CircleParams { radius_mm: 3.0, start_deg: 90.0, sweep_deg: -180.0 })
        );
        // Radius 0 is refused; a circle leaving the travel area too.
        assert_eq!(type_keys(&mut m, "0#", &status), []);
        assert_eq!(m.message(), Some(UiError::OutOfRange { min: 0.1, max: 500.0, unit: Unit::Mm }));
        assert_eq!(type_keys(&mut m, "C150# # #", &status), []);
        assert_eq!(m.message(), Some(UiError::Travel), "a full circle of r 150 from x 10 reaches x -290");
    }

    #[test]
    fn ellipse_and_sine_forms() {
        let mut m = Menu::new();
        let a = type_keys(&mut m, "4 20# 10# 45# 90#", &idle());
        assert_eq!(
            curve(&a[0]),
            CurveParams::Ellipse(EllipseParams { a_mm: 20.0, b_mm: 10.0, start_deg: 45.0, sweep_deg: 90.0 })
        );
        type_keys(&mut m, "D", &idle());
        let a = type_keys(&mut m, "5 A5# 20# # 40#", &idle());
        assert_eq!(
            curve(&a[0]),
            CurveParams::Sine(SineParams { amplitude_mm: -5.0, period_mm: 20.0, phase_deg: 0.0, length_mm: 40.0 })
        );
        assert_eq!(type_keys(&mut m, "5# 20# # 0#", &idle()), []);
        assert_eq!(m.message(), Some(UiError::Zero));
        // A 100 mm amplitude over a 1 mm period rises 628 mm per mm: far over the 5 mm jump limit.
        type_keys(&mut m, "D", &idle());
        assert_eq!(type_keys(&mut m, "5 100# 1# # 10#", &idle()), []);
        assert_eq!(m.message(), Some(UiError::TooSteep));
    }

    #[test]
    fn function_presets_and_their_domains() {
        let mut m = Menu::new();
        let a = type_keys(&mut m, "6 2# 0# 20#", &idle());
        assert_eq!(
            curve(&a[0]),
            CurveParams::Function(FunctionParams { preset: FunctionPreset::Wave, x0_mm: 0.0, x1_mm: 20.0 })
        );
        // The preset choice is kept for the next drawing; B steps to the next one.
        assert_eq!(form(&m).preset(), FunctionPreset::Wave);
        let a = type_keys(&mut m, "B# 0# 9#", &idle());
        assert_eq!(
            curve(&a[0]),
            CurveParams::Function(FunctionParams { preset: FunctionPreset::Root, x0_mm: 0.0, x1_mm: 9.0 })
        );
        // sqrt of negative x, and an empty interval, are refused.
        assert_eq!(type_keys(&mut m, "# A4# 9#", &idle()), []);
        assert_eq!(m.message(), Some(UiError::Domain));
        assert_eq!(type_keys(&mut m, "BBBB 9# 9#", &idle()), []);
        assert_eq!(m.message(), Some(UiError::SameEnds));
    }
}

//! The forms of the drawing modes: the ranges of their parameters, the fields each mode asks
//! for, and [`Form`], which takes the keys of a form, checks the values and says what to build
//! from the pen ([`Request`], built by the keypad task a slice at a time), then turns what was
//! built into the [`Plan`] its preview and run screen show, or into the job.

use core::fmt::Write;
use core::ops::RangeInclusive;

use core::f32::consts::TAU;
use heapless::String;

use super::building::Building;
use super::error::UiError;
use super::list;
use super::mode::Mode;
use crate::decimal::Num;
use crate::geom::{Axis, Point};
use crate::motion::drawing::{self, DrawError, EllipseParams, Request, SineParams};
use crate::motion::expr::Expr;
use crate::motion::job::Feed;
use crate::panel::entry::NumberEntry;
use crate::panel::expr_entry::ExprEntry;
use crate::panel::keypad::Key;
use crate::panel::language::Language;
use crate::panel::presets::FunctionPreset;
use crate::panel::run::{JOB_NAME_CHARS, Plan};
use crate::panel::texts::{Msg, Say};
use crate::settings::Settings;
use crate::status::{RunState, Status};
use crate::text::Text;
use crate::unit::Unit;

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

/// A number to type: its name, unit, range, and what an empty field means.
#[derive(Clone, Debug, PartialEq)]
pub struct NumberField {
    pub label: Msg,
    pub unit: Unit,
    pub range: RangeInclusive<f32>,
    /// Used when `#` confirms an empty field; `None`: a value is required.
    pub default: Option<f32>,
    pub zero_allowed: bool,
    /// One line of help shown under the field.
    pub hint: Msg,
}

impl NumberField {
    /// The value of `entry` for this field, checked.
    pub fn value(&self, entry: &NumberEntry) -> Result<f32, UiError> {
        let v = ranged_value(entry, self.default, &self.range, self.unit)?;
        if v == 0.0 && !self.zero_allowed {
            return Err(UiError::Zero);
        }
        Ok(v)
    }
}

/// The value typed in `entry`, or `default` when it is empty, if it lies in `range` (`unit`
/// says in what, for the error): the check of every number typed on the keypad.
pub(super) fn ranged_value(
    entry: &NumberEntry,
    default: Option<f32>,
    range: &RangeInclusive<f32>,
    unit: Unit,
) -> Result<f32, UiError> {
    let v = match entry.value().map_err(UiError::Entry)? {
        Some(v) => v,
        None => default.ok_or(UiError::Empty)?,
    };
    if !v.is_finite() || !range.contains(&v) {
        return Err(UiError::OutOfRange { min: *range.start(), max: *range.end(), unit });
    }
    Ok(v)
}

/// One field of a form.
#[derive(Clone, Debug, PartialEq)]
pub enum Field {
    Number(NumberField),
    /// Choice of a [`FunctionPreset`]: `1`..`5` pick, `A`/`B` step, `#` confirms; or, after `C`,
    /// a function typed ([`ExprEntry`]).
    Preset,
}

const fn mm(label: Msg, range: RangeInclusive<f32>, zero_allowed: bool, hint: Msg) -> Field {
    Field::Number(NumberField { label, unit: Unit::Mm, range, default: None, zero_allowed, hint })
}

const fn deg(label: Msg, range: RangeInclusive<f32>, hint: Msg) -> Field {
    Field::Number(NumberField { label, unit: Unit::Deg, range, default: Some(0.0), zero_allowed: true, hint })
}

const LINE_FIELDS: &[Field] = &[
    mm(Msg::FieldDx, LINE_DELTA_RANGE_MM, true, Msg::HelpDx),
    mm(Msg::FieldDy, LINE_DELTA_RANGE_MM, true, Msg::HelpDy),
];
const CIRCLE_FIELDS: &[Field] = &[
    mm(Msg::FieldRadius, CIRCLE_RADIUS_RANGE_MM, false, Msg::KeysNumber),
    deg(Msg::FieldStart, ARC_START_RANGE_DEG, Msg::HelpStart),
    deg(Msg::FieldSweep, ARC_SWEEP_RANGE_DEG, Msg::HelpSweep),
];
const ELLIPSE_FIELDS: &[Field] = &[
    mm(Msg::FieldA, ELLIPSE_SEMI_AXIS_RANGE_MM, false, Msg::HelpSemiX),
    mm(Msg::FieldB, ELLIPSE_SEMI_AXIS_RANGE_MM, false, Msg::HelpSemiY),
    deg(Msg::FieldStart, ARC_START_RANGE_DEG, Msg::HelpStart),
    deg(Msg::FieldSweep, ARC_SWEEP_RANGE_DEG, Msg::HelpSweep),
];
const SINE_FIELDS: &[Field] = &[
    mm(Msg::FieldAmplitude, SINE_AMPLITUDE_RANGE_MM, true, Msg::KeysNumber),
    mm(Msg::FieldPeriod, SINE_PERIOD_RANGE_MM, false, Msg::HelpPeriod),
    deg(Msg::FieldPhase, SINE_PHASE_RANGE_DEG, Msg::HelpEmptyZero),
    mm(Msg::FieldLength, SINE_LENGTH_RANGE_MM, false, Msg::HelpLength),
];
const FUNCTION_FIELDS: &[Field] = &[
    Field::Preset,
    mm(Msg::FieldX0, FUNCTION_X_RANGE_MM, true, Msg::HelpX0),
    mm(Msg::FieldX1, FUNCTION_X_RANGE_MM, true, Msg::HelpX1),
];

impl Mode {
    /// The fields of the mode's form; empty for modes without one.
    pub const fn fields(self) -> &'static [Field] {
        match self {
            Mode::Line => LINE_FIELDS,
            Mode::Circle => CIRCLE_FIELDS,
            Mode::Ellipse => ELLIPSE_FIELDS,
            Mode::Sine => SINE_FIELDS,
            Mode::Function => FUNCTION_FIELDS,
            Mode::Jog | Mode::Settings | Mode::Presets | Mode::Home | Mode::Language | Mode::Card => &[],
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Form {
    mode: Mode,
    field: usize,
    entries: [NumberEntry; FORM_MAX_FIELDS],
    preset: FunctionPreset,
    /// A function typed instead of a preset (`C` on the function field).
    typed: Option<ExprEntry>,
    /// The form started its drawing: it stays as typed (no empty form flashes up before the
    /// drawing shows) until the next key starts a new one.
    started: bool,
    /// Its drawing is being built (see [`MenuAction::Build`](super::MenuAction::Build)): for
    /// the preview, or, on the preview, to start it.
    pub(super) building: bool,
}

impl Form {
    pub(super) fn new(mode: Mode) -> Self {
        Form {
            mode,
            field: 0,
            entries: [const { NumberEntry::new() }; FORM_MAX_FIELDS],
            preset: FunctionPreset::Parabola,
            typed: None,
            started: false,
            building: false,
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

    /// The function being typed or typed (function mode), if one is.
    pub fn typed(&self) -> Option<&ExprEntry> {
        self.typed.as_ref()
    }

    /// True while a function is typed on the function field.
    pub fn typing(&self) -> bool {
        self.typed.is_some() && self.field() == Some(&Field::Preset)
    }

    /// `D` while a function is typed: deletes its last character (or function name); on an
    /// empty text, a fresh press goes back to the presets.
    pub(super) fn delete_typed(&mut self, repeated: bool) {
        if let Some(typed) = &mut self.typed
            && !typed.press(Key::D).unwrap_or(true)
            && !repeated
        {
            self.typed = None;
        }
    }

    /// Takes a key; `#` on the last field gives the drawing to build for the preview.
    pub(super) fn press(
        &mut self,
        key: Key,
        repeated: bool,
        status: &Status,
        settings: &Settings,
    ) -> Result<Option<Request>, UiError> {
        if self.started {
            *self = Form { preset: self.preset, typed: self.typed.take(), ..Form::new(self.mode) };
        }
        let Some(field) = self.field() else { return Ok(None) };
        let entry = &mut self.entries[self.field.min(FORM_MAX_FIELDS - 1)];
        match (field, key) {
            (_, Key::Hash) => return self.confirm(status, settings),
            (Field::Preset, key) => match &mut self.typed {
                Some(typed) => {
                    typed.press(key).map_err(UiError::Expression)?;
                }
                None if key == Key::C => self.typed = Some(ExprEntry::new(self.preset.expression())),
                None => {
                    self.preset = FunctionPreset::ALL[list::moved(self.preset.index(), FunctionPreset::ALL.len(), key)]
                }
            },
            (Field::Number(_), key) => {
                let deleted = entry.press(key).map_err(UiError::Entry)?;
                // An empty field gives way to the previous one, on a fresh press only.
                if !deleted && !repeated && self.field > 0 {
                    self.field -= 1;
                }
            }
        }
        Ok(None)
    }

    /// `#`: checks the field, then moves on or, after the last one, gives the drawing to build.
    fn confirm(&mut self, status: &Status, settings: &Settings) -> Result<Option<Request>, UiError> {
        match self.field() {
            Some(Field::Number(spec)) => {
                spec.value(self.entry())?;
            }
            Some(Field::Preset) => {
                self.function()?;
            }
            None => {}
        }
        if self.field + 1 < self.mode.fields().len() {
            self.field += 1;
            return Ok(None);
        }
        self.ask_build(status, settings).map(Some)
    }

    /// `#` on the preview: the drawing to build again from the pen (still where the preview was
    /// built: the machine is at rest), if the machine is still free for it.
    pub(super) fn start(&mut self, status: &Status, settings: &Settings) -> Result<Request, UiError> {
        self.ask_build(status, settings)
    }

    /// The preview's plan of the drawing [`confirm`](Self::confirm) asked for, now built.
    pub(super) fn plan(&mut self, built: &mut Building, status: &Status, settings: &Settings) -> Result<Plan, UiError> {
        self.building = false;
        free(status)?;
        built.check(status)?;
        Ok(Plan::of(built.steps(), built.take_path(), self.name(settings.language), feed(settings), settings))
    }

    /// Starts the drawing [`start`](Self::start) asked for, now built: at the feed returned.
    /// The form then stays as typed until the next key.
    pub(super) fn started(&mut self, built: &Building, status: &Status, settings: &Settings) -> Result<Feed, UiError> {
        self.building = false;
        free(status)?;
        built.check(status)?;
        self.started = true;
        Ok(feed(settings))
    }

    /// The function's text: typed, or the preset's.
    fn function_text(&self) -> &str {
        self.typed.as_ref().map_or(self.preset.expression(), ExprEntry::text)
    }

    /// The function, parsed. (The presets parse: a unit test checks every one.)
    fn function(&self) -> Result<Expr, UiError> {
        crate::motion::expr::parse(self.function_text()).map_err(UiError::Expression)
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

    /// The typed drawing, from the pen at `start`.
    pub fn request(&self, start: Point, settings: &Settings) -> Result<Request, UiError> {
        Ok(match self.mode {
            Mode::Line => {
                let (dx, dy) = (self.number(0)?, self.number(1)?);
                let pen_mm = [settings.steps_to_mm(Axis::X, start.x), settings.steps_to_mm(Axis::Y, start.y)];
                let to = drawing::line_target([pen_mm[0] + dx, pen_mm[1] + dy], settings)
                    .ok_or(UiError::Drawing(DrawError::Travel))?;
                Request::Straight { to }
            }
            Mode::Circle => Request::Ellipse(EllipseParams::circle(self.number(0)?, self.number(1)?, self.sweep(2)?)),
            Mode::Ellipse => Request::Ellipse(EllipseParams {
                a_mm: self.number(0)?,
                b_mm: self.number(1)?,
                start_deg: self.number(2)?,
                sweep_deg: self.sweep(3)?,
            }),
            Mode::Sine => Request::Sine(SineParams {
                amplitude_mm: self.number(0)?,
                omega_rad_per_mm: TAU / self.number(1)?,
                phase_deg: self.number(2)?,
                length_mm: self.number(3)?,
            }),
            Mode::Function => {
                let (x0_mm, x1_mm) = (self.number(1)?, self.number(2)?);
                if x0_mm == x1_mm {
                    return Err(UiError::SameEnds);
                }
                let expr = self.function()?;
                // Undefined where the pen is: say why, as the host link's `$F` does.
                expr.eval(x0_mm).map_err(UiError::UndefinedAtStart)?;
                Request::Function { expr, x0_mm, x1_mm }
            }
            Mode::Jog | Mode::Settings | Mode::Presets | Mode::Home | Mode::Language | Mode::Card => {
                return Err(UiError::Empty);
            }
        })
    }

    /// The drawing the form describes, to build from the pen at `status.position`, if the
    /// machine is free for it: the form now waits for it.
    fn ask_build(&mut self, status: &Status, settings: &Settings) -> Result<Request, UiError> {
        free(status)?;
        let request = self.request(status.position, settings)?;
        self.building = true;
        Ok(request)
    }

    /// The drawing's name on the run screen: the mode and its main figures.
    pub fn name(&self, language: Language) -> String<JOB_NAME_CHARS> {
        let mut name = String::new();
        // The name, then each figure after its separator: field numbers into the form.
        let (label, figures): (Msg, &[(&str, usize)]) = match self.mode {
            Mode::Line => (Msg::LabelLine, &[(" ", 0), (",", 1)]),
            Mode::Circle if self.sweep(2).unwrap_or(360.0).abs() >= 360.0 => (Msg::NameCircle, &[(" r", 0)]),
            Mode::Circle => (Msg::NameArc, &[(" r", 0), (" ", 2)]),
            Mode::Ellipse => (Msg::LabelEllipse, &[(" ", 0), ("x", 1)]),
            Mode::Sine => (Msg::NameSine, &[(" A", 0), (" P", 1)]),
            Mode::Function => {
                let _ = write!(name, "y={}", Text(self.function_text()));
                return name;
            }
            mode => (mode.label(), &[]),
        };
        let _ = write!(name, "{}", Say(label, language));
        for &(separator, field) in figures {
            let _ = write!(name, "{}{}", Text(separator), Num(self.number(field).unwrap_or(0.0)));
        }
        if label == Msg::NameArc {
            let _ = write!(name, "{}", Say(Msg::Degrees, language));
        }
        name
    }
}

/// A keypad drawing's feed: the default feed rate (`$203`).
fn feed(settings: &Settings) -> Feed {
    Feed::MmPerMin(settings.default_feed_mm_per_min)
}

/// The keypad starts a drawing only at rest with nothing queued, so it starts at the pen.
fn free(status: &Status) -> Result<(), UiError> {
    match status.state {
        RunState::Alarm => Err(UiError::Alarm),
        RunState::Idle if status.queued_jobs == 0 => Ok(()),
        _ => Err(UiError::Busy),
    }
}

//! One line of G-code or a `$` command in, machine [`Command`]s out, with GRBL 1.1's rules.
//!
//! [`GcodeState`] is GRBL's parser state: modal groups (motion, units, distance, spindle), the
//! feed rate, the G92 work offset and the *planned* position — where the pen will be once every
//! command handed out so far has run. [`GcodeState::execute`] parses a whole line first and
//! changes the state only if the line is valid: an error line leaves the modal state, the planned
//! position and the settings as they were. Positions inside are machine millimetres (as GRBL
//! keeps them, so that relative moves never drift by rounding); every command handed out is in
//! absolute steps, rounded from them.
//!
//! This module decides only; it does not move, wait or write. Settings changes are checked here
//! and handed out as [`Command::SetSetting`], applied by the caller.
//!
//! # G-code
//!
//! Words are a letter and a number (`10`, `-1.5`, `.5`, `+2`); case, spaces and tabs do not
//! matter, `(comments)` and `; comments` are dropped, `N` line numbers are accepted, a word
//! letter may appear once and a modal group once per line. Supported:
//!
//! - G0, G1 (X Y, F), G2/G3 with I J centre offsets or an R radius (negative R: the arc longer
//!   than half a circle), full circles when the end equals the start (`G91 G2 X0 Y0 I10`; as in
//!   GRBL the end must be written, `G2 I10` alone is error 26); radii up to
//!   [`CURVE_RADIUS_MAX_MM`];
//! - G4 P dwell (seconds), G17 (G18/G19 refused), G20/G21, G90/G91, G91.1, G92 / G92.1 (work
//!   offset), G53 (machine coordinates for one G0/G1 line), G80, and the header no-ops G40, G49,
//!   G54, G61, G94;
//! - M0 (pause), M1 (ignored), M2/M30 (program end), M3/M4/M5 and S (accepted, no spindle), M9,
//!   T (kept for `$G`).
//!
//! **Z words.** The plotter has no Z axis; senders move Z to lift and lower a pen. A Z word is
//! accepted and ignored: a move with only Z answers `ok` and does nothing, a move with Z and X/Y
//! moves X/Y only. Z counts as an axis word for GRBL's checks (G80 with Z is still error 31).
//!
//! A G1/G2/G3 before any F word uses the default feed rate (`$203`); only an explicit `F0`
//! leaves a feed move without a feed rate (error 22).
//!
//! # `$` commands
//!
//! `$` help, `$$` settings, `$N=value` set one, `$G` parser state, `$#` offsets, `$I` build info,
//! `$X` unlock, `$H` (no homing: error 5), `$RST=$` / `$RST=#` / `$RST=*` restore settings /
//! clear the G92 offset / both, `$J=` jog (GRBL's rules: only G20/G21, G90/G91, G53, X Y Z, N and
//! a required F; the line's modes apply to the jog only). GRBL's `$C` (check mode), `$N`
//! (startup lines) and `$SLP` are not supported (error 3).
//!
//! # Plotter curve commands
//!
//! One command per curve the machine draws, all starting at the pen, in millimetres and degrees
//! whatever G20/G21 says; an F word (mm/min) sets the modal feed rate like G1's. Angles follow
//! the usual convention: X to the right, Y up, positive sweeps counter-clockwise.
//!
//! | command | draws |
//! |---|---|
//! | `$E A<a> B<b> [S<start°>] [W<sweep°>] [F]` | ellipse with semi-axes `a` (X) and `b` (Y); the pen is the point at parametric angle S (default 0), the centre follows; W from -360 to 360, omitted: the full ellipse |
//! | `$O R<r> [S<start°>] [W<sweep°>] [F]` | circle (or arc) of radius r, same convention: `$O R10` is a full circle with its centre 10 mm left of the pen |
//! | `$S A<amp> W<ω rad/mm> L<length> [P<phase°>] [F]` | y = A·(sin(ω·u + P) − sin P) for u from 0 to L (negative L: to the left), u and y relative to the pen |
//! | `$F X<x0> U<x1> [F] Y=<expression>` | y = f(x) for x from x0 to x1, moved so that (x0, f(x0)) is at the pen; everything after `Y=` (up to a `;`) is the expression ([`crate::expr`]) |
//!
//! `$O` rather than `$C`, and `$SLP` kept apart from `$S`, so that a sender's check-mode or
//! sleep button never draws. Every point of the curve must lie inside the travel limits, else
//! error 15 and nothing moves. The check is exact for arcs, ellipses and sines, and for the X
//! range of a function (it is linear); the Y of a function is checked on
//! [`FUNCTION_CHECK_SAMPLES`] samples plus the end, an early refusal that catches most curves
//! before anything moves. The interpolator enforces the travel exactly, at every column: a
//! function that leaves it between the samples stops at its last column inside
//! (`CurveError::Travel`, reported by the motion as the curve stopping).
//!
//! What the parser accepts, the interpolators accept: every arc or ellipse is set up here with
//! the very steps it hands out (`ArcInterp::new`, `EllipseInterp::new`) and refused with error 33
//! if its interpolator would refuse it (a radius that rounds to a centre on the start or the
//! end, say), and so is a sine (`SineInterp::new`). A sine whose steepest rise between
//! neighbouring X steps, |A·ω| in steps, exceeds the jump limit (`$204`, as for functions) is
//! error 33 too: its interpolator would stop at the first such chord.
//!
//! Curves end on a step: the planned position afterwards is the [`Command::Curve`]'s `end`. A
//! curve that ends on its own start step is a full turn if it sweeps more than half a turn, and
//! draws nothing otherwise (it is shorter than a step).

// Limits are written `!(value <= limit)` on purpose: a NaN must fail them.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use core::f32::consts::{FRAC_PI_2, PI, TAU};

use super::GrblError;
use super::line::LINE_MAX_BYTES;
use crate::geom::{Axis, Point, Rotation};
use crate::interp::sine::{self, sin_range};
use crate::interp::{ArcInterp, EllipseInterp, SineInterp};
use crate::interp::{RowRange, jump_limit_steps};
use crate::job::{Feed, Job, Shape};
use crate::settings::{SettingError, Settings};
use crate::status::RunState;

/// What one line asks of the machine: an iterator over its [`Command`]s in execution order (a
/// G4 dwell, then the motion or `$` command, then an M0/M2/M30 stop — GRBL's order). Empty for a
/// line that only changes modes, or a comment: answer `ok`. It holds at most one large command,
/// so it costs little more than one [`Command`].
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Commands {
    dwell_ms: Option<u32>,
    main: Option<Command>,
    stop: Option<Stop>,
}

impl Commands {
    /// Commands still to come.
    pub fn len(&self) -> usize {
        self.dwell_ms.is_some() as usize + self.main.is_some() as usize + self.stop.is_some() as usize
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn one(command: Command) -> Self {
        Commands { main: Some(command), ..Commands::default() }
    }
}

impl Iterator for Commands {
    type Item = Command;

    fn next(&mut self) -> Option<Command> {
        if let Some(ms) = self.dwell_ms.take() {
            return Some(Command::Dwell { ms });
        }
        if let Some(main) = self.main.take() {
            return Some(main);
        }
        self.stop.take().map(|stop| match stop {
            Stop::Pause => Command::Pause,
            Stop::End => Command::ProgramEnd,
        })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.len(), Some(self.len()))
    }
}

pub const MM_PER_INCH: f32 = 25.4;

/// Largest N line number, GRBL's.
pub const LINE_NUMBER_MAX: f32 = 9_999_999.0;

/// Largest T tool number, GRBL's.
pub const TOOL_NUMBER_MAX: f32 = 255.0;

/// Longest G4 dwell: one hour.
pub const DWELL_MAX_MS: u32 = 3_600_000;

/// G2/G3 with I/J: the end may lie off the start's circle by this much without complaint...
pub const ARC_RADIUS_SLACK_MM: f32 = 0.005;
/// ...and never by more than this, nor by more than [`ARC_RADIUS_ERROR_MAX_RATIO`] of the
/// radius (GRBL's and LinuxCNC's rule).
pub const ARC_RADIUS_ERROR_MAX_MM: f32 = 0.5;
pub const ARC_RADIUS_ERROR_MAX_RATIO: f32 = 0.001;

/// Largest radius or semi-axis of an arc or ellipse: 1_000_000 steps at 200 steps/mm, the
/// circle interpolator's limit. Ellipses (and circles on axes of different steps/mm, which are
/// ellipses in steps) are held to their interpolator's smaller limit, 262_144 steps
/// (`MAX_ELLIPSE_AXIS_STEPS`), by the setup check: beyond it they are error 33.
pub const CURVE_RADIUS_MAX_MM: f32 = 5_000.0;

/// Rounding allowance when a target is compared with the travel limits.
pub const TRAVEL_SLACK_MM: f32 = 0.0005;

/// Samples of a `$F` function checked against the travel limits (plus both ends): an early
/// refusal only; the interpolator holds every column to the travel.
pub const FUNCTION_CHECK_SAMPLES: u32 = 64;

/// Arc sweeps closer than this to zero count as a full turn (GRBL's epsilon).
const ARC_ANGLE_EPSILON_RAD: f32 = 5e-7;

/// Length units of X, Y, I, J, R and F (G20/G21).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Units {
    Mm,
    Inch,
}

impl Units {
    pub const fn mm_per_unit(self) -> f32 {
        match self {
            Units::Mm => 1.0,
            Units::Inch => MM_PER_INCH,
        }
    }
}

/// G90/G91.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Distance {
    Absolute,
    Incremental,
}

/// The motion modal group: G0, G1, G2, G3, G80.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum MotionMode {
    Rapid,
    Linear,
    ArcCw,
    ArcCcw,
    Off,
}

/// M3/M4/M5: kept for `$G` only, the plotter has no spindle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Spindle {
    Cw,
    Ccw,
    Off,
}

/// What a report request asks for; the serial task formats it with [`crate::protocol::report`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Report {
    /// `$`: [`crate::protocol::report::help`].
    Help,
    /// `$$`: [`crate::protocol::report::settings`].
    Settings,
    /// `$G`: [`crate::protocol::report::parser_state`].
    ParserState,
    /// `$#`: [`crate::protocol::report::parameters`].
    Parameters,
    /// `$I`: [`crate::protocol::report::build_info`].
    BuildInfo,
}

/// What one line asks the machine to do.
// A function curve carries its parsed expression by value (no heap).
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// A straight move (G0, G1): a `Shape::Line` job.
    Job(Job),
    /// A curve (G2/G3, `$E`, `$O`, `$S`, `$F`) at a feed rate; it ends at `end`, where the parser
    /// planned it (the interpolator must end there too).
    Curve { shape: Shape, feed: Feed, end: Point },
    /// A `$J=` jog: a straight line; a jog cancel (0x85) aborts it, then
    /// [`GcodeState::sync_position`].
    Jog(Job),
    /// G4: wait this long once the motion before it has finished.
    Dwell { ms: u32 },
    /// M0: finish the queued motion, then hold until cycle start (`~`).
    Pause,
    /// M2/M30: finish the queued motion; the program is over (GRBL answers `[MSG:Pgm End]`).
    ProgramEnd,
    /// `$id=value`, already checked against the settings given to `execute`: apply it with
    /// `Settings::set` (which then succeeds).
    SetSetting { id: u16, value: f32 },
    /// `$RST=$` or `$RST=*`: every setting back to `Settings::default()`.
    RestoreSettings,
    /// Answer with a report (before the `ok`).
    Report(Report),
    /// `$X`: leave the alarm state (GRBL answers `[MSG:Caution: Unlocked]`).
    Unlock,
}

/// GRBL's parser state; see the module documentation.
#[derive(Clone, Debug, PartialEq)]
pub struct GcodeState {
    motion: MotionMode,
    units: Units,
    distance: Distance,
    spindle: Spindle,
    /// `None` until an F word: the default feed rate applies.
    feed_mm_per_min: Option<f32>,
    spindle_speed: f32,
    tool: u8,
    /// Planned position, machine coordinates.
    position_mm: [f32; 2],
    /// The same, rounded to steps: where the last command handed out ends.
    position: Point,
    /// G92 offset: machine position = work position + offset.
    offset_mm: [f32; 2],
}

impl Default for GcodeState {
    fn default() -> Self {
        Self::new()
    }
}

impl GcodeState {
    /// The power-on state: G0 G54 G17 G21 G90 G94 M5 M9 T0, no F yet, at the machine origin.
    pub const fn new() -> Self {
        GcodeState {
            motion: MotionMode::Rapid,
            units: Units::Mm,
            distance: Distance::Absolute,
            spindle: Spindle::Off,
            feed_mm_per_min: None,
            spindle_speed: 0.0,
            tool: 0,
            position_mm: [0.0; 2],
            position: Point::ORIGIN,
            offset_mm: [0.0; 2],
        }
    }

    /// After a soft reset: power-on modes and no G92 offset, at the machine's real `position`.
    pub fn reset(&mut self, position: Point, settings: &Settings) {
        *self = GcodeState::new();
        self.sync_position(position, settings);
    }

    /// Makes the planned position the machine's real one: after a jog cancel, an abort, an
    /// alarm, or a move made outside the protocol (keypad).
    pub fn sync_position(&mut self, position: Point, settings: &Settings) {
        self.position = position;
        self.position_mm = [settings.steps_to_mm(Axis::X, position.x), settings.steps_to_mm(Axis::Y, position.y)];
    }

    /// Where the pen will be once everything handed out so far has run, in steps.
    pub fn planned_position(&self) -> Point {
        self.position
    }

    /// The planned position in machine millimetres.
    pub fn planned_position_mm(&self) -> [f32; 2] {
        self.position_mm
    }

    /// The G92 work offset (machine = work + offset), for `WCO:` and `$#`.
    pub fn work_offset_mm(&self) -> [f32; 2] {
        self.offset_mm
    }

    /// The feed rate G1/G2/G3 use now: the last F word, or the default feed rate.
    pub fn feed_mm_per_min(&self, settings: &Settings) -> f32 {
        self.feed_mm_per_min.unwrap_or(settings.default_feed_mm_per_min)
    }

    pub fn motion_mode(&self) -> MotionMode {
        self.motion
    }

    pub fn units(&self) -> Units {
        self.units
    }

    pub fn distance(&self) -> Distance {
        self.distance
    }

    pub fn spindle(&self) -> Spindle {
        self.spindle
    }

    pub fn spindle_speed(&self) -> f32 {
        self.spindle_speed
    }

    pub fn tool(&self) -> u8 {
        self.tool
    }

    /// Executes one line (without its line end) against `settings` while the machine is in
    /// `state`. On success the state has advanced and the commands say what to do; on error
    /// nothing has changed.
    pub fn execute(&mut self, line: &str, settings: &Settings, state: RunState) -> Result<Commands, GrblError> {
        let text = line.trim_start();
        if let Some(rest) = text.strip_prefix('$') {
            return self.system(line, rest, settings, state);
        }
        let compact = compact(text, true)?;
        if compact.is_empty() || compact.as_slice() == b"%" {
            return Ok(Commands::default());
        }
        if matches!(state, RunState::Alarm | RunState::Jog) {
            return Err(GrblError::Locked);
        }
        let block = parse_block(&compact)?;
        let mut next = self.clone();
        let commands = next.run_block(block, settings)?;
        *self = next;
        Ok(commands)
    }

    // ----- G-code -------------------------------------------------------------------------

    /// Executes a parsed block on `self` (a copy the caller keeps only on success).
    fn run_block(&mut self, block: Block, settings: &Settings) -> Result<Commands, GrblError> {
        let start_mm = self.position_mm;
        let mut words = block.words;
        if let Some(n) = words.take(b'N')
            && n > LINE_NUMBER_MAX
        {
            return Err(GrblError::InvalidLineNumber);
        }
        if let Some(u) = block.units {
            self.units = u;
        }
        if let Some(d) = block.distance {
            self.distance = d;
        }
        if let Some(s) = block.spindle {
            self.spindle = s;
        }
        if let Some(m) = block.motion {
            self.motion = m;
        }
        let scale = self.units.mm_per_unit();
        if let Some(f) = words.take(b'F') {
            self.feed_mm_per_min = Some(f * scale);
        }
        if let Some(s) = words.take(b'S') {
            self.spindle_speed = s;
        }
        if let Some(t) = words.take(b'T') {
            self.tool = t as u8; // 0..=255, checked when parsed
        }

        let mut out = Commands::default();
        if block.non_modal == Some(NonModal::Dwell) {
            let p = words.take(b'P').ok_or(GrblError::ValueWordMissing)?;
            let ms = crate::math::round(p * 1000.0);
            if !(ms <= DWELL_MAX_MS as f32) {
                return Err(GrblError::MaxValueExceeded);
            }
            out.dwell_ms = Some(ms as u32);
        }

        let axis = [words.get(b'X').map(|v| v * scale), words.get(b'Y').map(|v| v * scale)];
        let has_z = words.get(b'Z').is_some();
        let has_xy = axis[0].is_some() || axis[1].is_some();
        let has_axis = has_xy || has_z;
        let axis_command = if block.non_modal == Some(NonModal::SetOffset) {
            AxisCommand::NonModal
        } else if block.motion_word || has_axis {
            AxisCommand::Motion
        } else {
            AxisCommand::None
        };

        match block.non_modal {
            Some(NonModal::SetOffset) => {
                if !has_axis {
                    return Err(GrblError::NoAxisWords);
                }
                for (i, v) in axis.iter().enumerate() {
                    if let Some(v) = v {
                        self.offset_mm[i] = start_mm[i] - v;
                    }
                }
            }
            Some(NonModal::ClearOffset) => self.offset_mm = [0.0; 2],
            Some(NonModal::MachineCoords) if !matches!(self.motion, MotionMode::Rapid | MotionMode::Linear) => {
                return Err(GrblError::G53InvalidMotionMode);
            }
            _ => {}
        }

        if self.motion == MotionMode::Off {
            if has_axis {
                return Err(GrblError::AxisWordsExist);
            }
        } else if axis_command == AxisCommand::Motion {
            let machine = block.non_modal == Some(NonModal::MachineCoords);
            let mut target = start_mm;
            for (i, v) in axis.iter().enumerate() {
                if let Some(v) = *v {
                    target[i] = if machine {
                        v
                    } else {
                        match self.distance {
                            Distance::Absolute => v + self.offset_mm[i],
                            Distance::Incremental => start_mm[i] + v,
                        }
                    };
                }
            }
            let motion = match self.motion {
                MotionMode::Rapid if has_xy => self.line(target, Feed::Rapid, settings)?,
                MotionMode::Linear => {
                    let feed = self.checked_feed(settings)?;
                    if has_xy { self.line(target, Feed::MmPerMin(feed), settings)? } else { None }
                }
                MotionMode::ArcCw | MotionMode::ArcCcw => {
                    let feed = self.checked_feed(settings)?;
                    if !has_axis {
                        return Err(GrblError::NoAxisWords);
                    }
                    if !has_xy {
                        return Err(GrblError::NoAxisWordsInPlane);
                    }
                    let form = match words.take(b'R') {
                        Some(r) => ArcForm::Radius(r * scale),
                        None => {
                            let (i, j) = (words.take(b'I'), words.take(b'J'));
                            words.take(b'K');
                            if i.is_none() && j.is_none() {
                                return Err(GrblError::NoOffsetsInPlane);
                            }
                            ArcForm::Offsets([i.unwrap_or(0.0) * scale, j.unwrap_or(0.0) * scale])
                        }
                    };
                    let rotation =
                        if self.motion == MotionMode::ArcCw { Rotation::Clockwise } else { Rotation::CounterClockwise };
                    self.arc(target, rotation, form, feed, settings)?
                }
                _ => None,
            };
            out.main = motion;
        }

        if axis_command != AxisCommand::None {
            words.take(b'X');
            words.take(b'Y');
            words.take(b'Z');
        }
        if !words.is_empty() {
            return Err(GrblError::UnusedWords);
        }

        if block.stop == Some(Stop::End) {
            // GRBL (after LinuxCNC) resets these groups at program end; units, F, S, T and the
            // G92 offset stay.
            self.motion = MotionMode::Linear;
            self.distance = Distance::Absolute;
            self.spindle = Spindle::Off;
        }
        out.stop = block.stop;
        Ok(out)
    }

    /// The feed rate for a feed move; zero (an explicit F0) is GRBL's undefined feed rate.
    fn checked_feed(&self, settings: &Settings) -> Result<f32, GrblError> {
        let feed = self.feed_mm_per_min(settings);
        if feed > 0.0 { Ok(feed) } else { Err(GrblError::UndefinedFeedRate) }
    }

    /// A straight move to `target_mm`; `None` when it ends on the step it starts from.
    fn line(&mut self, target_mm: [f32; 2], feed: Feed, settings: &Settings) -> Result<Option<Command>, GrblError> {
        check_travel(settings, target_mm)?;
        let from = self.position;
        let to = to_steps(settings, target_mm);
        self.position_mm = target_mm;
        self.position = to;
        Ok((to != from).then_some(Command::Job(Job::draw(Shape::Line { to }, feed))))
    }

    /// G2/G3 from the planned position to `end` (mm).
    fn arc(
        &mut self,
        end: [f32; 2],
        rotation: Rotation,
        form: ArcForm,
        feed_mm_per_min: f32,
        settings: &Settings,
    ) -> Result<Option<Command>, GrblError> {
        let start = self.position_mm;
        let (dx, dy) = (end[0] - start[0], end[1] - start[1]);
        let (center, radius) = match form {
            ArcForm::Radius(r) => {
                if dx == 0.0 && dy == 0.0 {
                    return Err(GrblError::InvalidTarget);
                }
                let h2 = 4.0 * r * r - dx * dx - dy * dy;
                if !(h2 >= 0.0) {
                    return Err(GrblError::ArcRadius);
                }
                // Centre on the perpendicular bisector of the chord; the side follows the
                // rotation, and a negative R takes the other side (the long arc).
                let mut k = -crate::math::sqrt(h2) / crate::math::hypot(dx, dy);
                if rotation == Rotation::CounterClockwise {
                    k = -k;
                }
                if r < 0.0 {
                    k = -k;
                }
                ([start[0] + 0.5 * (dx - dy * k), start[1] + 0.5 * (dy + dx * k)], r.abs())
            }
            ArcForm::Offsets([i, j]) => {
                let center = [start[0] + i, start[1] + j];
                let radius = crate::math::hypot(i, j);
                let delta = (crate::math::hypot(end[0] - center[0], end[1] - center[1]) - radius).abs();
                if delta > ARC_RADIUS_SLACK_MM
                    && (delta > ARC_RADIUS_ERROR_MAX_MM || delta > ARC_RADIUS_ERROR_MAX_RATIO * radius)
                {
                    return Err(GrblError::InvalidTarget);
                }
                (center, radius)
            }
        };
        let (sx, sy) = (start[0] - center[0], start[1] - center[1]);
        let (ex, ey) = (end[0] - center[0], end[1] - center[1]);
        let mut sweep = crate::math::atan2(sx * ey - sy * ex, sx * ex + sy * ey);
        match rotation {
            Rotation::Clockwise if sweep >= -ARC_ANGLE_EPSILON_RAD => sweep -= TAU,
            Rotation::CounterClockwise if sweep <= ARC_ANGLE_EPSILON_RAD => sweep += TAU,
            _ => {}
        }
        let conic = Conic {
            center,
            semi_axes_mm: [radius, radius],
            start_rad: crate::math::atan2(sy, sx),
            sweep_rad: sweep,
            end,
        };
        self.conic(conic, Feed::MmPerMin(feed_mm_per_min), settings)
    }

    /// An arc of a circle or an axis-aligned ellipse from the planned position to `c.end`.
    fn conic(&mut self, c: Conic, feed: Feed, settings: &Settings) -> Result<Option<Command>, GrblError> {
        if !(c.start_rad.is_finite() && c.sweep_rad.is_finite()) {
            return Err(GrblError::InvalidTarget);
        }
        for r in c.semi_axes_mm {
            if !(r <= CURVE_RADIUS_MAX_MM) {
                return Err(GrblError::InvalidTarget);
            }
        }
        check_travel(settings, c.end)?;
        // The extremes of each axis lie at parametric angles k·90°: check those the sweep passes.
        let (lo, hi) = if c.sweep_rad >= 0.0 {
            (c.start_rad, c.start_rad + c.sweep_rad)
        } else {
            (c.start_rad + c.sweep_rad, c.start_rad)
        };
        let first = crate::math::ceil(lo / FRAC_PI_2) as i32;
        let last = crate::math::floor(hi / FRAC_PI_2) as i32;
        // A sweep of at most a full turn passes at most five such angles.
        for k in first..=last.min(first.saturating_add(4)) {
            let (cos, sin) = match k.rem_euclid(4) {
                0 => (1.0, 0.0),
                1 => (0.0, 1.0),
                2 => (-1.0, 0.0),
                _ => (0.0, -1.0),
            };
            let p = [c.center[0] + c.semi_axes_mm[0] * cos, c.center[1] + c.semi_axes_mm[1] * sin];
            check_travel(settings, p)?;
        }

        let from = self.position;
        let to = to_steps(settings, c.end);
        if to == from && c.sweep_rad.abs() < PI {
            // Shorter than one step: nothing to draw.
            self.position_mm = c.end;
            return Ok(None);
        }
        let spm = settings.steps_per_mm;
        let semi = [crate::math::round(c.semi_axes_mm[0] * spm[0]), crate::math::round(c.semi_axes_mm[1] * spm[1])];
        if !(semi[0] >= 1.0 && semi[1] >= 1.0) {
            return Err(GrblError::InvalidTarget);
        }
        let center = to_steps(settings, c.center);
        let rotation = if c.sweep_rad > 0.0 { Rotation::CounterClockwise } else { Rotation::Clockwise };
        let shape = if c.semi_axes_mm[0] == c.semi_axes_mm[1] && spm[0] == spm[1] {
            Shape::Arc { center, to, rotation }
        } else {
            Shape::Ellipse { center, a_steps: semi[0] as i32, b_steps: semi[1] as i32, to, rotation }
        };
        // Set up as the motion will set it up, from the same steps: a curve its interpolator
        // would refuse (a tiny radius whose rounded centre falls on the start or the end) is
        // refused here, before the planned position moves.
        let accepted = match shape {
            Shape::Arc { center, to, rotation } => ArcInterp::new(from, center, to, rotation, settings.method).is_ok(),
            Shape::Ellipse { center, a_steps, b_steps, to, rotation } => {
                EllipseInterp::new(from, center, a_steps, b_steps, to, rotation, settings.method).is_ok()
            }
            _ => true,
        };
        if !accepted {
            return Err(GrblError::InvalidTarget);
        }
        self.position_mm = c.end;
        self.position = to;
        Ok(Some(Command::Curve { shape, feed, end: to }))
    }

    // ----- $ commands ---------------------------------------------------------------------

    /// A line starting with `$`; `rest` follows the `$` and is a suffix of `line`.
    fn system(&mut self, line: &str, rest: &str, settings: &Settings, state: RunState) -> Result<Commands, GrblError> {
        let c = compact(rest, true)?;
        let report = |r| Ok(Commands::one(Command::Report(r)));
        match c.as_slice() {
            b"" => report(Report::Help),
            b"$" => report(Report::Settings),
            b"G" => report(Report::ParserState),
            b"#" => report(Report::Parameters),
            b"I" => report(Report::BuildInfo),
            b"X" => Ok(Commands::one(Command::Unlock)),
            b"H" => Err(GrblError::SettingDisabled),
            b"SLP" => Err(GrblError::InvalidStatement),
            [b'R', b'S', b'T', b'=', what] => self.restore(*what, settings, state),
            [b'J', b'=', body @ ..] => self.jog(body, settings, state),
            [b'0'..=b'9', ..] => self.set_setting(&c, settings, state),
            [which @ (b'E' | b'O' | b'S'), ..] => {
                if matches!(state, RunState::Alarm | RunState::Jog) {
                    return Err(GrblError::Locked);
                }
                let mut next = self.clone();
                let commands = next.plotter_curve(*which, c.get(1..).unwrap_or(&[]), settings)?;
                *self = next;
                Ok(commands)
            }
            [b'F', ..] => {
                if matches!(state, RunState::Alarm | RunState::Jog) {
                    return Err(GrblError::Locked);
                }
                let mut next = self.clone();
                let commands = next.function(line, rest, settings)?;
                *self = next;
                Ok(commands)
            }
            _ => Err(GrblError::InvalidStatement),
        }
    }

    /// `$id=value`.
    fn set_setting(&mut self, c: &[u8], settings: &Settings, state: RunState) -> Result<Commands, GrblError> {
        if !matches!(state, RunState::Idle | RunState::Alarm) {
            return Err(GrblError::NotIdle);
        }
        let eq = c.iter().position(|&b| b == b'=').ok_or(GrblError::InvalidStatement)?;
        let (id_text, value_text) = (&c[..eq], &c[eq + 1..]);
        if id_text.len() > 5 || !id_text.iter().all(u8::is_ascii_digit) {
            return Err(GrblError::InvalidStatement);
        }
        let id = id_text.iter().fold(0u32, |n, d| n * 10 + (d - b'0') as u32);
        let id = u16::try_from(id).map_err(|_| GrblError::InvalidStatement)?;
        let value = parse_number(value_text)?;
        let mut next = settings.clone();
        next.set(id, value).map_err(|e| match e {
            SettingError::OutOfRange if value < 0.0 => GrblError::NegativeValue,
            SettingError::Unknown | SettingError::OutOfRange => GrblError::InvalidStatement,
        })?;
        self.rescale(&next);
        Ok(Commands::one(Command::SetSetting { id, value }))
    }

    /// `$RST=$`, `$RST=#`, `$RST=*`.
    fn restore(&mut self, what: u8, settings: &Settings, state: RunState) -> Result<Commands, GrblError> {
        if !matches!(what, b'$' | b'#' | b'*') {
            return Err(GrblError::InvalidStatement);
        }
        if !matches!(state, RunState::Idle | RunState::Alarm) {
            return Err(GrblError::NotIdle);
        }
        if what != b'$' {
            self.offset_mm = [0.0; 2];
        }
        if what == b'#' {
            return Ok(Commands::default());
        }
        let defaults = Settings::default();
        if defaults.steps_per_mm != settings.steps_per_mm {
            self.rescale(&defaults);
        }
        Ok(Commands::one(Command::RestoreSettings))
    }

    /// Keeps the planned position on the same step when steps/mm change.
    fn rescale(&mut self, next: &Settings) {
        let position = self.position;
        self.sync_position(position, next);
    }

    /// `$J=` followed by `body` (compacted).
    fn jog(&mut self, body: &[u8], settings: &Settings, state: RunState) -> Result<Commands, GrblError> {
        if !matches!(state, RunState::Idle | RunState::Jog) {
            return Err(GrblError::NotIdle);
        }
        let block = parse_block(body)?;
        let mut words = block.words;
        let units = block.units.unwrap_or(self.units);
        let distance = block.distance.unwrap_or(self.distance);
        let f = words.take(b'F').ok_or(GrblError::UndefinedFeedRate)?;
        let feed = f * units.mm_per_unit();
        if !(feed > 0.0) {
            return Err(GrblError::UndefinedFeedRate);
        }
        let allowed = Group::Distance.bit() | Group::Units.bit() | Group::NonModal.bit();
        if block.groups & !allowed != 0 || !matches!(block.non_modal, None | Some(NonModal::MachineCoords)) {
            return Err(GrblError::InvalidJog);
        }
        words.take(b'N');
        let axis = [words.take(b'X'), words.take(b'Y')];
        let has_z = words.take(b'Z').is_some();
        if !words.is_empty() {
            return Err(GrblError::InvalidJog);
        }
        if axis == [None, None] {
            // A Z-only jog (a sender's Z buttons) moves nothing.
            return if has_z { Ok(Commands::default()) } else { Err(GrblError::NoAxisWords) };
        }
        let machine = block.non_modal == Some(NonModal::MachineCoords);
        let mut target = self.position_mm;
        for (i, v) in axis.iter().enumerate() {
            if let Some(v) = *v {
                let v = v * units.mm_per_unit();
                target[i] = if machine {
                    v
                } else {
                    match distance {
                        Distance::Absolute => v + self.offset_mm[i],
                        Distance::Incremental => self.position_mm[i] + v,
                    }
                };
            }
        }
        check_travel(settings, target)?;
        let from = self.position;
        let to = to_steps(settings, target);
        self.position_mm = target;
        self.position = to;
        if to == from {
            return Ok(Commands::default());
        }
        Ok(Commands::one(Command::Jog(Job::jog_to(to, Feed::MmPerMin(feed)))))
    }

    /// `$E`, `$O`, `$S` with their words in `body` (compacted, after the command letter).
    fn plotter_curve(&mut self, which: u8, body: &[u8], settings: &Settings) -> Result<Commands, GrblError> {
        let mut words = Words::default();
        for word in WordIter::new(body) {
            let (letter, value) = word?;
            words.insert(letter, value)?;
        }
        let feed = self.curve_feed(&mut words, settings)?;
        let start_deg = words.take(b'S').unwrap_or(0.0);
        let command = match which {
            b'E' => {
                let a = positive(words.take(b'A'))?;
                let b = positive(words.take(b'B'))?;
                let sweep = words.take(b'W');
                no_unused(&words)?;
                self.ellipse([a, b], start_deg, sweep, feed, settings)?
            }
            b'O' => {
                let r = positive(words.take(b'R'))?;
                let sweep = words.take(b'W');
                no_unused(&words)?;
                self.ellipse([r, r], start_deg, sweep, feed, settings)?
            }
            _ => {
                let amplitude = words.take(b'A').ok_or(GrblError::ValueWordMissing)?;
                let omega = words.take(b'W').ok_or(GrblError::ValueWordMissing)?;
                let length = words.take(b'L').ok_or(GrblError::ValueWordMissing)?;
                let phase_deg = words.take(b'P').unwrap_or(0.0);
                // `S` means nothing to a sine; refuse it rather than ignore it.
                if start_deg != 0.0 {
                    return Err(GrblError::UnusedWords);
                }
                no_unused(&words)?;
                self.sine(amplitude, omega, phase_deg.to_radians(), length, feed, settings)?
            }
        };
        Ok(command.map(Commands::one).unwrap_or_default())
    }

    /// The F word of a curve command (mm/min, modal) or the current feed rate.
    fn curve_feed(&mut self, words: &mut Words, settings: &Settings) -> Result<Feed, GrblError> {
        if let Some(f) = words.take(b'F') {
            if f < 0.0 {
                return Err(GrblError::NegativeValue);
            }
            self.feed_mm_per_min = Some(f);
        }
        Ok(Feed::MmPerMin(self.checked_feed(settings)?))
    }

    /// `$E` / `$O`: the pen is at parametric angle `start_deg`; `sweep_deg` omitted is a full turn.
    fn ellipse(
        &mut self,
        semi_axes_mm: [f32; 2],
        start_deg: f32,
        sweep_deg: Option<f32>,
        feed: Feed,
        settings: &Settings,
    ) -> Result<Option<Command>, GrblError> {
        let sweep_deg = sweep_deg.unwrap_or(360.0);
        if !(sweep_deg.abs() <= 360.0) || !start_deg.is_finite() {
            return Err(GrblError::InvalidTarget);
        }
        if sweep_deg == 0.0 {
            return Ok(None);
        }
        let t0 = (start_deg % 360.0).to_radians();
        let sweep = sweep_deg.to_radians();
        let [a, b] = semi_axes_mm;
        let p = self.position_mm;
        let center = [p[0] - a * crate::math::cos(t0), p[1] - b * crate::math::sin(t0)];
        let end = if sweep_deg.abs() == 360.0 {
            p
        } else {
            [center[0] + a * crate::math::cos(t0 + sweep), center[1] + b * crate::math::sin(t0 + sweep)]
        };
        self.conic(Conic { center, semi_axes_mm, start_rad: t0, sweep_rad: sweep, end }, feed, settings)
    }

    /// `$S`: see [`Shape::Sine`].
    fn sine(
        &mut self,
        amplitude_mm: f32,
        omega_rad_per_mm: f32,
        phase_rad: f32,
        length_mm: f32,
        feed: Feed,
        settings: &Settings,
    ) -> Result<Option<Command>, GrblError> {
        let p = self.position_mm;
        let t1 = phase_rad + omega_rad_per_mm * length_mm;
        if !(t1.is_finite() && amplitude_mm.abs() <= CURVE_RADIUS_MAX_MM) {
            return Err(GrblError::InvalidTarget);
        }
        let s0 = crate::math::sin(phase_rad);
        let (lo, hi) = sin_range(phase_rad, t1);
        check_travel(settings, [p[0] + length_mm, p[1] + amplitude_mm * (lo - s0)])?;
        check_travel(settings, [p[0], p[1] + amplitude_mm * (hi - s0)])?;
        let spm = settings.steps_per_mm;
        let dx = crate::math::round(length_mm * spm[0]);
        if dx == 0.0 {
            return Ok(None);
        }
        let amplitude_steps = amplitude_mm * spm[1];
        let omega_rad_per_step = omega_rad_per_mm / spm[0];
        // The sine rises by at most |A·ω| steps from one X step to the next; above the jump
        // limit its interpolator would stop at the first chord that steep (as a function does
        // at a jump), so refuse it before anything moves.
        if !sine::fits_jump_limit(amplitude_steps, omega_rad_per_step, settings) {
            return Err(GrblError::InvalidTarget);
        }
        let max_jump_steps = jump_limit_steps(settings.max_jump_mm, spm[1]);
        let length_steps = dx as i32;
        // Set up as the motion will set it up (the travel is checked above, in millimetres);
        // its end is where the parser plans the pen.
        let sine = SineInterp::new(
            amplitude_steps,
            omega_rad_per_step,
            phase_rad,
            length_steps,
            max_jump_steps,
            RowRange::ANY,
            settings.method,
        )
        .map_err(|_| GrblError::InvalidTarget)?;
        let d = sine.end();
        // Within the travel checked above (±500 mm at 200 steps/mm at most).
        let to = Point::new(self.position.x + d.x, self.position.y + d.y);
        self.land_on(to, settings);
        let shape = Shape::Sine { amplitude_steps, omega_rad_per_step, phase_rad, length_steps };
        Ok(Some(Command::Curve { shape, feed, end: to }))
    }

    /// `$F X<x0> U<x1> [F] Y=<expr>`; `rest` follows the `$` and is a suffix of `line`.
    fn function(&mut self, line: &str, rest: &str, settings: &Settings) -> Result<Commands, GrblError> {
        // The expression starts after the first `Y=` (spaces allowed around the `=`); a `Y` with
        // no `=` after it is a malformed value.
        let equals_after = |at: usize| {
            let after = &rest[at + 1..];
            let spaces = after.len() - after.trim_start().len();
            (after.as_bytes().get(spaces) == Some(&b'=')).then_some(at + 1 + spaces + 1)
        };
        let mut seen_y = false;
        let found = rest.bytes().enumerate().filter(|&(_, b)| b == b'Y' || b == b'y').find_map(|(at, _)| {
            seen_y = true;
            equals_after(at).map(|expr_at| (at, expr_at))
        });
        let (y_at, expr_at) =
            found.ok_or(if seen_y { GrblError::BadNumberFormat } else { GrblError::ValueWordMissing })?;
        let expr_text = rest[expr_at..].split(';').next().unwrap_or("");
        let head = compact(&rest[..y_at], true)?;
        let mut words = Words::default();
        // `head` starts with the command letter F.
        for word in WordIter::new(head.get(1..).unwrap_or(&[])) {
            let (letter, value) = word?;
            words.insert(letter, value)?;
        }
        let feed = self.curve_feed(&mut words, settings)?;
        let x0_mm = words.take(b'X').ok_or(GrblError::ValueWordMissing)?;
        let x1_mm = words.take(b'U').ok_or(GrblError::ValueWordMissing)?;
        no_unused(&words)?;
        let expr = crate::expr::parse(expr_text).map_err(|e| {
            let column = line.len() - rest.len() + expr_at + e.pos + 1;
            GrblError::Expression { column: u16::try_from(column).unwrap_or(u16::MAX), kind: e.kind }
        })?;

        let p = self.position_mm;
        check_travel(settings, [p[0] + (x1_mm - x0_mm), p[1]])?;
        let spm = settings.steps_per_mm;
        let dx = crate::math::round((x1_mm - x0_mm) * spm[0]);
        if dx == 0.0 {
            return Ok(Commands::default());
        }
        let f = |x: f32| expr.eval(x).map_err(|error| GrblError::FunctionUndefined { x_mm: x, error });
        let (x0, x1) = (x0_mm, x1_mm);
        let y0 = f(x0)?;
        let y_at_pen = |y: f32| [p[0], p[1] + (y - y0)];
        for k in 0..=FUNCTION_CHECK_SAMPLES {
            let x = x0 + (x1 - x0) * k as f32 / FUNCTION_CHECK_SAMPLES as f32;
            check_travel(settings, y_at_pen(f(x)?))?;
        }
        // The x the curve really ends at, on the step lattice.
        let x_end = x0 + dx / spm[0];
        let y_end = f(x_end)?;
        check_travel(settings, y_at_pen(y_end))?;
        let dy = crate::math::floor((y_end - y0) * spm[1] + 0.5);
        let to = Point::new(self.position.x + dx as i32, self.position.y + dy as i32);
        self.land_on(to, settings);
        let shape = Shape::Function { expr, x0_mm, x1_mm };
        Ok(Commands::one(Command::Curve { shape, feed, end: to }))
    }

    /// Ends a curve on the lattice point `to`.
    fn land_on(&mut self, to: Point, settings: &Settings) {
        self.sync_position(to, settings);
    }
}

// ----- parsing helpers ---------------------------------------------------------------------

/// A line with spaces, tabs, block-delete slashes and comments removed, upper-cased.
type Compact = heapless::Vec<u8, LINE_MAX_BYTES>;

/// Compacts `text`; `(...)` are comments only when `parens_are_comments`; `;` always ends it.
fn compact(text: &str, parens_are_comments: bool) -> Result<Compact, GrblError> {
    let mut out = Compact::new();
    let mut in_comment = false;
    for &b in text.as_bytes() {
        if in_comment {
            in_comment = b != b')';
            continue;
        }
        match b {
            b'(' if parens_are_comments => in_comment = true,
            b';' => break,
            b' ' | b'\t' | b'/' => {}
            _ => out.push(b.to_ascii_uppercase()).map_err(|_| GrblError::LineOverflow)?,
        }
    }
    Ok(out)
}

/// The words of a compacted line: a letter and its number each.
struct WordIter<'a> {
    rest: &'a [u8],
}

impl<'a> WordIter<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        WordIter { rest: bytes }
    }
}

impl Iterator for WordIter<'_> {
    type Item = Result<(u8, f32), GrblError>;

    fn next(&mut self) -> Option<Self::Item> {
        let (&letter, tail) = self.rest.split_first()?;
        if !letter.is_ascii_uppercase() {
            self.rest = &[];
            return Some(Err(GrblError::ExpectedCommandLetter));
        }
        let n = tail.iter().take_while(|c| c.is_ascii_digit() || matches!(c, b'.' | b'+' | b'-')).count();
        let (number, rest) = tail.split_at(n);
        self.rest = rest;
        Some(parse_number(number).map(|v| (letter, v)))
    }
}

/// A G-code number: optional sign, digits with at most one point, at least one digit (no
/// exponent: in G-code `E` is a word letter). The whole of `text` must be the number.
fn parse_number(text: &[u8]) -> Result<f32, GrblError> {
    let syntax = crate::decimal::Syntax { sign: true, exponent: false };
    match crate::decimal::parse_prefix(text, syntax) {
        Ok(n) if n.len_bytes == text.len() => Ok(n.value),
        _ => Err(GrblError::BadNumberFormat),
    }
}

/// Letter values of one line.
#[derive(Clone, Copy, Default)]
struct Words {
    values: [Option<f32>; 26],
}

impl Words {
    fn insert(&mut self, letter: u8, value: f32) -> Result<(), GrblError> {
        let slot = &mut self.values[(letter.wrapping_sub(b'A')) as usize % 26];
        if slot.is_some() {
            return Err(GrblError::RepeatedWord);
        }
        *slot = Some(value);
        Ok(())
    }

    fn get(&self, letter: u8) -> Option<f32> {
        self.values[(letter.wrapping_sub(b'A')) as usize % 26]
    }

    fn take(&mut self, letter: u8) -> Option<f32> {
        self.values[(letter.wrapping_sub(b'A')) as usize % 26].take()
    }

    fn is_empty(&self) -> bool {
        self.values.iter().all(Option::is_none)
    }
}

fn no_unused(words: &Words) -> Result<(), GrblError> {
    if words.is_empty() { Ok(()) } else { Err(GrblError::UnusedWords) }
}

/// A required size word: present, not negative, not zero.
fn positive(value: Option<f32>) -> Result<f32, GrblError> {
    match value {
        None => Err(GrblError::ValueWordMissing),
        Some(v) if v < 0.0 => Err(GrblError::NegativeValue),
        Some(0.0) => Err(GrblError::InvalidTarget),
        Some(v) => Ok(v),
    }
}

/// Modal groups, as GRBL numbers them (NIST RS274/NGC table 4).
#[derive(Clone, Copy)]
enum Group {
    NonModal,
    Motion,
    Plane,
    Distance,
    ArcDistance,
    FeedMode,
    Units,
    CutterComp,
    ToolLength,
    CoordSystem,
    Control,
    Stop,
    Spindle,
    Coolant,
}

impl Group {
    const fn bit(self) -> u16 {
        1 << self as u16
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum NonModal {
    Dwell,
    MachineCoords,
    SetOffset,
    ClearOffset,
}

/// M0 or M2/M30 (M1, an optional stop without a switch, is no stop).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stop {
    Pause,
    End,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum AxisCommand {
    None,
    NonModal,
    Motion,
}

enum ArcForm {
    Radius(f32),
    Offsets([f32; 2]),
}

/// An elliptic (or circular) arc in machine millimetres.
struct Conic {
    center: [f32; 2],
    semi_axes_mm: [f32; 2],
    start_rad: f32,
    sweep_rad: f32,
    end: [f32; 2],
}

/// One parsed line of G-code, before its checks against the state.
#[derive(Default)]
struct Block {
    groups: u16,
    non_modal: Option<NonModal>,
    motion: Option<MotionMode>,
    /// G0–G3 given explicitly: the line is a motion command even without axis words.
    motion_word: bool,
    units: Option<Units>,
    distance: Option<Distance>,
    spindle: Option<Spindle>,
    stop: Option<Stop>,
    words: Words,
}

impl Block {
    fn enter(&mut self, group: Group) -> Result<(), GrblError> {
        if self.groups & group.bit() != 0 {
            return Err(GrblError::ModalGroupViolation);
        }
        self.groups |= group.bit();
        Ok(())
    }

    fn g(&mut self, value: f32) -> Result<(), GrblError> {
        let (int, tenths) = command_number(value)?;
        if tenths != 0 && !matches!((int, tenths), (91, 1) | (92, 1)) {
            // GRBL's other Gxx.x commands are unsupported here; anything else is no command.
            return Err(if matches!(int, 28 | 30 | 38 | 43 | 59 | 61 | 90 | 92) {
                GrblError::Unsupported
            } else {
                GrblError::ValueNotInteger
            });
        }
        let group = match (int, tenths) {
            (0..=3, 0) => {
                if self.non_modal == Some(NonModal::SetOffset) {
                    return Err(GrblError::AxisCommandConflict);
                }
                self.motion =
                    Some([MotionMode::Rapid, MotionMode::Linear, MotionMode::ArcCw, MotionMode::ArcCcw][int as usize]);
                self.motion_word = true;
                Group::Motion
            }
            (80, 0) => {
                self.motion = Some(MotionMode::Off);
                Group::Motion
            }
            (4, 0) => self.non_modal(NonModal::Dwell),
            (53, 0) => self.non_modal(NonModal::MachineCoords),
            (92, 0) => {
                if self.motion_word {
                    return Err(GrblError::AxisCommandConflict);
                }
                self.non_modal(NonModal::SetOffset)
            }
            (92, 1) => self.non_modal(NonModal::ClearOffset),
            (17, 0) => Group::Plane,
            (20, 0) | (21, 0) => {
                self.units = Some(if int == 20 { Units::Inch } else { Units::Mm });
                Group::Units
            }
            (90, 0) | (91, 0) => {
                self.distance = Some(if int == 90 { Distance::Absolute } else { Distance::Incremental });
                Group::Distance
            }
            (91, 1) => Group::ArcDistance,
            (94, 0) => Group::FeedMode,
            (40, 0) => Group::CutterComp,
            (49, 0) => Group::ToolLength,
            (54, 0) => Group::CoordSystem,
            (61, 0) => Group::Control,
            _ => return Err(GrblError::Unsupported),
        };
        self.enter(group)
    }

    fn non_modal(&mut self, command: NonModal) -> Group {
        // A second group-0 command fails in `enter`, so keeping the first one here is harmless.
        if self.non_modal.is_none() {
            self.non_modal = Some(command);
        }
        Group::NonModal
    }

    fn m(&mut self, value: f32) -> Result<(), GrblError> {
        let (int, tenths) = command_number(value)?;
        if tenths != 0 {
            return Err(GrblError::ValueNotInteger);
        }
        let group = match int {
            0 | 1 | 2 | 30 => {
                self.stop = match int {
                    0 => Some(Stop::Pause),
                    1 => None,
                    _ => Some(Stop::End),
                };
                Group::Stop
            }
            3..=5 => {
                self.spindle = Some([Spindle::Cw, Spindle::Ccw, Spindle::Off][int as usize - 3]);
                Group::Spindle
            }
            9 => Group::Coolant,
            _ => return Err(GrblError::Unsupported),
        };
        self.enter(group)
    }
}

/// A G or M number as (integer part, tenths): `92.1` is (92, 1); hundredths are refused.
fn command_number(value: f32) -> Result<(u16, u8), GrblError> {
    if !(0.0..1000.0).contains(&value) {
        return Err(GrblError::Unsupported);
    }
    let hundredths = crate::math::round(value * 100.0) as u32;
    if !hundredths.is_multiple_of(10) {
        return Err(GrblError::ValueNotInteger);
    }
    Ok(((hundredths / 100) as u16, ((hundredths % 100) / 10) as u8))
}

/// Parses one line of G-code words (compacted).
fn parse_block(bytes: &[u8]) -> Result<Block, GrblError> {
    let mut block = Block::default();
    for word in WordIter::new(bytes) {
        let (letter, value) = word?;
        match letter {
            b'G' => block.g(value)?,
            b'M' => block.m(value)?,
            b'F' | b'N' | b'P' | b'S' | b'T' => {
                block.words.insert(letter, value)?;
                if value < 0.0 {
                    return Err(GrblError::NegativeValue);
                }
                if letter == b'T' && value > TOOL_NUMBER_MAX {
                    return Err(GrblError::MaxValueExceeded);
                }
            }
            b'I' | b'J' | b'K' | b'R' | b'X' | b'Y' | b'Z' => block.words.insert(letter, value)?,
            _ => return Err(GrblError::Unsupported),
        }
    }
    Ok(block)
}

// ----- geometry helpers --------------------------------------------------------------------

/// Error 15 unless the point (machine mm) is inside the travel limits; NaN is outside.
fn check_travel(settings: &Settings, mm: [f32; 2]) -> Result<(), GrblError> {
    for (v, limit) in mm.iter().zip(settings.max_travel_mm) {
        if !(v.abs() <= limit + TRAVEL_SLACK_MM) {
            return Err(GrblError::TravelExceeded);
        }
    }
    Ok(())
}

/// Machine millimetres (inside the travel limits) to the nearest step.
fn to_steps(settings: &Settings, mm: [f32; 2]) -> Point {
    Point::new(settings.mm_to_steps(Axis::X, mm[0]), settings.mm_to_steps(Axis::Y, mm[1]))
}

#[cfg(test)]
mod tests;

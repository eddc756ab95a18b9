//! One line of G-code or a `$` command in, machine [`Command`]s out, with GRBL 1.1's rules.
//!
//! [`GcodeState`] is GRBL's parser state: modal groups (motion, units, distance, work coordinate
//! system, spindle), the feed rate, the coordinate data ([`Offsets`]: G54–G59, G28, G30, G92) and
//! the *planned* position — where the pen will be once every command handed out so far has run.
//! [`GcodeState::execute`] parses a whole line first and changes the state only if the line is
//! valid: an error line leaves the modal state, every offset, the planned position and the
//! settings as they were. Positions inside are machine millimetres (as GRBL keeps them, so that
//! relative moves never drift by rounding); every command handed out is in absolute steps,
//! rounded from them.
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
//!   [`CURVE_RADIUS_MAX_MM`](crate::motion::drawing::CURVE_RADIUS_MAX_MM);
//! - G4 P dwell (seconds), G17 (G18/G19 refused), G20/G21, G90/G91, G91.1, G80, and the header
//!   no-ops G40, G49, G61, G94;
//! - work coordinates, below: G54–G59, G10 L2 / L20, G28 / G30, G28.1 / G30.1, G92 / G92.1, G53;
//! - M0 (pause), M1 (ignored), M2/M30 (program end), M3/M4/M5 and S (accepted, no spindle),
//!   M8/M9 (accepted, no coolant), T (kept for `$G`, as GRBL keeps them).
//!
//! **Z words.** The plotter has no Z axis; senders move Z to lift and lower a pen. A Z word is
//! accepted and ignored: a move with only Z answers `ok` and does nothing, a move with Z and X/Y
//! moves X/Y only. Z counts as an axis word for GRBL's checks (G80 with Z is still error 31).
//!
//! A G1/G2/G3 before any F word uses the default feed rate (`$203`); only an explicit `F0`
//! leaves a feed move without a feed rate (error 22).
//!
//! # Work coordinates
//!
//! As in GRBL, every absolute target — of G0–G3 and of a `$J=` jog — is in work coordinates:
//! machine position = work position + the active system's offset + the G92 offset (`WCO`, see
//! [`GcodeState::work_offset_mm`]). G53 takes machine coordinates for one G0/G1 line (or jog);
//! G91 moves are relative and see no offset. The plotter curve commands draw from the pen and
//! have no absolute target, so no offset changes them.
//!
//! - G54–G59 select the active system (modal group 12; G54 at power-on, after a reset and after
//!   M2/M30). The selection in a line applies to that line's target.
//! - `G10 L2 Pn X Y` sets system n's offset to X Y; `G10 L20 Pn X Y` sets it so that the planned
//!   position has work coordinates X Y under it (a sender's "zero here": `G10 L20 P1 X0 Y0`).
//!   P0 is the active system, P1–P6 are G54–G59; an axis without a word keeps its offset.
//!   Errors, GRBL's: no axis word 26, no L or no P 28, a P other than 0 to 6 (or not whole) 29,
//!   an L other than 2 or 20, or L2 with R, 20.
//! - `G92 X Y` shifts every system further, so that the planned position has work coordinates
//!   X Y; G92.1 clears that shift.
//! - `G28` / `G30` rapid to the position `G28.1` / `G30.1` stored (machine coordinates, the
//!   planned position when they ran). With axis words they first rapid to the point the words
//!   give (work coordinates, G90/G91 as set), then only the axes named go on to the stored
//!   position, as in GRBL; a Z word alone moves nothing. Axis words with G28.1 / G30.1 are an
//!   ordinary move in the motion mode, after the position is stored.
//! - G10, G28, G30 and G92 take the line's axis words, so none of them shares a line with a
//!   motion command or another of them (error 24); under G80 they may have no axis word (31).
//!
//! The offsets of G54–G59 and the G28 and G30 positions outlive a soft reset, as GRBL's EEPROM
//! data does; the serial task keeps them in the flash store, so they outlive a power cycle too.
//! A reset clears the G92 offset and selects G54; `$RST=#` (or `$RST=*`) clears them all.
//!
//! # `$` commands
//!
//! `$` help, `$$` settings, `$N=value` set one, `$G` parser state (with the active G54–G59), `$#`
//! the coordinate data (GRBL's `[G54:…]` to `[G59:…]`, `[G28:…]`, `[G30:…]`, `[G92:…]`, then
//! `[TLO:0.000]` and `[PRB:0.000,0.000,0.000:0]`: no tool length, no probe), `$I` build info,
//! `$X` unlock, `$H` (no homing: error 5), `$RST=$` / `$RST=#` / `$RST=*` restore settings /
//! clear the coordinate data / both, `$J=` jog (GRBL's rules: only G20/G21, G90/G91, G53, X Y
//! Z, N and a required F; the line's modes apply to the jog only), `$C` check mode (at rest only,
//! error 8 otherwise: every line is parsed and every drawing built and checked against the
//! travel and the lattice, from the position the lines before it plan, and nothing moves; `$C`
//! again leaves it with a soft reset, as GRBL does), `$N` / `$Nn=line` startup blocks (two, run
//! after every reset; a block is checked when stored and refused, error 3, if it would move,
//! dwell or stop: no one expects the pen to move at a reset), `$SLP` (at rest, in an alarm,
//! or behind a running program, whose motion it waits for; error 8 held, jogging or homing: the
//! servos go off and every line is refused, error 9, until a reset, after which the machine is in
//! alarm, as in GRBL).
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
//! | `$F X<x0> U<x1> [F] Y=<expression>` | y = f(x) for x from x0 to x1, moved so that (x0, f(x0)) is at the pen; everything after `Y=` (up to a `;`) is the expression ([`crate::motion::expr`]) |
//!
//! `$O` rather than `$C`, and `$SLP` kept apart from `$S`, so that a sender's check-mode or
//! sleep button never draws.
//!
//! Every move and curve is built by the drawing builder ([`crate::motion::drawing`]) from the planned
//! position, exactly as it will be drawn: what would leave the travel limits is error 15, what
//! cannot be drawn as asked (a curve finer than the step lattice, a sine steeper than the jump
//! limit `$204`, a function undefined or jumping part way, changing faster than its X steps or
//! too far from zero for single precision) is error 33 with a message, and
//! nothing moves. The planned position afterwards is the curve's last lattice point (for a G-code
//! target that rounds to it, the target in millimetres). A curve that ends on its own start step
//! is a full turn if it sweeps at least half a turn, and draws nothing otherwise.

// Limits are written `!(value <= limit)` on purpose: a NaN must fail them.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod coordinates;
mod curves;
mod modal;
mod motion;
mod offsets;
mod snapshot;
mod system;
mod words;

pub use modal::{
    Coolant, Distance, MM_PER_INCH, MotionMode, Spindle, TOOL_NUMBER_MAX, Units, WORK_SYSTEMS, WorkSystem,
};
pub use offsets::{KEPT_OFFSETS, Offsets, StoredPosition};
pub use snapshot::Modal;

use super::GrblError;
use crate::geom::{Axis, Point};
use crate::host::startup::StartupLine;
use crate::machine_io::pen::{self, Pen, PenDepth};
use crate::motion::drawing::{self, Builder, Request, Slice};
use crate::motion::interp::ShapeKind;
use crate::motion::job::{Feed, Job, JobKind};
use crate::settings::Settings;
use crate::status::RunState;

use words::{ProgramStop, compact, parse_block};

/// What one line asks of the machine: an iterator over its [`Command`]s in execution order (the
/// pen for M3/M4/M5, a G4 dwell, then the motion or `$` command, then an M0/M2/M30 stop — GRBL's order). Empty for a
/// line that only changes modes, or a comment: answer `ok`. It holds at most two large commands
/// (G28 or G30 through an intermediate point: two moves), so it costs little more than two
/// [`Command`]s.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Commands {
    /// M3/M4/M5, or an S word under M3/M4, with a pen lift: the pen goes there first.
    pen: Option<(Pen, PenDepth)>,
    dwell_ms: Option<u32>,
    /// The move to the intermediate point of G28 or G30, before `main`.
    via: Option<Command>,
    main: Option<Command>,
    stop: Option<ProgramStop>,
    /// While the line is parsed: the curve that becomes `main` once it is built.
    curve: Option<LineCurve>,
}

/// The curve of a line (G2/G3, `$E`, `$O`, `$S`, `$F`) as parsed, to be built from the planned
/// position, and the job it becomes.
#[derive(Clone, Debug, PartialEq)]
struct LineCurve {
    request: Request,
    feed: Feed,
    pen: Option<Pen>,
    /// The G-code target (G2/G3), in millimetres: the planned position afterwards when the
    /// curve ends on the step it rounds to.
    target_mm: Option<[f32; 2]>,
}

/// A line parsed and checked, its curve (if it has one) not yet built: see
/// [`GcodeState::parse`]. It holds the parser state the line leads to, kept only by
/// [`GcodeState::commit`]. It is large (a curve and two jobs): the serial task keeps one and
/// parses every line into it.
pub struct Pending {
    /// The parser state once the line has run, but for the planned position after its curve.
    next: GcodeState,
    commands: Commands,
    /// The line's curve, being built.
    curve: Option<Building>,
    /// Check mode: the line is built and checked, and nothing of it runs.
    check: bool,
}

/// A line's curve being built, and the job it becomes.
struct Building {
    builder: Builder,
    feed: Feed,
    pen: Option<Pen>,
    target_mm: Option<[f32; 2]>,
}

impl Default for Pending {
    fn default() -> Self {
        Self::new()
    }
}

impl Pending {
    /// Whether the line changes what a power cycle keeps of the parser (a work offset, G28 or
    /// G30), compared with the parser `now`.
    pub fn changes_kept(&self, now: &GcodeState) -> bool {
        self.next.offsets().kept_mm() != now.offsets().kept_mm()
    }

    /// No line.
    pub fn new() -> Pending {
        Pending { next: GcodeState::new(), commands: Commands::default(), curve: None, check: false }
    }

    /// Drops the line held.
    fn clear(&mut self) {
        self.commands = Commands::default();
        self.curve = None;
    }

    /// Walks at most `max_steps` more of the line's curve; a line without one is done at once.
    pub fn advance(&mut self, max_steps: u32) -> Slice {
        match &mut self.curve {
            Some(curve) => curve.builder.advance(max_steps),
            None => Slice { kind: ShapeKind::Straight, expr_ops: 0, steps: 0, x_steps: 0, done: true },
        }
    }

    /// The line's commands once it is [committed](GcodeState::commit), those not yet taken: a
    /// caller that takes them a few at a time comes back for the rest here.
    pub fn commands(&mut self) -> &mut Commands {
        &mut self.commands
    }

    /// True when the line asks nothing of the machine (it only changes modes).
    pub fn is_empty(&self) -> bool {
        self.curve.is_none() && self.commands.is_empty()
    }
}

impl Commands {
    /// Commands still to come.
    pub fn len(&self) -> usize {
        self.pen.is_some() as usize
            + self.dwell_ms.is_some() as usize
            + self.via.is_some() as usize
            + self.main.is_some() as usize
            + self.stop.is_some() as usize
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Keeps what of these commands check mode carries out: no motion, no dwell and no pause.
    fn keep_checked(&mut self) {
        (self.pen, self.dwell_ms, self.via) = (None, None, None);
        if matches!(self.main, Some(Command::Job(_))) {
            self.main = None;
        }
        if self.stop == Some(ProgramStop::Pause) {
            self.stop = None;
        }
    }
}

impl Iterator for Commands {
    type Item = Command;

    fn next(&mut self) -> Option<Command> {
        if let Some(pen) = self.pen.take() {
            return Some(Command::Pen(pen.0, pen.1));
        }
        if let Some(ms) = self.dwell_ms.take() {
            return Some(Command::Dwell { ms });
        }
        if let Some(via) = self.via.take() {
            return Some(via);
        }
        if let Some(main) = self.main.take() {
            return Some(main);
        }
        self.stop.take().map(|stop| match stop {
            ProgramStop::Pause => Command::Pause,
            ProgramStop::End => Command::ProgramEnd,
        })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.len(), Some(self.len()))
    }
}

/// Largest N line number, GRBL's.
pub const LINE_NUMBER_MAX: f32 = 9_999_999.0;

/// Longest G4 dwell: one hour.
pub const DWELL_MAX_MS: u32 = 3_600_000;

/// G2/G3 with I/J: the end may lie off the start's circle by this much without complaint...
pub const ARC_RADIUS_SLACK_MM: f32 = 0.005;
/// ...and never by more than this, nor by more than [`ARC_RADIUS_ERROR_MAX_RATIO`] of the
/// radius (GRBL's and LinuxCNC's rule).
pub const ARC_RADIUS_ERROR_MAX_MM: f32 = 0.5;
pub const ARC_RADIUS_ERROR_MAX_RATIO: f32 = 0.001;

/// Arc sweeps closer than this to zero count as a full turn (GRBL's epsilon).
const ARC_ANGLE_EPSILON_RAD: f32 = 5e-7;

/// What a report request asks for; the serial task formats it with [`crate::host::report`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Report {
    /// `$`: [`crate::host::report::help`].
    Help,
    /// `$$`: [`crate::host::report::settings`].
    Settings,
    /// `$G`: [`crate::host::report::parser_state`].
    ParserState,
    /// `$#`: [`crate::host::report::parameters`].
    Parameters,
    /// `$I`: [`crate::host::report::build_info`].
    BuildInfo,
    /// `$N`: [`crate::host::report::startup_lines`].
    StartupLines,
}

/// What one line asks the machine to do.
// A function curve carries its parsed expression by value (no heap).
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// A drawing (G0, G1, G2/G3, `$E`, `$O`, `$S`, `$F`) or a `$J=` jog, built and checked;
    /// the parser's planned position is its end. A jog cancel (0x85) aborts a jog; the parser
    /// then plans from where it stopped ([`GcodeState::plan_from`]).
    Job(Job),
    /// G4: wait this long once the motion before it has finished.
    Dwell { ms: u32 },
    /// M0: finish the queued motion, then hold until cycle start (`~`).
    Pause,
    /// M2/M30: finish the queued motion; the program is over (GRBL answers `[MSG:Pgm End]`).
    ProgramEnd,
    /// `$id=value`, already checked against the settings given to `execute`: apply it with
    /// `Settings::set` (which then succeeds).
    SetSetting { id: u16, value: f32 },
    /// `$RST=$` or `$RST=*`: every setting back to `Settings::default()`, and for `$RST=*` the
    /// startup blocks cleared.
    RestoreSettings { startup_lines: bool },
    /// `$Nn=line`: store startup block `index` (checked: it parses and moves nothing).
    StoreStartupLine { index: u8, line: StartupLine },
    /// `$I=line`: store the build info line `$I` shows.
    StoreBuildInfo(StartupLine),
    /// `$SLP`: servos off and every line refused until a reset (GRBL answers `[MSG:Sleeping]`).
    Sleep,
    /// Answer with a report (before the `ok`).
    Report(Report),
    /// `$X`: leave the alarm state (GRBL answers `[MSG:Caution: Unlocked]`).
    Unlock,
    /// `$H`: run the homing cycle; `ok` once the machine is homed.
    Home,
    /// M3/M4 (down, as deep as the S word says) or M5 (up) with a pen lift (`$213`): at rest,
    /// the pen moves and settles.
    Pen(Pen, PenDepth),
    /// `$C`: enter check mode (`[MSG:Enabled]`), or leave it (`[MSG:Disabled]`, then a soft
    /// reset once the line is answered, as GRBL does, so the parser plans from the pen again).
    CheckMode { on: bool },
}

/// GRBL's parser state; see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GcodeState {
    motion: MotionMode,
    units: Units,
    distance: Distance,
    work_system: WorkSystem,
    spindle: Spindle,
    coolant: Coolant,
    /// `None` until an F word: the default feed rate applies.
    feed_mm_per_min: Option<f32>,
    /// The last S word, `None` until one is given.
    spindle_speed: Option<f32>,
    tool: u8,
    /// Planned position, machine coordinates.
    position_mm: [f32; 2],
    /// The same, rounded to steps: where the last command handed out ends.
    position: Point,
    /// G54–G59, G28, G30 and G92: machine position = work position + the active system's
    /// offset + the G92 offset.
    offsets: Offsets,
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
            work_system: WorkSystem::G54,
            spindle: Spindle::Off,
            coolant: Coolant::Off,
            feed_mm_per_min: None,
            spindle_speed: None,
            tool: 0,
            position_mm: [0.0; 2],
            position: Point::ORIGIN,
            offsets: Offsets::new(),
        }
    }

    /// Power-on: the modes of [`new`](Self::new) with the offsets a power cycle kept.
    pub fn with_offsets(offsets: Offsets) -> Self {
        GcodeState { offsets: offsets.after_reset(), ..GcodeState::new() }
    }

    /// After a soft reset: power-on modes (G54 active) and no G92 offset, at the machine's real
    /// `position`. The offsets of G54–G59 and the G28 and G30 positions stay, as GRBL keeps them
    /// (in EEPROM there, in the flash store here).
    pub fn reset(&mut self, position: Point, settings: &Settings) {
        let offsets = self.offsets.after_reset();
        *self = GcodeState { offsets, ..GcodeState::new() };
        self.sync_position(position, settings);
    }

    /// Plans on from `end`, where the machine says the plan ends: unchanged if that is where
    /// the parser planned to (its fractions of a step kept), else the parser's planned position
    /// becomes `end` (the keypad drew, an abort stopped the pen, or homing moved machine zero).
    pub fn plan_from(&mut self, end: Point, settings: &Settings) {
        if end != self.position {
            self.sync_position(end, settings);
        }
    }

    /// Makes the planned position `position`, in steps. Out of line: three callers.
    #[inline(never)]
    fn sync_position(&mut self, position: Point, settings: &Settings) {
        self.position = position;
        self.position_mm = [settings.steps_to_mm(Axis::X, position.x), settings.steps_to_mm(Axis::Y, position.y)];
    }

    /// Where the pen will be once everything handed out so far has run, in steps.
    pub fn planned_position(&self) -> Point {
        self.position
    }

    /// The work coordinate offset (machine = work + offset): the active system's offset plus
    /// the G92 offset, GRBL's `WCO:`.
    pub fn work_offset_mm(&self) -> [f32; 2] {
        self.offsets.work_offset_mm(self.work_system)
    }

    /// G54–G59, G28, G30 and G92, for `$#`.
    pub fn offsets(&self) -> &Offsets {
        &self.offsets
    }

    /// The active work coordinate system (G54–G59).
    pub fn work_system(&self) -> WorkSystem {
        self.work_system
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

    pub fn coolant(&self) -> Coolant {
        self.coolant
    }

    pub fn spindle_speed(&self) -> Option<f32> {
        self.spindle_speed
    }

    pub fn tool(&self) -> u8 {
        self.tool
    }

    /// Executes one line (without its line end) against `settings` while the machine is in
    /// `state`, building its curve in one go. On success the state has advanced and the
    /// commands say what to do; on error nothing has changed. The serial task builds a curve a
    /// slice at a time instead: [`parse`](Self::parse), [`Pending::advance`],
    /// [`commit`](Self::commit).
    pub fn execute(&mut self, line: &str, settings: &Settings, state: RunState) -> Result<Commands, GrblError> {
        let mut pending = Pending::new();
        self.parse(line, settings, state, &mut pending)?;
        self.commit(&mut pending, settings)?;
        Ok(core::mem::take(&mut pending.commands))
    }

    /// Parses and checks one line (without its line end) against `settings` while the machine
    /// is in `state`, into `pending` (whatever it held before is dropped), and sets its curve
    /// up; changes nothing. The curve is then walked with [`Pending::advance`], and
    /// [`commit`](Self::commit) keeps the line.
    pub fn parse(
        &self,
        line: &str,
        settings: &Settings,
        state: RunState,
        pending: &mut Pending,
    ) -> Result<(), GrblError> {
        pending.clear();
        if state == RunState::Sleep {
            // Asleep (`$SLP`), the servos are off: every line waits for a reset.
            return Err(GrblError::Locked);
        }
        // The line runs on a copy, kept only by `commit`: an error line changes nothing.
        pending.next = *self;
        pending.check = state == RunState::Check;
        pending.next.parse_line(line, settings, state, &mut pending.commands)?;
        if let Some(LineCurve { request, feed, pen, target_mm }) = &pending.commands.curve {
            let next = &mut pending.next;
            match Builder::new(request, next.position, settings)? {
                Some(builder) => {
                    pending.curve = Some(Building { builder, feed: *feed, pen: *pen, target_mm: *target_mm })
                }
                // Shorter than a step, it draws nothing: the pen is planned at its G-code
                // target, if it has one.
                None => next.position_mm = target_mm.unwrap_or(next.position_mm),
            }
            pending.commands.curve = None;
        }
        Ok(())
    }

    /// Keeps the line `pending` holds from [`parse`](Self::parse) (with the same `settings`),
    /// once its curve is built (whatever is left of it is walked now, in one go): the state
    /// advances to the line's, and the commands say what to do. A curve refused as it was
    /// walked is the line's error, and nothing changes.
    pub fn commit<'p>(&mut self, pending: &'p mut Pending, settings: &Settings) -> Result<&'p mut Commands, GrblError> {
        if let Some(Building { builder, feed, pen, target_mm }) = &mut pending.curve {
            let drawing = builder.finish()?;
            let (job, target_mm) =
                (Job { drawing, feed: *feed, kind: JobKind::Draw, pen: *pen, raise_after: false }, *target_mm);
            pending.next.plan(job, target_mm, settings, &mut pending.commands.main);
            pending.curve = None;
        }
        *self = pending.next;
        if pending.check {
            // Check mode: the line was parsed and its drawing built and checked; nothing runs.
            pending.commands.keep_checked();
        }
        Ok(&mut pending.commands)
    }

    /// Runs a startup block: a line that moves nothing (checked when it is stored, with this
    /// very rule): one that would move, dwell or stop is refused (error 3), and changes nothing.
    pub fn run_startup_block(&mut self, line: &str, settings: &Settings) -> Result<(), GrblError> {
        let mut pending = Pending::new();
        self.parse(line, settings, RunState::Idle, &mut pending)?;
        if !pending.is_empty() {
            return Err(GrblError::InvalidStatement);
        }
        self.commit(&mut pending, settings).map(|_| ())
    }

    fn parse_line(
        &mut self,
        line: &str,
        settings: &Settings,
        state: RunState,
        out: &mut Commands,
    ) -> Result<(), GrblError> {
        let text = line.trim_ascii_start();
        if let Some(rest) = text.strip_prefix('$') {
            return self.system(line, rest, settings, state, out);
        }
        let compact = compact(text, true)?;
        if compact.is_empty() || compact.as_slice() == b"%" {
            return Ok(());
        }
        if matches!(state, RunState::Alarm | RunState::Jog | RunState::Home) {
            return Err(GrblError::Locked);
        }
        self.run_block(parse_block(&compact)?, settings, out)
    }
}

impl GcodeState {
    /// A straight move to the lattice point `to` from the planned position into `slot`, built at
    /// once (a line needs no walk), with the pen planned at its end: `target_mm` (the G-code
    /// target, kept in millimetres so relative moves never drift by rounding; `to` is the step
    /// it rounds to). Nothing when it ends on the step it starts from.
    fn straight(
        &mut self,
        to: Point,
        target_mm: [f32; 2],
        feed: Feed,
        kind: JobKind,
        settings: &Settings,
        slot: &mut Option<Command>,
    ) -> Result<(), GrblError> {
        let built = drawing::build(&Request::Straight { to }, self.position, settings)?;
        self.position_mm = target_mm;
        if let Some(drawing) = built {
            let pen = match kind {
                JobKind::Draw => pen::for_move(settings, feed == Feed::Rapid, self.spindle != Spindle::Off),
                JobKind::Jog | JobKind::Home => None,
            };
            self.plan(Job { drawing, feed, kind, pen, raise_after: false }, Some(target_mm), settings, slot);
        }
        Ok(())
    }

    /// The line's curve: drawn from the planned position at `feed`; `target_mm` is its G-code
    /// target, if it has one (G2/G3). It is set up once the line is parsed, built by the slices
    /// of [`Pending::advance`] and planned by [`commit`](Self::commit).
    fn curve(
        &self,
        request: Request,
        feed: Feed,
        target_mm: Option<[f32; 2]>,
        settings: &Settings,
        out: &mut Commands,
    ) {
        let pen = pen::for_move(settings, false, self.spindle != Spindle::Off);
        out.curve = Some(LineCurve { request, feed, pen, target_mm });
    }

    /// Puts `job` into `slot` and plans the pen at the end of its drawing: `target_mm` (its
    /// G-code target, kept in millimetres so relative moves never drift by rounding) when the
    /// drawing ends on the step it rounds to (as a line always does), else its own last lattice
    /// point.
    fn plan(&mut self, job: Job, target_mm: Option<[f32; 2]>, settings: &Settings, slot: &mut Option<Command>) {
        let end = job.drawing.end();
        self.position_mm = match target_mm {
            Some(target) if drawing::line_target(target, settings) == Some(end) => target,
            _ => [settings.steps_to_mm(Axis::X, end.x), settings.steps_to_mm(Axis::Y, end.y)],
        };
        self.position = end;
        *slot = Some(Command::Job(job));
    }
}

#[cfg(test)]
mod tests;

//! The check of a whole program, a line at a time, before anything moves: [`ProgramCheck`].
//!
//! Each line goes through the host link's parser and the drawing builder exactly as it will when
//! the program runs ([`GcodeState::parse`] in [`RunState::Run`], [`Pending::advance`],
//! [`GcodeState::commit`]): every word checked, every drawing built and checked against the
//! lattice and the travel, from the position the lines before it plan, as check mode (`$C`)
//! does; and nothing of it runs. (Check mode itself would refuse a setting line, `$213=1` at the
//! top of a file, which the running program takes.) The first refused line ends the check with
//! its number and error ([`Refusal`]). The motion the lines plan is then handed to a planner as
//! the motion task hands it (look-ahead kept full, a rest where the pen moves, before a dwell, a
//! stop or a setting), and its step commands are summed: the plot time by the planner's own
//! model. The same steps give the boxes (every motion, and the pen-down strokes) and set the
//! strokes' pixels of the picture ([`crate::program::preview`]).
//!
//! The work is resumable and bounded: [`ProgramCheck::push_line`] parses one line (at most
//! [`LINE_MAX_BYTES`], the host link's limit) and sets its drawing up, then each
//! [`ProgramCheck::work`] does one bounded piece: a slice of the builder's walk
//! ([`BUILD_SLICE_STEPS`] steps' worth, as the host link builds a line), the line's commit, or
//! at most [`PLAN_SLICE_STEPS`] step commands of the planner; and returns, so the caller may
//! yield between calls. A line of `n` steps takes about `n / BUILD_SLICE_STEPS` calls to walk
//! (a curve; a straight line none) and `n / PLAN_SLICE_STEPS` to time, each call within a few
//! milliseconds of the F407: a circle of 100 mm diameter (40,000 steps at the defaults) about
//! 180 calls. The line's text is needed only by `push_line`. Nothing here waits, reads a card or
//! moves anything.
//!
//! Commands of the host's session have no place in a program and are refused as the parser
//! refuses them while a program runs (`$C`, `$RST=`, `$J=`: `error:8`; `$H`: `error:5` without
//! homing switches, else 8), or here with `error:8` (`$X`, `$SLP`, `$Nn=`, `$I=`: the machine is
//! not at rest while a program runs). A setting (`$nnn=`) applies to the lines after it, as it
//! will when the program runs.

use crate::geom::{Axis, Point, StepCmd, TICK_HZ};
use crate::host::gcode::Pending;
use crate::host::{Command, GcodeState, GrblError, LINE_MAX_BYTES};
use crate::machine_io::pen::{self, Pen, PenLift};
use crate::motion::drawing::{BUILD_SLICE_STEPS, Bounds};
use crate::motion::interp::Curve;
use crate::motion::job::{Job, JobKind};
use crate::motion::planner::{Limits, PLANNER_SEGMENTS, Planner};
use crate::program::preview::{MapScale, PenStrokes, StrokeMap};
use crate::settings::Settings;
use crate::status::RunState;

/// The planner a check times the plot with: the motion task's own kind and depth, so the times
/// are the motion's. It is about 50 KB: the caller keeps it in static storage, built in place
/// ([`Planner::init`]), and lends it to each [`ProgramCheck::work`].
pub type CheckPlanner = Planner<Curve, PLANNER_SEGMENTS>;

/// Step commands one [`ProgramCheck::work`] takes from the planner at most. The planner's work
/// per step is the motion's (up to about 900 instructions a step for a function of 27
/// operations, see the README's cost table) and the picture's (a pixel per step): 1024 steps
/// took up to 11.6 ms of the F407 on the model board (`model/card.py`), so a quarter of that,
/// well within the 10 ms any task may hold the processor.
pub const PLAN_SLICE_STEPS: usize = 256;

/// Step commands taken from the planner at a time, within a call.
const PLAN_BATCH_STEPS: usize = 64;

/// Microseconds per second, for the planner's ticks.
const US_PER_S: u64 = 1_000_000;

/// The first refused line of a program.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refusal {
    /// The line's number in the program, from 1.
    pub line: u32,
    /// Why: the host link would answer it with [`crate::host::report::error`].
    pub error: GrblError,
}

/// What the check found of the program so far (all of it once [`ProgramCheck::work`] says
/// [`Progress::Done`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    /// Lines checked.
    pub lines: u32,
    /// The box of every motion, machine steps; `None` when nothing moves.
    pub motion: Option<Bounds>,
    /// The box of the pen-down strokes; `None` when nothing is drawn.
    pub strokes: Option<Bounds>,
    /// Every motion stays within the travel (`$130`, `$131`).
    pub within_travel: bool,
    /// The plot's time by the planner's model, µs: the step commands' intervals, the pen's
    /// settle times and the dwells. An `M0` pause counts nothing: it waits for the user.
    pub plot_time_us: u64,
    /// Step commands the plot emits (a diagonal step is one): what the machine's emitted-steps
    /// count goes up by while it runs.
    pub steps: u64,
}

/// What [`ProgramCheck::work`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Progress {
    /// More to do for the line (or the end): call again.
    Working,
    /// The line is checked: push the next, or [`ProgramCheck::end`].
    Ready,
    /// A line was refused: the check is over ([`ProgramCheck::refusal`]).
    Refused(Refusal),
    /// The program is checked and timed ([`ProgramCheck::summary`]).
    Done,
}

/// Where the check stands.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Stage {
    /// Waiting for a line.
    Ready,
    /// The line's curve is being walked.
    Walking,
    /// The line's commands are being handed on.
    Commands,
    /// No more lines: the planner runs out.
    Ending,
    Done,
    Refused(Refusal),
}

/// A program being checked; see the module documentation. About 4 KB (the line's parse and one
/// job held): keep it where it lies and [`start`](Self::start) it again for the next program.
pub struct ProgramCheck {
    settings: Settings,
    gcode: GcodeState,
    pending: Pending,
    stage: Stage,
    /// A command waiting for its turn: for the machine to rest, or for room in the planner.
    held: Option<Command>,
    lines: u32,
    /// Where the pen is after the steps emitted so far, and where it is held.
    at: Point,
    pen: Pen,
    /// The pen moved: the next motion waits for it to settle.
    settle_due: bool,
    /// The boxes so far.
    motion: Option<Bounds>,
    strokes: Option<Bounds>,
    /// Sums of the plot's time: planner ticks, and waits in µs.
    ticks: u64,
    /// Step commands emitted so far.
    steps: u64,
    waits_us: u64,
    scale: MapScale,
    trail: PenStrokes,
}

impl ProgramCheck {
    /// A check of a program run from the parser state `gcode` (its planned position, modes and
    /// work offsets) with `settings`, the pen at `pen`. Then [`start`](Self::start) it.
    pub fn new(gcode: GcodeState, settings: &Settings, pen: Pen) -> ProgramCheck {
        ProgramCheck {
            settings: *settings,
            gcode,
            pending: Pending::new(),
            stage: Stage::Ready,
            held: None,
            lines: 0,
            at: gcode.planned_position(),
            pen,
            settle_due: false,
            motion: None,
            strokes: None,
            ticks: 0,
            steps: 0,
            waits_us: 0,
            scale: MapScale::for_travel(settings),
            trail: PenStrokes::new(),
        }
    }

    /// A check waiting for its first program, built in `slot` where it lies, a field at a time
    /// (it is 4 KB: the board keeps it in static storage). Then [`start`](Self::start) it.
    pub fn init<'s>(slot: &'s mut core::mem::MaybeUninit<Self>, settings: &Settings) -> &'s mut Self {
        use core::ptr::addr_of_mut;
        let p = slot.as_mut_ptr();
        let gcode = GcodeState::new();
        // SAFETY: every field of `*p` is written once below, in place, before the slot is taken
        // as initialised; `every_field` lists them all, so that a new field cannot be left out
        // unnoticed.
        unsafe {
            addr_of_mut!((*p).settings).write(*settings);
            addr_of_mut!((*p).gcode).write(gcode);
            addr_of_mut!((*p).pending).write(Pending::new());
            addr_of_mut!((*p).stage).write(Stage::Ready);
            addr_of_mut!((*p).held).write(None);
            addr_of_mut!((*p).lines).write(0);
            addr_of_mut!((*p).at).write(gcode.planned_position());
            addr_of_mut!((*p).pen).write(Pen::Up);
            addr_of_mut!((*p).settle_due).write(false);
            addr_of_mut!((*p).motion).write(None);
            addr_of_mut!((*p).strokes).write(None);
            addr_of_mut!((*p).ticks).write(0);
            addr_of_mut!((*p).steps).write(0);
            addr_of_mut!((*p).waits_us).write(0);
            addr_of_mut!((*p).scale).write(MapScale::for_travel(settings));
            addr_of_mut!((*p).trail).write(PenStrokes::new());
            slot.assume_init_mut()
        }
    }

    /// Every field of the check: this pattern stops compiling when one is added, a reminder
    /// that [`init`](Self::init) must write it too.
    #[allow(dead_code)]
    fn every_field(self) {
        let ProgramCheck {
            settings: _,
            gcode: _,
            pending: _,
            stage: _,
            held: _,
            lines: _,
            at: _,
            pen: _,
            settle_due: _,
            motion: _,
            strokes: _,
            ticks: _,
            steps: _,
            waits_us: _,
            scale: _,
            trail: _,
        } = self;
    }

    /// Starts the check over, as [`new`](Self::new) sets it up, with `planner` emptied and set
    /// to `settings`' limits.
    pub fn start(&mut self, gcode: GcodeState, settings: &Settings, pen: Pen, planner: &mut CheckPlanner) {
        self.settings = *settings;
        self.gcode = gcode;
        self.stage = Stage::Ready;
        self.held = None;
        self.lines = 0;
        self.at = gcode.planned_position();
        self.pen = pen;
        self.settle_due = false;
        (self.motion, self.strokes) = (None, None);
        (self.ticks, self.steps, self.waits_us) = (0, 0, 0);
        self.scale = MapScale::for_travel(settings);
        self.trail = PenStrokes::new();
        planner.drop_all();
        planner.set_overrides(Default::default());
        planner.set_limits(Limits::from_settings(settings));
    }

    /// Takes the program's next line (without its line end; a trailing `\r` is dropped). It is
    /// parsed at once; its work follows in [`work`](Self::work). False when the check is not
    /// waiting for a line (the line before is not done, or the check is over): nothing changes.
    pub fn push_line(&mut self, line: &str) -> bool {
        if self.stage != Stage::Ready {
            return false;
        }
        self.lines += 1;
        let line = line.strip_suffix('\r').unwrap_or(line);
        let parsed = if line.len() > LINE_MAX_BYTES {
            Err(GrblError::LineOverflow)
        } else {
            self.gcode.parse(line, &self.settings, RunState::Run, &mut self.pending)
        };
        self.stage = match parsed {
            Ok(()) => Stage::Walking,
            Err(error) => Stage::Refused(Refusal { line: self.lines, error }),
        };
        true
    }

    /// No more lines: [`work`](Self::work) then runs the planner out and says
    /// [`Progress::Done`]. False when the check is not waiting for a line.
    pub fn end(&mut self) -> bool {
        if self.stage != Stage::Ready {
            return false;
        }
        self.stage = Stage::Ending;
        true
    }

    /// Does one bounded piece of the work (see the module documentation), with the `planner`
    /// [`start`](Self::start) set up, and says where the check stands.
    pub fn work(&mut self, planner: &mut CheckPlanner) -> Progress {
        match self.stage {
            Stage::Ready => return Progress::Ready,
            Stage::Done => return Progress::Done,
            Stage::Refused(r) => return Progress::Refused(r),
            Stage::Walking => {
                if self.pending.advance(BUILD_SLICE_STEPS).done {
                    self.stage = match self.gcode.commit(&mut self.pending, &self.settings) {
                        Ok(_) => Stage::Commands,
                        Err(error) => Stage::Refused(Refusal { line: self.lines, error }),
                    };
                }
            }
            Stage::Commands => self.hand_on(planner),
            Stage::Ending => {
                if self.run_planner(planner, true) {
                    self.stage = Stage::Done;
                }
            }
        }
        match self.stage {
            Stage::Ready => Progress::Ready,
            Stage::Done => Progress::Done,
            Stage::Refused(r) => Progress::Refused(r),
            _ => Progress::Working,
        }
    }

    /// The first refused line, if any.
    pub fn refusal(&self) -> Option<Refusal> {
        match self.stage {
            Stage::Refused(r) => Some(r),
            _ => None,
        }
    }

    /// What the check found so far.
    pub fn summary(&self) -> Summary {
        let within_travel = self.motion.is_none_or(|b| b.within_travel(&self.settings));
        let plot_time_us = self.ticks * US_PER_S / u64::from(TICK_HZ) + self.waits_us;
        let (lines, motion, strokes, steps) = (self.lines, self.motion, self.strokes, self.steps);
        Summary { lines, motion, strokes, within_travel, plot_time_us, steps }
    }

    /// The settings the program leaves (a `$nnn=` line changes them for the lines after it).
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The pen-down strokes' pixels so far.
    pub fn strokes_map(&self) -> &StrokeMap {
        self.trail.map()
    }

    /// How the picture maps the travel (the travel of the settings the check started with).
    pub fn scale(&self) -> &MapScale {
        &self.scale
    }

    /// Hands the line's commands on, one piece of work at a time.
    fn hand_on(&mut self, planner: &mut CheckPlanner) {
        let command = match self.held.take() {
            Some(command) => command,
            None => match self.pending.commands().next() {
                Some(command) => command,
                None => {
                    self.stage = Stage::Ready;
                    return;
                }
            },
        };
        let rest_first = match &command {
            Command::Job(job) => job.pen.is_some_and(|p| p != self.pen),
            Command::Report(_) => false,
            _ => true,
        };
        if rest_first && !planner.is_idle() {
            self.held = Some(command);
            self.run_planner(planner, true);
            return;
        }
        match command {
            Command::Job(job) if planner.is_full() => {
                self.held = Some(Command::Job(job));
                self.run_planner(planner, false);
            }
            Command::Job(job) => self.plan(job, planner),
            Command::Dwell { ms } => self.waits_us += u64::from(ms) * 1000,
            Command::Pen(p, _) => self.move_pen(p),
            Command::ProgramEnd => {
                if let Some(p) = pen::at_program_end(&self.settings) {
                    self.move_pen(p);
                }
            }
            Command::SetSetting { id, value } => {
                // Checked by the parser against these very settings: it applies.
                // The picture keeps the travel it started with: its pixels are set already.
                if self.settings.set(id, value).is_ok() {
                    planner.set_limits(Limits::from_settings(&self.settings));
                }
            }
            // An M0 pause waits for the user, a report answers at once: no time of the plot's.
            Command::Pause | Command::Report(_) => {}
            Command::CheckMode { .. }
            | Command::Home
            | Command::Unlock
            | Command::Sleep
            | Command::RestoreSettings { .. }
            | Command::StoreStartupLine { .. }
            | Command::StoreBuildInfo(_) => {
                self.stage = Stage::Refused(Refusal { line: self.lines, error: GrblError::NotIdle });
            }
        }
    }

    fn move_pen(&mut self, p: Pen) {
        if p != self.pen {
            self.pen = p;
            self.settle_due = true;
        }
    }

    /// Hands a job to the planner (which has room), the pen where it needs it.
    fn plan(&mut self, job: Job, planner: &mut CheckPlanner) {
        if let Some(p) = job.pen {
            self.move_pen(p);
        }
        if self.settle_due {
            self.settle_due = false;
            self.waits_us += u64::from(self.settings.pen_settle_ms) * 1000;
        }
        let bounds = job.drawing.bounds();
        grow(&mut self.motion, bounds);
        if PenLift::of(&self.settings).draws(self.pen) {
            grow(&mut self.strokes, bounds);
        }
        let (feed, method) = (job.feed, self.settings.method);
        let curve = job.drawing.into_curve();
        // A program's jobs are drawings; a jog keeps its own feed, as the motion task plans it.
        let pushed = match job.kind {
            JobKind::Draw => planner.push(curve, feed, method),
            JobKind::Jog | JobKind::Home => planner.push_jog(curve, feed, method),
        };
        if pushed.is_err() {
            // The caller made room: not reached. The check goes on without its time.
            warn!("program check: planner full");
        }
    }

    /// Takes at most [`PLAN_SLICE_STEPS`] step commands from the planner: all it has (`drain`,
    /// to a rest) or until it has room for a job. True once it is at rest.
    fn run_planner(&mut self, planner: &mut CheckPlanner, drain: bool) -> bool {
        let mut batch = [StepCmd::NONE; PLAN_BATCH_STEPS];
        let draws = PenLift::of(&self.settings).draws(self.pen);
        let mut taken = 0;
        while taken < PLAN_SLICE_STEPS {
            if planner.is_idle() || (!drain && !planner.is_full()) {
                break;
            }
            let emitted = planner.fill(&mut batch, u32::MAX);
            self.ticks += u64::from(emitted.ticks);
            for cmd in &batch[..emitted.steps] {
                self.at = self.at.stepped(cmd.step);
                self.trail.pen_at(self.scale.pixel(self.at), draws);
            }
            taken += emitted.steps;
            self.steps += emitted.steps as u64;
            if emitted.steps == 0 && emitted.end.is_some() && !planner.is_idle() {
                // Nothing to emit and not at rest (a hold): never so in a check, but never
                // loop on it.
                break;
            }
        }
        planner.is_idle()
    }
}

/// Grows `into` to take `b`.
fn grow(into: &mut Option<Bounds>, b: Bounds) {
    match into {
        Some(into) => {
            into.add(b.min);
            into.add(b.max);
        }
        None => *into = Some(b),
    }
}

impl Summary {
    /// The pen-down strokes' width and height, mm; `None` when nothing is drawn.
    pub fn strokes_size_mm(&self, settings: &Settings) -> Option<[f32; 2]> {
        self.strokes.map(|b| {
            [settings.steps_to_mm(Axis::X, b.max.x - b.min.x), settings.steps_to_mm(Axis::Y, b.max.y - b.min.y)]
        })
    }
}

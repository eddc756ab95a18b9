//! The state the tasks share: queues between them, the position counters and the settings.
//!
//! One `Machine` exists per plotter (a `static` on target, a local in the simulator). Tasks
//! receive `&Machine` and talk only through it: the job queue (inputs → motion, [`jobs`]), the
//! control slot (inputs → motion), the counters of the step queue (the queue itself, motion →
//! pulses, is a lock-free single-producer single-consumer ring owned by its two ends), the
//! position counters (written only by the pulse engine), the settings ([`settings`]) and a
//! change signal that wakes the LCD. The keypad menu is not here: the keypad and LCD tasks share
//! it in thread mode ([`crate::tasks::panel`]).
//!
//! The machine also answers where the plan ends, the one point every input plans from
//! ([`plan_end`](Machine::plan_end)): the end of the last job handed over, or, after an abort,
//! where the pen stops. A job is handed over with the [`PlanEnd`] it was planned from, and
//! refused ([`Stale`]) if that is not where the plan ends by then (see [`jobs`]).
//!
//! The pen's orders are kept here too: where it is to be, and whether the servo task has seen it
//! settle there ([`set_pen`](Machine::set_pen), [`pen_settled`](Machine::pen_settled)).
//!
//! The machine also owns where machine zero is: the position is the pulses emitted less the
//! origin homing found ([`set_origin`](Machine::set_origin)), and whether it can be trusted
//! ([`position_lost`](Machine::position_lost)).
//!
//! The overrides (GRBL's feed, rapid and spindle percentages) are one shared word: the host link
//! sets them, the motion task hands them to its planner, reports and the LCD show them.
//!
//! Everything here is shared across priorities, up to the pulse interrupt, which every critical
//! section holds off. Every counter is an atomic with a single writer; the jobs (648 bytes) and
//! the settings (116) are handed over without a lock ([`job_queue`], [`published`]). The
//! critical sections left each copy at most [`LOCKED_VALUE_MAX_BYTES`] in or out (checked
//! below, at compile time) and wake at most the tasks that wait there:
//! - `control`: the control requested and not yet taken (1 byte);
//! - `work_offset_mm`: the work offset, two `f32`;
//! - `fault`: an `Option<MotionFault>`; `trip` and `switch_found`: an `Option<Trip>`;
//! - the signals `control_requested`, `changed`, `pulses_done`, `homing_requested`,
//!   `settings_changed` and `faults`: the waiting task's waker, or what was signalled (`()`, a
//!   `MotionFault`);
//! - `plan`: where the plan ends, a [`PlanEnd`] twice and a flag (28 bytes);
//! - the job queue's waiters: the motion task's waker, and the wakers of the inputs waiting
//!   for room (taken out, and woken outside the lock).

/// Defines a writer's handle, `$name`: a `Copy` reference to the machine that derefs to it for
/// the reads, and whose own methods (in the writer's module) are the writes of its part.
macro_rules! writer_handle {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Clone, Copy)]
        pub struct $name<'m> {
            machine: &'m super::Machine,
        }

        impl<'m> $name<'m> {
            /// Only [`Machine::handles`](super::Machine::handles) makes one.
            pub(super) const fn new(machine: &'m super::Machine) -> Self {
                $name { machine }
            }

            /// The machine, to read.
            #[inline(always)]
            pub fn machine(self) -> &'m super::Machine {
                self.machine
            }
        }

        impl core::ops::Deref for $name<'_> {
            type Target = super::Machine;

            #[inline(always)]
            fn deref(&self) -> &super::Machine {
                self.machine
            }
        }
    };
}

mod handles;
mod job_queue;
mod jobs;
mod path_steps;
mod plan_end;
mod published;
mod pulse_news;
mod pulse_side;
mod pulse_writer;
mod servo_side;
mod servo_writer;
mod settings;

use core::cell::Cell;
use core::sync::atomic::{AtomicBool, AtomicI32, AtomicU8, AtomicU16, AtomicU32, Ordering};
use core::task::Waker;

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;

use crate::geom::{Point, TICK_HZ};
use crate::inputs::Trip;
use crate::interp::ShapeKind;
use crate::job::{Control, Job};
use crate::overrides::{OverrideCommand, Overrides};
use crate::pen::{Pen, PenDepth, PenOrder};
use crate::planner::PLANNER_SEGMENTS;
use crate::settings::Settings;
pub use crate::status::MotionFault;
use crate::status::{RunState, Status};
pub use handles::Handles;
use job_queue::JobQueue;
use path_steps::PathSteps;
use plan_end::PlanState;
pub use plan_end::{PlanEnd, Stale};
use published::Published;
use pulse_side::PulseSide;
pub use pulse_writer::PulseWriter;
use servo_side::ServoSide;
pub use servo_writer::ServoWriter;

/// Jobs accepted from the inputs and not yet taken by the planner. Small: the planner holds the
/// look-ahead; this only decouples the inputs from it.
pub const JOB_QUEUE_LEN: usize = 4;

/// At most this much motion time waits in the step queue, however slow the steps: a hold or an
/// abort starts decelerating within it, even at a feed of 1 mm/min.
pub const STEP_QUEUE_MAX_US: u32 = 20_000;
/// The same in pulse timer ticks.
pub const STEP_QUEUE_MAX_TICKS: u32 = STEP_QUEUE_MAX_US * (TICK_HZ / 1_000_000);

/// The tasks that may wait at once to hand over a job: the host link and the homing task (the
/// keypad's is refused when the queue is full). More are woken to look again, not lost.
pub const JOB_SUBMITTERS: usize = 2;

/// The most a critical section here copies in or out, bytes: the pulse interrupt waits for it,
/// and 64 bytes take at most some 40 instructions (a third of a microsecond) on the F407.
pub const LOCKED_VALUE_MAX_BYTES: usize = 64;

const _: () = {
    use core::mem::size_of;
    assert!(size_of::<Option<Control>>() <= LOCKED_VALUE_MAX_BYTES);
    assert!(size_of::<[f32; 2]>() <= LOCKED_VALUE_MAX_BYTES);
    assert!(size_of::<Option<MotionFault>>() <= LOCKED_VALUE_MAX_BYTES);
    assert!(size_of::<Option<Trip>>() <= LOCKED_VALUE_MAX_BYTES);
    assert!(size_of::<PlanState>() <= LOCKED_VALUE_MAX_BYTES);
    assert!(size_of::<Signal<CriticalSectionRawMutex, MotionFault>>() <= LOCKED_VALUE_MAX_BYTES);
    assert!(size_of::<Signal<CriticalSectionRawMutex, ()>>() <= LOCKED_VALUE_MAX_BYTES);
    // The job queue's waiters: a list of wakers each.
    assert!(size_of::<heapless::Vec<Waker, JOB_SUBMITTERS>>() <= LOCKED_VALUE_MAX_BYTES);
};

/// Why [`Machine::try_submit`] did not queue a job.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Refused {
    /// The job queue is full.
    Full,
    /// See [`Stale`].
    Stale,
}

/// The run states as [`Machine`] stores them.
const STATE_IDLE: u8 = 0;
const STATE_RUN: u8 = 1;
const STATE_HOLD: u8 = 2;
const STATE_JOG: u8 = 3;
const STATE_ALARM: u8 = 4;

/// Everything the tasks share.
pub struct Machine {
    /// What the pulse interrupt writes ([`PulseWriter`]).
    pulses: PulseSide,
    /// What the servo task writes ([`ServoWriter`]).
    servo: ServoSide,
    /// The writers' handles were handed out ([`handles`](Self::handles)).
    handed_out: AtomicBool,
    /// Jobs handed over, each with the plan's end it was planned from.
    jobs: JobQueue<(PlanEnd, Job), JOB_QUEUE_LEN, JOB_SUBMITTERS>,
    /// Where the plan ends (see [`jobs`]).
    plan: Mutex<CriticalSectionRawMutex, Cell<PlanState>>,
    control: Mutex<CriticalSectionRawMutex, Cell<Option<Control>>>,
    /// Wakes the motion task when a control is requested or an override changes.
    control_requested: Signal<CriticalSectionRawMutex, ()>,
    /// The overrides in force, [`Overrides::to_bits`] (written only by the host link).
    overrides: AtomicU32,
    /// Wakes the LCD task after anything it shows may have changed.
    changed: Signal<CriticalSectionRawMutex, ()>,
    /// Every fault as it happens, for the host link.
    faults: Signal<CriticalSectionRawMutex, MotionFault>,
    /// The planner holds nothing (set by the motion task).
    plan_empty: AtomicBool,
    /// The host link is in check mode (`$C`): reported as [`RunState::Check`] while idle.
    check_mode: AtomicBool,
    /// The current hold came from the safety door.
    door: AtomicBool,
    /// `$SLP`: the servos are off until a reset.
    asleep: AtomicBool,
    /// Segments the planner has room for (set by the motion task).
    plan_free: AtomicU8,
    /// Wakes the motion task when the pulse engine has emitted everything queued and stopped.
    pulses_done: Signal<CriticalSectionRawMutex, ()>,
    state: AtomicU8,
    /// Steps queued for the pulse engine so far, and the sum of their intervals in ticks
    /// (written only by the motion task; both wrap).
    queued_steps: AtomicU32,
    queued_ticks: AtomicU32,
    /// How far the queued steps advance along the ideal curve (written only by the motion task):
    /// the pen's speed along its path is this over the interval of the step emitted last.
    path_steps: PathSteps,
    /// Machine position minus work position, mm (written by the host link's parser).
    work_offset_mm: Mutex<CriticalSectionRawMutex, Cell<[f32; 2]>>,
    /// The kind of the job the motion task took last (`ShapeKind` as its index + 1, 0 for none).
    drawing: AtomicU8,
    settings: Published<Settings>,
    /// Wakes the serial task, which keeps the settings in flash, after they changed.
    settings_changed: Signal<CriticalSectionRawMutex, ()>,
    fault: Mutex<CriticalSectionRawMutex, Cell<Option<MotionFault>>>,
    /// An input tripped: the pulse engine stops at once and starts nothing until the alarm is
    /// cleared. Set by [`trip`](Self::trip), cleared by [`unlock`](Self::unlock).
    halted: AtomicBool,
    /// The trip the motion task has not yet handled.
    trip: Mutex<CriticalSectionRawMutex, Cell<Option<Trip>>>,
    /// A homing cycle runs: limit switches ahead are watched, and one found is no alarm.
    homing: AtomicBool,
    /// Wakes the homing task.
    homing_requested: Signal<CriticalSectionRawMutex, ()>,
    /// The switch a homing approach stopped at, until the homing task takes it.
    switch_found: Mutex<CriticalSectionRawMutex, Cell<Option<Trip>>>,
    /// Where the pen is to be, as a [`PenOrder`]: bit 0 set for down, above it a count of the
    /// times it was sent anywhere (changed only at rest).
    pen: AtomicU32,
    /// How deep the pen goes down, per mille ([`PenDepth`]): the last `M3 S…`'s.
    pen_depth: AtomicU16,
    /// Pulses emitted at machine zero (written only by the homing task, at rest).
    origin: [AtomicI32; 2],
    /// The pulses stopped without braking, or the axes were free (`$SLP`): the position may be
    /// wrong until the next homing.
    position_lost: AtomicBool,
}

impl Machine {
    /// The machine at power-on: locked in an alarm when homing is enabled (`$22`), until it is
    /// homed or unlocked, and its position unknown until homed.
    pub fn new(settings: Settings) -> Self {
        let locked = settings.homing;
        Machine {
            pulses: PulseSide::new(),
            servo: ServoSide::new(),
            handed_out: AtomicBool::new(false),
            jobs: JobQueue::new(),
            plan: Mutex::new(Cell::new(PlanState::at(Point::ORIGIN))),
            control: Mutex::new(Cell::new(None)),
            control_requested: Signal::new(),
            overrides: AtomicU32::new(Overrides::NONE.to_bits()),
            changed: Signal::new(),
            pulses_done: Signal::new(),
            plan_empty: AtomicBool::new(true),
            check_mode: AtomicBool::new(false),
            door: AtomicBool::new(false),
            asleep: AtomicBool::new(false),
            plan_free: AtomicU8::new(PLANNER_SEGMENTS as u8),
            faults: Signal::new(),
            state: AtomicU8::new(if locked { STATE_ALARM } else { STATE_IDLE }),
            queued_steps: AtomicU32::new(0),
            queued_ticks: AtomicU32::new(0),
            path_steps: PathSteps::new(),
            work_offset_mm: Mutex::new(Cell::new([0.0; 2])),
            drawing: AtomicU8::new(0),
            settings: Published::new(settings),
            settings_changed: Signal::new(),
            fault: Mutex::new(Cell::new(None)),
            halted: AtomicBool::new(false),
            trip: Mutex::new(Cell::new(None)),
            homing: AtomicBool::new(false),
            pen: AtomicU32::new(0),
            pen_depth: AtomicU16::new(PenDepth::FULL.permille()),
            homing_requested: Signal::new(),
            switch_found: Mutex::new(Cell::new(None)),
            origin: [AtomicI32::new(0), AtomicI32::new(0)],
            position_lost: AtomicBool::new(locked),
        }
    }

    /// The machine position: the pulses emitted so far, from machine zero.
    pub fn position(&self) -> Point {
        let at = |axis: usize| {
            let emitted = self.pulses.emitted_on(axis);
            emitted.wrapping_sub(self.origin[axis].load(Ordering::Relaxed))
        };
        Point::new(at(0), at(1))
    }

    /// Homing found machine zero: the pen, at rest, is at `position`. Only the homing task
    /// calls this.
    pub fn set_origin(&self, position: Point) {
        for (axis, at) in [position.x, position.y].into_iter().enumerate() {
            let emitted = self.pulses.emitted_on(axis);
            self.origin[axis].store(emitted.wrapping_sub(at), Ordering::Relaxed);
        }
        self.position_lost.store(false, Ordering::Relaxed);
        // The same point has new coordinates.
        self.plan_from_pen();
        self.changed.signal(());
    }

    /// True when the position may be wrong: from power-on with homing enabled, and after a
    /// trip stopped the pulses without braking, until the next homing.
    pub fn position_lost(&self) -> bool {
        self.position_lost.load(Ordering::Relaxed)
    }

    /// Asks the homing task for a cycle; false if one runs already. The state is
    /// [`RunState::Home`] from now until it ends.
    pub fn request_homing(&self) -> bool {
        if self.homing.swap(true, Ordering::AcqRel) {
            return false;
        }
        self.homing_requested.signal(());
        self.changed.signal(());
        true
    }

    /// Waits for a homing request. For the homing task.
    pub async fn homing_requested(&self) {
        self.homing_requested.wait().await
    }

    /// True while a homing cycle runs.
    pub fn homing(&self) -> bool {
        self.homing.load(Ordering::Acquire)
    }

    /// True when `trip` is what a homing approach looks for: a limit switch, while homing.
    pub fn is_homing_switch(&self, trip: Trip) -> bool {
        self.homing() && matches!(trip, Trip::Limit { .. })
    }

    /// True when nothing is queued, planned or moving and no homing cycle runs: the machine
    /// stands still for good (a homing cycle pauses between its moves).
    pub fn at_standstill(&self) -> bool {
        self.stopped() && !self.homing()
    }

    /// The homing cycle ended: at rest, in an alarm if it failed. Only the homing task calls
    /// this.
    pub fn end_homing(&self) {
        self.homing.store(false, Ordering::Release);
        self.changed.signal(());
    }

    /// A homing approach stopped at `trip`'s switch: the pulse engine stays halted until the
    /// homing task has seen it ([`take_switch_found`](Self::take_switch_found)). Only the
    /// motion task calls this.
    pub fn found_switch(&self, trip: Trip) {
        // The approach ends here, short of where it was planned to.
        self.plan_from_pen();
        self.switch_found.lock(|f| f.set(Some(trip)));
    }

    /// The switch the last homing approach stopped at, if it did, and lets pulses out again.
    /// Only the homing task calls this.
    pub fn take_switch_found(&self) -> Option<Trip> {
        let found = self.switch_found.lock(|f| f.take());
        if found.is_some() {
            self.halted.store(false, Ordering::Release);
        }
        found
    }

    /// Asks the motion task for `control`; see [`Control::then`] for requests not yet taken.
    /// A resume or an abort closes the safety door.
    pub fn request(&self, control: Control) {
        if control != Control::Hold && self.door.swap(false, Ordering::Relaxed) {
            self.changed.signal(());
        }
        self.control.lock(|c| c.set(Some(c.get().map_or(control, |pending| pending.then(control)))));
        self.control_requested.signal(());
    }

    /// A feed hold from the host (`!`): ignored in check mode and asleep, where nothing moves.
    pub fn feed_hold(&self) {
        if !matches!(self.state(), RunState::Check | RunState::Sleep) {
            self.request(Control::Hold);
        }
    }

    /// The safety door (GRBL's 0x84): a hold, reported as `Door` until a resume or an abort.
    /// Ignored in an alarm and in check mode, where nothing moves.
    pub fn open_door(&self) {
        if matches!(self.state(), RunState::Alarm | RunState::Check | RunState::Sleep) {
            return;
        }
        self.door.store(true, Ordering::Relaxed);
        self.request(Control::Hold);
    }

    /// The feed, rapid and spindle overrides in force.
    pub fn overrides(&self) -> Overrides {
        Overrides::from_bits(self.overrides.load(Ordering::Relaxed))
    }

    /// Changes the overrides by `command` (an override byte from the host link); the motion task
    /// applies them to the motion in progress at its next refill. Only the host link calls this.
    pub fn change_overrides(&self, command: OverrideCommand) {
        self.set_overrides(self.overrides().after(command));
    }

    /// Sets the overrides: [`Overrides::NONE`] after a reset. Only the host link calls this.
    pub fn set_overrides(&self, overrides: Overrides) {
        let bits = overrides.to_bits();
        if self.overrides.swap(bits, Ordering::Relaxed) != bits {
            self.control_requested.signal(());
            self.changed.signal(());
        }
    }

    /// The pending control request, if any, taking it.
    pub fn take_control(&self) -> Option<Control> {
        self.control.lock(|c| c.take())
    }

    /// Waits until a control is requested (it may already be) or an override changes.
    pub async fn control_requested(&self) {
        if self.control.lock(|c| c.get().is_none()) {
            self.control_requested.wait().await;
        }
    }

    /// The motion task has queued `steps` step commands in all so far, `ticks` ticks of motion
    /// in all (both wrapping). Only the motion task calls this.
    pub fn set_queued(&self, steps: u32, ticks: u32) {
        self.queued_ticks.store(ticks, Ordering::Release);
        self.queued_steps.store(steps, Ordering::Release);
    }

    /// Motion time queued for the pulse engine and not yet emitted, in ticks.
    pub fn queued_ticks(&self) -> u32 {
        self.queued_ticks.load(Ordering::Acquire).wrapping_sub(self.pulses.emitted_ticks())
    }

    /// Step commands queued for the pulse engine and not yet emitted.
    pub fn queued_steps(&self) -> u32 {
        self.queued_steps.load(Ordering::Acquire).wrapping_sub(self.pulses.emitted_steps())
    }

    /// How fast the pen moves along its path now, mm/min: how far a step advances along the
    /// ideal curve over the interval of the step being emitted; 0 at rest (stopped, or held
    /// once stopped). Not the lattice step's own length: on a line at 30° the steps are X steps
    /// and diagonal ones, each advancing the same distance along the line at the same pace.
    pub fn speed_mm_per_min(&self) -> f32 {
        let interval = self.pulses.last_interval_ticks();
        if self.pulses_idle() || interval == 0 {
            return 0.0;
        }
        // The step emitted last is the one being timed.
        let step = self.pulses.emitted_steps().wrapping_sub(1);
        self.path_steps.at(step) * (60.0 * TICK_HZ as f32) / interval as f32
    }

    /// The steps of a batch queued after `first` steps (counted as `set_queued` counts them)
    /// each advance `step_mm` along the ideal curve (see
    /// [`speed_mm_per_min`](Self::speed_mm_per_min)). Only the motion task calls this.
    pub fn set_path_step_mm(&self, first: u32, step_mm: f32) {
        self.path_steps.record(first, step_mm);
    }

    /// The work coordinate offset the host link's parser plans with (machine = work + offset),
    /// mm.
    pub fn work_offset_mm(&self) -> [f32; 2] {
        self.work_offset_mm.lock(|o| o.get())
    }

    /// Sets the work coordinate offset; only the host link's parser calls this.
    pub fn set_work_offset_mm(&self, offset_mm: [f32; 2]) {
        if self.work_offset_mm.lock(|o| o.replace(offset_mm)) != offset_mm {
            self.changed.signal(());
        }
    }

    /// Planner segments free: how many more drawings the planner could take now.
    pub fn plan_free_segments(&self) -> u8 {
        self.plan_free.load(Ordering::Relaxed)
    }

    /// The motion task took a job drawing `kind`. Only the motion task calls this.
    pub fn set_drawing(&self, kind: ShapeKind) {
        let code = ShapeKind::ALL.iter().position(|&k| k == kind).map_or(0, |i| i as u8 + 1);
        self.drawing.store(code, Ordering::Relaxed);
    }

    /// The kind of the job the motion task took last, if any.
    pub fn drawing(&self) -> Option<ShapeKind> {
        let code = self.drawing.load(Ordering::Relaxed);
        ShapeKind::ALL.get(usize::from(code).checked_sub(1)?).copied()
    }

    /// Waits until the pulse engine next reports that it stopped.
    pub async fn until_pulses_stopped(&self) {
        self.pulses_done.wait().await
    }

    /// Waits until anything a display shows may have changed.
    pub async fn changed(&self) {
        self.changed.wait().await
    }

    /// Waits for the next fault (a curve stopped part way), for the host link.
    pub async fn next_fault(&self) -> MotionFault {
        self.faults.wait().await
    }

    /// True when no step is queued or being emitted.
    pub fn pulses_idle(&self) -> bool {
        self.queued_steps.load(Ordering::Acquire) == self.pulses.emitted_steps()
    }

    pub fn run_state(&self) -> RunState {
        match self.state.load(Ordering::Relaxed) {
            STATE_RUN => RunState::Run,
            STATE_HOLD => RunState::Hold,
            STATE_JOG => RunState::Jog,
            STATE_ALARM => RunState::Alarm,
            _ => RunState::Idle,
        }
    }

    /// Sets the motion's state. Check mode is not one: see [`set_check_mode`](Self::set_check_mode).
    pub fn set_run_state(&self, state: RunState) {
        let v = match state {
            RunState::Idle | RunState::Check | RunState::Sleep | RunState::Home => STATE_IDLE,
            RunState::Run => STATE_RUN,
            RunState::Hold => STATE_HOLD,
            RunState::Jog => STATE_JOG,
            RunState::Alarm => STATE_ALARM,
        };
        if self.state.swap(v, Ordering::Relaxed) != v {
            self.changed.signal(());
        }
    }

    /// The host link enters or leaves check mode (`$C`); only the serial task calls this.
    pub fn set_check_mode(&self, on: bool) {
        if self.check_mode.swap(on, Ordering::Relaxed) != on {
            self.changed.signal(());
        }
    }

    /// The state to report and to act on: the run state, [`RunState::Sleep`] after `$SLP`,
    /// [`RunState::Home`] during a homing cycle, or [`RunState::Check`] while the host link
    /// checks its lines at rest.
    pub fn state(&self) -> RunState {
        match self.run_state() {
            _ if self.asleep.load(Ordering::Relaxed) => RunState::Sleep,
            RunState::Alarm => RunState::Alarm,
            _ if self.homing() => RunState::Home,
            RunState::Idle if self.check_mode.load(Ordering::Relaxed) => RunState::Check,
            state => state,
        }
    }

    /// The state a host line is judged in: [`state`](Self::state), but [`RunState::Run`] as
    /// soon as anything is queued, not only once it moves, as GRBL's cycle starts with its first
    /// block: a jog sent right behind a move is refused, a setting waits for the move to end.
    pub fn line_state(&self) -> RunState {
        match self.state() {
            RunState::Idle if !self.stopped() => RunState::Run,
            state => state,
        }
    }

    /// `$SLP` at rest: the servos go off (the board drops SON, see [`servos_on`](Self::servos_on))
    /// until [`wake`](Self::wake). Only the serial task calls this.
    pub fn sleep(&self) {
        self.asleep.store(true, Ordering::Relaxed);
        // The axes are free until the reset.
        self.position_lost.store(true, Ordering::Relaxed);
        self.changed.signal(());
    }

    /// A reset after `$SLP`: the servos come back on and the machine is in alarm, since the free
    /// axes may have been moved. Nothing when not asleep.
    pub fn wake(&self) {
        if self.asleep.swap(false, Ordering::Relaxed) {
            self.set_run_state(RunState::Alarm);
            self.changed.signal(());
        }
    }

    /// Whether the servo drivers are to be enabled (SON high): not asleep, and not after a
    /// driver alarm until it is cleared.
    pub fn servos_on(&self) -> bool {
        let driver_alarm = matches!(self.fault(), Some(MotionFault::Tripped(Trip::DriverAlarm(_))));
        let off_for_alarm = driver_alarm && self.halted();
        !self.asleep.load(Ordering::Relaxed) && !off_for_alarm
    }

    /// Sends the pen to `pen`; the motion task and the host link call this only at rest, and
    /// wait for [`pen_settled`](Self::pen_settled) before anything moves.
    pub fn set_pen(&self, pen: Pen) {
        let depth = PenDepth::from_permille(self.pen_depth.load(Ordering::Relaxed));
        let sent = self.pen.fetch_update(Ordering::AcqRel, Ordering::Acquire, |bits| {
            PenOrder::from_bits(bits).then(pen, depth).map(PenOrder::bits)
        });
        if sent.is_ok() {
            self.changed.signal(());
        }
    }

    /// How deep the pen goes down from now on (`M3 S…`); a pen down now goes there. The host
    /// link calls this only at rest, as [`set_pen`](Self::set_pen).
    pub fn set_pen_depth(&self, depth: PenDepth) {
        self.pen_depth.store(depth.permille(), Ordering::Relaxed);
        if self.pen() == Pen::Down {
            self.set_pen(Pen::Down);
        }
    }

    /// Where the pen is to be.
    pub fn pen(&self) -> Pen {
        self.pen_order().pen()
    }

    /// The pen's last order, for the servo task.
    pub fn pen_order(&self) -> PenOrder {
        PenOrder::from_bits(self.pen.load(Ordering::Acquire))
    }

    /// An input tripped (see [`crate::inputs`]): the pulse engine stops at its next period if it
    /// has not stopped itself already, and starts nothing until [`unlock`](Self::unlock); the
    /// motion task drops what was planned and raises the alarm. A trip while halted is no news.
    pub fn trip(&self, trip: Trip) {
        if self.halt(trip) {
            self.post_trip(trip);
        }
    }

    /// Halts the pulses for `trip`; false if they were halted already.
    fn halt(&self, trip: Trip) -> bool {
        if self.halted.swap(true, Ordering::AcqRel) {
            return false;
        }
        // A limit switch a homing approach looks for stops nothing it does not expect.
        if !self.is_homing_switch(trip) {
            self.position_lost.store(true, Ordering::Relaxed);
        }
        true
    }

    /// Leaves `trip` for the motion task, and wakes it and the displays.
    fn post_trip(&self, trip: Trip) {
        self.trip.lock(|t| t.set(Some(trip)));
        self.control_requested.signal(());
        self.changed.signal(());
    }

    /// True from a trip until the alarm is cleared: no pulse goes out.
    #[inline(always)]
    pub fn halted(&self) -> bool {
        self.halted.load(Ordering::Relaxed)
    }

    /// The trip the motion task has yet to handle, taking it. Only the motion task calls this.
    pub fn take_trip(&self) -> Option<Trip> {
        self.trip.lock(|t| t.take())
    }

    /// `$X`: leaves the alarm, and lets pulses out again after a trip (handled by the motion
    /// task by now: the machine has stopped). Only the serial task calls this.
    pub fn unlock(&self) {
        if self.run_state() == RunState::Alarm {
            self.set_run_state(RunState::Idle);
        }
        self.halted.store(false, Ordering::Release);
    }

    /// A snapshot for displays and reports.
    pub fn status(&self) -> Status {
        Status {
            state: self.state(),
            position: self.position(),
            position_lost: self.position_lost(),
            queued_jobs: self.queued_jobs() as u8,
            fault: self.fault(),
            door: self.door.load(Ordering::Relaxed),
            underruns: self.underruns(),
            missed_updates: self.missed_updates(),
            overrides: self.overrides(),
            emitted_steps: self.pulses.emitted_steps(),
            work_left: !self.stopped(),
        }
    }

    pub fn set_fault(&self, fault: Option<MotionFault>) {
        self.fault.lock(|f| f.set(fault));
        if let Some(f) = fault {
            self.faults.signal(f);
        }
        self.changed.signal(());
    }

    /// The fault that ended the last job early, if any.
    pub fn fault(&self) -> Option<MotionFault> {
        self.fault.lock(|f| f.get())
    }

    /// Whether the planner holds anything. Only the motion task calls this.
    pub fn set_plan_empty(&self, empty: bool) {
        self.plan_empty.store(empty, Ordering::Release);
    }

    /// How many segments the planner has room for. Only the motion task calls this.
    pub fn set_plan_free_segments(&self, free: usize) {
        self.plan_free.store(free.min(usize::from(u8::MAX)) as u8, Ordering::Relaxed);
    }

    /// True when nothing is queued, planned or moving, held or not: the position is final.
    pub fn stopped(&self) -> bool {
        self.plan_empty.load(Ordering::Acquire) && self.jobs.is_empty() && self.pulses_idle()
    }

    /// True when the machine waits for its inputs: idle, or stopped in an alarm.
    pub fn at_rest(&self) -> bool {
        match self.run_state() {
            _ if self.homing() => false,
            RunState::Idle => self.is_idle(),
            RunState::Alarm => self.stopped(),
            _ => false,
        }
    }

    /// True when nothing is queued, planned or moving.
    pub fn is_idle(&self) -> bool {
        self.run_state() == RunState::Idle && self.stopped()
    }
}

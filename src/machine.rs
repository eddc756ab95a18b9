//! The state the tasks share, split by writer: each task holds a handle to the part it writes,
//! and reads the rest through narrow methods on [`Machine`].
//!
//! One `Machine` exists per plotter (a `static` on target, a local in the simulator). Its
//! writers' handles come from [`Machine::handles`], once; the board, the simulator and the
//! tests take them there and give each task its own ([`handles`]). Each part has private fields
//! and one writer:
//! - the pulse interrupt ([`PulseWriter`], [`pulse_side`]): the pulses emitted, the emitted
//!   totals, the last interval, underruns, missed updates, the step timer running, its news;
//! - the motion task ([`MotionWriter`], [`motion_side`]): what it queued and planned, the job
//!   it draws, and the motion's state (idle, running, held, jogging);
//! - the host link ([`HostWriter`], [`host_side`]): the overrides, the work offset, check mode,
//!   sleep, the pen's depth;
//! - the servo task ([`ServoWriter`], [`servo_side`]): the input levels, the drivers'
//!   readiness, the pen's settling;
//! - the homing task ([`HomingWriter`], [`homing_side`]): machine zero.
//!
//! The keypad and the LCD write no part of their own: the keypad posts requests, the LCD reads.
//!
//! State with several writers by nature is a mailbox with one taker, posted to through a
//! narrow method on `Machine` by anyone and taken through the taker's handle: the jobs and
//! where the plan ends ([`jobs`]; the motion task takes), the controls
//! ([`request`](Machine::request); the motion task), a homing request
//! ([`request_homing`](Machine::request_homing); the homing task), the settings
//! ([`update_settings`](Machine::update_settings); the host link keeps them in flash) and the
//! trips ([`trip`](Machine::trip); the motion task raises the alarm, `$X` or the homing task
//! clears it). The alarm is a latch over the motion's state ([`alarm`]): raised by whoever finds
//! a fault (the motion task, the homing task, the host link's wake after `$SLP`), through their
//! handles, and cleared only by an unlock (`$X`, a homing cycle's start); the switch a homing approach stopped at has one poster, the motion task, and the
//! homing task takes it. The pen's orders have two writers, both at rest: the motion task (a keypad
//! drawing's pen lift) and the host link (`M3`, `M5`), each a single read-modify-write of one
//! word ([`PenOrder`]); the servo task says when the pen has settled.
//!
//! Everything here is shared across priorities, up to the pulse interrupt, which every critical
//! section holds off. Every counter is an atomic; the jobs (648 bytes) and the settings (116)
//! are handed over without a lock ([`job_queue`], [`published`]). The critical sections left
//! each copy at most [`LOCKED_VALUE_MAX_BYTES`] in or out (checked below, at compile time) and
//! wake at most the tasks that wait there:
//! - `control`: the control requested and not yet taken (1 byte);
//! - the host link's work offset, two `f32`;
//! - the alarm's fault, an `Option<MotionFault>`; `trip` and the homing's switch found, an
//!   `Option<Trip>`;
//! - the signals `control_requested`, `changed`, `pulses_done`, the homing request,
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

mod alarm;
mod handles;
mod homing_side;
mod homing_writer;
mod host_side;
mod host_writer;
mod job_queue;
mod jobs;
mod motion_side;
mod motion_writer;
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
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use core::task::Waker;

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;

use crate::geom::{Point, TICK_HZ};
use crate::machine_io::inputs::Trip;
use crate::machine_io::pen::{Pen, PenOrder};
use crate::motion::job::{Control, Job};
use crate::settings::Settings;
pub use crate::status::MotionFault;
use crate::status::{RunState, Status};
use alarm::Alarm;
pub use handles::Handles;
use homing_side::HomingSide;
pub use homing_writer::HomingWriter;
use host_side::HostSide;
pub use host_writer::HostWriter;
use job_queue::JobQueue;
use motion_side::MotionSide;
pub use motion_writer::MotionWriter;
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

/// Everything the tasks share (see the module documentation).
pub struct Machine {
    /// What the pulse interrupt writes ([`PulseWriter`]).
    pulse_side: PulseSide,
    /// What the motion task writes ([`MotionWriter`]).
    motion_side: MotionSide,
    /// What the host link writes ([`HostWriter`]).
    host_side: HostSide,
    /// What the servo task writes ([`ServoWriter`]).
    servo_side: ServoSide,
    /// What the homing task writes ([`HomingWriter`]), and its mailboxes.
    homing_side: HomingSide,
    /// The alarm latch and the last fault, raised and cleared by their posters (see [`alarm`]).
    alarm: Alarm,
    /// The writers' handles were handed out ([`handles`](Self::handles)).
    handed_out: AtomicBool,
    /// Jobs handed over, each with the plan's end it was planned from (a mailbox: anyone
    /// submits, the motion task takes).
    jobs: JobQueue<(PlanEnd, Job), JOB_QUEUE_LEN, JOB_SUBMITTERS>,
    /// Where the plan ends (see [`jobs`]).
    plan: Mutex<CriticalSectionRawMutex, Cell<PlanState>>,
    /// The control requested and not yet taken (a mailbox: anyone requests, the motion task
    /// takes).
    control: Mutex<CriticalSectionRawMutex, Cell<Option<Control>>>,
    /// Wakes the motion task when a control is requested, an override changes or a trip comes.
    control_requested: Signal<CriticalSectionRawMutex, ()>,
    /// Wakes the LCD task after anything it shows may have changed.
    changed: Signal<CriticalSectionRawMutex, ()>,
    /// Every fault as it happens, for the host link.
    faults: Signal<CriticalSectionRawMutex, MotionFault>,
    /// The current hold came from the safety door: set with the hold, cleared by a resume or
    /// an abort (part of the controls' mailbox).
    door: AtomicBool,
    /// Wakes the motion task when the pulse engine has emitted everything queued and stopped.
    pulses_done: Signal<CriticalSectionRawMutex, ()>,
    /// The settings (a mailbox: the thread-mode inputs update them, see [`settings`]).
    settings: Published<Settings>,
    /// Wakes the serial task, which keeps the settings in flash, after they changed.
    settings_changed: Signal<CriticalSectionRawMutex, ()>,
    /// An input tripped: the pulse engine stops at once and starts nothing until the alarm is
    /// cleared. Set by a trip, cleared by `$X` (or a homing cycle's start) and by the homing
    /// task once it has seen the switch an approach stopped at.
    halted: AtomicBool,
    /// The trip the motion task has not yet handled (a mailbox: anyone trips, the motion task
    /// takes).
    trip: Mutex<CriticalSectionRawMutex, Cell<Option<Trip>>>,
    /// Where the pen is to be, as a [`PenOrder`]: bit 0 set for down, above it a count of the
    /// times it was sent anywhere (changed only at rest, by the motion task and the host link).
    pen: AtomicU32,
    /// The pulses stopped without braking, or the axes were free (`$SLP`): the position may be
    /// wrong until the next homing. Set by a trip and by `$SLP`, cleared by homing.
    position_lost: AtomicBool,
}

impl Machine {
    /// The machine at power-on: locked in an alarm when homing is enabled (`$22`), until it is
    /// homed or unlocked, and its position unknown until homed.
    pub fn new(settings: Settings) -> Self {
        let locked = settings.homing;
        Machine {
            pulse_side: PulseSide::new(),
            motion_side: MotionSide::new(),
            host_side: HostSide::new(),
            servo_side: ServoSide::new(),
            homing_side: HomingSide::new(),
            alarm: Alarm::new(locked),
            handed_out: AtomicBool::new(false),
            jobs: JobQueue::new(),
            plan: Mutex::new(Cell::new(PlanState::at(Point::ORIGIN))),
            control: Mutex::new(Cell::new(None)),
            control_requested: Signal::new(),
            changed: Signal::new(),
            faults: Signal::new(),
            door: AtomicBool::new(false),
            pulses_done: Signal::new(),
            settings: Published::new(settings),
            settings_changed: Signal::new(),
            halted: AtomicBool::new(false),
            trip: Mutex::new(Cell::new(None)),
            pen: AtomicU32::new(0),
            position_lost: AtomicBool::new(locked),
        }
    }

    /// True when the position may be wrong: from power-on with homing enabled, and after a
    /// trip stopped the pulses without braking, until the next homing.
    pub fn position_lost(&self) -> bool {
        self.position_lost.load(Ordering::Relaxed)
    }

    /// Asks the motion task for `control`; see [`Control::then`] for requests not yet taken.
    /// A resume or an abort closes the safety door. A request anyone may post (the host link,
    /// the keypad); the motion task takes it.
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

    /// Waits until anything a display shows may have changed. For the LCD task.
    pub async fn changed(&self) {
        self.changed.wait().await
    }

    /// The state to report and to act on: the run state, [`RunState::Sleep`] after `$SLP`,
    /// [`RunState::Home`] during a homing cycle, or [`RunState::Check`] while the host link
    /// checks its lines at rest.
    pub fn state(&self) -> RunState {
        match self.run_state() {
            _ if self.host_side.asleep() => RunState::Sleep,
            RunState::Alarm => RunState::Alarm,
            _ if self.homing() => RunState::Home,
            RunState::Idle if self.host_side.check_mode() => RunState::Check,
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

    /// Whether the servo drivers are to be enabled (SON high): not asleep, and not after a
    /// driver alarm until it is cleared.
    pub fn servos_on(&self) -> bool {
        let driver_alarm = matches!(self.fault(), Some(MotionFault::Tripped(Trip::DriverAlarm(_))));
        let off_for_alarm = driver_alarm && self.halted();
        !self.host_side.asleep() && !off_for_alarm
    }

    /// Sends the pen to `pen` at the depth in force. For the pen's two writers, both at rest.
    fn send_pen(&self, pen: Pen) {
        let depth = self.host_side.pen_depth();
        let sent = self.pen.fetch_update(Ordering::AcqRel, Ordering::Acquire, |bits| {
            PenOrder::from_bits(bits).then(pen, depth).map(PenOrder::bits)
        });
        if sent.is_ok() {
            self.changed.signal(());
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

    /// An input tripped (see [`crate::machine_io::inputs`]): the pulse engine stops at its next period if it
    /// has not stopped itself already, and starts nothing until `$X`; the motion task drops
    /// what was planned and raises the alarm. A trip while halted is no news. A request anyone
    /// may post (the servo task's inputs; the pulse interrupt has its own,
    /// [`PulseWriter::pulse_trip`]); the motion task takes it.
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

    /// Leaves the alarm, and lets pulses out again after a trip (handled by the motion task by
    /// now: the machine has stopped). For `$X` and a homing cycle's start.
    fn unlock(&self) {
        if self.alarm.clear() {
            self.changed.signal(());
        }
        self.halted.store(false, Ordering::Release);
    }

    /// Raises the alarm, for `fault` if one is given; a fault goes to the host link too. For the
    /// alarm's posters (see [`alarm`]).
    fn raise_alarm(&self, fault: Option<MotionFault>) {
        self.alarm.raise(fault);
        if let Some(f) = fault {
            self.faults.signal(f);
        }
        self.changed.signal(());
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
            emitted_steps: self.emitted_totals().0,
            work_left: !self.stopped(),
        }
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

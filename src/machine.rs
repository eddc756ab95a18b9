//! The state the tasks share: queues between them, the position counters and the settings.
//!
//! One `Machine` exists per plotter (a `static` on target, a local in the simulator). Tasks
//! receive `&Machine` and talk only through it: the job queue (inputs → motion), the control
//! slot (inputs → motion), the step queue (motion → pulses, bounded in count and in time), the
//! position counters (written only by the pulse task) and a change signal that wakes the LCD.
//! Everything here is shared across priorities, so every lock is a critical section that only
//! copies a value in or out.

use core::cell::{Cell, RefCell};
use core::sync::atomic::{AtomicBool, AtomicI32, AtomicU8, AtomicU32, Ordering};

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_sync::signal::Signal;

use crate::geom::{Axis, Point, Step, StepCmd, TICK_HZ};
use crate::job::{Control, Job};
use crate::settings::Settings;
pub use crate::status::MotionFault;
use crate::status::{RunState, Status};
use crate::ui::Menu;

/// Jobs accepted from the inputs and not yet taken by the planner. Small: the planner holds the
/// look-ahead; this only decouples the inputs from it.
pub const JOB_QUEUE_LEN: usize = 4;

/// Step commands between the motion task and the pulse task. At 20 kHz, 32 commands are 1.6 ms
/// of motion, many times the motion task's latency on its own interrupt executor.
pub const STEP_QUEUE_LEN: usize = 32;

/// At most this much motion time waits in the step queue, however slow the steps: a hold or an
/// abort starts decelerating within it, even at a feed of 1 mm/min.
pub const STEP_QUEUE_MAX_US: u32 = 20_000;
/// The same in pulse timer ticks.
pub const STEP_QUEUE_MAX_TICKS: u32 = STEP_QUEUE_MAX_US * (TICK_HZ / 1_000_000);

/// Everything the tasks share.
pub struct Machine {
    pub jobs: Channel<CriticalSectionRawMutex, Job, JOB_QUEUE_LEN>,
    control: Mutex<CriticalSectionRawMutex, Cell<Option<Control>>>,
    /// Wakes the motion task when a control is requested.
    control_requested: Signal<CriticalSectionRawMutex, ()>,
    pub steps: Channel<CriticalSectionRawMutex, StepCmd, STEP_QUEUE_LEN>,
    /// Wakes the LCD task after anything it shows may have changed.
    pub changed: Signal<CriticalSectionRawMutex, ()>,
    /// Every fault as it happens, for the host link.
    pub faults: Signal<CriticalSectionRawMutex, MotionFault>,
    /// Counts aborts (a control, a curve stopped part way): jobs planned before one were
    /// planned from a point the pen may never reach.
    aborts: AtomicU32,
    /// Wakes whoever waits to hand over a job when an abort happens.
    pub aborted: Signal<CriticalSectionRawMutex, ()>,
    /// The planner holds nothing (set by the motion task).
    plan_empty: AtomicBool,
    /// Wakes the motion task when the pulse task has emitted everything queued.
    pub pulses_done: Signal<CriticalSectionRawMutex, ()>,
    menu: Mutex<CriticalSectionRawMutex, RefCell<Menu>>,
    position: [AtomicI32; 2],
    state: AtomicU8,
    /// Sum of the intervals of the step commands queued and not yet emitted, in ticks.
    queued_ticks: AtomicU32,
    /// True while the pulse task holds a command it has not finished emitting.
    pulsing: AtomicBool,
    settings: Mutex<CriticalSectionRawMutex, RefCell<Settings>>,
    fault: Mutex<CriticalSectionRawMutex, Cell<Option<MotionFault>>>,
}

impl Machine {
    pub fn new(settings: Settings) -> Self {
        Machine {
            jobs: Channel::new(),
            control: Mutex::new(Cell::new(None)),
            control_requested: Signal::new(),
            steps: Channel::new(),
            changed: Signal::new(),
            pulses_done: Signal::new(),
            aborts: AtomicU32::new(0),
            aborted: Signal::new(),
            plan_empty: AtomicBool::new(true),
            faults: Signal::new(),
            menu: Mutex::new(RefCell::new(Menu::new())),
            position: [AtomicI32::new(0), AtomicI32::new(0)],
            state: AtomicU8::new(0),
            queued_ticks: AtomicU32::new(0),
            pulsing: AtomicBool::new(false),
            settings: Mutex::new(RefCell::new(settings)),
            fault: Mutex::new(Cell::new(None)),
        }
    }

    /// Pulses emitted so far: the position, always.
    pub fn position(&self) -> Point {
        Point::new(self.position[0].load(Ordering::Relaxed), self.position[1].load(Ordering::Relaxed))
    }

    fn count_pulse(&self, step: Step) {
        for axis in Axis::ALL {
            let d = step.on(axis) as i32;
            if d != 0 {
                self.position[axis.index()].fetch_add(d, Ordering::Relaxed);
            }
        }
    }

    /// Asks the motion task for `control`; see [`Control::then`] for requests not yet taken.
    pub fn request(&self, control: Control) {
        self.control.lock(|c| c.set(Some(c.get().map_or(control, |pending| pending.then(control)))));
        self.control_requested.signal(());
    }

    /// The pending control request, if any, taking it.
    pub fn take_control(&self) -> Option<Control> {
        self.control.lock(|c| c.take())
    }

    /// Waits until a control is requested (it may already be).
    pub async fn control_requested(&self) {
        if self.control.lock(|c| c.get().is_none()) {
            self.control_requested.wait().await;
        }
    }

    /// Queues a step command for the pulse task, waiting for room.
    pub async fn queue_step(&self, cmd: StepCmd) {
        self.queued_ticks.fetch_add(cmd.interval_ticks, Ordering::AcqRel);
        self.steps.send(cmd).await;
    }

    /// Motion time queued for the pulse task and not yet emitted, in ticks.
    pub fn queued_ticks(&self) -> u32 {
        self.queued_ticks.load(Ordering::Acquire)
    }

    /// Counts one emitted pulse per moving axis and takes its command's time off the queue.
    /// Only the pulse task calls this.
    pub fn emitted(&self, cmd: StepCmd) {
        self.count_pulse(cmd.step);
        self.queued_ticks.fetch_sub(cmd.interval_ticks, Ordering::AcqRel);
    }

    pub fn set_pulsing(&self, busy: bool) {
        self.pulsing.store(busy, Ordering::Release);
    }

    /// True when no step is queued or being emitted.
    pub fn pulses_idle(&self) -> bool {
        !self.pulsing.load(Ordering::Acquire) && self.steps.is_empty()
    }

    pub fn run_state(&self) -> RunState {
        match self.state.load(Ordering::Relaxed) {
            1 => RunState::Run,
            2 => RunState::Hold,
            3 => RunState::Jog,
            4 => RunState::Alarm,
            _ => RunState::Idle,
        }
    }

    pub fn set_run_state(&self, state: RunState) {
        let v = match state {
            RunState::Idle => 0,
            RunState::Run => 1,
            RunState::Hold => 2,
            RunState::Jog => 3,
            RunState::Alarm => 4,
        };
        if self.state.swap(v, Ordering::Relaxed) != v {
            self.changed.signal(());
        }
    }

    /// A snapshot for displays and reports.
    pub fn status(&self) -> Status {
        Status {
            state: self.run_state(),
            position: self.position(),
            queued_jobs: self.jobs.len() as u8,
            fault: self.fault(),
        }
    }

    /// A copy of the current settings.
    pub fn settings(&self) -> Settings {
        self.settings.lock(|s| s.borrow().clone())
    }

    /// Changes the settings through `f`; the planner picks them up for the next job.
    pub fn update_settings<R>(&self, f: impl FnOnce(&mut Settings) -> R) -> R {
        let r = self.settings.lock(|s| f(&mut s.borrow_mut()));
        self.changed.signal(());
        r
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

    /// A copy of the keypad menu (the keypad task changes it, the LCD task draws it). Work on
    /// the menu happens on the copy, never inside the lock.
    pub fn menu(&self) -> Menu {
        self.menu.lock(|m| m.borrow().clone())
    }

    pub fn set_menu(&self, menu: Menu) {
        self.menu.lock(|m| *m.borrow_mut() = menu);
        self.changed.signal(());
    }

    /// Counts an abort: what was planned is dropped. Only the motion task calls this.
    pub fn note_abort(&self) {
        self.aborts.fetch_add(1, Ordering::AcqRel);
        self.aborted.signal(());
    }

    /// Aborts so far: when this changes, positions planned before it are stale.
    pub fn aborts(&self) -> u32 {
        self.aborts.load(Ordering::Acquire)
    }

    /// Whether the planner holds anything. Only the motion task calls this.
    pub fn set_plan_empty(&self, empty: bool) {
        self.plan_empty.store(empty, Ordering::Release);
    }

    /// True when nothing is queued, planned or moving, held or not: the position is final.
    pub fn stopped(&self) -> bool {
        self.plan_empty.load(Ordering::Acquire) && self.jobs.is_empty() && self.pulses_idle()
    }

    /// True when nothing is queued, planned or moving.
    pub fn is_idle(&self) -> bool {
        self.run_state() == RunState::Idle && self.jobs.is_empty() && self.pulses_idle()
    }
}

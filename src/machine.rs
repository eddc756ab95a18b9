//! The state the tasks share: queues between them, the position counters and the settings.
//!
//! One `Machine` exists per plotter (a `static` on target, a local in the simulator). Tasks
//! receive `&Machine` and talk only through it: the job queue (inputs → motion), the control
//! signal (inputs → motion), the step queue (motion → pulses, bounded for back-pressure), the
//! position counters (written only by the pulse task) and a change signal that wakes the LCD.

use core::cell::{Cell, RefCell};
use core::sync::atomic::{AtomicBool, AtomicI32, AtomicU8, Ordering};

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_sync::signal::Signal;

use crate::geom::{Axis, Point, Step, StepCmd};
use crate::interp::{CurveError, CurveSetupError};
use crate::job::{Control, Job};
use crate::settings::Settings;
use crate::status::{RunState, Status};
use crate::ui::Menu;

/// Jobs accepted from the inputs and not yet taken by the planner. Small: the planner holds the
/// look-ahead; this only decouples the inputs from it.
pub const JOB_QUEUE_LEN: usize = 4;

/// Step commands between the motion task and the pulse task. At 20 kHz, 32 commands are 1.6 ms
/// of motion: enough to ride over an LCD flush on the thread executor's other tasks, short enough
/// that a hold starts decelerating within a few milliseconds.
pub const STEP_QUEUE_LEN: usize = 32;

/// Why the last job stopped early, shown on the LCD and reported to the host.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum MotionFault {
    /// The job could not start (bad parameter, function undefined at its first point).
    Setup(CurveSetupError),
    /// The curve ended part way (domain error, jump).
    Curve(CurveError),
}

/// Everything the tasks share.
pub struct Machine {
    pub jobs: Channel<CriticalSectionRawMutex, Job, JOB_QUEUE_LEN>,
    pub control: Signal<CriticalSectionRawMutex, Control>,
    pub steps: Channel<CriticalSectionRawMutex, StepCmd, STEP_QUEUE_LEN>,
    /// Wakes the LCD task after anything it shows may have changed.
    pub changed: Signal<CriticalSectionRawMutex, ()>,
    /// Every fault as it happens, for the host link.
    pub faults: Signal<CriticalSectionRawMutex, MotionFault>,
    /// Wakes the motion task when the pulse task has emitted everything queued.
    pub pulses_done: Signal<CriticalSectionRawMutex, ()>,
    menu: Mutex<CriticalSectionRawMutex, RefCell<Menu>>,
    position: [AtomicI32; 2],
    state: AtomicU8,
    /// True while the pulse task holds a command it has not finished emitting.
    pulsing: AtomicBool,
    settings: Mutex<CriticalSectionRawMutex, RefCell<Settings>>,
    fault: Mutex<CriticalSectionRawMutex, Cell<Option<MotionFault>>>,
}

impl Machine {
    pub fn new(settings: Settings) -> Self {
        Machine {
            jobs: Channel::new(),
            control: Signal::new(),
            steps: Channel::new(),
            changed: Signal::new(),
            pulses_done: Signal::new(),
            faults: Signal::new(),
            menu: Mutex::new(RefCell::new(Menu::new())),
            position: [AtomicI32::new(0), AtomicI32::new(0)],
            state: AtomicU8::new(0),
            pulsing: AtomicBool::new(false),
            settings: Mutex::new(RefCell::new(settings)),
            fault: Mutex::new(Cell::new(None)),
        }
    }

    /// Pulses emitted so far: the position, always.
    pub fn position(&self) -> Point {
        Point::new(self.position[0].load(Ordering::Relaxed), self.position[1].load(Ordering::Relaxed))
    }

    /// Counts one emitted pulse per moving axis. Only the pulse task calls this.
    pub fn count_pulse(&self, step: Step) {
        for axis in Axis::ALL {
            let d = step.on(axis) as i32;
            if d != 0 {
                self.position[axis.index()].fetch_add(d, Ordering::Relaxed);
            }
        }
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
        Status { state: self.run_state(), position: self.position(), queued_jobs: self.jobs.len() as u8 }
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

    /// Runs `f` on the keypad menu (the keypad task changes it, the LCD task draws it).
    pub fn with_menu<R>(&self, f: impl FnOnce(&mut Menu) -> R) -> R {
        self.menu.lock(|m| f(&mut m.borrow_mut()))
    }

    /// True when nothing is queued, planned or moving.
    pub fn is_idle(&self) -> bool {
        self.run_state() == RunState::Idle && self.jobs.is_empty() && self.pulses_idle()
    }
}

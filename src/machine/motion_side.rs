//! The part of the machine the motion task writes, through its handle
//! ([`MotionWriter`](super::MotionWriter)): the step commands and motion time queued for the
//! pulse engine so far, how far the queued steps advance along the ideal curve, whether the
//! planner holds anything and how much room it has, the kind of the job taken last, and the
//! motion's state (idle, running, held, jogging).
//!
//! One writer: the motion task ([`crate::tasks::motion`]). It writes the motion's state only as
//! it takes a job, a control or a trip, or as the motion it runs ends. An alarm is not a state
//! of the motion but a latch over it ([`alarm`](super::alarm)): the motion goes on being what it
//! is (an abort brakes, then rests) while the machine reports the alarm.
//!
//! Readers: every task, through the narrow reads on [`Machine`](super::Machine) (the state, the
//! status, the queued work, the speed, the planner's room).

use core::sync::atomic::{AtomicBool, AtomicU8, AtomicU32, Ordering};

use super::path_steps::PathSteps;
use crate::motion::interp::ShapeKind;
use crate::motion::planner::PLANNER_SEGMENTS;
use crate::status::RunState;

/// The run states as the machine stores them.
const STATE_IDLE: u8 = 0;
const STATE_RUN: u8 = 1;
const STATE_HOLD: u8 = 2;
const STATE_JOG: u8 = 3;

/// What the motion task writes (see the module documentation).
pub(super) struct MotionSide {
    /// Steps queued for the pulse engine so far, and the sum of their intervals in ticks (both
    /// wrap).
    queued_steps: AtomicU32,
    queued_ticks: AtomicU32,
    /// How far the queued steps advance along the ideal curve: the pen's speed along its path is
    /// this over the interval of the step emitted last.
    path_steps: PathSteps,
    /// The planner holds nothing.
    plan_empty: AtomicBool,
    /// Segments the planner has room for.
    plan_free: AtomicU8,
    /// The kind of the job taken last (`ShapeKind` as its index + 1, 0 for none).
    drawing: AtomicU8,
    /// The motion's state, as one of the `STATE_` values.
    state: AtomicU8,
}

impl MotionSide {
    /// Nothing queued or planned, idle.
    pub(super) const fn new() -> Self {
        MotionSide {
            queued_steps: AtomicU32::new(0),
            queued_ticks: AtomicU32::new(0),
            path_steps: PathSteps::new(),
            plan_empty: AtomicBool::new(true),
            plan_free: AtomicU8::new(PLANNER_SEGMENTS as u8),
            drawing: AtomicU8::new(0),
            state: AtomicU8::new(STATE_IDLE),
        }
    }

    /// Steps queued so far (wraps).
    pub(super) fn queued_steps_total(&self) -> u32 {
        self.queued_steps.load(Ordering::Acquire)
    }

    /// Motion time queued so far, ticks (wraps).
    pub(super) fn queued_ticks_total(&self) -> u32 {
        self.queued_ticks.load(Ordering::Acquire)
    }

    pub(super) fn set_queued(&self, steps: u32, ticks: u32) {
        self.queued_ticks.store(ticks, Ordering::Release);
        self.queued_steps.store(steps, Ordering::Release);
    }

    /// How far step number `step` advances along the ideal curve, mm.
    pub(super) fn path_step_mm(&self, step: u32) -> f32 {
        self.path_steps.at(step)
    }

    pub(super) fn set_path_step_mm(&self, first: u32, step_mm: f32) {
        self.path_steps.record(first, step_mm);
    }

    pub(super) fn plan_empty(&self) -> bool {
        self.plan_empty.load(Ordering::Acquire)
    }

    pub(super) fn set_plan_empty(&self, empty: bool) {
        self.plan_empty.store(empty, Ordering::Release);
    }

    pub(super) fn plan_free(&self) -> u8 {
        self.plan_free.load(Ordering::Relaxed)
    }

    pub(super) fn set_plan_free(&self, free: usize) {
        self.plan_free.store(free.min(usize::from(u8::MAX)) as u8, Ordering::Relaxed);
    }

    pub(super) fn drawing(&self) -> Option<ShapeKind> {
        let code = self.drawing.load(Ordering::Relaxed);
        ShapeKind::ALL.get(usize::from(code).checked_sub(1)?).copied()
    }

    pub(super) fn set_drawing(&self, kind: ShapeKind) {
        let code = ShapeKind::ALL.iter().position(|&k| k == kind).map_or(0, |i| i as u8 + 1);
        self.drawing.store(code, Ordering::Relaxed);
    }

    pub(super) fn run_state(&self) -> RunState {
        match self.state.load(Ordering::Relaxed) {
            STATE_RUN => RunState::Run,
            STATE_HOLD => RunState::Hold,
            STATE_JOG => RunState::Jog,
            _ => RunState::Idle,
        }
    }

    /// Sets the motion's state; true if it changed. Check mode, sleep, homing and the alarm are
    /// not states of the motion (they are kept where they are set) and store as idle.
    pub(super) fn set_run_state(&self, state: RunState) -> bool {
        let v = state_code(state);
        self.state.swap(v, Ordering::Relaxed) != v
    }
}

const fn state_code(state: RunState) -> u8 {
    match state {
        RunState::Idle | RunState::Check | RunState::Sleep | RunState::Home | RunState::Alarm => STATE_IDLE,
        RunState::Run => STATE_RUN,
        RunState::Hold => STATE_HOLD,
        RunState::Jog => STATE_JOG,
    }
}

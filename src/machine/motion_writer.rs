//! The motion task's handle, [`MotionWriter`]: the writes of the motion side of the machine
//! ([`motion_side`](super::motion_side)), the mailboxes the motion task alone takes from (the
//! controls, the trips, the jobs, in [`jobs`](super::jobs)), and the machine's reads of its
//! part.

use super::Machine;
use crate::geom::TICK_HZ;
use crate::machine_io::inputs::Trip;
use crate::machine_io::pen::Pen;
use crate::motion::interp::ShapeKind;
use crate::motion::job::Control;
use crate::status::{MotionFault, RunState};

writer_handle!(
    /// The motion task's handle: what it queued and planned, the run state, the fault, and the
    /// mailboxes it takes from. Reads go through the machine it derefs to.
    MotionWriter
);

impl MotionWriter<'_> {
    /// The motion task has queued `steps` step commands in all so far, `ticks` ticks of motion
    /// in all (both wrapping).
    pub fn set_queued(self, steps: u32, ticks: u32) {
        self.machine.motion_side.set_queued(steps, ticks);
    }

    /// The steps of a batch queued after `first` steps (counted as `set_queued` counts them)
    /// each advance `step_mm` along the ideal curve (see
    /// [`speed_mm_per_min`](Machine::speed_mm_per_min)).
    pub fn set_path_step_mm(self, first: u32, step_mm: f32) {
        self.machine.motion_side.set_path_step_mm(first, step_mm);
    }

    /// The motion task took a job drawing `kind`.
    pub fn set_drawing(self, kind: ShapeKind) {
        self.machine.motion_side.set_drawing(kind);
    }

    /// Whether the planner holds anything.
    pub fn set_plan_empty(self, empty: bool) {
        self.machine.motion_side.set_plan_empty(empty);
    }

    /// How many segments the planner has room for.
    pub fn set_plan_free_segments(self, free: usize) {
        self.machine.motion_side.set_plan_free(free);
    }

    /// A job started: the fault that ended the last one is history.
    pub fn forget_fault(self) {
        self.machine.alarm.forget_fault();
        self.machine.changed.signal(());
    }

    /// A curve stopped part way, or a trip: the alarm, for `fault`.
    pub fn raise_alarm(self, fault: MotionFault) {
        self.machine.raise_alarm(Some(fault));
    }

    /// Sets the motion's state: idle, running, held or jogging. Check mode and the alarm are
    /// not states of the motion: see [`HostWriter::set_check_mode`](super::HostWriter::set_check_mode)
    /// and [`alarm`](super::alarm).
    pub fn set_run_state(self, state: RunState) {
        if self.machine.motion_side.set_run_state(state) {
            self.machine.changed.signal(());
        }
    }

    /// Sends the pen to `pen`, only at rest; the pen settles before anything moves (see
    /// [`Machine::pen_settled`]). The host link sends it too (`M3`, `M5`), also only at rest.
    pub fn set_pen(self, pen: Pen) {
        self.machine.send_pen(pen);
    }

    /// A homing approach stopped at `trip`'s switch: the pulse engine stays halted until the
    /// homing task has seen it
    /// ([`HomingWriter::take_switch_found`](super::HomingWriter::take_switch_found)).
    pub fn found_switch(self, trip: Trip) {
        // The approach ends here, short of where it was planned to.
        self.machine.plan_from_pen();
        self.machine.homing_side.post_switch_found(trip);
    }

    /// The pending control request, if any, taking it.
    pub fn take_control(self) -> Option<Control> {
        self.machine.control.lock(|c| c.take())
    }

    /// Waits until a control is requested (it may already be), an override changes or a trip
    /// is posted.
    pub async fn control_requested(self) {
        if self.machine.control.lock(|c| c.get().is_none()) {
            self.machine.control_requested.wait().await;
        }
    }

    /// The trip the motion task has yet to handle, taking it.
    pub fn take_trip(self) -> Option<Trip> {
        self.machine.trip.lock(|t| t.take())
    }

    /// Waits until the pulse engine next reports that it stopped.
    pub async fn until_pulses_stopped(self) {
        self.machine.pulses_done.wait().await
    }
}

impl Machine {
    /// Motion time queued for the pulse engine and not yet emitted, in ticks.
    pub fn queued_ticks(&self) -> u32 {
        self.motion_side.queued_ticks_total().wrapping_sub(self.pulse_side.emitted_ticks())
    }

    /// Step commands queued for the pulse engine and not yet emitted.
    pub fn queued_steps(&self) -> u32 {
        self.motion_side.queued_steps_total().wrapping_sub(self.pulse_side.emitted_steps())
    }

    /// True when no step is queued or being emitted.
    pub fn pulses_idle(&self) -> bool {
        self.motion_side.queued_steps_total() == self.pulse_side.emitted_steps()
    }

    /// How fast the pen moves along its path now, mm/min: how far a step advances along the
    /// ideal curve over the interval of the step being emitted; 0 at rest (stopped, or held
    /// once stopped). Not the lattice step's own length: on a line at 30° the steps are X steps
    /// and diagonal ones, each advancing the same distance along the line at the same pace.
    pub fn speed_mm_per_min(&self) -> f32 {
        let interval = self.pulse_side.last_interval_ticks();
        if self.pulses_idle() || interval == 0 {
            return 0.0;
        }
        // The step emitted last is the one being timed.
        let step = self.pulse_side.emitted_steps().wrapping_sub(1);
        self.motion_side.path_step_mm(step) * (60.0 * TICK_HZ as f32) / interval as f32
    }

    /// Planner segments free: how many more drawings the planner could take now.
    pub fn plan_free_segments(&self) -> u8 {
        self.motion_side.plan_free()
    }

    /// The kind of the job the motion task took last, if any.
    pub fn drawing(&self) -> Option<ShapeKind> {
        self.motion_side.drawing()
    }

    /// The run state: in an alarm while the alarm is raised ([`alarm`](super::alarm)), else the
    /// motion's: idle, running, held or jogging (see [`state`](Self::state) for the state to
    /// report).
    pub fn run_state(&self) -> RunState {
        if self.alarm.latched() { RunState::Alarm } else { self.motion_side.run_state() }
    }

    /// The fault that raised the last alarm, until the next job starts.
    pub fn fault(&self) -> Option<MotionFault> {
        self.alarm.fault()
    }

    /// True when nothing is queued, planned or moving, held or not: the position is final.
    pub fn stopped(&self) -> bool {
        self.motion_side.plan_empty() && self.jobs.is_empty() && self.pulses_idle()
    }
}

//! The homing task's handle, [`HomingWriter`]: the writes of the homing side of the machine
//! ([`homing_side`](super::homing_side)), the mailboxes it takes from, and the machine's reads
//! of that part.

use core::sync::atomic::Ordering;

use super::Machine;
use crate::geom::Point;
use crate::machine_io::inputs::Trip;
use crate::status::MotionFault;

writer_handle!(
    /// The homing task's handle: machine zero, the end of a cycle, and the switch an approach
    /// found. Reads go through the machine it derefs to.
    HomingWriter
);

impl HomingWriter<'_> {
    /// Homing found machine zero: the pen, at rest, is at `position`.
    pub fn set_origin(self, position: Point) {
        let machine = self.machine;
        for (axis, at) in [position.x, position.y].into_iter().enumerate() {
            machine.homing_side.set_origin(axis, machine.pulse_side.emitted_on(axis).wrapping_sub(at));
        }
        machine.position_lost.store(false, Ordering::Relaxed);
        // The same point has new coordinates.
        machine.plan_from_pen();
        machine.changed.signal(());
    }

    /// Waits for a homing request.
    pub async fn homing_requested(self) {
        self.machine.homing_side.requested().await
    }

    /// The homing cycle ended: at rest, in an alarm if it failed.
    pub fn end_homing(self) {
        self.machine.homing_side.end();
        self.machine.changed.signal(());
    }

    /// The switch the last homing approach stopped at, if it did, and lets pulses out again.
    pub fn take_switch_found(self) -> Option<Trip> {
        let found = self.machine.homing_side.take_switch_found();
        if found.is_some() {
            self.machine.halted.store(false, Ordering::Release);
        }
        found
    }

    /// A cycle starts from rest: it leaves an alarm, as `$X` does (one of the
    /// [`alarm`](super::alarm)'s posters).
    pub fn unlock(self) {
        self.machine.unlock();
    }

    /// The cycle failed for `fault`, its moves ended: an alarm (one of the
    /// [`alarm`](super::alarm)'s posters).
    pub fn fail(self, fault: MotionFault) {
        self.machine.raise_alarm(Some(fault));
    }
}

impl Machine {
    /// The machine position: the pulses emitted so far, from machine zero.
    pub fn position(&self) -> Point {
        let at = |axis: usize| self.pulse_side.emitted_on(axis).wrapping_sub(self.homing_side.origin(axis));
        Point::new(at(0), at(1))
    }

    /// Asks the homing task for a cycle; false if one runs already. The state is
    /// [`RunState::Home`](crate::status::RunState::Home) from now until it ends. A request anyone may post (the host link's
    /// `$H`, the keypad's menu); the homing task takes it.
    pub fn request_homing(&self) -> bool {
        if !self.homing_side.request() {
            return false;
        }
        self.changed.signal(());
        true
    }

    /// True while a homing cycle runs.
    pub fn homing(&self) -> bool {
        self.homing_side.running()
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
}

//! The alarm: a latch that stops every motion until `$X`, and the fault that raised it.
//!
//! An alarm is raised by whoever finds the fault, and cleared only by an unlock, as GRBL's alarm
//! state is: the motion task raises it for a curve that stopped part way or a trip, the homing
//! task for a cycle that failed, the host link on the reset after `$SLP` (the free axes may have
//! been moved) and when the card is lost mid-plot, and the machine starts in it when homing is
//! required. `$X` (the host link) and a
//! homing cycle's start (the homing task) clear it. Each of these is one store of a whole value,
//! done through the poster's own handle; no one else writes the latch.
//!
//! The fault stays after the unlock, for the screen to say what stopped the last job, until the
//! motion task takes the next job. It is copied in and out under a critical section (an
//! `Option<MotionFault>`, a few bytes).
//!
//! Readers: every task, through [`Machine::run_state`](super::Machine::run_state) (which says
//! [`RunState::Alarm`](crate::status::RunState::Alarm) while the latch is set, whatever the
//! motion does) and [`Machine::fault`](super::Machine::fault).

use core::cell::Cell;
use core::sync::atomic::{AtomicBool, Ordering};

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;

use crate::status::MotionFault;

/// The alarm latch and the last fault (see the module documentation).
pub(super) struct Alarm {
    latched: AtomicBool,
    fault: Mutex<CriticalSectionRawMutex, Cell<Option<MotionFault>>>,
}

impl Alarm {
    /// No alarm, or (`latched`) the alarm a machine that must be homed starts in.
    pub(super) const fn new(latched: bool) -> Self {
        Alarm { latched: AtomicBool::new(latched), fault: Mutex::new(Cell::new(None)) }
    }

    pub(super) fn latched(&self) -> bool {
        self.latched.load(Ordering::Acquire)
    }

    pub(super) fn fault(&self) -> Option<MotionFault> {
        self.fault.lock(|f| f.get())
    }

    /// Raises the alarm, for `fault` if one is given (the last fault stays otherwise); true if
    /// it was not raised before.
    pub(super) fn raise(&self, fault: Option<MotionFault>) -> bool {
        if fault.is_some() {
            self.fault.lock(|f| f.set(fault));
        }
        !self.latched.swap(true, Ordering::AcqRel)
    }

    /// Clears the alarm (the fault stays, to be shown); true if it was raised.
    pub(super) fn clear(&self) -> bool {
        self.latched.swap(false, Ordering::AcqRel)
    }

    /// The motion task takes a new job: the last fault is history.
    pub(super) fn forget_fault(&self) {
        self.fault.lock(|f| f.set(None));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::interp::CurveError;

    #[test]
    fn the_alarm_stays_until_cleared_and_its_fault_until_forgotten() {
        let alarm = Alarm::new(false);
        assert!(!alarm.latched());
        assert!(alarm.raise(Some(MotionFault::Curve(CurveError::Domain))));
        assert!(!alarm.raise(None), "raised once");
        assert!(alarm.latched());
        assert_eq!(alarm.fault(), Some(MotionFault::Curve(CurveError::Domain)), "a raise without a fault keeps it");
        assert!(alarm.clear());
        assert!(!alarm.latched());
        assert_eq!(alarm.fault(), Some(MotionFault::Curve(CurveError::Domain)), "shown after the unlock");
        alarm.forget_fault();
        assert_eq!(alarm.fault(), None);
        assert!(!alarm.clear(), "nothing to clear");
    }
}

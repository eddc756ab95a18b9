//! The writers' handles, handed out once: each task gets the handle to the part of the machine
//! it writes, and reads the rest through the narrow reads on [`Machine`] (every handle derefs to
//! it). The setters live on the handles only, so a task cannot write what it does not own.
//!
//! The board, the simulator and the tests take the handles from [`Machine::handles`] when they
//! build the machine, and give each task its own. A handle is a reference: `Copy`, free to pass.
//!
//! A write is a method of its writer's handle, not of the machine:
//!
//! ```compile_fail
//! use servoplot::machine::Machine;
//! use servoplot::settings::Settings;
//!
//! let machine = Machine::new(Settings::default());
//! // The motion task's write: only its handle has it.
//! machine.set_queued(1, 1);
//! ```
//!
//! ```
//! use servoplot::machine::Machine;
//! use servoplot::settings::Settings;
//!
//! let machine = Machine::new(Settings::default());
//! let handles = machine.handles().unwrap();
//! handles.motion.set_queued(1, 1);
//! assert_eq!(machine.queued_steps(), 1);
//! ```

use core::sync::atomic::Ordering;

use super::Machine;
use super::homing_writer::HomingWriter;
use super::host_writer::HostWriter;
use super::motion_writer::MotionWriter;
use super::pulse_writer::PulseWriter;
use super::servo_writer::ServoWriter;

/// The machine's writers, one handle each. The keypad and the LCD have none: the keypad only
/// posts requests (jobs, controls, a homing cycle, settings), which anyone may, and the LCD reads.
#[derive(Clone, Copy)]
pub struct Handles<'m> {
    /// For the pulse interrupt.
    pub pulse: PulseWriter<'m>,
    /// For the motion task.
    pub motion: MotionWriter<'m>,
    /// For the host link.
    pub host: HostWriter<'m>,
    /// For the servo task.
    pub servo: ServoWriter<'m>,
    /// For the homing task.
    pub homing: HomingWriter<'m>,
}

impl Machine {
    /// The writers' handles: once per machine, `None` after the first call.
    pub fn handles(&self) -> Option<Handles<'_>> {
        if self.handed_out.swap(true, Ordering::AcqRel) {
            return None;
        }
        Some(Handles {
            pulse: PulseWriter::new(self),
            motion: MotionWriter::new(self),
            host: HostWriter::new(self),
            servo: ServoWriter::new(self),
            homing: HomingWriter::new(self),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Point, Step, StepCmd};
    use crate::settings::Settings;

    #[test]
    fn the_handles_come_once_and_write_what_every_task_then_reads() {
        let machine = Machine::new(Settings::default());
        let handles = machine.handles().unwrap();
        assert!(machine.handles().is_none(), "a second set of writers is refused");
        handles.motion.set_queued(1, 10);
        assert_eq!((machine.queued_steps(), machine.pulses_idle()), (1, false));
        handles.pulse.emitted(StepCmd::new(Step::new(1, -1), 10));
        assert_eq!(machine.position(), Point::new(1, -1));
        assert!(machine.pulses_idle(), "the step queued is emitted");
        handles.host.set_work_offset_mm([2.0, 3.0]);
        assert_eq!(machine.work_offset_mm(), [2.0, 3.0]);
    }

    #[test]
    fn an_alarm_stays_over_the_motion_until_unlock_and_its_fault_until_the_next_job() {
        use crate::motion::interp::CurveError;
        use crate::status::{MotionFault, RunState};
        let machine = Machine::new(Settings::default());
        let handles = machine.handles().unwrap();
        handles.motion.set_run_state(RunState::Run);
        let fault = MotionFault::Curve(CurveError::Travel);
        handles.motion.raise_alarm(fault);
        assert_eq!(machine.run_state(), RunState::Alarm);
        // The motion brakes and rests under the alarm: the alarm stays.
        handles.motion.set_run_state(RunState::Idle);
        assert_eq!((machine.state(), machine.fault()), (RunState::Alarm, Some(fault)));
        handles.host.unlock();
        assert_eq!((machine.state(), machine.fault()), (RunState::Idle, Some(fault)), "the fault is still shown");
        handles.motion.forget_fault();
        assert_eq!(machine.fault(), None, "a new job starts");
    }

    #[test]
    fn a_machine_that_must_be_homed_starts_in_the_alarm() {
        use crate::status::RunState;
        let machine = Machine::new(Settings { homing: true, ..Settings::default() });
        let handles = machine.handles().unwrap();
        assert_eq!(machine.state(), RunState::Alarm);
        handles.homing.unlock();
        assert_eq!(machine.state(), RunState::Idle);
    }
}

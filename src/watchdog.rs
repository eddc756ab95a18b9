//! When the independent watchdog is fed: only while the pulse engine and the motion task are seen
//! to make progress. Pure logic; the servo task (`tasks::servo`) looks at the machine every
//! `SERVO_ENABLE_POLL_MS` and feeds the watchdog while [`Progress::healthy`] says so.
//!
//! A task that hangs in a loop at a higher priority starves the servo task, so the watchdog
//! resets the board. A task that waits forever is caught here: while steps should be flowing
//! (steps queued, or the motion running, with the servos ready and nothing tripped), the pulses
//! emitted must grow within [`WATCHDOG_STALL_MS`] more than the queued motion takes.

use crate::geom::TICK_HZ;
use crate::machine::Machine;
use crate::status::RunState;

/// The independent watchdog resets the board when it has not been fed for this long: longer
/// than the flash store's sector erase (up to 2 s on the F407, at 3.3 V), during which the
/// processor stalls and nothing feeds it.
pub const WATCHDOG_TIMEOUT_MS: u32 = 4_000;

/// Longest time without a pulse, beyond the motion queued, before the machine counts as stalled.
pub const WATCHDOG_STALL_MS: u32 = 1_000;

/// What the watchdog task sees of the machine at one look.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Look {
    /// Steps emitted so far (wrapping).
    pub emitted_steps: u32,
    /// Steps should be flowing.
    pub expecting: bool,
    /// The motion queued and not yet emitted, ms.
    pub queued_ms: u32,
}

impl Look {
    /// What `machine` shows now: steps should flow while steps are queued or a drawing or jog
    /// runs, the servos ready, the pen settled and nothing tripped.
    pub fn of(machine: &Machine) -> Look {
        let flowing = machine.queued_steps() > 0 || matches!(machine.run_state(), RunState::Run | RunState::Jog);
        Look {
            emitted_steps: machine.emitted_totals().0,
            expecting: flowing && machine.servos_ready() && machine.pen_settled() && !machine.halted(),
            queued_ms: machine.queued_ticks() / (TICK_HZ / 1_000),
        }
    }
}

/// The progress seen so far.
#[derive(Clone, Copy, Debug, Default)]
pub struct Progress {
    emitted_steps: u32,
    since_ms: u32,
}

impl Progress {
    /// Takes a look at `now_ms` (a wrapping clock); true while the machine makes progress.
    pub fn healthy(&mut self, now_ms: u32, look: Look) -> bool {
        if !look.expecting || look.emitted_steps != self.emitted_steps {
            self.emitted_steps = look.emitted_steps;
            self.since_ms = now_ms;
            return true;
        }
        now_ms.wrapping_sub(self.since_ms) <= WATCHDOG_STALL_MS.saturating_add(look.queued_ms)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn look(emitted_steps: u32, expecting: bool) -> Look {
        Look { emitted_steps, expecting, queued_ms: 20 }
    }

    #[test]
    fn pulses_that_stop_flowing_while_expected_stop_the_feeding() {
        let mut p = Progress::default();
        assert!(p.healthy(0, look(0, true)));
        assert!(p.healthy(500, look(10, true)), "pulses flow");
        assert!(p.healthy(1_520, look(10, true)), "within the stall time and the queued motion");
        assert!(!p.healthy(1_521, look(10, true)), "stalled");
        assert!(p.healthy(1_600, look(11, true)), "a pulse again");
    }

    #[test]
    fn a_machine_at_rest_is_always_healthy() {
        let mut p = Progress::default();
        for t in 0..100 {
            assert!(p.healthy(t * 1_000, look(7, false)));
        }
    }
}

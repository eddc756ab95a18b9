//! When the independent watchdog is fed: only while the pulse engine and the motion task are seen
//! to make progress. Pure logic; the servo task (`tasks::servo`) looks at the machine every
//! `SERVO_ENABLE_POLL_MS` and feeds the watchdog while [`Progress::healthy`] says so.
//!
//! A task that hangs in a loop at a higher priority starves the servo task, so the watchdog
//! resets the board. A task that waits forever is caught here: while steps should be flowing
//! (steps queued, or the motion running, with the servos ready and nothing tripped), the pulses
//! emitted must grow within [`WATCHDOG_STALL_MS`] more than the queued motion takes.
//!
//! The watchdog's timeout on the F407 is a range: its LSI clock runs anywhere from 17 to 47 kHz,
//! so the prescaler and reload chosen here reset the board after 3.0 s ([`WATCHDOG_TIMEOUT_MS`],
//! the fastest LSI) to 8.3 s ([`WATCHDOG_TIMEOUT_LONGEST_MS`], the slowest), 4.4 s at the typical
//! 32 kHz. The shortest outlasts the longest save of the flash store, which stalls the processor
//! for up to 2 s, by almost a second.

use crate::geom::TICK_HZ;
use crate::machine::Machine;
use crate::status::RunState;
use crate::store::STORE_SAVE_STALL_MAX_MS;

/// The clock the F407's independent watchdog counts, its LSI oscillator: DS8626's "LSI
/// oscillator characteristics" give 17 kHz to 47 kHz (32 kHz typical) over supply, temperature
/// and parts. The timeout scales inversely with it, so it is a range, not a figure.
pub const WATCHDOG_LSI_MIN_HZ: u32 = 17_000;
pub const WATCHDOG_LSI_MAX_HZ: u32 = 47_000;
/// The watchdog's prescaler: it counts LSI / 64 (IWDG_PR, RM0090 §21.4.2; /4 to /256).
pub const WATCHDOG_PRESCALER: u32 = 64;
/// Its reload value: it counts down from here to 0, then resets the board (IWDG_RLR, 12 bits,
/// RM0090 §21.4.3).
pub const WATCHDOG_RELOAD: u32 = 2_203;
const _: () = assert!(WATCHDOG_RELOAD <= 0xFFF);

/// The independent watchdog resets the board when it has not been fed for this long at the
/// fastest LSI (47 kHz): the shortest its timeout can be, and the one the firmware must meet.
/// It outlasts the longest stall of a save ([`STORE_SAVE_STALL_MAX_MS`]: a sector erase, up to
/// 2 s, during which the processor stalls and nothing feeds it) by [`WATCHDOG_SAVE_MARGIN_MS`].
pub const WATCHDOG_TIMEOUT_MS: u32 = WATCHDOG_PRESCALER * (WATCHDOG_RELOAD + 1) * 1_000 / WATCHDOG_LSI_MAX_HZ;
/// The same at the slowest LSI (17 kHz): the longest a hung board can go before it is reset.
pub const WATCHDOG_TIMEOUT_LONGEST_MS: u32 =
    (WATCHDOG_PRESCALER * (WATCHDOG_RELOAD + 1) * 1_000).div_ceil(WATCHDOG_LSI_MIN_HZ);
/// What the shortest timeout keeps over the longest save, for the feeding task's period and
/// the polls that may run between its last feed and the save.
pub const WATCHDOG_SAVE_MARGIN_MS: u32 = 900;
const _: () = assert!(WATCHDOG_TIMEOUT_MS >= STORE_SAVE_STALL_MAX_MS + WATCHDOG_SAVE_MARGIN_MS);

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
    use crate::tasks::servo::SERVO_ENABLE_POLL_MS;

    #[test]
    fn the_shortest_timeout_outlasts_a_save_and_a_feeding_period() {
        // The extremes the documentation gives, from the prescaler and reload the board writes.
        assert_eq!((WATCHDOG_TIMEOUT_MS, WATCHDOG_TIMEOUT_LONGEST_MS), (3_001, 8_298));
        assert_eq!(WATCHDOG_PRESCALER * (WATCHDOG_RELOAD + 1) * 1_000 / 32_000, 4_408, "typical LSI");
        // The servo task fed the watchdog at most one period before a save began; the save
        // stalls everything for up to a sector erase and a record; the rest is margin.
        assert_eq!(STORE_SAVE_STALL_MAX_MS, 2_014, "a 2 s erase, then 134 words of 100 µs");
        let unfed_ms = SERVO_ENABLE_POLL_MS as u32 + STORE_SAVE_STALL_MAX_MS;
        assert!(WATCHDOG_TIMEOUT_MS >= unfed_ms * 14 / 10, "{} ms against {unfed_ms} ms", WATCHDOG_TIMEOUT_MS);
    }

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

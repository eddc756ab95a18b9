//! Virtual time for the simulator: embassy-time's driver on the host.
//!
//! Time stands still while tasks run and jumps to the next timer deadline when every task waits,
//! so a simulated minute of plotting takes a fraction of a second and every pulse timestamp is
//! exact. The clock is per thread, so tests can run simulators side by side. In a live session
//! ([`WallPace`]) each jump waits until the wall clock has caught up with it.

use core::cell::Cell;
use core::task::Waker;
use std::cell::RefCell;

std::thread_local! {
    static NOW_TICKS: Cell<u64> = const { Cell::new(0) };
    /// Earliest deadline any timer asked for, with the wakers to call then.
    static WAKE_AT: RefCell<Option<(u64, std::vec::Vec<Waker>)>> = const { RefCell::new(None) };
}

struct VirtualClock;

impl embassy_time_driver::Driver for VirtualClock {
    fn now(&self) -> u64 {
        NOW_TICKS.with(|n| n.get())
    }

    fn schedule_wake(&self, at: u64, waker: &Waker) {
        WAKE_AT.with(|w| {
            let mut w = w.borrow_mut();
            match &mut *w {
                Some((t, wakers)) => {
                    *t = (*t).min(at);
                    if !wakers.iter().any(|k| k.will_wake(waker)) {
                        wakers.push(waker.clone());
                    }
                }
                None => *w = Some((at, std::vec![waker.clone()])),
            }
        });
    }
}

embassy_time_driver::time_driver_impl!(static CLOCK: VirtualClock = VirtualClock);

/// The current virtual time in ticks (microseconds).
pub fn now_ticks() -> u64 {
    NOW_TICKS.with(|n| n.get())
}

/// Starts this thread's clock again at zero with no timer pending.
pub fn reset() {
    NOW_TICKS.with(|n| n.set(0));
    WAKE_AT.with(|w| *w.borrow_mut() = None);
}

/// The earliest pending timer deadline, if any.
pub fn next_deadline() -> Option<u64> {
    WAKE_AT.with(|w| w.borrow().as_ref().map(|(t, _)| *t))
}

/// Jumps to `t` (never backwards) without waking anything: an input arrives then.
pub fn jump_to(t: u64) {
    NOW_TICKS.with(|n| n.set(n.get().max(t)));
}

/// Jumps to the earliest timer deadline (never backwards) and wakes its waiters.
/// Every timer re-arms itself when polled, so waking all waiters at the earliest deadline is
/// exact: those not yet due simply ask again.
pub fn jump_to_next_deadline() -> bool {
    let Some((at, wakers)) = WAKE_AT.with(|w| w.borrow_mut().take()) else {
        return false;
    };
    NOW_TICKS.with(|n| n.set(n.get().max(at)));
    for w in wakers {
        w.wake();
    }
    true
}

/// Virtual time may run this far ahead of the wall clock in a live session before the run
/// waits for the wall clock: shorter waits would cost more than they keep.
pub const LIVE_AHEAD_MAX_US: u64 = 1_000;

/// Virtual time held to the wall clock, for a live session: the deadlines fall due at their
/// wall time, whatever the work between them took, so a sender's job takes its plot time.
pub struct WallPace {
    /// The wall clock and the virtual clock at the same instant.
    wall_at_start: std::time::Instant,
    virtual_at_start_us: u64,
}

impl WallPace {
    /// Holds the virtual clock from its time now to the wall clock from now.
    pub fn start() -> Self {
        WallPace { wall_at_start: std::time::Instant::now(), virtual_at_start_us: now_ticks() }
    }

    /// Wall time and virtual time passed since the start, µs.
    pub fn kept_us(&self) -> (u64, u64) {
        (self.wall_at_start.elapsed().as_micros() as u64, now_ticks().saturating_sub(self.virtual_at_start_us))
    }

    /// The virtual time the wall clock has reached.
    pub fn wall_us(&self) -> u64 {
        self.virtual_at_start_us.saturating_add(self.wall_at_start.elapsed().as_micros() as u64)
    }

    /// How long the wall clock takes to reach virtual time `t_us`, if that is more than
    /// [`LIVE_AHEAD_MAX_US`] away; `None` if virtual time may go on to it at once.
    pub fn wait_for(&self, t_us: u64) -> Option<std::time::Duration> {
        let ahead_us = t_us.saturating_sub(self.wall_us());
        (ahead_us > LIVE_AHEAD_MAX_US).then(|| std::time::Duration::from_micros(ahead_us))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_deadline_ahead_of_the_wall_clock_is_waited_for_and_one_behind_is_not() {
        reset();
        jump_to(5_000_000);
        let pace = WallPace::start();
        let wait = pace.wait_for(7_000_000).expect("2 s ahead");
        assert!(wait <= std::time::Duration::from_secs(2) && wait > std::time::Duration::from_secs(1), "{wait:?}");
        assert_eq!(pace.wait_for(5_000_000 + LIVE_AHEAD_MAX_US / 2), None, "within the slack");
        assert_eq!(pace.wait_for(4_000_000), None, "behind the wall clock");
        assert!(pace.wall_us() >= 5_000_000);
    }
}

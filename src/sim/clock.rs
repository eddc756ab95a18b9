//! Virtual time for the simulator: embassy-time's driver on the host.
//!
//! Time stands still while tasks run and jumps to the next timer deadline when every task waits,
//! so a simulated minute of plotting takes a fraction of a second and every pulse timestamp is
//! exact. The clock is per thread, so tests can run simulators side by side.

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

//! The model's time: embassy-time's driver, the poll clock, and the watchdog.
//!
//! QEMU runs the model with `-icount shift=4,sleep=off`: each instruction takes 16 ns of virtual
//! time, and idle time is skipped. The firmware's microsecond is the time the STM32F407 takes
//! to run the instructions the model runs in it: at 168 MHz and the cycles per instruction the
//! cost model derives from the Cortex-M4's instruction timings (`cost/f407.txt`: 1.5 for lines,
//! up to 1.85 for functions), at the costliest 1.87 the F407 runs 168 / 1.87 ≈ 90 instructions
//! a µs, which take 90 × 16 ns = 1.44 µs of virtual time: [`CLOCKS_PER_US`] counts of the
//! model's 25 MHz timers. So every deadline, poll time and pulse rate the firmware sees on the
//! model is what it would be on the chip, or a little worse.
//!
//! Timer 0 counts down freely through 2^32 counts, its interrupt counting the wraps: the time
//! since reset. The dual timer's first counter, one-shot, is the alarm of embassy-time's queue;
//! its second counter, periodic, is the watchdog: fed, it starts over; run out, the model stops
//! with a failure, as the F407's independent watchdog would reset the board.

use core::cell::{Cell, RefCell};

use critical_section::{CriticalSection, Mutex};
use embassy_time_driver::Driver;
use embassy_time_queue_utils::Queue;

use super::regs::{self, *};

/// Model timer counts per µs of the F407's time (see the module documentation).
pub const CLOCKS_PER_US: u32 = 36;

/// The longest alarm the one-shot counter is set for at a time, counts; a later deadline is
/// set again when it fires.
const ALARM_MAX_CLOCKS: u64 = u32::MAX as u64;

/// The free-running counter's wraps, in µs: whole µs up to the last wrap, and the counts past
/// the last whole µs (written only by its interrupt, read in critical sections).
static WRAPS: Mutex<Cell<Wraps>> = Mutex::new(Cell::new(Wraps { us: 0, rest: 0 }));

#[derive(Clone, Copy)]
struct Wraps {
    us: u64,
    rest: u32,
}

/// µs since the clock started. In a critical section, so its interrupt cannot count a wrap
/// between the reads; 32-bit divisions by a constant only (the time driver is read often).
fn now_us(cs: CriticalSection) -> u64 {
    let value = regs::read(TIMER0, TIMER_VALUE);
    let mut wraps = WRAPS.borrow(cs).get();
    // A wrap its interrupt has not counted yet: the value read is after it if it is high.
    if regs::read(TIMER0, TIMER_INTCLEAR) & 1 != 0 && value > u32::MAX / 2 {
        wraps = wraps.after_wrap();
    }
    let counted = u32::MAX - value;
    let (whole, part) = (counted / CLOCKS_PER_US, counted % CLOCKS_PER_US);
    wraps.us + u64::from(whole) + u64::from((part + wraps.rest) / CLOCKS_PER_US)
}

impl Wraps {
    /// One wrap (2^32 counts) later.
    fn after_wrap(self) -> Wraps {
        // 2^32 counts: (2^32 - 1) / CLOCKS_PER_US whole µs and the rest, plus one count.
        let wrap_us = u64::from(u32::MAX / CLOCKS_PER_US);
        let rest = self.rest + u32::MAX % CLOCKS_PER_US + 1;
        Wraps { us: self.us + wrap_us + u64::from(rest / CLOCKS_PER_US), rest: rest % CLOCKS_PER_US }
    }
}

/// The poll clock: the free-running counter's low 32 bits, [`CLOCKS_PER_US`] a µs.
pub fn poll_clock() -> u32 {
    u32::MAX - regs::read(TIMER0, TIMER_VALUE)
}

/// embassy-time's driver.
struct ModelTime {
    queue: Mutex<RefCell<Queue>>,
    /// When the alarm is set for, µs; `u64::MAX` when it is not.
    alarm_at: Mutex<Cell<u64>>,
}

embassy_time_driver::time_driver_impl!(static DRIVER: ModelTime = ModelTime {
    queue: Mutex::new(RefCell::new(Queue::new())),
    alarm_at: Mutex::new(Cell::new(u64::MAX)),
});

impl ModelTime {
    fn now_us(&self, cs: CriticalSection) -> u64 {
        now_us(cs)
    }

    /// Sets the alarm for `at` (µs); false, and no alarm, if `at` has passed.
    fn set_alarm(&self, cs: CriticalSection, at: u64) -> bool {
        self.alarm_at.borrow(cs).set(at);
        regs::write(DUALTIMER1, DUAL_CTRL, 0);
        let now = self.now_us(cs);
        if at <= now {
            self.alarm_at.borrow(cs).set(u64::MAX);
            return false;
        }
        if at == u64::MAX {
            // Nothing waits.
            return true;
        }
        let clocks = (at - now).saturating_mul(u64::from(CLOCKS_PER_US)).min(ALARM_MAX_CLOCKS) as u32;
        regs::write(DUALTIMER1, DUAL_LOAD, clocks);
        regs::write(DUALTIMER1, DUAL_CTRL, DUAL_ENABLE | DUAL_IRQ_ENABLE | DUAL_32BIT | DUAL_ONESHOT);
        true
    }

    /// The alarm rang (or the queue changed): wakes what is due and sets the alarm for the next.
    fn trigger(&self, cs: CriticalSection) {
        let mut queue = self.queue.borrow(cs).borrow_mut();
        let mut next = queue.next_expiration(self.now_us(cs));
        while !self.set_alarm(cs, next) {
            next = queue.next_expiration(self.now_us(cs));
        }
    }
}

impl Driver for ModelTime {
    fn now(&self) -> u64 {
        critical_section::with(|cs| self.now_us(cs))
    }

    fn schedule_wake(&self, at: u64, waker: &core::task::Waker) {
        critical_section::with(|cs| {
            if self.queue.borrow(cs).borrow_mut().schedule_wake(at, waker) {
                self.trigger(cs);
            }
        })
    }
}

/// Starts the free-running counter.
pub fn start() {
    regs::write(TIMER0, TIMER_CTRL, 0);
    regs::write(TIMER0, TIMER_RELOAD, u32::MAX);
    regs::write(TIMER0, TIMER_VALUE, u32::MAX);
    regs::write(TIMER0, TIMER_INTCLEAR, 1);
    regs::write(TIMER0, TIMER_CTRL, TIMER_ENABLE | TIMER_IRQ_ENABLE);
}

/// Timer 0's interrupt: the free-running counter wrapped.
pub fn on_wrap() {
    critical_section::with(|cs| {
        regs::write(TIMER0, TIMER_INTCLEAR, 1);
        let wraps = WRAPS.borrow(cs);
        wraps.set(wraps.get().after_wrap());
    });
}

/// The dual timer's interrupt: the alarm rang, or the watchdog ran out (true).
pub fn on_dual_timer() -> bool {
    if regs::read(DUALTIMER2, DUAL_MIS) != 0 {
        return true;
    }
    if regs::read(DUALTIMER1, DUAL_MIS) != 0 {
        regs::write(DUALTIMER1, DUAL_INTCLR, 1);
        critical_section::with(|cs| DRIVER.trigger(cs));
    }
    false
}

/// The watchdog: the dual timer's second counter, periodic.
pub struct Watchdog {
    timeout_clocks: u32,
}

impl Watchdog {
    /// Starts it: unless fed, it runs out after `timeout_ms`.
    pub fn start(timeout_ms: u32) -> Watchdog {
        let timeout_clocks = timeout_ms * 1_000 * CLOCKS_PER_US;
        regs::write(DUALTIMER2, DUAL_LOAD, timeout_clocks);
        regs::write(DUALTIMER2, DUAL_CTRL, DUAL_ENABLE | DUAL_IRQ_ENABLE | DUAL_32BIT | DUAL_PERIODIC);
        Watchdog { timeout_clocks }
    }

    /// Feeds it: the count starts over.
    pub fn feed(&mut self) {
        regs::write(DUALTIMER2, DUAL_LOAD, self.timeout_clocks);
    }
}

//! The two executors every board runs: the thread-mode executor, which sleeps with WFI between
//! polls, and the motion task's interrupt executor.
//!
//! The thread-mode executor is embassy's raw executor with a loop of its own. Its pender (a task
//! woken, from thread mode or from an interrupt) pends a spare interrupt at the lowest priority;
//! that interrupt's handler, [`on_thread_pender`], only notes the wake-up. The loop polls, then
//! with interrupts masked sleeps (WFI) unless a wake-up came meanwhile: a pending interrupt ends
//! WFI even while masked, so no wake-up is lost between the look and the sleep. WFI rather than
//! embassy's WFE: an emulated core (QEMU) treats WFE as a mere yield, so the stock executor
//! would never let the model board's virtual time skip its idle stretches; on the chip both
//! sleep the same.

use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::NVIC;
use embassy_executor::{InterruptExecutor, Spawner, raw};
use static_cell::StaticCell;

/// The motion task's executor; the board's handler of its spare interrupt calls
/// `MOTION_EXECUTOR.on_interrupt()`.
pub static MOTION_EXECUTOR: InterruptExecutor = InterruptExecutor::new();

/// A thread-mode task was woken since the loop last looked.
static WOKEN: AtomicBool = AtomicBool::new(false);

/// An interrupt line by its number.
#[derive(Clone, Copy)]
pub struct Irq(pub u16);

// SAFETY: the boards give the numbers of their own spare interrupt lines.
unsafe impl InterruptNumber for Irq {
    fn number(self) -> u16 {
        self.0
    }
}

/// The thread-mode pender's interrupt: the board's handler of that spare line calls this.
pub fn on_thread_pender() {
    WOKEN.store(true, Ordering::Release);
}

/// Runs the thread-mode executor forever, its pender on `pender` (a spare interrupt line, at
/// `priority`, the lowest), after `init` has spawned the first tasks.
pub fn run_thread_mode(pender: Irq, priority: u8, init: impl FnOnce(Spawner)) -> ! {
    static EXECUTOR: StaticCell<raw::Executor> = StaticCell::new();
    let executor: &'static raw::Executor = EXECUTOR.init(raw::Executor::new(usize::from(pender.0) as *mut ()));
    // SAFETY: the priority is set before the line is unmasked, and its handler only sets a flag.
    unsafe {
        let mut core = cortex_m::Peripherals::steal();
        core.NVIC.set_priority(pender, priority);
        NVIC::unmask(pender);
    }
    init(executor.spawner());
    loop {
        WOKEN.store(false, Ordering::Relaxed);
        // SAFETY: polled only from this loop, in thread mode.
        unsafe { executor.poll() };
        cortex_m::interrupt::disable();
        if !WOKEN.load(Ordering::Acquire) {
            cortex_m::asm::wfi();
        }
        // SAFETY: masked only for the look and the sleep above.
        unsafe { cortex_m::interrupt::enable() };
    }
}

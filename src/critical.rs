//! Critical sections on the chip: they mask every interrupt but the pulse engine's.
//!
//! A critical section here raises BASEPRI (ARMv7-M: exceptions at that priority and below are
//! held back) to [`MASKED_FROM`] instead of setting PRIMASK, so the step timer's interrupt, the
//! one at priority 0, still comes in time while any task, the executors, embassy-time's queue or
//! the log hold a lock. The pulse engine may then take no lock itself: it works on atomics and
//! the lock-free step queue, and leaves the rest to an interrupt below it
//! (`crate::machine`'s pulse news). On the host the `critical-section` crate's own (a mutex)
//! serves the simulator and the tests.
//!
//! Nested sections nest: each raises BASEPRI no lower than it stands (BASEPRI_MAX) and puts back
//! what it found.

/// The first priority a critical section masks: every interrupt less urgent than the pulse
/// interrupt (priority 0). Upper nibble only: the STM32F407 implements 4 priority bits.
pub const MASKED_FROM: u8 = 0x10;

/// The `critical-section` implementation of the chip.
struct MaskBelowPulses;

critical_section::set_impl!(MaskBelowPulses);

// SAFETY: single core; BASEPRI masks every exception of priority MASKED_FROM and below for as
// long as the section lasts, and release() puts back what acquire() found, so sections nest.
// Nothing at a priority above MASKED_FROM (the pulse interrupt) ever enters a section.
unsafe impl critical_section::Impl for MaskBelowPulses {
    unsafe fn acquire() -> critical_section::RawRestoreState {
        let was = cortex_m::register::basepri::read();
        // Raising BASEPRI only masks more; it is put back in `release`.
        cortex_m::register::basepri_max::write(MASKED_FROM);
        was
    }

    unsafe fn release(was: critical_section::RawRestoreState) {
        // SAFETY: `was` is what `acquire` found: the section's end lowers BASEPRI back to it.
        unsafe { cortex_m::register::basepri::write(was) };
    }
}

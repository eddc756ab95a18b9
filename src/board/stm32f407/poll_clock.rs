//! The clock task polls are timed by: the core's cycle counter (DWT CYCCNT), 168 counts a µs.

/// Counts per µs.
pub const PER_US: u32 = 168;

/// The count now, wrapping.
pub fn now() -> u32 {
    cortex_m::peripheral::DWT::cycle_count()
}

/// Starts the counter; once, at start-up.
pub fn start() {
    // SAFETY: only this board's start-up touches the debug and trace units.
    let mut core = unsafe { cortex_m::Peripherals::steal() };
    core.DCB.enable_trace();
    core.DWT.enable_cycle_counter();
}

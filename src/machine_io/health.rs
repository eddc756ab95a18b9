//! What the firmware measures of itself on the chip: the most of the stack ever used and the
//! longest task poll. The board measures them (the core cannot: it knows neither the chip's
//! stack nor its clock) and publishes them here; `$I` reports them (see
//! [`crate::host::report::build_info`]), and the board's log names the task. The simulator
//! publishes nothing: its stack and its time are the host's.

use core::sync::atomic::{AtomicU32, Ordering};

/// One measurement.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Health {
    /// The most of the stack ever used, bytes.
    pub stack_peak_bytes: u32,
    pub stack_size_bytes: u32,
    /// The longest poll of any task, µs of the chip's time: its own work, less the motion task's
    /// polls that preempted it.
    pub longest_poll_us: u32,
    /// The longest poll of any task with the motion task's polls that preempted it: what the
    /// tasks behind it waited.
    pub longest_poll_with_preemption_us: u32,
}

static STACK_PEAK_BYTES: AtomicU32 = AtomicU32::new(0);
static STACK_SIZE_BYTES: AtomicU32 = AtomicU32::new(0);
static LONGEST_POLL_US: AtomicU32 = AtomicU32::new(0);
static LONGEST_POLL_WITH_PREEMPTION_US: AtomicU32 = AtomicU32::new(0);

/// Publishes a measurement. Only the board's health task calls this.
pub fn publish(health: &Health) {
    STACK_PEAK_BYTES.store(health.stack_peak_bytes, Ordering::Relaxed);
    LONGEST_POLL_US.store(health.longest_poll_us, Ordering::Relaxed);
    LONGEST_POLL_WITH_PREEMPTION_US.store(health.longest_poll_with_preemption_us, Ordering::Relaxed);
    // Last: a size of 0 means nothing was published.
    STACK_SIZE_BYTES.store(health.stack_size_bytes, Ordering::Release);
}

/// The last measurement published, if any.
pub fn read() -> Option<Health> {
    let stack_size_bytes = STACK_SIZE_BYTES.load(Ordering::Acquire);
    (stack_size_bytes != 0).then(|| Health {
        stack_peak_bytes: STACK_PEAK_BYTES.load(Ordering::Relaxed),
        stack_size_bytes,
        longest_poll_us: LONGEST_POLL_US.load(Ordering::Relaxed),
        longest_poll_with_preemption_us: LONGEST_POLL_WITH_PREEMPTION_US.load(Ordering::Relaxed),
    })
}

//! The part of the machine the servo task writes, through its handle
//! ([`ServoWriter`](super::ServoWriter)): the input levels it read last, whether the drivers
//! hold their axes (SON high for the enable delay), and the last pen order the pen servo has had
//! its settle time for.
//!
//! One writer: the servo task (the servos, the pen servo, the inputs and the watchdog,
//! [`crate::tasks::servo`]). Readers: the motion task (no pulse before the drivers are ready and
//! the pen settled), the pulse engine's watchdog look, the host link (`$I`'s inputs, the pen's
//! wait) and the homing task (the switches), through the narrow reads on
//! [`Machine`](super::Machine).

use core::sync::atomic::{AtomicBool, AtomicU8, AtomicU32, Ordering};

use crate::machine_io::inputs::InputLevels;
use crate::machine_io::pen::PenOrder;

/// What the servo task writes (see the module documentation).
pub(super) struct ServoSide {
    /// The input levels read last.
    input_levels: AtomicU8,
    /// SON has been high for the drivers' enable delay.
    servos_ready: AtomicBool,
    /// The last pen order (its bits) the pen servo has had its settle time for.
    pen_settled: AtomicU32,
}

impl ServoSide {
    pub(super) const fn new() -> Self {
        ServoSide {
            input_levels: AtomicU8::new(0),
            servos_ready: AtomicBool::new(false),
            pen_settled: AtomicU32::new(u32::MAX),
        }
    }

    pub(super) fn input_levels(&self) -> InputLevels {
        self.input_levels.load(Ordering::Relaxed)
    }

    pub(super) fn set_input_levels(&self, levels: InputLevels) {
        self.input_levels.store(levels, Ordering::Relaxed);
    }

    pub(super) fn servos_ready(&self) -> bool {
        self.servos_ready.load(Ordering::SeqCst)
    }

    pub(super) fn set_servos_ready(&self, ready: bool) {
        // Sequentially consistent: the servo task's going-off handshake with the motion task.
        self.servos_ready.store(ready, Ordering::SeqCst);
    }

    /// The bits of the last order the pen has settled for.
    pub(super) fn pen_settled_bits(&self) -> u32 {
        self.pen_settled.load(Ordering::Acquire)
    }

    pub(super) fn set_pen_settled(&self, order: PenOrder) {
        self.pen_settled.store(order.bits(), Ordering::Release);
    }
}

//! The servo task's handle, [`ServoWriter`]: the writes of the servo side of the machine
//! ([`servo_side`](super::servo_side)), and the machine's reads of that part.

use core::sync::atomic::Ordering;

use super::Machine;
use crate::machine_io::inputs::InputLevels;
use crate::machine_io::pen::PenOrder;

writer_handle!(
    /// The servo task's handle: the input levels, the drivers' readiness and the pen's settling.
    /// Reads go through the machine it derefs to; a trip is posted to the machine as anyone's.
    ServoWriter
);

impl ServoWriter<'_> {
    /// The input levels just read.
    pub fn set_input_levels(self, levels: InputLevels) {
        self.machine.servo_side.set_input_levels(levels);
    }

    /// Whether the drivers hold their axes: SON high for the enable delay (`$209`).
    pub fn set_servos_ready(self, ready: bool) {
        self.machine.servo_side.set_servos_ready(ready);
    }

    /// The pen servo has settled as `order` says.
    pub fn set_pen_settled(self, order: PenOrder) {
        self.machine.servo_side.set_pen_settled(order);
    }
}

impl Machine {
    /// The input levels last read.
    pub fn input_levels(&self) -> InputLevels {
        self.servo_side.input_levels()
    }

    /// True once the drivers hold their axes; no pulse may go out before.
    pub fn servos_ready(&self) -> bool {
        self.servo_side.servos_ready()
    }

    /// True once the pen is where it was last sent: no pulse may go out before.
    pub fn pen_settled(&self) -> bool {
        self.servo_side.pen_settled_bits() == self.pen.load(Ordering::Acquire)
    }
}

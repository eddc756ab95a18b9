//! The machine's input pins: the four limit switches, the two drivers' alarm outputs and the
//! emergency stop, all on port E with pull-ups, so that one read of the port gives every level
//! (the pulse engine reads them at every period). What the levels mean is `servoplot::machine_io::inputs`'s.
//!
//! | input            | pin  | bit                 |
//! |------------------|------|---------------------|
//! | X min, Y min     | PE4, PE5 | `LIMIT_X_MIN`, `LIMIT_Y_MIN` |
//! | X max, Y max     | PE6, PE7 | `LIMIT_X_MAX`, `LIMIT_Y_MAX` |
//! | X ALM, Y ALM     | PE8, PE14 | `DRIVER_ALARM_X`, `DRIVER_ALARM_Y` |
//! | e-stop           | PE15 | `ESTOP`             |

use embassy_stm32::Peri;
use embassy_stm32::gpio::{Input, Pull};
use embassy_stm32::pac;
use embassy_stm32::peripherals::{PE4, PE5, PE6, PE7, PE8, PE14, PE15};
use servoplot::machine_io::inputs::{ESTOP, InputLevels};

/// PE4..PE8 are bits 0..4 of the levels, PE14 and PE15 bits 5 and 6.
const LOW_PINS_SHIFT: u32 = 4;
const LOW_PINS_MASK: u32 = 0x1F;
const HIGH_PINS_SHIFT: u32 = 9;
const HIGH_PINS_MASK: u32 = 0x60;
const _: () = assert!(ESTOP as u32 == 1 << (15 - HIGH_PINS_SHIFT));

/// The input pins, configured as inputs with pull-ups for as long as this lives.
pub struct InputPins {
    _pins: [Input<'static>; 7],
}

impl InputPins {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        x_min: Peri<'static, PE4>,
        y_min: Peri<'static, PE5>,
        x_max: Peri<'static, PE6>,
        y_max: Peri<'static, PE7>,
        x_alarm: Peri<'static, PE8>,
        y_alarm: Peri<'static, PE14>,
        estop: Peri<'static, PE15>,
    ) -> Self {
        InputPins {
            _pins: [
                Input::new(x_min, Pull::Up),
                Input::new(y_min, Pull::Up),
                Input::new(x_max, Pull::Up),
                Input::new(y_max, Pull::Up),
                Input::new(x_alarm, Pull::Up),
                Input::new(y_alarm, Pull::Up),
                Input::new(estop, Pull::Up),
            ],
        }
    }

    /// Every input's level, from one read of port E.
    #[inline(always)]
    pub fn levels(&self) -> InputLevels {
        read()
    }
}

/// Every input's level, from one read of port E: for the servo task, which reads them beside
/// the pulse engine (reading a port changes nothing).
#[inline(always)]
pub fn read() -> InputLevels {
    let idr = pac::GPIOE.idr().read().0;
    (((idr >> LOW_PINS_SHIFT) & LOW_PINS_MASK) | ((idr >> HIGH_PINS_SHIFT) & HIGH_PINS_MASK)) as InputLevels
}

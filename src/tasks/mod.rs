//! The async loops of the firmware, generic over embedded-hal / embedded-io-async traits so the
//! STM32 board and the simulated board run the same code. They wait, read, write and hand values
//! to the core; they decide nothing. Boards wrap each in an `#[embassy_executor::task]`.

pub mod homing;
pub mod keypad;
pub mod lcd;
pub mod motion;
pub mod serial;
pub mod servo;

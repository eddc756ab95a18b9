//! The async loops of the firmware, generic over embedded-hal / embedded-io-async traits so the
//! STM32 board and the simulated board run the same code. They wait, read, write and hand values
//! to the core; they decide nothing. Boards wrap each in an `#[embassy_executor::task]`.
//!
//! A task that writes part of the shared machine runs on its writer's handle (the motion task
//! on a [`MotionWriter`](crate::machine::MotionWriter), the host link on a
//! [`HostWriter`](crate::machine::HostWriter), the servo and homing tasks on theirs), which
//! reads the rest of the machine too; the keypad and the LCD, which only post requests and read,
//! take the machine itself.

pub mod homing;
pub mod keypad;
pub mod lcd;
pub mod motion;
pub mod panel;
pub mod serial;
pub mod servo;
pub mod slices;

use embassy_time::{Instant, TICK_HZ};

/// Clock ticks per millisecond: a whole number that fits 16 bits (the clock counts at 1 MHz).
const TICKS_PER_MS: u64 = TICK_HZ / 1000;
const _: () = assert!(TICK_HZ.is_multiple_of(1000) && TICKS_PER_MS <= u16::MAX as u64);

/// Milliseconds since boot, wrapping every 2^32 ms (49.7 days): `Instant::now().as_millis() as
/// u32`, divided without the runtime's 64-bit division (see [`crate::wide`]).
pub fn now_ms() -> u32 {
    crate::wide::div_rem(Instant::now().as_ticks(), TICKS_PER_MS as u16).0 as u32
}

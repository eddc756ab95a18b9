//! NVIC priorities of the firmware's interrupts, the same on every board, most urgent first
//! (upper nibble only: the F407 implements 4 priority bits).
//!
//! Critical sections hold off every interrupt from [`servoplot::critical::MASKED_FROM`] down:
//! all but the pulse interrupt, which takes no lock (see `servoplot::critical`).

use servoplot::critical::MASKED_FROM;

/// The step timer's interrupt: the pulse engine. Above every critical section.
pub const PULSE: u8 = 0x00;
/// The interrupt that hands the pulse engine's news to the tasks, just below it.
pub const PULSE_NEWS: u8 = 0x10;
/// embassy-time's timer (its alarm and overflow interrupts).
pub const TIME_DRIVER: u8 = 0x10;
/// The host links' ports (UART, USB): above the motion task, whose polls may take a few
/// milliseconds, so a UART that holds one received byte (87 µs at 115200 baud) never overruns.
pub const HOST_LINK: u8 = 0x20;
/// The motion task's interrupt executor.
pub const MOTION: u8 = 0x30;
/// The thread-mode executor's pender: below everything.
pub const THREAD_PENDER: u8 = 0xF0;

const _: () = assert!(PULSE < MASKED_FROM && PULSE_NEWS >= MASKED_FROM && TIME_DRIVER >= MASKED_FROM);

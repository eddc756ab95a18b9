//! NVIC priorities of the firmware's interrupts, the same on every board, most urgent first
//! (upper nibble only: the F407 implements 4 priority bits).

/// The step timer's interrupt: the pulse engine.
pub const PULSE: u8 = 0x00;
/// embassy-time's timer (its alarm and overflow interrupts).
pub const TIME_DRIVER: u8 = 0x10;
/// The motion task's interrupt executor.
pub const MOTION: u8 = 0x20;
/// The host link's port (UART).
pub const HOST_LINK: u8 = 0x30;
/// The thread-mode executor's pender: below everything.
pub const THREAD_PENDER: u8 = 0xF0;

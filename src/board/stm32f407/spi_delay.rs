//! The delays the board's SPI devices wait with (the LCD's and the card's), in 32 bits.

use embassy_time::Delay;
use embedded_hal::delay::DelayNs;

/// embassy-time's delays, the nanoseconds rounded up to whole microseconds (the clock's ticks)
/// in 32 bits, as embassy-time rounds them in 64 (which would link the runtime's 64-bit
/// division, see `servoplot::wide`).
pub struct SpiDelay;

impl DelayNs for SpiDelay {
    fn delay_ns(&mut self, ns: u32) {
        DelayNs::delay_us(&mut Delay, ns.div_ceil(1_000));
    }
    fn delay_us(&mut self, us: u32) {
        DelayNs::delay_us(&mut Delay, us);
    }
    fn delay_ms(&mut self, ms: u32) {
        DelayNs::delay_ms(&mut Delay, ms);
    }
}

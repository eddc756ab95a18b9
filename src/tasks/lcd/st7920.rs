//! The ST7920 LCD controller in serial mode, behind the `st7920` crate: the 122x32 picture
//! drawn into the crate's buffer, the controller's start-up, and the picture sent a row at a
//! time, every write paced to the controller's time.
//!
//! Serial mode (PSB low; ST7920 datasheet V4.0, "Serial interface") is write only: each write is
//! a frame of three bytes, a sync byte (five 1s, RW = 0, RS: 0xF8 an instruction, 0xFA data)
//! and the value's high and low nibbles each followed by four 0s. There is no busy flag to
//! read, and "ST7920 has no internal instruction buffer area": the next write must wait until
//! the last one has executed, [`ST7920_WRITE_US`] (72 µs) for a write and [`ST7920_CLEAR_US`]
//! (1.6 ms) for a clear (the instruction table's execution times, at f_OSC = 540 kHz). The crate
//! sends its writes back to back (37 µs a frame at 656 kHz), so it talks to the controller
//! through [`Paced`], which waits after each frame until the controller has executed it: from
//! one write's last bit to the next write's last bit at least 72 µs (the controller takes a
//! write as its 24th bit arrives, as the parallel bus's enable strobe).
//!
//! The picture is the upper half of graphics RAM, its first 122 columns (128 x 32, 16 bytes a
//! row); a row is sent as its vertical and horizontal addresses and its 16 bytes (the crate's
//! `flush_region` of one row), 18 writes, ~1.3 ms. The 32 rows (~43 ms) go out one per call of
//! [`St7920Lcd::show_slice`], so the LCD task lets the other tasks run between rows.

use core::convert::Infallible;
use embedded_graphics::Pixel;
use embedded_graphics::draw_target::DrawTarget;
use embedded_graphics::geometry::{Dimensions, OriginDimensions, Size};
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_graphics::primitives::Rectangle;

use embedded_hal::delay::DelayNs;
use embedded_hal::digital::OutputPin;
use embedded_hal::spi::{Operation, SpiDevice};

use super::Lcd;
use crate::panel::layout::{SCREEN_HEIGHT_PX, SCREEN_WIDTH_PX};

/// The shortest time from one write to the next, µs: an instruction's or a data write's
/// execution time (the datasheet's instruction table, f_OSC = 540 kHz).
pub const ST7920_WRITE_US: u32 = 72;
/// The same after Display Clear.
pub const ST7920_CLEAR_US: u32 = 1_600;
/// Clocks of one write's frame: the sync byte and the two nibble bytes.
pub const ST7920_FRAME_BITS: u32 = 24;
/// Rows of the picture sent by one call of [`St7920Lcd::show_slice`]: 20 writes, ~1.5 ms.
pub const ST7920_ROWS_PER_SLICE: u8 = 1;

/// Sync bytes: an instruction (RS = 0) or data (RS = 1), written (RW = 0).
const SYNC_INSTRUCTION: u8 = 0xF8;
const SYNC_DATA: u8 = 0xFA;
/// Display clear (basic instruction set).
const DISPLAY_CLEAR: u8 = 0x01;

/// Picture rows: the upper half of graphics RAM.
const ROWS: u8 = SCREEN_HEIGHT_PX as u8;
const _: () = assert!(SCREEN_HEIGHT_PX <= 32 && SCREEN_WIDTH_PX <= 128, "the upper half of graphics RAM");

/// How long the reset line is held low, and how long the controller then takes to start (the
/// datasheet's initial flow waits more than 40 ms after power-on before the first instruction),
/// and how long after its start-up's clear before the first picture (the initial flow's "wait
/// time > 10 ms" after the clear, beyond the 1.6 ms the instruction table gives it). The LCD
/// task waits these out, yielding.
const RESET_LOW_US: u32 = 40_000;
const RESET_START_US: u32 = 40_000;
const CLEAR_SETTLE_US: u32 = 10_000;

/// The three bytes that write `value` as an instruction or as data.
pub const fn frame(data: bool, value: u8) -> [u8; 3] {
    [if data { SYNC_DATA } else { SYNC_INSTRUCTION }, value & 0xF0, value << 4]
}

/// The wait after each write's frame, µs, so that from its last bit to the next frame's last
/// bit at least [`ST7920_WRITE_US`] pass on a link clocked at `spi_hz`: the execution time less
/// the next frame's own length (rounded down), plus a microsecond for a delay that counts whole
/// clock ticks and may end up to one tick early.
pub const fn write_gap_us(spi_hz: u32) -> u32 {
    let frame_us = match (ST7920_FRAME_BITS * 1_000_000).checked_div(spi_hz) {
        Some(us) => us,
        None => 0,
    };
    ST7920_WRITE_US.saturating_sub(frame_us) + 1
}

/// The controller's SPI link, paced: after each frame written, a wait until the controller has
/// executed it (see the module documentation).
pub struct Paced<SPI: SpiDevice, D: DelayNs> {
    spi: SPI,
    delay: D,
    /// The wait after a write, and after a clear.
    gap_us: u32,
    clear_gap_us: u32,
}

impl<SPI: SpiDevice, D: DelayNs> embedded_hal::spi::ErrorType for Paced<SPI, D> {
    type Error = SPI::Error;
}

impl<SPI: SpiDevice, D: DelayNs> SpiDevice for Paced<SPI, D> {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), Self::Error> {
        for op in operations.iter_mut() {
            let wait_us = match op {
                Operation::Write(bytes) if bytes.len() == 3 && bytes[0] == SYNC_INSTRUCTION => {
                    let value = bytes[1] | bytes[2] >> 4;
                    if value == DISPLAY_CLEAR { self.clear_gap_us } else { self.gap_us }
                }
                Operation::Write(_) => self.gap_us,
                _ => 0,
            };
            self.spi.transaction(core::slice::from_mut(op))?;
            self.delay.delay_us(wait_us);
        }
        Ok(())
    }
}

/// A pin the crate is given where the LCD task drives the real one itself (the reset line: the
/// crate's own reset holds the task 80 ms at once).
pub struct Unused;

impl embedded_hal::digital::ErrorType for Unused {
    type Error = Infallible;
}

impl OutputPin for Unused {
    fn set_low(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// No wait: the crate's own waits in its start-up (up to 100 ms each) are not the controller's
/// needs; [`Paced`] waits out each write's execution, and the LCD task the long waits.
struct NoWait;

impl DelayNs for NoWait {
    fn delay_ns(&mut self, _ns: u32) {}
}

/// Where the start-up stands.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Start {
    ResetLow,
    ResetHigh,
    Instructions,
    Ready,
}

/// An ST7920 in serial mode on `spi` (its clock at most ~1 MHz: datasheet, serial timing), with
/// its reset line and its chip select (the RS pin, active high: high from a picture's first row
/// to its last), showing the 122x32 picture drawn into it.
pub struct St7920Lcd<SPI: SpiDevice, PIN: OutputPin<Error = Infallible>, D: DelayNs> {
    driver: st7920::ST7920<Paced<SPI, D>, Unused, Unused>,
    reset: PIN,
    cs: PIN,
    start: Start,
    /// The row the next slice sends.
    next_row: u8,
}

impl<SPI: SpiDevice, PIN: OutputPin<Error = Infallible>, D: DelayNs> St7920Lcd<SPI, PIN, D> {
    /// The controller on `spi`, clocked at `spi_hz` (the clock the link really runs at: the
    /// writes are paced from it), waiting with `delay`.
    pub fn new(spi: SPI, reset: PIN, cs: PIN, delay: D, spi_hz: u32) -> Self {
        let gap_us = write_gap_us(spi_hz);
        let paced = Paced { spi, delay, gap_us, clear_gap_us: gap_us + (ST7920_CLEAR_US - ST7920_WRITE_US) };
        let driver = st7920::ST7920::new(paced, Unused, None, false);
        St7920Lcd { driver, reset, cs, start: Start::ResetLow, next_row: 0 }
    }
}

impl<SPI: SpiDevice, PIN: OutputPin<Error = Infallible>, D: DelayNs> Lcd for St7920Lcd<SPI, PIN, D> {
    fn start(&mut self) -> Option<u32> {
        match self.start {
            Start::ResetLow => {
                let _ = self.reset.set_low();
                self.start = Start::ResetHigh;
                Some(RESET_LOW_US)
            }
            Start::ResetHigh => {
                let _ = self.reset.set_high();
                self.start = Start::Instructions;
                Some(RESET_START_US)
            }
            Start::Instructions => {
                // Function set, display on, clear, entry mode, extended set, graphics on: each
                // paced, ~2 ms in all.
                let _ = self.cs.set_high();
                if self.driver.init(&mut NoWait).is_err() {
                    warn!("LCD start-up failed");
                }
                let _ = self.cs.set_low();
                self.start = Start::Ready;
                Some(CLEAR_SETTLE_US)
            }
            Start::Ready => None,
        }
    }

    fn show_slice(&mut self) -> bool {
        let row = self.next_row;
        if row == 0 {
            let _ = self.cs.set_high();
        }
        let rows = ST7920_ROWS_PER_SLICE.min(ROWS - row);
        let sent = self.driver.flush_region(0, row, SCREEN_WIDTH_PX as u8, rows, &mut NoWait);
        if sent.is_err() {
            warn!("LCD flush failed");
        }
        self.next_row = row + rows;
        if self.next_row < ROWS {
            return true;
        }
        self.next_row = 0;
        let _ = self.cs.set_low();
        false
    }
}

impl<SPI: SpiDevice, PIN: OutputPin<Error = Infallible>, D: DelayNs> OriginDimensions for St7920Lcd<SPI, PIN, D> {
    fn size(&self) -> Size {
        Size::new(SCREEN_WIDTH_PX, SCREEN_HEIGHT_PX)
    }
}

impl<SPI: SpiDevice, PIN: OutputPin<Error = Infallible>, D: DelayNs> DrawTarget for St7920Lcd<SPI, PIN, D> {
    type Color = BinaryColor;
    type Error = Infallible;

    /// Into the crate's buffer (128x64, the screen its top-left 122x32), a pixel at a time.
    fn draw_iter<I: IntoIterator<Item = Pixel<BinaryColor>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
        for Pixel(at, color) in pixels {
            if (0..SCREEN_WIDTH_PX as i32).contains(&at.x) && (0..SCREEN_HEIGHT_PX as i32).contains(&at.y) {
                self.driver.set_pixel_unchecked(at.x as u8, at.y as u8, u8::from(color.is_on()));
            }
        }
        Ok(())
    }

    /// A box of one colour: cleared a byte at a time where it reaches the screen's right edge
    /// (the crate clears whole bytes, and the columns past 122 show nothing), else a pixel at a
    /// time, never through a pixel iterator.
    fn fill_solid(&mut self, area: &Rectangle, color: BinaryColor) -> Result<(), Self::Error> {
        let area = area.intersection(&self.bounding_box());
        let Some(end) = area.bottom_right() else { return Ok(()) };
        let (x, y, w, h) =
            (area.top_left.x as u8, area.top_left.y as u8, area.size.width as u8, area.size.height as u8);
        if color.is_off() && end.x == SCREEN_WIDTH_PX as i32 - 1 {
            let _ = self.driver.clear_buffer_region(x, y, w, h);
            return Ok(());
        }
        for row in y..y + h {
            for column in x..x + w {
                self.driver.set_pixel_unchecked(column, row, u8::from(color.is_on()));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_write_is_a_sync_byte_and_two_nibbles() {
        assert_eq!(frame(false, 0x36), [0xF8, 0x30, 0x60]);
        assert_eq!(frame(true, 0xA5), [0xFA, 0xA0, 0x50]);
    }

    #[test]
    fn the_gap_makes_up_the_execution_time_whatever_the_clock() {
        // 656.25 kHz (the F407's 42 MHz / 64): a frame lasts 36.6 µs, the gap 37 µs.
        assert_eq!(write_gap_us(656_250), 37);
        for spi_hz in [100_000, 328_125, 600_000, 656_250, 1_000_000, 2_000_000] {
            let frame_ns = u64::from(ST7920_FRAME_BITS) * 1_000_000_000 / u64::from(spi_hz);
            // The delay may end a microsecond early.
            let period_ns = frame_ns + u64::from(write_gap_us(spi_hz) - 1) * 1_000;
            assert!(period_ns >= u64::from(ST7920_WRITE_US) * 1_000, "{spi_hz} Hz: {period_ns} ns");
        }
    }
}

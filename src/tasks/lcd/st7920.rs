//! The ST7920 LCD controller in serial mode, driven directly: the 122x32 picture drawn into it,
//! the controller's start-up, and the picture sent a row at a time, every write paced to the
//! controller's time.
//!
//! Serial mode (PSB low; ST7920 datasheet V4.0, "Serial interface") is write only: each write is
//! a frame of three bytes, a sync byte (five 1s, RW = 0, RS: 0xF8 an instruction, 0xFA data)
//! and the value's high and low nibbles each followed by four 0s. There is no busy flag to
//! read, and "ST7920 has no internal instruction buffer area": the next write must wait until
//! the last one has executed, [`ST7920_WRITE_US`] (72 µs) for a write and [`ST7920_CLEAR_US`]
//! (1.6 ms) for a clear (the instruction table's execution times, at f_OSC = 540 kHz). Sent back
//! to back at 656 kHz a frame takes 37 µs, so the writes are paced: after each, a wait that
//! brings the time from its last bit to the next write's last bit to at least 72 µs (the
//! controller takes a write as its 24th bit arrives, as the parallel bus's enable strobe).
//!
//! The picture is the upper half of graphics RAM, its first 122 columns (128 x 32, 16 bytes a
//! row); a row is sent as its vertical and horizontal addresses (extended instruction set) and
//! its 16 bytes, 18 writes, ~1.3 ms. The 32 rows (~43 ms) go out one per call of
//! [`St7920Lcd::show_slice`], so the LCD task lets the other tasks run between rows.

use embedded_graphics::Pixel;
use embedded_graphics::draw_target::DrawTarget;
use embedded_graphics::geometry::{OriginDimensions, Size};
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_hal::delay::DelayNs;
use embedded_hal::digital::OutputPin;
use embedded_hal::spi::SpiDevice;

use super::Lcd;
use crate::ui::layout::{SCREEN_HEIGHT_PX, SCREEN_WIDTH_PX};

/// The shortest time from one write to the next, µs: an instruction's or a data write's
/// execution time (the datasheet's instruction table, f_OSC = 540 kHz).
pub const ST7920_WRITE_US: u32 = 72;
/// The same after Display Clear.
pub const ST7920_CLEAR_US: u32 = 1_600;
/// Clocks of one write's frame: the sync byte and the two nibble bytes.
pub const ST7920_FRAME_BITS: u32 = 24;
/// Rows of the picture sent by one call of [`St7920Lcd::show_slice`]: 18 writes, ~1.3 ms.
pub const ST7920_ROWS_PER_SLICE: usize = 1;

/// Sync bytes: an instruction (RS = 0) or data (RS = 1), written (RW = 0).
const SYNC_INSTRUCTION: u8 = 0xF8;
const SYNC_DATA: u8 = 0xFA;
/// Instructions used (datasheet, instruction tables). Basic set: function set with RE = 0
/// (DL is the parallel bus's width, unused in serial mode); display on, cursor and blink off;
/// display clear; entry mode: the address counts up, nothing shifts. Extended set: function set
/// with RE = 1 (RE is changed in an instruction of its own, after DL), then with the graphics
/// display on; set graphics RAM address (vertical, then horizontal in 16-bit words).
const FUNCTION_SET_BASIC: u8 = 0x30;
const DISPLAY_ON: u8 = 0x0C;
const DISPLAY_CLEAR: u8 = 0x01;
const ENTRY_MODE_INCREMENT: u8 = 0x06;
const FUNCTION_SET_EXTENDED: u8 = 0x34;
const GRAPHICS_ON: u8 = 0x36;
const SET_GRAPHICS_ADDRESS: u8 = 0x80;

/// Picture rows, and bytes in each (8 pixels a byte, the leftmost in bit 7).
const ROWS: usize = SCREEN_HEIGHT_PX as usize;
const ROW_BYTES: usize = (SCREEN_WIDTH_PX as usize).div_ceil(16) * 2;
const _: () = assert!(ROWS <= 32 && ROW_BYTES <= 16, "the upper half of graphics RAM");

/// How long the reset line is held low, and how long the controller then takes to start (the
/// datasheet's initial flow waits more than 40 ms after power-on before the first instruction).
const RESET_LOW_US: u32 = 40_000;
const RESET_START_US: u32 = 40_000;
/// The initial flow's waits after the first function set and after display on (more than
/// 100 µs), and after the clear (more than 10 ms, the flowchart's figure, above the 1.6 ms of
/// the instruction table).
const FIRST_FUNCTION_SET_US: u32 = 100;
const DISPLAY_ON_US: u32 = 100;
const CLEAR_WAIT_US: u32 = 10_000;

/// Waits this long or longer are the LCD task's (it yields to the other tasks meanwhile); shorter
/// ones are the driver's own. The yielded ones add up to whole milliseconds (90 ms), so the
/// pictures, timed in milliseconds, start on one.
const START_YIELD_MIN_US: u32 = 1_000;

/// What a step of the start-up does.
#[derive(Clone, Copy)]
enum Start {
    ResetLow,
    ResetHigh,
    Instruction(u8),
}

/// The start-up (the datasheet's initial flow, then graphics mode), each step with how long to
/// wait after it before the next, µs.
const START: [(Start, u32); 9] = [
    (Start::ResetLow, RESET_LOW_US),
    (Start::ResetHigh, RESET_START_US),
    (Start::Instruction(FUNCTION_SET_BASIC), FIRST_FUNCTION_SET_US),
    (Start::Instruction(FUNCTION_SET_BASIC), 0),
    (Start::Instruction(DISPLAY_ON), DISPLAY_ON_US),
    (Start::Instruction(DISPLAY_CLEAR), CLEAR_WAIT_US),
    (Start::Instruction(ENTRY_MODE_INCREMENT), 0),
    (Start::Instruction(FUNCTION_SET_EXTENDED), 0),
    (Start::Instruction(GRAPHICS_ON), 0),
];
const _: () = {
    assert!(CLEAR_WAIT_US >= ST7920_CLEAR_US);
    let mut yielded_us = 0;
    let mut i = 0;
    while i < START.len() {
        if START[i].1 >= START_YIELD_MIN_US {
            yielded_us += START[i].1;
        }
        i += 1;
    }
    assert!(yielded_us % 1_000 == 0);
};

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

/// An ST7920 in serial mode on `spi` (its clock at most ~1 MHz: datasheet, serial timing), with
/// its reset line and its chip select (the RS pin, active high), showing the 122x32 picture
/// drawn into it.
pub struct St7920Lcd<SPI: SpiDevice, PIN: OutputPin, D: DelayNs> {
    spi: SPI,
    reset: PIN,
    cs: PIN,
    delay: D,
    gap_us: u32,
    pixels: [[u8; ROW_BYTES]; ROWS],
    /// The start-up step to take next.
    start_step: usize,
    /// The row the next slice sends.
    next_row: usize,
    /// A write of the start-up or of the picture being sent failed.
    failed: bool,
}

impl<SPI: SpiDevice, PIN: OutputPin, D: DelayNs> St7920Lcd<SPI, PIN, D> {
    /// The controller on `spi`, clocked at `spi_hz` (the clock the link really runs at: the
    /// writes are paced from it), waiting with `delay`.
    pub fn new(spi: SPI, reset: PIN, cs: PIN, delay: D, spi_hz: u32) -> Self {
        St7920Lcd {
            spi,
            reset,
            cs,
            delay,
            gap_us: write_gap_us(spi_hz),
            pixels: [[0; ROW_BYTES]; ROWS],
            start_step: 0,
            next_row: 0,
            failed: false,
        }
    }

    /// Writes `value` as an instruction or data, then waits out its execution.
    fn write(&mut self, data: bool, value: u8) {
        if self.spi.write(&frame(data, value)).is_err() {
            self.failed = true;
        }
        self.delay.delay_us(self.gap_us);
    }
}

impl<SPI: SpiDevice, PIN: OutputPin, D: DelayNs> Lcd for St7920Lcd<SPI, PIN, D> {
    fn start(&mut self) -> Option<u32> {
        while let Some(&(step, wait_us)) = START.get(self.start_step) {
            match step {
                Start::ResetLow => {
                    let _ = self.cs.set_low();
                    let _ = self.reset.set_low();
                }
                Start::ResetHigh => {
                    let _ = self.reset.set_high();
                }
                Start::Instruction(instruction) => {
                    let _ = self.cs.set_high();
                    self.write(false, instruction);
                }
            }
            self.start_step += 1;
            if self.start_step == START.len() {
                let _ = self.cs.set_low();
                if core::mem::take(&mut self.failed) {
                    warn!("LCD start-up failed");
                }
            }
            if wait_us >= START_YIELD_MIN_US {
                return Some(wait_us);
            }
            self.delay.delay_us(wait_us);
        }
        None
    }

    fn show_slice(&mut self) -> bool {
        if self.next_row == 0 {
            let _ = self.cs.set_high();
        }
        let rows = self.next_row..(self.next_row + ST7920_ROWS_PER_SLICE).min(ROWS);
        for row in rows.clone() {
            // Vertical address: the row; horizontal: its first 16-bit word.
            self.write(false, SET_GRAPHICS_ADDRESS | row as u8);
            self.write(false, SET_GRAPHICS_ADDRESS);
            for i in 0..ROW_BYTES {
                self.write(true, self.pixels[row][i]);
            }
        }
        self.next_row = rows.end;
        if self.next_row < ROWS {
            return true;
        }
        self.next_row = 0;
        let _ = self.cs.set_low();
        if core::mem::take(&mut self.failed) {
            warn!("LCD flush failed");
        }
        false
    }
}

impl<SPI: SpiDevice, PIN: OutputPin, D: DelayNs> OriginDimensions for St7920Lcd<SPI, PIN, D> {
    fn size(&self) -> Size {
        Size::new(SCREEN_WIDTH_PX, SCREEN_HEIGHT_PX)
    }
}

impl<SPI: SpiDevice, PIN: OutputPin, D: DelayNs> DrawTarget for St7920Lcd<SPI, PIN, D> {
    type Color = BinaryColor;
    type Error = core::convert::Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<BinaryColor>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
        for Pixel(at, color) in pixels {
            let (Ok(x), Ok(y)) = (u32::try_from(at.x), u32::try_from(at.y)) else { continue };
            if x >= SCREEN_WIDTH_PX || y >= SCREEN_HEIGHT_PX {
                continue;
            }
            let byte = &mut self.pixels[y as usize][x as usize / 8];
            let bit = 0x80 >> (x % 8);
            match color {
                BinaryColor::On => *byte |= bit,
                BinaryColor::Off => *byte &= !bit,
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
        assert_eq!(frame(false, GRAPHICS_ON), [0xF8, 0x30, 0x60]);
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

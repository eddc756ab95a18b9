//! A model of the ST7920 controller in serial mode, fed by the firmware's own driver.
//!
//! It decodes the 3-byte serial frames (0xF8 command / 0xFA data, then the high and low nibbles)
//! and the extended-instruction graphics addressing into a graphics RAM, so the simulator shows
//! exactly what the driver sent, and the visible 122x32 area is cut from that RAM the way the
//! glass shows it.
//!
//! It also keeps the link's time: each byte takes 8 clocks of the SPI link, and the driver's
//! waits ([`LcdDelay`]) move the link's clock on, as the processor spins through them on the
//! board, while virtual time stands still (the LCD task is the lowest priority: on the board
//! everything else pre-empts it). A write whose last bit arrives sooner after the previous
//! write's than that one takes to execute (72 µs, 1.6 ms after a clear: `ST7920_WRITE_US`,
//! `ST7920_CLEAR_US`) is counted as too soon: the controller, which has no busy flag in serial
//! mode and buffers nothing, would have lost or garbled it.

use std::cell::RefCell;
use std::rc::Rc;
use std::vec::Vec;

use embedded_hal::spi::{ErrorType, Operation, SpiDevice};

use crate::panel::layout::{SCREEN_HEIGHT_PX, SCREEN_WIDTH_PX};
use crate::tasks::lcd::st7920::{ST7920_CLEAR_US, ST7920_WRITE_US};

/// The simulated board's LCD link clock: the F407 board's (SPI2 on APB1's 42 MHz, divided by 64).
pub const SIM_LCD_SPI_HZ: u32 = 656_250;

const GDRAM_ROWS: usize = 32;
/// Display Clear, the one instruction that executes longer than the others.
const DISPLAY_CLEAR: u8 = 0x01;
const GDRAM_ROW_BYTES: usize = 32;

/// One picture of the visible area, a row of `SCREEN_WIDTH_PX` booleans per line.
#[derive(Clone, PartialEq, Eq, Debug)]
pub struct Frame {
    pub pixels: [[bool; SCREEN_WIDTH_PX as usize]; SCREEN_HEIGHT_PX as usize],
}

impl Frame {
    pub fn lit(&self) -> usize {
        self.pixels.iter().flatten().filter(|p| **p).count()
    }
}

/// The controller's state as far as graphics mode needs it.
#[derive(Debug)]
pub struct St7920Model {
    /// What the glass showed each time chip select fell after new pixels were written, with the
    /// virtual time.
    pub frames: Vec<(u64, Frame)>,
    /// Pixels were written since the last frame.
    written: bool,
    gdram: [[u8; GDRAM_ROW_BYTES]; GDRAM_ROWS],
    /// Bytes of the frame in progress.
    frame: [u8; 3],
    frame_len: usize,
    extended: bool,
    /// The next address command sets the vertical address (else the horizontal one).
    expect_vertical: bool,
    row: usize,
    /// Byte position in the row (two per 16-bit word).
    col_byte: usize,
    /// Frames that did not decode (bad sync byte or nibble bits): a wiring or driver fault.
    pub bad_frames: u32,
    /// The link's clock.
    spi_hz: u32,
    /// When the link is next free, ns of virtual time: the end of the last byte sent or of the
    /// driver's last wait, whichever is later.
    link_free_ns: u64,
    /// When the last write's last bit arrived, and how long it executes, ns.
    last_write: Option<(u64, u64)>,
    /// Writes decoded.
    pub writes: u32,
    /// Writes that came before the previous one had executed.
    pub writes_too_soon: u32,
    /// The shortest time from one write's last bit to the next's, ns.
    pub shortest_write_gap_ns: Option<u64>,
}

impl Default for St7920Model {
    fn default() -> Self {
        St7920Model {
            frames: Vec::new(),
            written: false,
            gdram: [[0; GDRAM_ROW_BYTES]; GDRAM_ROWS],
            frame: [0; 3],
            frame_len: 0,
            extended: false,
            expect_vertical: true,
            row: 0,
            col_byte: 0,
            bad_frames: 0,
            spi_hz: SIM_LCD_SPI_HZ,
            link_free_ns: 0,
            last_write: None,
            writes: 0,
            writes_too_soon: 0,
            shortest_write_gap_ns: None,
        }
    }
}

impl St7920Model {
    /// When the link is next free, ns of virtual time.
    pub fn link_free_ns(&self) -> u64 {
        self.link_free_ns.max(now_ns())
    }

    /// The link is busy for `ns` more (a byte, or the driver's wait).
    fn link_busy(&mut self, ns: u64) {
        self.link_free_ns = self.link_free_ns() + ns;
    }

    /// A write decoded, its last bit just arrived: on time or too soon after the previous one.
    fn timed_write(&mut self, executes_ns: u64) {
        let at = self.link_free_ns;
        if let Some((last, last_executes_ns)) = self.last_write {
            let gap = at - last;
            self.shortest_write_gap_ns = Some(self.shortest_write_gap_ns.map_or(gap, |g| g.min(gap)));
            if gap < last_executes_ns {
                self.writes_too_soon += 1;
            }
        }
        self.last_write = Some((at, executes_ns));
        self.writes += 1;
    }

    fn byte(&mut self, b: u8) {
        self.link_busy(8 * 1_000_000_000 / u64::from(self.spi_hz));
        if self.frame_len == 0 && b & 0xF8 != 0xF8 {
            self.bad_frames += 1;
            return;
        }
        self.frame[self.frame_len] = b;
        self.frame_len += 1;
        if self.frame_len < 3 {
            return;
        }
        self.frame_len = 0;
        let [sync, hi, lo] = self.frame;
        if hi & 0x0F != 0 || lo & 0x0F != 0 || sync & 0x04 != 0 {
            self.bad_frames += 1;
            return;
        }
        let value = hi | (lo >> 4);
        let is_data = sync & 0x02 != 0;
        let executes_us = if !is_data && value == DISPLAY_CLEAR { ST7920_CLEAR_US } else { ST7920_WRITE_US };
        self.timed_write(u64::from(executes_us) * 1_000);
        if is_data {
            self.data(value);
        } else {
            self.command(value);
        }
    }

    fn command(&mut self, c: u8) {
        if c & 0xE0 == 0x20 {
            // Function set: RE (bit 2) selects the extended instruction set.
            self.extended = c & 0x04 != 0;
            self.expect_vertical = true;
        } else if c & 0x80 != 0 && self.extended {
            if self.expect_vertical {
                self.row = (c & 0x3F) as usize % GDRAM_ROWS;
            } else {
                self.col_byte = ((c & 0x0F) as usize * 2) % GDRAM_ROW_BYTES;
            }
            self.expect_vertical = !self.expect_vertical;
        }
    }

    fn data(&mut self, d: u8) {
        self.written = true;
        self.gdram[self.row][self.col_byte] = d;
        self.col_byte = (self.col_byte + 1) % GDRAM_ROW_BYTES;
        self.expect_vertical = true;
    }

    /// What the glass shows of the top-left 122x32 area (the upper half of graphics RAM).
    pub fn visible(&self) -> Frame {
        let mut f = Frame { pixels: [[false; SCREEN_WIDTH_PX as usize]; SCREEN_HEIGHT_PX as usize] };
        for (y, line) in f.pixels.iter_mut().enumerate() {
            for (x, px) in line.iter_mut().enumerate() {
                *px = self.gdram[y][x / 8] & (0x80 >> (x % 8)) != 0;
            }
        }
        f
    }
}

/// The controller's chip select (RS pin, active high) and reset lines.
pub enum LcdPin {
    /// Chip select: when it falls after pixels were written, the glass shows a new frame.
    ChipSelect(Rc<RefCell<St7920Model>>),
    Reset,
}

impl embedded_hal::digital::ErrorType for LcdPin {
    type Error = core::convert::Infallible;
}

impl embedded_hal::digital::OutputPin for LcdPin {
    fn set_low(&mut self) -> Result<(), Self::Error> {
        if let LcdPin::ChipSelect(model) = self {
            let mut m = model.borrow_mut();
            if m.written {
                m.written = false;
                let frame = m.visible();
                m.frames.push((crate::sim::clock::now_ticks(), frame));
            }
        }
        Ok(())
    }

    fn set_high(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// Virtual time, ns.
fn now_ns() -> u64 {
    crate::sim::clock::now_ticks() * 1_000
}

/// The SPI link to the modelled controller, clocked at [`SIM_LCD_SPI_HZ`] unless made with
/// [`SimSpi::clocked`].
#[derive(Clone, Default)]
pub struct SimSpi {
    pub model: Rc<RefCell<St7920Model>>,
}

impl SimSpi {
    /// A link clocked at `spi_hz`.
    pub fn clocked(spi_hz: u32) -> Self {
        SimSpi { model: Rc::new(RefCell::new(St7920Model { spi_hz, ..St7920Model::default() })) }
    }

    /// The driver's waits between writes.
    pub fn delay(&self) -> LcdDelay {
        LcdDelay(self.model.clone())
    }
}

/// The LCD driver's waits: they move the link's clock on (the processor spins through them on
/// the board), not virtual time.
pub struct LcdDelay(Rc<RefCell<St7920Model>>);

impl embedded_hal::delay::DelayNs for LcdDelay {
    fn delay_ns(&mut self, ns: u32) {
        self.0.borrow_mut().link_busy(u64::from(ns));
    }
}

impl ErrorType for SimSpi {
    type Error = core::convert::Infallible;
}

impl SpiDevice for SimSpi {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), Self::Error> {
        let mut model = self.model.borrow_mut();
        for op in operations.iter() {
            if let Operation::Write(bytes) = op {
                for &b in bytes.iter() {
                    model.byte(b);
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::clock;
    use crate::tasks::lcd::Lcd;
    use crate::tasks::lcd::St7920Lcd;
    use crate::tasks::lcd::st7920::frame;
    use embedded_graphics::pixelcolor::BinaryColor;
    use embedded_graphics::prelude::*;
    use embedded_graphics::primitives::{PrimitiveStyle, Rectangle};

    type SimLcd = St7920Lcd<SimSpi, LcdPin, LcdDelay>;

    /// The driver on `spi`, told the link runs at `spi_hz`, started as the LCD task starts it
    /// (virtual time passing through the start-up's waits).
    fn started(spi: &SimSpi, spi_hz: u32) -> SimLcd {
        clock::reset();
        let cs = LcdPin::ChipSelect(spi.model.clone());
        let mut lcd = St7920Lcd::new(spi.clone(), LcdPin::Reset, cs, spi.delay(), spi_hz);
        while let Some(wait_us) = lcd.start() {
            clock::jump_to(clock::now_ticks() + u64::from(wait_us));
        }
        lcd
    }

    #[test]
    fn every_write_is_paced_and_the_picture_lands_on_the_visible_pixels() {
        let spi = SimSpi::default();
        let mut lcd = started(&spi, SIM_LCD_SPI_HZ);
        Rectangle::new(Point::new(100, 3), Size::new(22, 2))
            .into_styled(PrimitiveStyle::with_fill(BinaryColor::On))
            .draw(&mut lcd)
            .unwrap();
        // Virtual time stands still while the slices go out, as when nothing else is due.
        let begun_ns = spi.model.borrow().link_free_ns();
        let mut slices = 0;
        loop {
            let before_ns = spi.model.borrow().link_free_ns();
            let more = lcd.show_slice();
            slices += 1;
            let slice_ns = spi.model.borrow().link_free_ns() - before_ns;
            assert!(slice_ns <= 1_500_000, "a slice takes {slice_ns} ns");
            if !more {
                break;
            }
        }
        let picture_ns = spi.model.borrow().link_free_ns() - begun_ns;
        let m = spi.model.borrow();
        assert_eq!(slices, 32, "a row a slice");
        assert_eq!(m.bad_frames, 0);
        // 6 start-up instructions, then 32 rows of two addresses (sent twice by the st7920
        // crate) and 16 bytes.
        assert_eq!(m.writes, 6 + 32 * 20);
        assert_eq!(m.writes_too_soon, 0);
        assert!(
            m.shortest_write_gap_ns.is_some_and(|g| (72_000..74_000).contains(&g)),
            "{:?}",
            m.shortest_write_gap_ns
        );
        assert!((46_000_000..47_500_000).contains(&picture_ns), "the picture took {picture_ns} ns");
        assert_eq!(m.frames.len(), 1, "one frame when chip select fell after the picture");
        let f = m.visible();
        assert_eq!(m.frames[0].1, f);
        assert_eq!(f.lit(), 44);
        assert!(f.pixels[3][100] && f.pixels[4][121] && !f.pixels[5][100] && !f.pixels[3][99]);
    }

    #[test]
    fn writes_sooner_than_the_controller_executes_them_are_counted() {
        use embedded_hal::delay::DelayNs;
        clock::reset();
        let mut spi = SimSpi::default();
        let mut wait = spi.delay();
        // Three writes back to back, 36.6 µs apart: the last two too soon.
        for value in [0x30, 0x30, 0x0C] {
            spi.write(&frame(false, value)).unwrap();
        }
        assert_eq!(spi.model.borrow().writes_too_soon, 2);
        // A clear after a wait, on time; the next write 1 ms after it, too soon (1.6 ms).
        wait.delay_us(72);
        spi.write(&frame(false, DISPLAY_CLEAR)).unwrap();
        wait.delay_us(1_000);
        spi.write(&frame(false, 0x06)).unwrap();
        assert_eq!(spi.model.borrow().writes_too_soon, 3);
        // Virtual time passing counts as well: 72 µs later, on time.
        clock::jump_to(spi.model.borrow().link_free_ns() / 1_000 + 72);
        spi.write(&frame(false, 0x34)).unwrap();
        assert_eq!(spi.model.borrow().writes_too_soon, 3);
        assert_eq!(spi.model.borrow().writes, 6);
    }

    #[test]
    fn a_driver_told_a_slower_link_than_the_real_one_paces_too_little() {
        // Told 600 kHz on a link running at 656 kHz: each frame is 3.4 µs shorter than the
        // driver reckons, and the writes come 69.6 µs apart.
        let spi = SimSpi::default();
        let mut lcd = started(&spi, 600_000);
        while lcd.show_slice() {}
        let m = spi.model.borrow();
        assert!(m.writes_too_soon > 500, "{} of {}", m.writes_too_soon, m.writes);
        assert!(m.shortest_write_gap_ns.is_some_and(|g| g < 70_000));
    }
}

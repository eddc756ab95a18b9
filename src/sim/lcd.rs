//! A model of the ST7920 controller in serial mode, fed by the real `st7920` driver.
//!
//! It decodes the 3-byte serial frames (0xF8 command / 0xFA data, then the high and low nibbles)
//! and the extended-instruction graphics addressing into a graphics RAM, so the simulator shows
//! exactly what the driver sent, and the visible 122x32 area is cut from that RAM the way the
//! glass shows it.

use std::cell::RefCell;
use std::rc::Rc;
use std::vec::Vec;

use embedded_hal::spi::{ErrorType, Operation, SpiDevice};

use crate::ui::layout::{SCREEN_HEIGHT_PX, SCREEN_WIDTH_PX};

const GDRAM_ROWS: usize = 32;
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
        }
    }
}

impl St7920Model {
    fn byte(&mut self, b: u8) {
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
        if sync & 0x02 == 0 {
            self.command(value);
        } else {
            self.data(value);
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

/// The SPI link to the modelled controller.
#[derive(Clone, Default)]
pub struct SimSpi {
    pub model: Rc<RefCell<St7920Model>>,
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
    use crate::sim::clock::FreeDelay;
    use embedded_graphics::pixelcolor::BinaryColor;
    use embedded_graphics::prelude::*;
    use embedded_graphics::primitives::{PrimitiveStyle, Rectangle};

    #[test]
    fn the_driver_region_flush_lands_on_the_visible_pixels() {
        let spi = SimSpi::default();
        let cs = LcdPin::ChipSelect(spi.model.clone());
        let mut lcd = st7920::ST7920::new(spi.clone(), LcdPin::Reset, Some(cs), false);
        lcd.init(&mut FreeDelay).unwrap();
        Rectangle::new(Point::new(100, 3), Size::new(22, 2))
            .into_styled(PrimitiveStyle::with_fill(BinaryColor::On))
            .draw(&mut lcd)
            .unwrap();
        lcd.flush_region(0, 0, SCREEN_WIDTH_PX as u8, SCREEN_HEIGHT_PX as u8, &mut FreeDelay).unwrap();
        let f = spi.model.borrow().visible();
        assert_eq!(spi.model.borrow().bad_frames, 0);
        assert_eq!(spi.model.borrow().frames.len(), 1, "one frame when chip select fell after the flush");
        assert_eq!(spi.model.borrow().frames[0].1, f);
        assert_eq!(f.lit(), 44);
        assert!(f.pixels[3][100] && f.pixels[4][121] && !f.pixels[5][100] && !f.pixels[3][99]);
    }
}

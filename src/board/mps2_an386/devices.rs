//! What the model has in place of the F407 board's other devices: output pins that drive
//! nothing, a keypad with no key pressed, a pen servo signal that goes nowhere, an LCD bus that
//! takes the bytes in the time the F407's SPI would, and the flash store's sectors in the
//! model's code RAM.

use core::convert::Infallible;

use embassy_time::{Duration, block_for};
use embedded_hal::digital::{ErrorType, InputPin, OutputPin};
use embedded_hal::pwm::SetDutyCycle;
use embedded_hal::spi::{Operation, SpiDevice};
use embedded_storage::nor_flash::{ErrorType as FlashErrorType, NorFlash, NorFlashErrorKind, ReadNorFlash};
use servoplot::machine_io::pen::PEN_SERVO_PERIOD_US;
use servoplot::store::{STORE_FLASH_RANGE, STORE_SECTOR_BYTES};

/// A pin of the board the model has nothing behind: as an output it drives nothing; as an
/// input it reads high, as a keypad row with its pull-up and no key pressed does.
pub struct NoPin;

impl ErrorType for NoPin {
    type Error = Infallible;
}

impl OutputPin for NoPin {
    fn set_low(&mut self) -> Result<(), Infallible> {
        Ok(())
    }

    fn set_high(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

impl InputPin for NoPin {
    fn is_high(&mut self) -> Result<bool, Infallible> {
        Ok(true)
    }

    fn is_low(&mut self) -> Result<bool, Infallible> {
        Ok(false)
    }
}

/// The pen servo's signal: taken and dropped.
pub struct NoPwm;

impl embedded_hal::pwm::ErrorType for NoPwm {
    type Error = Infallible;
}

impl SetDutyCycle for NoPwm {
    fn max_duty_cycle(&self) -> u16 {
        PEN_SERVO_PERIOD_US as u16
    }

    fn set_duty_cycle(&mut self, _duty: u16) -> Result<(), Infallible> {
        Ok(())
    }
}

/// The LCD's serial clock on the F407 board (its SPI2: APB1's 42 MHz / 64). The LCD driver
/// paces its writes from it.
pub const LCD_SPI_HZ: u32 = 656_250;

/// The LCD's SPI device: each transfer takes the time the F407's blocking SPI takes to clock
/// its bits out, so the LCD task's polls cost the model what they cost the board.
pub struct LcdBus;

impl embedded_hal::spi::ErrorType for LcdBus {
    type Error = Infallible;
}

impl SpiDevice for LcdBus {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), Infallible> {
        for op in operations {
            let bytes = match op {
                Operation::Write(b) => b.len(),
                Operation::Read(b) => b.len(),
                Operation::Transfer(r, w) => r.len().max(w.len()),
                Operation::TransferInPlace(b) => b.len(),
                Operation::DelayNs(ns) => {
                    block_for(Duration::from_micros(u64::from(ns.div_ceil(1_000))));
                    0
                }
            };
            block_for(Duration::from_micros((bytes as u64 * 8 * 1_000_000).div_ceil(u64::from(LCD_SPI_HZ))));
        }
        Ok(())
    }
}

/// The flash store's two sectors, at the offsets they have in the F407's flash (see
/// `servoplot::store::STORE_FLASH_RANGE`), in the model's code RAM beyond the image. QEMU
/// starts that RAM zeroed where erased flash reads all ones, so each byte is kept inverted: RAM
/// as QEMU leaves it reads as erased flash, an erase zeroes it, and programming can only turn
/// ones into zeros, as on flash.
pub struct ModelFlash;

/// The model's flash, as the F407's: everything below the store's end.
const FLASH_BYTES: u32 = STORE_FLASH_RANGE.end;
/// The F407 programs 32-bit words (at x32 parallelism).
const WRITE_BYTES: usize = 4;

impl ModelFlash {
    /// The RAM byte behind flash offset `offset`: only the store's sectors have any.
    fn cell(offset: u32) -> Option<*mut u8> {
        STORE_FLASH_RANGE.contains(&offset).then_some(offset as usize as *mut u8)
    }
}

impl FlashErrorType for ModelFlash {
    type Error = NorFlashErrorKind;
}

impl ReadNorFlash for ModelFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        for (k, byte) in bytes.iter_mut().enumerate() {
            let cell = Self::cell(offset + k as u32).ok_or(NorFlashErrorKind::OutOfBounds)?;
            // SAFETY: `cell` lies in the store's range of code RAM, which nothing else uses
            // (the image ends below it, see memory.x).
            *byte = !unsafe { core::ptr::read_volatile(cell) };
        }
        Ok(())
    }

    fn capacity(&self) -> usize {
        FLASH_BYTES as usize
    }
}

impl NorFlash for ModelFlash {
    const WRITE_SIZE: usize = WRITE_BYTES;
    const ERASE_SIZE: usize = STORE_SECTOR_BYTES;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        if !(from as usize).is_multiple_of(STORE_SECTOR_BYTES) || !(to as usize).is_multiple_of(STORE_SECTOR_BYTES) {
            return Err(NorFlashErrorKind::NotAligned);
        }
        let (Some(start), true) = (Self::cell(from), from <= to && to <= STORE_FLASH_RANGE.end) else {
            return Err(NorFlashErrorKind::OutOfBounds);
        };
        // SAFETY: `from..to` lies in the store's range of code RAM (as in `read`). At once, as
        // flash erases a sector: on the F407 an erase stalls the core for up to 2 s (the store
        // saves only at rest), here it takes no time of the firmware's.
        unsafe { core::ptr::write_bytes(start, 0, (to - from) as usize) };
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        if !(offset as usize).is_multiple_of(WRITE_BYTES) || !bytes.len().is_multiple_of(WRITE_BYTES) {
            return Err(NorFlashErrorKind::NotAligned);
        }
        for (k, &byte) in bytes.iter().enumerate() {
            let cell = Self::cell(offset + k as u32).ok_or(NorFlashErrorKind::OutOfBounds)?;
            // SAFETY: as in `read`. Programming clears bits: stored inverted, it sets them.
            unsafe { core::ptr::write_volatile(cell, core::ptr::read_volatile(cell) | !byte) };
        }
        Ok(())
    }
}

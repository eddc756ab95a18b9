//! The flash store's two sectors (10 and 11) as NOR flash, erased and programmed 32 bits at a
//! time.
//!
//! embassy-stm32 0.6's F4 driver erases at the reset parallelism (FLASH_CR.PSIZE = 0, x8): a
//! 128 KB sector then takes up to 4 s. RM0090 §3.6.2 ("Program/erase parallelism") sets x32 for
//! a 2.7-3.6 V supply (the Discovery board runs at 3 V), and DS8626's "Flash memory programming"
//! table gives a 128 KB erase at x32 2 s at most (`servoplot::store::STORE_SECTOR_ERASE_MAX_MS`).
//! So the store gets this driver: the sequences of RM0090 §3.6.3 (sector erase) and §3.6.4
//! (programming) through the registers, with PSIZE = x32 for both, on the store's sectors only.
//!
//! Every fetch from flash waits while an erase or a program runs (one bank): the processor, the
//! pulse interrupt included, stands still meanwhile, which is why the store saves only at rest.

use core::ptr;

use embassy_stm32::Peri;
use embassy_stm32::pac;
use embassy_stm32::pac::flash::vals::Psize;
use embassy_stm32::peripherals::FLASH;
use embedded_storage::nor_flash::{ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash};
use servoplot::store::{STORE_FLASH_RANGE, STORE_SECTOR_BYTES};

/// Where the flash is mapped: the store's offsets count from here (RM0090 §3.3, the flash
/// module's organisation).
const FLASH_BASE: u32 = 0x0800_0000;
/// The store's first sector: RM0090 §3.3 puts sector 10 at 0x080C_0000 and sector 11 at
/// 0x080E_0000, 128 KB each, the last two of the 1 MB flash.
const STORE_FIRST_SECTOR: u8 = 10;
const _: () = assert!(STORE_FLASH_RANGE.start == 0x000C_0000 && STORE_SECTOR_BYTES == 128 * 1024);
/// FLASH_KEYR's two keys, written in turn, unlock FLASH_CR (RM0090 §3.6.1, §3.9.2).
const FLASH_KEY1: u32 = 0x4567_0123;
const FLASH_KEY2: u32 = 0xCDEF_89AB;
/// x32: erase and program 32 bits at a time, for a 2.7-3.6 V supply (RM0090 §3.6.2).
const PARALLELISM: Psize = Psize::PSIZE32;
/// What one program writes at x32.
const WORD_BYTES: usize = 4;

/// Why the flash refused an operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StoreFlashError {
    /// Outside the store's sectors.
    OutOfBounds,
    /// Not on a word (a write) or a sector (an erase) boundary.
    NotAligned,
    /// The flash interface set an error flag in FLASH_SR (RM0090 §3.9.4): a protected sector
    /// (WRPERR), a wrong programming sequence (PGSERR), parallelism (PGPERR) or alignment
    /// (PGAERR).
    Refused,
}

impl NorFlashError for StoreFlashError {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            StoreFlashError::OutOfBounds => NorFlashErrorKind::OutOfBounds,
            StoreFlashError::NotAligned => NorFlashErrorKind::NotAligned,
            StoreFlashError::Refused => NorFlashErrorKind::Other,
        }
    }
}

/// The flash store's sectors. Offsets count from the start of flash, as
/// `servoplot::store::STORE_FLASH_RANGE` gives them; nothing outside that range is read,
/// written or erased.
pub struct StoreFlash {
    _flash: Peri<'static, FLASH>,
}

impl StoreFlash {
    pub fn new(flash: Peri<'static, FLASH>) -> Self {
        StoreFlash { _flash: flash }
    }
}

/// `len` bytes from `offset`, if they lie in the store's sectors.
fn in_store(offset: u32, len: usize) -> Result<(), StoreFlashError> {
    let end = offset.checked_add(len as u32).ok_or(StoreFlashError::OutOfBounds)?;
    if offset < STORE_FLASH_RANGE.start || end > STORE_FLASH_RANGE.end {
        return Err(StoreFlashError::OutOfBounds);
    }
    Ok(())
}

/// Runs `operations` with FLASH_CR unlocked (RM0090 §3.6.1: locked after reset, unlocked by
/// the two keys in turn), then locks it again (LOCK set, every other bit of FLASH_CR cleared:
/// PG, SER) and empties the data cache.
fn unlocked(operations: impl FnOnce() -> Result<(), StoreFlashError>) -> Result<(), StoreFlashError> {
    let flash = pac::FLASH;
    wait_not_busy();
    clear_errors();
    if flash.cr().read().lock() {
        flash.keyr().write_value(FLASH_KEY1);
        flash.keyr().write_value(FLASH_KEY2);
    }
    let done = operations();
    flash.cr().write(|w| w.set_lock(true));
    data_cache_reset();
    done
}

/// Waits for the erase or program just started to end (BSY clear) and says whether the flash
/// interface flagged an error; clears the flags (written 1, RM0090 §3.9.4).
fn finished() -> Result<(), StoreFlashError> {
    wait_not_busy();
    let sr = pac::FLASH.sr().read();
    let failed = sr.wrperr() || sr.pgserr() || sr.pgperr() || sr.pgaerr();
    clear_errors();
    if failed { Err(StoreFlashError::Refused) } else { Ok(()) }
}

/// Waits while an erase or a program runs (FLASH_SR.BSY). FLASH_CR must not be written
/// meanwhile: RM0090 says such a write stalls the bus until BSY clears.
fn wait_not_busy() {
    while pac::FLASH.sr().read().bsy() {}
}

fn clear_errors() {
    pac::FLASH.sr().write(|w| {
        w.set_eop(true);
        w.set_operr(true);
        w.set_wrperr(true);
        w.set_pgaerr(true);
        w.set_pgperr(true);
        w.set_pgserr(true);
    });
}

/// Empties the flash accelerator's data cache, which may hold lines of the store's sectors as
/// they read before the erase or program: the ART keeps no watch on the flash's contents
/// (RM0090 §3.5.2), and DCRST may be written only while the data cache is off (§3.9.1).
fn data_cache_reset() {
    let acr = pac::FLASH.acr();
    let on = acr.read().dcen();
    acr.modify(|w| w.set_dcen(false));
    acr.modify(|w| w.set_dcrst(true));
    acr.modify(|w| w.set_dcrst(false));
    acr.modify(|w| w.set_dcen(on));
}

impl ErrorType for StoreFlash {
    type Error = StoreFlashError;
}

impl ReadNorFlash for StoreFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), StoreFlashError> {
        in_store(offset, bytes.len())?;
        let from = (FLASH_BASE + offset) as *const u8;
        for (i, byte) in bytes.iter_mut().enumerate() {
            // SAFETY: in the store's sectors (checked above), which the flash maps at
            // FLASH_BASE + offset; read as volatile since erases and programs change them
            // behind the compiler's back.
            *byte = unsafe { ptr::read_volatile(from.add(i)) };
        }
        Ok(())
    }

    fn capacity(&self) -> usize {
        STORE_FLASH_RANGE.end as usize
    }
}

impl NorFlash for StoreFlash {
    const WRITE_SIZE: usize = WORD_BYTES;
    const ERASE_SIZE: usize = STORE_SECTOR_BYTES;

    /// Erases the sectors from `from` to `to`: RM0090 §3.6.3, SER and SNB with PSIZE = x32, then
    /// STRT, and wait for BSY to clear (up to 2 s a sector, the processor stalled throughout).
    fn erase(&mut self, from: u32, to: u32) -> Result<(), StoreFlashError> {
        if !(from as usize).is_multiple_of(STORE_SECTOR_BYTES) || !(to as usize).is_multiple_of(STORE_SECTOR_BYTES) {
            return Err(StoreFlashError::NotAligned);
        }
        in_store(from, to.saturating_sub(from) as usize)?;
        unlocked(|| {
            for start in (from..to).step_by(STORE_SECTOR_BYTES) {
                let sector =
                    STORE_FIRST_SECTOR + ((start - STORE_FLASH_RANGE.start) as usize / STORE_SECTOR_BYTES) as u8;
                pac::FLASH.cr().write(|w| {
                    w.set_psize(PARALLELISM);
                    w.set_ser(true);
                    w.set_snb(sector);
                });
                pac::FLASH.cr().modify(|w| w.set_strt(true));
                finished()?;
            }
            Ok(())
        })
    }

    /// Programs `bytes` at `offset` a word at a time: RM0090 §3.6.4, PG with PSIZE = x32, one
    /// 32-bit write to the flash's address, and wait for BSY to clear (up to 100 µs a word).
    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), StoreFlashError> {
        if !(offset as usize).is_multiple_of(WORD_BYTES) || !bytes.len().is_multiple_of(WORD_BYTES) {
            return Err(StoreFlashError::NotAligned);
        }
        in_store(offset, bytes.len())?;
        let to = (FLASH_BASE + offset) as *mut u32;
        unlocked(|| {
            pac::FLASH.cr().write(|w| {
                w.set_psize(PARALLELISM);
                w.set_pg(true);
            });
            for (i, word) in bytes.chunks_exact(WORD_BYTES).enumerate() {
                let value = u32::from_le_bytes([word[0], word[1], word[2], word[3]]);
                // SAFETY: a word-aligned address in the store's sectors (checked above), with
                // FLASH_CR set to program a word.
                unsafe { ptr::write_volatile(to.add(i), value) };
                finished()?;
            }
            Ok(())
        })
    }
}

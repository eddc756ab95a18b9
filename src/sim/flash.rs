//! The simulated board's flash: the flash store's sectors as NOR flash, kept in a file if given
//! one, with a power supply that can be cut part way through a write or an erase.
//!
//! As on the chip, erasing sets a whole sector's bytes to 0xFF and writing can only clear bits
//! (a written byte is the old one AND the new one). Each byte written or erased draws on the
//! power left ([`SimFlash::cut_power_after`]): the byte that finds none is not touched, the
//! operation fails, and so does every one after it, as if the board had lost power there.

use std::cell::{Cell, RefCell};
use std::format;
use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;
use std::rc::Rc;
use std::vec;
use std::vec::Vec;

use embedded_storage::nor_flash::{ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash};

use crate::store::{STORE_SECTOR_BYTES, STORE_SECTORS};

/// Bytes a write must cover, and align to: the F407's 32-bit program size.
pub const SIM_FLASH_WRITE_BYTES: usize = 4;

/// Why the simulated flash refused an operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SimFlashError {
    OutOfBounds,
    NotAligned,
    /// The power was cut.
    PowerCut,
    /// The file behind the flash could not be written.
    File,
}

impl NorFlashError for SimFlashError {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            SimFlashError::OutOfBounds => NorFlashErrorKind::OutOfBounds,
            SimFlashError::NotAligned => NorFlashErrorKind::NotAligned,
            SimFlashError::PowerCut | SimFlashError::File => NorFlashErrorKind::Other,
        }
    }
}

/// `SECTORS` erase sectors of `SECTOR_BYTES` each. Clones share the same flash.
#[derive(Clone)]
pub struct SimFlash<const SECTOR_BYTES: usize = STORE_SECTOR_BYTES> {
    bytes: Rc<RefCell<Vec<u8>>>,
    /// Bytes the power lasts for; `None`: it stays on.
    power_bytes: Rc<Cell<Option<u64>>>,
    /// Bytes written or erased so far, and erases so far per sector.
    changed_bytes: Rc<Cell<u64>>,
    erases: Rc<RefCell<Vec<u32>>>,
    /// When each write or erase came, virtual time.
    operations_at_us: Rc<RefCell<Vec<u64>>>,
    file: Option<Rc<RefCell<File>>>,
}

impl<const SECTOR_BYTES: usize> SimFlash<SECTOR_BYTES> {
    /// Erased flash of `sectors` sectors, as on a new chip.
    pub fn erased(sectors: usize) -> Self {
        Self::holding(vec![0xFF; sectors * SECTOR_BYTES])
    }

    /// Flash holding `bytes` (whole sectors).
    pub fn holding(bytes: Vec<u8>) -> Self {
        assert!(bytes.len().is_multiple_of(SECTOR_BYTES), "the flash is whole sectors");
        let sectors = bytes.len() / SECTOR_BYTES;
        SimFlash {
            bytes: Rc::new(RefCell::new(bytes)),
            power_bytes: Rc::new(Cell::new(None)),
            changed_bytes: Rc::new(Cell::new(0)),
            erases: Rc::new(RefCell::new(vec![0; sectors])),
            operations_at_us: Rc::new(RefCell::new(Vec::new())),
            file: None,
        }
    }

    /// Flash of `sectors` sectors kept in the file at `path`: read from it if it exists (it
    /// must be that size), created erased if not, and written through on every change.
    pub fn in_file(path: &Path, sectors: usize) -> std::io::Result<Self> {
        let size = sectors * SECTOR_BYTES;
        let mut file = File::options().read(true).write(true).create(true).truncate(false).open(path)?;
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes)?;
        if bytes.is_empty() {
            bytes = vec![0xFF; size];
            file.write_all(&bytes)?;
        } else if bytes.len() != size {
            return Err(std::io::Error::other(format!("{} bytes, not the {size} of the flash store", bytes.len())));
        }
        let mut flash = Self::holding(bytes);
        flash.file = Some(Rc::new(RefCell::new(file)));
        Ok(flash)
    }

    /// A copy of every byte.
    pub fn bytes(&self) -> Vec<u8> {
        self.bytes.borrow().clone()
    }

    /// The power goes off once `bytes` more bytes have been written or erased.
    pub fn cut_power_after(&self, bytes: u64) {
        self.power_bytes.set(Some(bytes));
    }

    /// Bytes written or erased since power-on.
    pub fn bytes_changed(&self) -> u64 {
        self.changed_bytes.get()
    }

    /// Erases since power-on, per sector.
    pub fn erased_sectors(&self) -> Vec<u32> {
        self.erases.borrow().clone()
    }

    /// The virtual time of every write and erase since power-on. On the F407 each stalls the
    /// processor, interrupts included, until it ends (an erase up to 2 s): the machine must be
    /// at rest then.
    pub fn operations_at_us(&self) -> Vec<u64> {
        self.operations_at_us.borrow().clone()
    }

    /// Sets the bytes from `offset` on by `change`, one byte at a time while the power lasts,
    /// writing them through to the file.
    fn change(&self, offset: usize, len: usize, change: impl Fn(usize, u8) -> u8) -> Result<(), SimFlashError> {
        self.operations_at_us.borrow_mut().push(crate::sim::clock::now_ticks());
        let mut bytes = self.bytes.borrow_mut();
        let range = bytes.get_mut(offset..offset + len).ok_or(SimFlashError::OutOfBounds)?;
        let mut done = 0;
        let mut result = Ok(());
        for (i, byte) in range.iter_mut().enumerate() {
            match self.power_bytes.get() {
                Some(0) => {
                    result = Err(SimFlashError::PowerCut);
                    break;
                }
                Some(n) => self.power_bytes.set(Some(n - 1)),
                None => {}
            }
            *byte = change(i, *byte);
            done = i + 1;
            self.changed_bytes.set(self.changed_bytes.get() + 1);
        }
        if let Some(file) = &self.file {
            let mut file = file.borrow_mut();
            let written = file.seek(SeekFrom::Start(offset as u64)).and_then(|_| file.write_all(&range[..done]));
            written.map_err(|_| SimFlashError::File)?;
        }
        result
    }
}

impl Default for SimFlash {
    /// The flash store's sectors, erased.
    fn default() -> Self {
        SimFlash::erased(STORE_SECTORS)
    }
}

impl<const SECTOR_BYTES: usize> ErrorType for SimFlash<SECTOR_BYTES> {
    type Error = SimFlashError;
}

impl<const SECTOR_BYTES: usize> ReadNorFlash for SimFlash<SECTOR_BYTES> {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, out: &mut [u8]) -> Result<(), SimFlashError> {
        let bytes = self.bytes.borrow();
        let offset = offset as usize;
        out.copy_from_slice(bytes.get(offset..offset + out.len()).ok_or(SimFlashError::OutOfBounds)?);
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.bytes.borrow().len()
    }
}

impl<const SECTOR_BYTES: usize> NorFlash for SimFlash<SECTOR_BYTES> {
    const WRITE_SIZE: usize = SIM_FLASH_WRITE_BYTES;
    const ERASE_SIZE: usize = SECTOR_BYTES;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), SimFlashError> {
        let (from, to) = (from as usize, to as usize);
        if !from.is_multiple_of(SECTOR_BYTES) || !to.is_multiple_of(SECTOR_BYTES) || to < from {
            return Err(SimFlashError::NotAligned);
        }
        for sector in from / SECTOR_BYTES..to / SECTOR_BYTES {
            if let Some(count) = self.erases.borrow_mut().get_mut(sector) {
                *count += 1;
            }
        }
        self.change(from, to - from, |_, _| 0xFF)
    }

    fn write(&mut self, offset: u32, data: &[u8]) -> Result<(), SimFlashError> {
        if !(offset as usize).is_multiple_of(SIM_FLASH_WRITE_BYTES) || !data.len().is_multiple_of(SIM_FLASH_WRITE_BYTES)
        {
            return Err(SimFlashError::NotAligned);
        }
        self.change(offset as usize, data.len(), |i, old| old & data[i])
    }
}

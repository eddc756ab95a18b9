//! The FAT16/FAT32 volume on a card's 512-byte blocks, read through the `embedded-sdmmc`
//! crate, as a [`Card`]; and a card formatted without a partition table (as `mkfs.fat -C`
//! makes an image, and some cards come) seen as one with a single partition.

use core::cell::Cell;
use core::ops::ControlFlow;

use embedded_sdmmc::{
    Block, BlockCount, BlockDevice, BlockIdx, Error, LfnBuffer, Mode, RawDirectory, RawFile, RawVolume, ShortFileName,
    TimeSource, Timestamp, VolumeIdx, VolumeManager,
};
use heapless::String;

use super::names::CARD_SHORT_NAME_MAX_BYTES;
use super::resume::{RESUME_FILE_BYTES, RESUME_FILE_NAME, RESUME_SLOT_BYTES, ResumeBytes, ResumeSlots};
use super::{CARD_NAME_MAX_BYTES, Card, CardError, CardFile, CardFiles};

/// Where a partition table's first entry starts in block 0, and its type byte.
const MBR_PARTITION1_AT: usize = 446;
const MBR_TYPE_AT: usize = MBR_PARTITION1_AT + 4;
/// The partition types `embedded-sdmmc` opens: FAT16 (LBA) and FAT32 (LBA).
const MBR_TYPE_FAT16_LBA: u8 = 0x0E;
const MBR_TYPE_FAT32_LBA: u8 = 0x0C;
const MBR_FAT_TYPES: [u8; 5] = [0x01, 0x04, 0x06, MBR_TYPE_FAT16_LBA, MBR_TYPE_FAT32_LBA];

/// The plotter keeps no clock, so no file times: every stamp is the FAT epoch (and a store
/// rewrites the resume record's directory entry as it was).
pub struct NoClock;

impl TimeSource for NoClock {
    fn get_timestamp(&self) -> Timestamp {
        Timestamp { year_since_1970: 10, zero_indexed_month: 0, zero_indexed_day: 0, hours: 0, minutes: 0, seconds: 0 }
    }
}

/// Whether block 0 is a FAT boot sector itself (no partition table): a BIOS parameter block
/// of 512-byte sectors, and no FAT partition in the first entry.
fn is_boot_sector(block: &Block) -> bool {
    let b = &block.contents;
    let sector_bytes = u16::from_le_bytes([b[11], b[12]]);
    let signed = b[510] == 0x55 && b[511] == 0xAA;
    let jump = b[0] == 0xEB || b[0] == 0xE9;
    let cluster = b[13];
    signed && jump && sector_bytes == 512 && cluster.is_power_of_two() && !MBR_FAT_TYPES.contains(&b[MBR_TYPE_AT])
}

/// A card's blocks as a partitioned card's: one without a partition table is shown a made-up
/// block 0 with one FAT partition, its own blocks after it. Which one a card is, is learnt each
/// time block 0 is read (every volume is opened by reading it), so a card changed in the slot
/// is seen as it is.
pub struct Partitioned<D> {
    inner: D,
    /// The card has no partition table: its own block 0 is the FAT's boot sector.
    bare: Cell<bool>,
}

impl<D: BlockDevice> Partitioned<D> {
    pub fn new(inner: D) -> Self {
        Partitioned { inner, bare: Cell::new(false) }
    }

    /// The card's own blocks.
    pub fn inner_mut(&mut self) -> &mut D {
        &mut self.inner
    }

    /// Block 0 as seen: the card's own, or the table made up for a card without one.
    fn read_first(&self, first: &mut Block) -> Result<(), D::Error> {
        self.inner.read(core::slice::from_mut(first), BlockIdx(0))?;
        self.bare.set(is_boot_sector(first));
        if self.bare.get() {
            *first = table_for(first, self.inner.num_blocks()?);
        }
        Ok(())
    }
}

/// A partition table with one partition of `blocks` blocks from block 1, of the type that
/// `boot`'s parameter block tells (FAT32 keeps no 16-bit FAT size).
fn table_for(boot: &Block, blocks: BlockCount) -> Block {
    let b = &boot.contents;
    let fat32 = u16::from_le_bytes([b[22], b[23]]) == 0;
    let mut table = Block::new();
    let entry = &mut table.contents[MBR_PARTITION1_AT..MBR_PARTITION1_AT + 16];
    entry[4] = if fat32 { MBR_TYPE_FAT32_LBA } else { MBR_TYPE_FAT16_LBA };
    entry[8..12].copy_from_slice(&1u32.to_le_bytes());
    entry[12..16].copy_from_slice(&blocks.0.to_le_bytes());
    table.contents[510] = 0x55;
    table.contents[511] = 0xAA;
    table
}

impl<D: BlockDevice> BlockDevice for Partitioned<D> {
    type Error = D::Error;

    fn read(&self, blocks: &mut [Block], start: BlockIdx) -> Result<(), Self::Error> {
        match (start.0, blocks) {
            (0, [first, rest @ ..]) => {
                self.read_first(first)?;
                match (rest.is_empty(), self.bare.get()) {
                    (true, _) => Ok(()),
                    (false, true) => self.inner.read(rest, BlockIdx(0)),
                    (false, false) => self.inner.read(rest, BlockIdx(1)),
                }
            }
            (n, blocks) if self.bare.get() => self.inner.read(blocks, BlockIdx(n - 1)),
            (_, blocks) => self.inner.read(blocks, start),
        }
    }

    fn write(&self, blocks: &[Block], start: BlockIdx) -> Result<(), Self::Error> {
        match (self.bare.get(), start.0, blocks) {
            (false, _, _) => self.inner.write(blocks, start),
            // The made-up table is never written.
            (true, 0, [_]) => Ok(()),
            (true, 0, [_, rest @ ..]) => self.inner.write(rest, BlockIdx(0)),
            (true, n, blocks) => self.inner.write(blocks, BlockIdx(n - 1)),
        }
    }

    fn num_blocks(&self) -> Result<BlockCount, Self::Error> {
        let n = self.inner.num_blocks()?;
        Ok(if self.bare.get() { BlockCount(n.0 + 1) } else { n })
    }
}

/// Volumes open at once: the card's first.
const OPEN_VOLUMES_MAX: usize = 1;
/// Folders open at once: the top one, which the plotted file and the resume record share.
const OPEN_DIRS_MAX: usize = 1;
/// Files open at once: the plotted file, and the resume record while it is read or stored.
const OPEN_FILES_MAX: usize = 2;

/// The volume manager for the limits above.
type Volumes<D> = VolumeManager<Partitioned<D>, NoClock, OPEN_DIRS_MAX, OPEN_FILES_MAX, OPEN_VOLUMES_MAX>;

/// A FAT card on `D`'s blocks: its first partition's top folder.
pub struct FatCard<D: BlockDevice> {
    volumes: Volumes<D>,
    /// The volume, folder and file open while a file is read.
    open: Option<(RawVolume, RawDirectory, RawFile)>,
}

/// Zeros to fill the resume record's file with, a piece at a time.
const ZERO_FILL_BYTES: usize = 64;

/// The first of the volume manager's handle numbers (any will do).
const HANDLE_IDS_FROM: u32 = 1;

/// Long names read back (in UTF-8), in bytes: longer ones are shown by their 8.3 names.
const LONG_NAME_BUFFER_BYTES: usize = CARD_NAME_MAX_BYTES * 2;

impl<D: BlockDevice> FatCard<D> {
    pub fn new(blocks: D) -> Self {
        FatCard {
            volumes: VolumeManager::new_with_limits(Partitioned::new(blocks), NoClock, HANDLE_IDS_FROM),
            open: None,
        }
    }

    /// Opens the volume and its top folder; closes the volume again if the folder fails.
    fn open_root(&self) -> Result<(RawVolume, RawDirectory), CardError> {
        let volume = self.volumes.open_raw_volume(VolumeIdx(0)).map_err(card_error)?;
        match self.volumes.open_root_dir(volume) {
            Ok(dir) => Ok((volume, dir)),
            Err(e) => {
                let _ = self.volumes.close_volume(volume);
                Err(card_error(e))
            }
        }
    }

    /// Reaches the card's own blocks through `f` (to change how they are read: a board's SPI
    /// clock).
    pub fn with_blocks<R>(&self, f: impl FnOnce(&mut D) -> R) -> R {
        self.volumes.device(|blocks| f(blocks.inner_mut()))
    }

    fn close_root(&self, volume: RawVolume, dir: RawDirectory) {
        let _ = self.volumes.close_dir(dir);
        let _ = self.volumes.close_volume(volume);
    }

    /// Runs `f` on the top folder: the open file's (a volume is opened once), else opened for
    /// `f` alone.
    fn in_root<R>(&self, f: impl FnOnce(&Volumes<D>, RawDirectory) -> Result<R, CardError>) -> Result<R, CardError> {
        if let Some((_, dir, _)) = self.open {
            return f(&self.volumes, dir);
        }
        let (volume, dir) = self.open_root()?;
        let result = f(&self.volumes, dir);
        self.close_root(volume, dir);
        result
    }
}

/// Reads each slot's record bytes from the resume record's `file`; a slot the file is too short
/// for is left as it was.
fn read_slots<D: BlockDevice>(volumes: &Volumes<D>, file: RawFile, slots: &mut ResumeSlots) -> Result<(), CardError> {
    let length = volumes.file_length(file).map_err(card_error)? as usize;
    for (i, slot) in slots.slots.iter_mut().enumerate() {
        let at = i * RESUME_SLOT_BYTES;
        if at >= length {
            break;
        }
        volumes.file_seek_from_start(file, at as u32).map_err(card_error)?;
        let mut got = 0;
        while got < slot.len() {
            match volumes.read(file, &mut slot[got..]).map_err(card_error)? {
                0 => break,
                n => got += n,
            }
        }
    }
    Ok(())
}

/// Writes `bytes` at the start of slot `slot` of the resume record's `file`, open for writing
/// at its end: the file is first filled out with zeros to its two slots.
fn write_slot<D: BlockDevice>(
    volumes: &Volumes<D>,
    file: RawFile,
    slot: usize,
    bytes: &ResumeBytes,
) -> Result<(), CardError> {
    let mut length = volumes.file_length(file).map_err(card_error)? as usize;
    while length < RESUME_FILE_BYTES {
        let n = ZERO_FILL_BYTES.min(RESUME_FILE_BYTES - length);
        volumes.write(file, &[0; ZERO_FILL_BYTES][..n]).map_err(card_error)?;
        length += n;
    }
    volumes.file_seek_from_start(file, (slot * RESUME_SLOT_BYTES) as u32).map_err(card_error)?;
    volumes.write(file, bytes).map_err(card_error)
}

/// What the crate's error means to the user.
fn card_error<E: core::error::Error>(e: Error<E>) -> CardError {
    match e {
        Error::FormatError(_) | Error::NoSuchVolume | Error::BadBlockSize(_) => CardError::NotFat,
        Error::NotFound => CardError::NoSuchFile,
        _ => CardError::Unreadable,
    }
}

impl<D: BlockDevice> Card for FatCard<D> {
    fn files(&mut self) -> Result<CardFiles, CardError> {
        self.close();
        let (volume, dir) = self.open_root()?;
        let mut files = CardFiles::new();
        let mut storage = [0u8; LONG_NAME_BUFFER_BYTES];
        let mut long = LfnBuffer::new(&mut storage);
        let listed = self.volumes.iterate_dir_lfn(dir, &mut long, |entry, long| {
            if !entry.attributes.is_directory() && !entry.attributes.is_volume() {
                files.offer(&short_name(&entry.name), long, entry.size);
            }
            ControlFlow::Continue(())
        });
        self.close_root(volume, dir);
        listed.map_err(card_error)?;
        Ok(files)
    }

    fn open(&mut self, file: &CardFile) -> Result<u32, CardError> {
        self.close();
        let (volume, dir) = self.open_root()?;
        match self.volumes.open_file_in_dir(dir, file.short.as_str(), Mode::ReadOnly) {
            Ok(raw) => {
                self.open = Some((volume, dir, raw));
                self.volumes.file_length(raw).map_err(card_error)
            }
            Err(e) => {
                self.close_root(volume, dir);
                Err(card_error(e))
            }
        }
    }

    fn read(&mut self, buf: &mut [u8]) -> Result<usize, CardError> {
        let Some((_, _, file)) = self.open else {
            return Ok(0);
        };
        if self.volumes.file_eof(file).map_err(card_error)? {
            return Ok(0);
        }
        self.volumes.read(file, buf).map_err(card_error)
    }

    fn seek(&mut self, offset: u32) -> Result<(), CardError> {
        let Some((_, _, file)) = self.open else {
            return Err(CardError::NoSuchFile);
        };
        self.volumes.file_seek_from_start(file, offset).map_err(card_error)
    }

    fn close(&mut self) {
        if let Some((volume, dir, file)) = self.open.take() {
            let _ = self.volumes.close_file(file);
            self.close_root(volume, dir);
        }
    }

    fn read_resume(&mut self, slots: &mut ResumeSlots) -> Result<(), CardError> {
        *slots = ResumeSlots::new();
        self.in_root(|volumes, dir| {
            let file = match volumes.open_file_in_dir(dir, RESUME_FILE_NAME, Mode::ReadOnly) {
                Err(Error::NotFound) => return Ok(()),
                opened => opened.map_err(card_error)?,
            };
            let read = read_slots(volumes, file, slots);
            let _ = volumes.close_file(file);
            read
        })
    }

    fn write_resume(&mut self, slot: usize, bytes: &ResumeBytes) -> Result<(), CardError> {
        self.in_root(|volumes, dir| {
            // Created if missing, else open at its end.
            let file =
                volumes.open_file_in_dir(dir, RESUME_FILE_NAME, Mode::ReadWriteCreateOrAppend).map_err(card_error)?;
            let written = write_slot(volumes, file, slot, bytes);
            // Closing writes the file's directory entry (unchanged once the file has its size).
            let closed = volumes.close_file(file).map_err(card_error);
            written.and(closed)
        })
    }
}

/// An 8.3 name as text, `BASE.EXT`: its bytes as they are (ISO-8859-1), written without core's
/// formatting (whose padding code the image does without).
fn short_name(name: &ShortFileName) -> String<CARD_SHORT_NAME_MAX_BYTES> {
    let mut short = String::new();
    let dot: &[u8] = if name.extension().is_empty() { b"" } else { b"." };
    for &b in name.base_name().iter().chain(dot).chain(name.extension()) {
        // 8 + 1 + 3 ASCII bytes fit; a byte beyond ASCII takes two and may not.
        if short.push(char::from(b)).is_err() {
            break;
        }
    }
    short
}

//! The flash store: what the plotter keeps across power cycles (the settings, the work
//! coordinate systems G54–G59, the G28 and G30 positions, the startup blocks and the build info
//! line), as one [`Record`] in two erase sectors of flash set apart for it.
//!
//! It is a log over the two sectors. A sector starts with a header (a magic word and a sequence
//! number, checksummed, written twice over) written after each erase; saves append the whole
//! record after the last one, each with its length and a CRC-32. Reading takes the last record
//! whose CRC holds, in the sector with the highest sequence number that holds one. Damage does
//! not hide what lies behind it: a record that fails its CRC is skipped and the scan goes on at
//! the next word, so every intact record is found; a header needs only one of its two copies,
//! and a sector whose header is lost still gives its records when the other sector has none.
//! When anything was skipped, opening the store says so ([`StoreError::Repaired`]). A save appends to that sector while
//! it has room and nothing but erased flash after its last record; otherwise it erases the
//! other sector, gives it the next sequence number and writes the record there. So:
//!
//! - **wear levelling:** a sector is erased once per sector full of records, the two in turn;
//! - **power-loss safety:** the sector holding the record kept is never erased or written over
//!   by a save, so a cut at any byte leaves it readable, or the new record complete (a torn
//!   record fails its CRC and is skipped). Everything kept is one record, written whole: a cut
//!   leaves the old values or the new ones, never a mix.
//!
//! Flash that reads back as something else (written by a firmware with another layout, a value
//! out of range, or sectors the store never wrote) gives the defaults and says why; erased flash
//! gives them silently.
//!
//! On the F407 a write or an erase stalls every fetch from flash, interrupts included: nothing
//! else runs meanwhile (up to [`STORE_SAVE_STALL_MAX_MS`] for a save that erases a sector), so
//! the store is plain blocking code, and the serial task saves only at rest (as GRBL writes its
//! EEPROM), between the lines that change what is kept: a save in motion would leave the step
//! timer pulsing at its last rate with no interrupt to stop it. The independent watchdog's
//! shortest timeout outlasts the longest stall (`watchdog`).

mod record;
#[cfg(test)]
mod tests;

use core::ops::Range;

use embedded_storage::nor_flash::NorFlash;

use crate::crc::crc32;

use crate::host::gcode::Offsets;
use crate::host::startup::StartupLines;
use crate::settings::Settings;

pub use record::{BadRecord, LAYOUT_TAG, RECORD_MAX_BYTES, Record};

/// The flash the store uses on the F407: sectors 10 and 11, its last two, as offsets from the
/// start of flash. `memory.x` ends the firmware's flash before them.
pub const STORE_FLASH_RANGE: Range<u32> = 0x000C_0000..0x0010_0000;
/// The size of those sectors.
pub const STORE_SECTOR_BYTES: usize = 128 * 1024;
/// How many the store uses.
pub const STORE_SECTORS: usize = 2;
const _: () = assert!((STORE_FLASH_RANGE.end - STORE_FLASH_RANGE.start) as usize == STORE_SECTORS * STORE_SECTOR_BYTES);

/// The longest erase of one of those 128 KB sectors on the F407, erased 32 bits at a time (the
/// parallelism for a 2.7-3.6 V supply, RM0090 §3.6.2): DS8626's "Flash memory programming"
/// table gives t_ERASE128KB 1 s typical, 2 s at most (x8, the reset parallelism: 4 s).
pub const STORE_SECTOR_ERASE_MAX_MS: u32 = 2_000;
/// The longest program of one 32-bit word (x32): DS8626's t_prog, 16 µs typical, 100 µs at most.
pub const STORE_WORD_PROGRAM_MAX_US: u32 = 100;
/// The longest a save stalls the processor on the F407: one sector erased, its header and the
/// longest record programmed. Every fetch from flash (instructions, interrupt vectors and
/// handlers) waits for a program or an erase to end (one bank), so nothing runs meanwhile, not
/// even the pulse interrupt: the serial task saves only with the machine at rest.
pub const STORE_SAVE_STALL_MAX_MS: u32 = STORE_SECTOR_ERASE_MAX_MS
    + (((SECTOR_HEADER_BYTES + STORE_BUFFER_BYTES) / ALIGN_BYTES) as u32 * STORE_WORD_PROGRAM_MAX_US).div_ceil(1_000);

/// Starts a sector header: "SPLT".
const SECTOR_MAGIC: u32 = 0x544c_5053;
/// One copy of a sector header: magic, sequence number, CRC-32 of the two.
const SECTOR_HEADER_COPY_BYTES: usize = 12;
/// A sector header: two copies, so that one damaged byte does not lose the sector's number.
const SECTOR_HEADER_BYTES: usize = 2 * SECTOR_HEADER_COPY_BYTES;
/// Record header: length of the record's bytes (u16), then this.
const RECORD_MAGIC: u16 = 0x5252;
/// Record header (length and magic) and CRC-32 trailer.
const RECORD_OVERHEAD_BYTES: usize = 4 + 4;
/// Records and headers are laid out on this boundary: a multiple of every flash's write size
/// the store runs on (the F407 programs 32-bit words).
const ALIGN_BYTES: usize = 4;
/// The store's working buffer: the longest record with its header, padding and CRC.
pub const STORE_BUFFER_BYTES: usize = (RECORD_MAX_BYTES + RECORD_OVERHEAD_BYTES).next_multiple_of(ALIGN_BYTES);

/// Why the flash did not give back a record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum StoreError {
    /// The sectors hold what the store did not write.
    Corrupt,
    /// A record of another firmware version, with other settings.
    OtherVersion,
    /// A record with a value out of its range.
    Invalid,
    /// The flash refused a read, a write or an erase.
    Flash,
    /// Damaged data (or a save cut short) was skipped: the newest intact record was loaded,
    /// or the defaults if there is none.
    Repaired,
}

impl StoreError {
    /// What a user is told.
    pub fn message(self) -> &'static str {
        match self {
            StoreError::Corrupt => "Flash store unreadable: defaults loaded",
            StoreError::OtherVersion => "Flash store from another version: defaults loaded",
            StoreError::Invalid => "Flash store holds invalid values: defaults loaded",
            StoreError::Flash => "Flash store failed",
            StoreError::Repaired => "Flash store: damaged data skipped, the newest intact record loaded",
        }
    }
}

/// What a scan found in one sector.
#[derive(Clone, Copy, Debug, Default)]
struct Sector {
    /// The header's sequence number, if the header is whole.
    seq: Option<u32>,
    /// The last record whose CRC holds: its offset in the sector and length.
    last: Option<(usize, usize)>,
    /// Where the next record goes, if everything from there on is erased.
    append_at: Option<usize>,
    /// Something that is neither a whole record nor erased flash was skipped.
    skipped: bool,
}

/// The flash store over `F`, in a range of it, and the record it keeps.
pub struct Store<F: NorFlash> {
    flash: F,
    /// The first byte of the store in `flash`.
    start: u32,
    sectors: [Sector; STORE_SECTORS],
    buf: [u8; STORE_BUFFER_BYTES],
    kept: Record,
    /// The flash holds `kept` (false after a failed save).
    in_flash: bool,
}

impl<F: NorFlash> Store<F> {
    /// Power-on: the store in `range` of `flash` ([`STORE_SECTORS`] erase sectors), keeping
    /// the record read back, or the defaults and why none was read. Erased flash gives the
    /// defaults and no error.
    pub fn open(flash: F, range: Range<u32>) -> (Self, Result<(), StoreError>) {
        assert!(range.len() == STORE_SECTORS * F::ERASE_SIZE && F::ERASE_SIZE.is_multiple_of(ALIGN_BYTES));
        let mut store = Store {
            flash,
            start: range.start,
            sectors: [Sector::default(); STORE_SECTORS],
            buf: [0; STORE_BUFFER_BYTES],
            kept: Record::default(),
            in_flash: true,
        };
        let loaded = store.load();
        if let Err(e) = loaded {
            warn!("flash store: {}", e.message());
        }
        (store, loaded)
    }

    /// What the flash keeps (as read at power-on or last saved).
    pub fn kept(&self) -> &Record {
        &self.kept
    }

    /// Whether the flash holds these values already: saving them would change nothing.
    pub fn holds(&self, settings: &Settings, offsets: &Offsets, startup: &StartupLines) -> bool {
        let kept = &self.kept;
        self.in_flash && kept.settings == *settings && kept.offsets_mm == offsets.kept_mm() && kept.startup == *startup
    }

    /// Keeps `record` in place of the one kept so far. If the flash fails, what it keeps is
    /// unknown: the next save writes again.
    pub fn save(&mut self, record: &Record) -> Result<(), StoreError> {
        let len = record.encode(&mut self.buf[4..]);
        let saved = self.append(len);
        if saved.is_err() {
            warn!("flash store: {}", StoreError::Flash.message());
            // What the flash holds now, so the next save still spares the record kept.
            for s in 0..STORE_SECTORS {
                self.sectors[s] = self.scan(s).map(|(sector, _)| sector).unwrap_or_default();
            }
        }
        self.in_flash = saved.is_ok();
        self.kept.clone_from(record);
        saved.map_err(|_| StoreError::Flash)
    }

    /// The sector holding the record kept: the highest sequence number with a record.
    fn newest(&self) -> Option<usize> {
        (0..STORE_SECTORS).filter(|&s| self.sectors[s].last.is_some()).max_by_key(|&s| self.sectors[s].seq)
    }

    fn load(&mut self) -> Result<(), StoreError> {
        let (mut foreign, mut skipped) = (false, false);
        for s in 0..STORE_SECTORS {
            let (sector, empty) = self.scan(s).map_err(|_| StoreError::Flash)?;
            self.sectors[s] = sector;
            foreign |= sector.seq.is_none() && sector.last.is_none() && !empty;
            skipped |= sector.skipped;
        }
        let Some(s) = self.newest() else {
            return if foreign {
                Err(StoreError::Corrupt)
            } else if skipped {
                Err(StoreError::Repaired)
            } else {
                Ok(())
            };
        };
        let (at, len) = self.sectors[s].last.unwrap_or_default();
        let from = self.sector_start(s) + at as u32 + 4;
        let bytes = &mut self.buf[..len];
        self.flash.read(from, bytes).map_err(|_| StoreError::Flash)?;
        self.kept = Record::decode(bytes).map_err(|bad| match bad {
            BadRecord::OtherLayout => StoreError::OtherVersion,
            BadRecord::Invalid => StoreError::Invalid,
        })?;
        if skipped { Err(StoreError::Repaired) } else { Ok(()) }
    }

    fn sector_start(&self, s: usize) -> u32 {
        self.start + (s * F::ERASE_SIZE) as u32
    }

    /// Reads sector `s`: its header, its last good record and where a record may go next, and
    /// whether it holds nothing at all past a header that is not whole (erased, or a header
    /// write cut short).
    fn scan(&mut self, s: usize) -> Result<(Sector, bool), F::Error> {
        let base = self.sector_start(s);
        let mut header = [0u8; SECTOR_HEADER_BYTES];
        self.flash.read(base, &mut header)?;
        let mut sector =
            Sector { seq: header.chunks_exact(SECTOR_HEADER_COPY_BYTES).find_map(header_seq), ..Sector::default() };
        // Records one after another; anything else is skipped a word at a time, so that the
        // records after it are still found, up to the erased end of the log.
        let (mut at, mut end) = (SECTOR_HEADER_BYTES, SECTOR_HEADER_BYTES);
        while at + RECORD_OVERHEAD_BYTES <= F::ERASE_SIZE {
            if let Some((len, size)) = self.record_at(base, at)? {
                sector.last = Some((at, len));
                at += size;
                end = at;
            } else if self.erased_from(base, at)? {
                break;
            } else {
                sector.skipped = true;
                at += ALIGN_BYTES;
            }
        }
        if sector.seq.is_none() && sector.last.is_none() {
            // Erased, or a header cut short in its first copy (erased after it): nothing the
            // store wrote is lost. Anything else is not the store's.
            let empty = self.erased_from(base, SECTOR_HEADER_COPY_BYTES)?;
            return Ok((Sector { skipped: false, ..sector }, empty));
        }
        // Records behind a header lost to damage.
        sector.skipped |= sector.seq.is_none();
        if sector.seq.is_some() && self.erased_from(base, end)? {
            sector.append_at = Some(end);
        }
        Ok((sector, false))
    }

    /// The record at `at` in the sector at `base`, if one is whole there: its length and the
    /// bytes it takes.
    fn record_at(&mut self, base: u32, at: usize) -> Result<Option<(usize, usize)>, F::Error> {
        let mut head = [0u8; 4];
        self.flash.read(base + at as u32, &mut head)?;
        let len = usize::from(u16::from_le_bytes([head[0], head[1]]));
        let size = (len + RECORD_OVERHEAD_BYTES).next_multiple_of(ALIGN_BYTES);
        if u16::from_le_bytes([head[2], head[3]]) != RECORD_MAGIC
            || size > STORE_BUFFER_BYTES
            || at + size > F::ERASE_SIZE
        {
            return Ok(None);
        }
        let bytes = &mut self.buf[..size];
        self.flash.read(base + at as u32, bytes)?;
        Ok((le_u32(bytes, size - 4) == crc32(&bytes[..size - 4])).then_some((len, size)))
    }

    /// Whether every byte of the sector at `base` from `at` on is erased.
    fn erased_from(&mut self, base: u32, mut at: usize) -> Result<bool, F::Error> {
        let mut chunk = [0u8; 64];
        while at < F::ERASE_SIZE {
            let n = chunk.len().min(F::ERASE_SIZE - at);
            self.flash.read(base + at as u32, &mut chunk[..n])?;
            if chunk[..n].iter().any(|&b| b != 0xFF) {
                return Ok(false);
            }
            at += n;
        }
        Ok(true)
    }

    /// Writes the record of `len` bytes at `buf[4..]`: after the record kept if its sector has
    /// room, else in the other sector, erased and numbered next.
    fn append(&mut self, len: usize) -> Result<(), F::Error> {
        let size = (len + RECORD_OVERHEAD_BYTES).next_multiple_of(ALIGN_BYTES);
        self.buf[..2].copy_from_slice(&(len as u16).to_le_bytes());
        self.buf[2..4].copy_from_slice(&RECORD_MAGIC.to_le_bytes());
        self.buf[4 + len..size - 4].fill(0xFF);
        let crc = crc32(&self.buf[..size - 4]);
        self.buf[size - 4..size].copy_from_slice(&crc.to_le_bytes());

        let newest = self.newest();
        let fits = |sector: &Sector| sector.append_at.is_some_and(|at| at + size <= F::ERASE_SIZE);
        let (s, at) = match newest.filter(|&s| fits(&self.sectors[s])) {
            Some(s) => (s, self.sectors[s].append_at.unwrap_or_default()),
            None => {
                // Never the sector holding the record kept; numbered after every other.
                let s = newest.map_or(0, |n| (n + 1) % STORE_SECTORS);
                let seq = self.sectors.iter().filter_map(|sector| sector.seq).max().map_or(1, |q| q.wrapping_add(1));
                self.sectors[s] = Sector::default();
                let base = self.sector_start(s);
                self.flash.erase(base, base + F::ERASE_SIZE as u32)?;
                let mut header = [0u8; SECTOR_HEADER_BYTES];
                header[..4].copy_from_slice(&SECTOR_MAGIC.to_le_bytes());
                header[4..8].copy_from_slice(&seq.to_le_bytes());
                let crc = crc32(&header[..8]);
                header[8..12].copy_from_slice(&crc.to_le_bytes());
                header.copy_within(..SECTOR_HEADER_COPY_BYTES, SECTOR_HEADER_COPY_BYTES);
                self.flash.write(base, &header)?;
                self.sectors[s].seq = Some(seq);
                (s, SECTOR_HEADER_BYTES)
            }
        };
        self.flash.write(self.sector_start(s) + at as u32, &self.buf[..size])?;
        self.sectors[s].last = Some((at, len));
        self.sectors[s].append_at = Some(at + size);
        Ok(())
    }
}

/// The sequence number of a copy of a sector header, if the copy is whole.
fn header_seq(copy: &[u8]) -> Option<u32> {
    let [magic, seq, crc] = [0, 4, 8].map(|at| le_u32(copy, at));
    (magic == SECTOR_MAGIC && crc == crc32(&copy[..8])).then_some(seq)
}

/// The little-endian word at `at` in `bytes`.
fn le_u32(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([0, 1, 2, 3].map(|k| bytes[at + k]))
}

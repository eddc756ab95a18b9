//! The flash store's reader: any bytes as the store's two sectors (small ones, so that the input
//! covers them whole; what is missing reads as erased flash), opened as at power-on.
//!
//! Checks, besides that nothing panics: opening gives either a record that lies in the flash
//! whole, with its header and a CRC-32 that holds (checked here with a CRC of its own), or the
//! defaults (and then, for flash the store did not write, an error saying why); a save over
//! whatever the flash held succeeds and is what the next power-on reads back; and the same save
//! cut short by a power loss at any byte leaves the record read before or the new one.
#![no_main]

use libfuzzer_sys::fuzz_target;
use servoplot::sim::flash::SimFlash;
use servoplot::store::{RECORD_MAX_BYTES, Record, STORE_SECTORS, Store, StoreError};

/// Sectors small enough for a fuzz input to fill, large enough for a few records.
const SECTOR_BYTES: usize = 2048;
const FLASH_BYTES: usize = SECTOR_BYTES * STORE_SECTORS;
/// A record's header: its length (u16) and this magic (u16), little-endian; then the record,
/// 0xFF up to a 4-byte boundary, and the CRC-32 of all that.
const RECORD_MAGIC: u16 = 0x5252;
const RECORD_ALIGN_BYTES: usize = 4;

type Flash = SimFlash<SECTOR_BYTES>;

/// Power-on over `flash` (a clone: it shares the bytes).
fn open(flash: &Flash) -> (Store<Flash>, Result<(), StoreError>) {
    Store::open(flash.clone(), 0..FLASH_BYTES as u32)
}

/// CRC-32 (IEEE 802.3, reflected), as the store writes it.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &byte in bytes {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            crc = if crc & 1 == 1 { (crc >> 1) ^ 0xEDB8_8320 } else { crc >> 1 };
        }
    }
    !crc
}

/// Whether `flash` holds `record` whole somewhere: header, bytes, padding and a CRC that holds.
fn holds_whole(flash: &[u8], record: &Record) -> bool {
    let mut bytes = [0u8; RECORD_MAX_BYTES];
    let len = record.encode(&mut bytes);
    let size = (4 + len + 4).next_multiple_of(RECORD_ALIGN_BYTES);
    let mut framed = Vec::with_capacity(size);
    framed.extend_from_slice(&(len as u16).to_le_bytes());
    framed.extend_from_slice(&RECORD_MAGIC.to_le_bytes());
    framed.extend_from_slice(&bytes[..len]);
    framed.resize(size - 4, 0xFF);
    framed.extend_from_slice(&crc32(&framed).to_le_bytes());
    flash.chunks_exact(SECTOR_BYTES).any(|sector| {
        (0..SECTOR_BYTES.saturating_sub(size) + 1)
            .step_by(RECORD_ALIGN_BYTES)
            .any(|at| sector[at..at + size] == framed[..])
    })
}

fuzz_target!(|data: &[u8]| {
    let mut bytes = data[..data.len().min(FLASH_BYTES)].to_vec();
    bytes.resize(FLASH_BYTES, 0xFF);

    let flash = Flash::holding(bytes.clone());
    let (mut store, loaded) = open(&flash);
    let kept = store.kept().clone();
    match loaded {
        Ok(()) | Err(StoreError::Repaired) => {
            assert!(kept == Record::default() || holds_whole(&bytes, &kept), "a record not in the flash: {kept:?}");
        }
        Err(StoreError::Corrupt | StoreError::OtherVersion | StoreError::Invalid) => {
            assert_eq!(kept, Record::default(), "defaults after {loaded:?}");
        }
        Err(StoreError::Flash) => panic!("the simulated flash never fails a read"),
    }

    // A save over whatever was there, and a power cycle: the new record reads back.
    let mut settings = kept.settings;
    let idle_delay_ms = if settings.servo_idle_delay_ms == 25 { 200.0 } else { 25.0 };
    settings.set(1, idle_delay_ms).expect("a servo idle delay ($1) within its range");
    let record = Record { settings, ..kept.clone() };
    assert_eq!(store.save(&record), Ok(()));
    let (again, reloaded) = open(&Flash::holding(flash.bytes()));
    assert!(matches!(reloaded, Ok(()) | Err(StoreError::Repaired)), "{reloaded:?} after a save");
    assert_eq!(again.kept(), &record, "the record saved is not the one read back");

    // The same save cut short by a power loss, at a byte the input picks among those it writes
    // or erases: the next power-on reads the record kept before or the new one, nothing else.
    let cut_flash = Flash::holding(bytes);
    let (mut cut_store, _) = open(&cut_flash);
    cut_flash.cut_power_after(u64::from(crc32(data)) % (flash.bytes_changed() + 1));
    let _ = cut_store.save(&record);
    let (after_cut, _) = open(&Flash::holding(cut_flash.bytes()));
    let read = after_cut.kept();
    assert!(read == &kept || read == &record, "after a cut save: {read:?}");
});

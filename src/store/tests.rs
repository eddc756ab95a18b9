//! The store on simulated NOR flash: records read back after power cycles, and a power cut at
//! every byte of a save leaves the record before it or the new one.

use std::vec::Vec;

use embedded_storage::nor_flash::NorFlash;

use super::*;
use crate::host::startup::StartupLine;
use crate::settings::Settings;
use crate::sim::flash::SimFlash;

/// Small sectors, so that a few saves fill one and the store moves on and erases.
const SMALL_SECTOR_BYTES: usize = 2048;
type SmallFlash = SimFlash<SMALL_SECTOR_BYTES>;
/// The board's sectors.
type BoardFlash = SimFlash<STORE_SECTOR_BYTES>;

fn range<F: NorFlash>(sectors: usize) -> Range<u32> {
    0..(sectors * F::ERASE_SIZE) as u32
}

fn open<F: NorFlash + Clone>(flash: &F, sectors: usize) -> (Store<F>, Result<(), StoreError>) {
    Store::open(flash.clone(), range::<F>(sectors))
}

/// The `n`th of a run of different records: settings, offsets and startup blocks all change,
/// and so does the record's length.
fn record(n: usize) -> Record {
    let mut settings = Settings::default();
    settings.set(100, 50.0 + n as f32).unwrap();
    settings.set(110, 1_000.0 + 10.0 * n as f32).unwrap();
    let mut record = Record { settings, ..Record::default() };
    record.offsets_mm[n % record.offsets_mm.len()] = [n as f32, -(n as f32) / 4.0];
    let line = "G1".repeat(n % 30);
    record.startup.set(n % 2, StartupLine::try_from(line.as_str()).unwrap());
    record
}

#[test]
fn erased_flash_gives_the_defaults_without_complaint() {
    let flash = BoardFlash::default();
    let (store, loaded) = open(&flash, STORE_SECTORS);
    assert_eq!(loaded, Ok(()));
    assert_eq!(store.kept(), &Record::default());
}

#[test]
fn a_saved_record_is_there_after_a_power_cycle() {
    let flash = BoardFlash::default();
    let (mut store, _) = open(&flash, STORE_SECTORS);
    for n in 0..5 {
        assert_eq!(store.save(&record(n)), Ok(()));
    }
    let rebooted = BoardFlash::holding(flash.bytes());
    let (store, loaded) = open(&rebooted, STORE_SECTORS);
    assert_eq!(loaded, Ok(()));
    assert_eq!(store.kept(), &record(4));
}

#[test]
fn saves_spread_over_both_sectors() {
    let flash = SmallFlash::erased(2);
    let (mut store, _) = open(&flash, 2);
    for n in 0..60 {
        store.save(&record(n)).unwrap();
        let (again, loaded) = open(&SmallFlash::holding(flash.bytes()), 2);
        assert_eq!((again.kept(), loaded), (&record(n), Ok(())), "after save {n}");
    }
    // Both sectors were erased and written again along the way.
    let erases = flash.erased_sectors();
    assert!(erases.iter().all(|&e| e >= 2), "erases per sector: {erases:?}");
}

/// Cuts the power after every byte of the save of `record(n)` over flash holding `before`, and
/// boots from what is left: the old record or the new one, and a store that saves again.
fn cut_every_byte_of_save(before: &[u8], n: usize) -> usize {
    // How many bytes the save writes or erases, uncut.
    let whole = SmallFlash::holding(before.to_vec());
    let (mut store, _) = open(&whole, 2);
    store.save(&record(n)).unwrap();
    let steps = whole.bytes_changed();
    let old = open(&SmallFlash::holding(before.to_vec()), 2).0.kept().clone();
    for cut in 0..steps {
        let flash = SmallFlash::holding(before.to_vec());
        let (mut store, _) = open(&flash, 2);
        flash.cut_power_after(cut);
        assert!(store.save(&record(n)).is_err(), "cut after {cut} of {steps} bytes");
        let rebooted = SmallFlash::holding(flash.bytes());
        let (mut store, loaded) = open(&rebooted, 2);
        assert!(
            matches!(loaded, Ok(()) | Err(StoreError::Repaired)),
            "save {n} cut after {cut} of {steps} bytes: {loaded:?}"
        );
        let kept = store.kept().clone();
        assert!(kept == old || kept == record(n), "save {n} cut after {cut} of {steps} bytes: a mix");
        // The store works on: the next save reads back.
        store.save(&record(n + 1)).unwrap();
        assert_eq!(open(&SmallFlash::holding(rebooted.bytes()), 2).0.kept(), &record(n + 1));
    }
    steps as usize
}

#[test]
fn a_power_cut_anywhere_in_a_save_leaves_the_old_record_or_the_new() {
    let flash = SmallFlash::erased(2);
    let (mut store, _) = open(&flash, 2);
    let mut steps = 0;
    let mut erasing_saves = 0;
    // Enough saves to fill both sectors more than once: some of them erase a sector.
    for n in 0..30 {
        let before = flash.bytes();
        let save_steps = cut_every_byte_of_save(&before, n);
        steps += save_steps;
        erasing_saves += usize::from(save_steps > SMALL_SECTOR_BYTES);
        store.save(&record(n)).unwrap();
    }
    assert!(erasing_saves >= 2, "{erasing_saves} saves erased a sector");
    assert!(steps > 30 * 100, "{steps} cuts");
}

#[test]
fn a_power_cut_anywhere_in_a_save_on_the_boards_sectors() {
    // The board's geometry: 128 KiB sectors, so no save here erases.
    let flash = BoardFlash::default();
    let (mut store, _) = open(&flash, STORE_SECTORS);
    store.save(&record(1)).unwrap();
    let before = flash.bytes();
    let whole = BoardFlash::holding(before.clone());
    open(&whole, STORE_SECTORS).0.save(&record(2)).unwrap();
    for cut in 0..whole.bytes_changed() {
        let flash = BoardFlash::holding(before.clone());
        let (mut store, _) = open(&flash, STORE_SECTORS);
        flash.cut_power_after(cut);
        assert!(store.save(&record(2)).is_err());
        let (store, loaded) = open(&BoardFlash::holding(flash.bytes()), STORE_SECTORS);
        assert!(matches!(loaded, Ok(()) | Err(StoreError::Repaired)), "cut after {cut} bytes: {loaded:?}");
        assert!(store.kept() == &record(1) || store.kept() == &record(2), "cut after {cut} bytes: a mix");
    }
}

#[test]
fn flash_the_store_did_not_write_is_reported_and_written_over() {
    // A firmware image once flashed over these sectors: not a store.
    let garbage: Vec<u8> = (0..STORE_SECTORS * STORE_SECTOR_BYTES).map(|i| (i * 7 + i / 3) as u8).collect();
    let flash = BoardFlash::holding(garbage);
    let (mut store, loaded) = open(&flash, STORE_SECTORS);
    assert_eq!(loaded, Err(StoreError::Corrupt));
    assert_eq!(store.kept(), &Record::default());
    // Saving works: it erases a sector first.
    store.save(&record(3)).unwrap();
    assert_eq!(open(&BoardFlash::holding(flash.bytes()), STORE_SECTORS).0.kept(), &record(3));
}

#[test]
fn a_record_of_another_version_or_out_of_range_gives_the_defaults() {
    let mut buf = [0u8; RECORD_MAX_BYTES];
    let n = record(5).encode(&mut buf);
    // The same record written by a firmware whose layout tag differs.
    let mut other = buf;
    other[..2].copy_from_slice(&(LAYOUT_TAG ^ 0x5a5a).to_le_bytes());
    // And one whose steps/mm ($100, the fifth value) are out of range.
    let mut invalid = buf;
    invalid[2 + 4 * 4..][..4].copy_from_slice(&(-1.0f32).to_le_bytes());
    for (bytes, error) in [(other, StoreError::OtherVersion), (invalid, StoreError::Invalid)] {
        let flash = BoardFlash::default();
        let (mut store, _) = open(&flash, STORE_SECTORS);
        store.buf[4..4 + n].copy_from_slice(&bytes[..n]);
        store.append(n).unwrap();
        let (store, loaded) = open(&BoardFlash::holding(flash.bytes()), STORE_SECTORS);
        assert_eq!((loaded, store.kept()), (Err(error), &Record::default()));
    }
}

#[test]
fn one_flipped_bit_anywhere_leaves_the_newest_intact_record() {
    // Many records over both sectors (some saves erased a sector and moved on).
    let flash = SmallFlash::erased(2);
    let (mut store, _) = open(&flash, 2);
    let saves = 25;
    for n in 0..saves {
        store.save(&record(n)).unwrap();
    }
    assert!(flash.erased_sectors().iter().sum::<u32>() >= 2, "both sectors used");
    let bytes = flash.bytes();
    // The bytes of the newest record: a bit flipped there leaves the one saved before it.
    let s = store.newest().unwrap();
    let (at, len) = store.sectors[s].last.unwrap();
    let start = store.sector_start(s) as usize + at;
    let newest = start..start + (len + RECORD_OVERHEAD_BYTES).next_multiple_of(ALIGN_BYTES);
    for bit in 0..bytes.len() * 8 {
        let mut flipped = bytes.clone();
        flipped[bit / 8] ^= 1 << (bit % 8);
        let (store, loaded) = open(&SmallFlash::holding(flipped), 2);
        let want = if newest.contains(&(bit / 8)) { record(saves - 2) } else { record(saves - 1) };
        assert!(store.kept() == &want, "bit {bit} (byte {}) flipped: not the newest intact record", bit / 8);
        assert!(matches!(loaded, Ok(()) | Err(StoreError::Repaired)), "bit {bit}: {loaded:?}");
        if newest.contains(&(bit / 8)) {
            assert_eq!(loaded, Err(StoreError::Repaired), "bit {bit}: the damage is reported");
        }
    }
}

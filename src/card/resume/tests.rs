//! Tests of the resume record's bytes and of the choice between the file's two slots.

extern crate std;

use proptest::prelude::*;
use std::vec::Vec;

use super::*;
use crate::host::gcode::WORK_SYSTEMS;

/// A record a plot might keep: line 42 of a 5000-byte file, in G91 with offsets set.
fn sample(seq: u32) -> ResumeRecord {
    let mut kept_mm = [[0.0; 2]; KEPT_OFFSETS];
    kept_mm[1] = [12.5, -3.25];
    kept_mm[KEPT_OFFSETS - 1] = [100.0, 80.0];
    ResumeRecord {
        seq,
        file: String::try_from("SQUARE~1.GCO").unwrap(),
        name: String::try_from("square with a long name.gcode").unwrap(),
        file_bytes: 5000,
        offset: 1234,
        line: 42,
        after_cr: true,
        position: Point::new(-1500, 2750),
        lines: 120,
        modal: Modal {
            motion: MotionMode::ArcCcw,
            units: Units::Inch,
            distance: Distance::Incremental,
            work_system: WorkSystem::from_index(1).unwrap(),
            spindle: Spindle::Cw,
            coolant: Coolant::Off,
            feed_mm_per_min: Some(1800.0),
            spindle_speed: None,
            tool: 3,
            kept_mm,
            g92_mm: [1.0, 2.0],
        },
    }
}

/// `bytes` with its CRC made right again, so that a field's own check is what refuses it.
fn resealed(mut bytes: ResumeBytes) -> ResumeBytes {
    let crc = crc32(&bytes[..RESUME_RECORD_BYTES - 4]);
    bytes[RESUME_RECORD_BYTES - 4..].copy_from_slice(&crc.to_le_bytes());
    bytes
}

/// The sample's bytes with `f` done to them, resealed.
fn changed(f: impl FnOnce(&mut ResumeBytes)) -> Result<ResumeRecord, BadResume> {
    let mut bytes = sample(1).encode();
    f(&mut bytes);
    ResumeRecord::decode(&resealed(bytes))
}

/// Where the fields lie in the bytes (see `RESUME_RECORD_BYTES`).
const NAME_AT: usize = 12;
const PLACE_AT: usize = NAME_AT + CARD_SHORT_NAME_MAX_BYTES;
const MODES_AT: usize = PLACE_AT + 24;
const FEED_AT: usize = MODES_AT + 8;
const OFFSETS_AT: usize = FEED_AT + 8;

#[test]
fn a_record_reads_back_as_written() {
    let record = sample(7);
    let bytes = record.encode();
    assert_eq!(ResumeRecord::decode(&bytes), Ok(record.clone()));
    // A slot's bytes after the record are not the record's.
    let mut slot = [0xA5u8; RESUME_SLOT_BYTES];
    slot[..RESUME_RECORD_BYTES].copy_from_slice(&bytes);
    assert_eq!(ResumeRecord::decode(&slot), Ok(record));
}

#[test]
fn a_record_is_of_its_file_as_long_as_the_file_is_unchanged() {
    let record = sample(1);
    let mut file = CardFile { name: "square.gcode".try_into().unwrap(), short: record.file.clone(), bytes: 5000 };
    assert!(record.is_for(&file));
    file.bytes = 5001;
    assert!(!record.is_for(&file), "a file of another length has changed");
    file.bytes = 5000;
    file.short = "OTHER.NC".try_into().unwrap();
    assert!(!record.is_for(&file));
}

#[test]
fn bytes_that_are_not_a_record_say_why() {
    let bytes = sample(1).encode();
    assert_eq!(ResumeRecord::decode(&bytes[..RESUME_RECORD_BYTES - 1]), Err(BadResume::Short));
    assert_eq!(ResumeRecord::decode(&[0; RESUME_SLOT_BYTES]), Err(BadResume::Magic));
    assert_eq!(ResumeRecord::decode(&[0xFF; RESUME_SLOT_BYTES]), Err(BadResume::Magic));
    assert_eq!(changed(|b| b[4] = 2), Err(BadResume::Version));
    let mut damaged = bytes;
    damaged[PLACE_AT] ^= 0x10;
    assert_eq!(ResumeRecord::decode(&damaged), Err(BadResume::Checksum));

    assert_eq!(changed(|b| b[NAME_AT..PLACE_AT].fill(0)), Err(BadResume::Name), "no name");
    assert_eq!(changed(|b| b[NAME_AT] = 0xC3), Err(BadResume::Name), "not UTF-8");
    assert_eq!(changed(|b| b[NAME_AT + 1] = b'\n'), Err(BadResume::Name), "a control byte");
    assert_eq!(changed(|b| b[NAME_AT + 2] = 0), Err(BadResume::Name), "text after the end");

    let place = |file_bytes: u32, offset: u32, line: u32| {
        changed(|b| {
            for (k, word) in [file_bytes, offset, line].iter().enumerate() {
                b[PLACE_AT + 4 * k..PLACE_AT + 4 * k + 4].copy_from_slice(&word.to_le_bytes());
            }
        })
    };
    assert_eq!(place(100, 101, 2), Err(BadResume::Place), "past the file's end");
    assert_eq!(place(100, 50, 0), Err(BadResume::Place), "line 0");
    assert_eq!(place(100, 5, 7), Err(BadResume::Place), "more lines than bytes before");
    assert!(place(100, 100, 3).is_ok(), "the end of the file");
    let lines = |lines: u32| changed(|b| b[PLACE_AT + 20..PLACE_AT + 24].copy_from_slice(&lines.to_le_bytes()));
    assert_eq!(lines(40), Err(BadResume::Place), "line 42 of a file of 40 lines");
    assert!(lines(41).is_ok(), "the end of a file of 41 lines");

    for (at, value) in [(0, 5), (1, 2), (2, 2), (3, WORK_SYSTEMS as u8), (4, 3), (5, 2), (6, 1), (7, 1)] {
        assert_eq!(changed(|b| b[MODES_AT + at] = value), Err(BadResume::Mode), "mode byte {at} = {value}");
    }
    assert_eq!(changed(|b| b[6] |= 8), Err(BadResume::Mode), "an unknown flag");

    let nan = f32::NAN.to_le_bytes();
    assert_eq!(changed(|b| b[FEED_AT..FEED_AT + 4].copy_from_slice(&nan)), Err(BadResume::Number));
    let negative = (-1.0f32).to_le_bytes();
    assert_eq!(changed(|b| b[FEED_AT..FEED_AT + 4].copy_from_slice(&negative)), Err(BadResume::Number));
    let one = 1.0f32.to_le_bytes();
    assert_eq!(changed(|b| b[FEED_AT + 4..FEED_AT + 8].copy_from_slice(&one)), Err(BadResume::Number), "S unset");
    let infinite = f32::INFINITY.to_le_bytes();
    assert_eq!(changed(|b| b[OFFSETS_AT + 12..OFFSETS_AT + 16].copy_from_slice(&infinite)), Err(BadResume::Number));
}

/// Slots holding `a` and `b` (`None`: never written).
fn slots(a: Option<ResumeBytes>, b: Option<ResumeBytes>) -> ResumeSlots {
    ResumeSlots { slots: [a.unwrap_or([0; RESUME_RECORD_BYTES]), b.unwrap_or([0; RESUME_RECORD_BYTES])] }
}

#[test]
fn the_newest_valid_record_is_read_and_the_next_store_goes_to_the_other_slot() {
    let empty = ResumeSlots::new();
    assert_eq!(empty.newest(), None);
    assert_eq!(empty.next_write(), (0, 1));

    let first = slots(Some(sample(1).encode()), None);
    assert_eq!(first.newest(), Some((0, sample(1))));
    assert_eq!(first.next_write(), (1, 2));

    let both = slots(Some(sample(3).encode()), Some(sample(4).encode()));
    assert_eq!(both.newest(), Some((1, sample(4))));
    assert_eq!(both.next_write(), (0, 5));
    let swapped = slots(Some(sample(6).encode()), Some(sample(5).encode()));
    assert_eq!(swapped.newest(), Some((0, sample(6))));
    assert_eq!(swapped.next_write(), (1, 7));
}

#[test]
fn a_torn_store_leaves_the_record_before_it() {
    let old = sample(8).encode();
    let mut new = sample(9);
    new.line = 43;
    let new = new.encode();
    // Cut part way through the write: the slot holds the new bytes up to the cut, then what
    // was there (a record two stores older, or nothing).
    for cut in 1..RESUME_RECORD_BYTES {
        for before in [sample(7).encode(), [0; RESUME_RECORD_BYTES], [0xFF; RESUME_RECORD_BYTES]] {
            let mut torn = before;
            torn[..cut].copy_from_slice(&new[..cut]);
            let slots = slots(Some(old), Some(torn));
            let expected = if torn == new { 9 } else { 8 };
            assert_eq!(slots.newest().map(|(_, r)| r.seq), Some(expected), "cut at {cut}");
        }
    }
    let garbage = slots(Some([0x5A; RESUME_RECORD_BYTES]), Some(old));
    assert_eq!(garbage.newest(), Some((1, sample(8))));
    assert_eq!(garbage.next_write(), (0, 9));
    let both_bad = slots(Some([0x5A; RESUME_RECORD_BYTES]), Some(resealed([0x11; RESUME_RECORD_BYTES])));
    assert_eq!(both_bad.newest(), None);
}

#[test]
fn sequence_numbers_wrap() {
    let wrapped = slots(Some(sample(u32::MAX).encode()), Some(sample(0).encode()));
    assert_eq!(wrapped.newest(), Some((1, sample(0))));
    assert_eq!(wrapped.next_write(), (0, 1));
    let at_the_top = slots(Some(sample(u32::MAX - 1).encode()), Some(sample(u32::MAX).encode()));
    assert_eq!(at_the_top.next_write(), (0, 0));
    assert!(newer(0, u32::MAX) && !newer(u32::MAX, 0) && !newer(5, 5));
}

/// Any valid record.
fn any_record() -> impl Strategy<Value = ResumeRecord> {
    let name = (prop::collection::vec(prop::sample::select(b"ABCXYZ019_~-".to_vec()), 1..=8), 0usize..=3).prop_map(
        |(base, ext)| {
            let mut text: std::string::String = base.iter().map(|&b| char::from(b)).collect();
            if ext > 0 {
                text.push('.');
                text.extend(core::iter::repeat_n('N', ext));
            }
            String::<CARD_SHORT_NAME_MAX_BYTES>::try_from(text.as_str()).unwrap()
        },
    );
    let place = (any::<u32>(), any::<u32>(), any::<u32>(), any::<u32>(), any::<bool>()).prop_map(
        |(file_bytes, o, l, more, after_cr)| {
            let offset = if file_bytes == 0 { 0 } else { o % (file_bytes + 1) };
            let line = if offset == u32::MAX { l.max(1) } else { 1 + l % (offset + 1) };
            (file_bytes, offset, line, (line - 1).saturating_add(more), after_cr)
        },
    );
    let value = -1.0e6f32..1.0e6;
    let modes = (0u8..5, 0u8..2, 0u8..2, 0..WORK_SYSTEMS, 0u8..3, 0u8..2, any::<u8>());
    let numbers = (
        prop::option::of(0.0f32..1.0e5),
        prop::option::of(0.0f32..1.0e5),
        prop::array::uniform8(prop::array::uniform2(value.clone())),
        prop::array::uniform2(value),
    );
    (any::<u32>(), name, place, any::<(i32, i32)>(), modes, numbers).prop_map(
        |(seq, file, (file_bytes, offset, line, lines, after_cr), (x, y), modes, numbers)| {
            let (motion, units, distance, system, spindle, coolant, tool) = modes;
            let (feed_mm_per_min, spindle_speed, kept_mm, g92_mm) = numbers;
            ResumeRecord {
                seq,
                name: file.as_str().try_into().unwrap(),
                file,
                file_bytes,
                offset,
                line,
                after_cr,
                position: Point::new(x, y),
                lines,
                modal: Modal {
                    motion: motion_of(motion).unwrap(),
                    units: units_of(units).unwrap(),
                    distance: distance_of(distance).unwrap(),
                    work_system: WorkSystem::from_index(system).unwrap(),
                    spindle: spindle_of(spindle).unwrap(),
                    coolant: coolant_of(coolant).unwrap(),
                    feed_mm_per_min,
                    spindle_speed,
                    tool,
                    kept_mm,
                    g92_mm,
                },
            }
        },
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn random_bytes_never_decode(bytes in prop::collection::vec(any::<u8>(), 0..RESUME_SLOT_BYTES)) {
        prop_assert!(ResumeRecord::decode(&bytes).is_err());
    }

    #[test]
    fn random_bytes_behind_a_right_header_never_decode(rest in prop::collection::vec(any::<u8>(), RESUME_RECORD_BYTES - 6)) {
        let mut bytes = Vec::from(RESUME_MAGIC.to_le_bytes());
        bytes.extend_from_slice(&RESUME_FORMAT.to_le_bytes());
        bytes.extend_from_slice(&rest);
        prop_assert_eq!(ResumeRecord::decode(&bytes), Err(BadResume::Checksum));
    }

    #[test]
    fn any_record_round_trips(record in any_record()) {
        prop_assert_eq!(ResumeRecord::decode(&record.encode()), Ok(record));
    }

    #[test]
    fn flipping_any_bit_of_a_record_refuses_it(record in any_record(), bit in 0..RESUME_RECORD_BYTES * 8) {
        let mut bytes = record.encode();
        bytes[bit / 8] ^= 1 << (bit % 8);
        prop_assert!(ResumeRecord::decode(&bytes).is_err());
    }
}

//! Tests of the simulator's card: files listed and read from a FAT image, and the resume
//! record stored on it.

use super::*;
use crate::card::resume::{
    RESUME_FILE_BYTES, RESUME_FILE_NAME, RESUME_RECORD_BYTES, RESUME_SLOT_BYTES, RESUME_SLOTS, ResumeRecord,
};
use crate::card::{Card, CardError, CardLine, CardLines, NoSlot};
use crate::geom::Point;
use crate::host::GcodeState;
use crate::settings::Settings;
use crate::status::RunState;

fn lines_of(card: &mut SimCard, index: usize) -> Vec<String> {
    let files = card.files().unwrap();
    card.open(files.get(index).unwrap()).unwrap();
    let mut lines = CardLines::new();
    let mut out = Vec::new();
    while let CardLine::Line { text, .. } = lines.next(card).unwrap() {
        out.push(text.into());
    }
    out
}

#[test]
fn the_card_lists_its_gcode_files_and_reads_them() {
    let big: String = (0..2000).map(|i| std::format!("G1 X{} Y{}\n", i % 50, i % 30)).collect();
    let image = image_of(&[
        ("square.gcode", b"G0 X0 Y0\nG1 X10\n"),
        ("NOTES.TXT", b"not G-code"),
        ("A Long Name For A Plot.NC", big.as_bytes()),
    ])
    .unwrap();
    let mut card = FatCard::new(ImageBlocks::new(image));
    let files = card.files().unwrap();
    let names: Vec<&str> = files.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["A Long Name For A Plot.NC", "square.gcode"]);
    assert_eq!(lines_of(&mut card, 1), ["G0X0Y0", "G1X10"]);
    let long = lines_of(&mut card, 0);
    assert_eq!(long.len(), 2000);
    assert_eq!(long[1999], "G1X49Y19");
    assert_eq!(files.get(0).unwrap().bytes as usize, big.len());
}

#[test]
fn a_card_with_a_partition_table_reads_the_same() {
    let bare = image_of(&[("plot.nc", b"G0 X1\nG1 Y2\n")]).unwrap();
    let mut image = std::vec![0u8; BLOCK_BYTES];
    let entry = &mut image[446..462];
    entry[4] = 0x0E;
    entry[8..12].copy_from_slice(&1u32.to_le_bytes());
    entry[12..16].copy_from_slice(&((bare.len() / BLOCK_BYTES) as u32).to_le_bytes());
    image[510..512].copy_from_slice(&[0x55, 0xAA]);
    image.extend_from_slice(&bare);
    let mut card = FatCard::new(ImageBlocks::new(image));
    assert_eq!(lines_of(&mut card, 0), ["G0X1", "G1Y2"]);
}

#[test]
fn a_card_that_is_not_fat_says_so() {
    let mut card = FatCard::new(ImageBlocks::new(std::vec![0x5Au8; 64 * BLOCK_BYTES]));
    assert_eq!(card.files(), Err(CardError::NotFat));
}

#[test]
fn a_file_gone_from_the_card_says_so() {
    let mut card = FatCard::new(ImageBlocks::new(image_of(&[("A.NC", b"G0X1\n")]).unwrap()));
    let mut file = card.files().unwrap().get(0).unwrap().clone();
    file.short = "B.NC".try_into().unwrap();
    assert_eq!(card.open(&file), Err(CardError::NoSuchFile));
    // The card is still read after the failure.
    assert_eq!(card.files().unwrap().len(), 1);
}

/// A plot's file: enough lines to span many blocks.
fn plot_file() -> String {
    (0..1500).map(|i| std::format!("G1 X{} Y{} F{}\n", i % 70, i % 40, 1000 + i)).collect()
}

/// A record for line `line` of the plot file, its parser in G91 with G55 offset.
fn record(line: u32) -> ResumeRecord {
    let settings = Settings::default();
    let mut gcode = GcodeState::new();
    for l in ["G10 L2 P2 X5 Y-3", "G55 G91", "G1 X1 F800"] {
        gcode.execute(l, &settings, RunState::Idle).unwrap();
    }
    ResumeRecord {
        seq: 0,
        file: "PLOT.NC".try_into().unwrap(),
        name: "plot.nc".try_into().unwrap(),
        file_bytes: plot_file().len() as u32,
        offset: line * 10,
        line,
        after_cr: false,
        position: Point::new(line as i32 * 3, -7),
        lines: 1500,
        modal: gcode.modal(),
    }
}

/// The resume record's file as a PC reads it (through another FAT implementation).
fn resume_file(image: &[u8]) -> Option<Vec<u8>> {
    let fs = fatfs::FileSystem::new(Cursor::new(image.to_vec()), fatfs::FsOptions::new()).unwrap();
    let mut file = fs.root_dir().open_file(RESUME_FILE_NAME).ok()?;
    let mut bytes = Vec::new();
    file.read_to_end(&mut bytes).unwrap();
    Some(bytes)
}

/// The sequence number of the record in each slot of the file, if valid.
fn slot_seqs(image: &[u8]) -> [Option<u32>; RESUME_SLOTS] {
    let file = resume_file(image).expect("the resume record's file");
    assert_eq!(file.len(), RESUME_FILE_BYTES);
    core::array::from_fn(|i| ResumeRecord::decode(&file[i * RESUME_SLOT_BYTES..]).ok().map(|r| r.seq))
}

fn fat16_card() -> SimCard {
    FatCard::new(ImageBlocks::new(image_of(&[("plot.nc", plot_file().as_bytes())]).unwrap()))
}

fn fat32_card() -> SimCard {
    let image = fat32_image_of(&[("plot.nc", plot_file().as_bytes())]).unwrap();
    // The boot sector's file system type, and no 16-bit FAT size: FAT32.
    assert_eq!((&image[82..87], &image[22..24]), (&b"FAT32"[..], &[0u8, 0][..]));
    FatCard::new(ImageBlocks::new(image))
}

#[test]
fn a_record_stored_on_a_fat16_or_fat32_card_loads_back_after_a_restart() {
    for (kind, mut card) in [("FAT16", fat16_card()), ("FAT32", fat32_card())] {
        assert_eq!(card.load_resume(), Ok(None), "{kind}: no record yet");
        assert_eq!(resume_file(&card.image()), None, "{kind}: nothing written by loading");
        let mut first = record(10);
        card.store_resume(&mut first).unwrap();
        assert_eq!(first.seq, 1);
        assert_eq!(card.load_resume(), Ok(Some(first.clone())), "{kind}");
        let mut second = record(11);
        card.store_resume(&mut second).unwrap();
        assert_eq!(second.seq, 2);
        // Power off and on: a new card from the same bytes.
        let mut again = FatCard::new(ImageBlocks::new(card.image()));
        assert_eq!(again.load_resume(), Ok(Some(second)), "{kind}");
        // The card is still whole: its files list and read as before.
        assert_eq!(lines_of(&mut again, 0).len(), 1500, "{kind}");
    }
}

#[test]
fn stores_alternate_between_the_two_slots() {
    let mut card = fat16_card();
    let mut expected = [None, None];
    for n in 1..=5u32 {
        card.store_resume(&mut record(n)).unwrap();
        expected[(n as usize + 1) % 2] = Some(n);
        assert_eq!(slot_seqs(&card.image()), expected, "after store {n}");
    }
}

/// `image` with the first half of `stored`'s bytes (found where they lie) overwritten.
fn corrupted(image: &[u8], stored: &ResumeRecord) -> Vec<u8> {
    let bytes = stored.encode();
    let at = image.windows(bytes.len()).position(|w| w == bytes).expect("the record's bytes in the image");
    let mut image = image.to_vec();
    image[at..at + RESUME_RECORD_BYTES / 2].fill(0x5A);
    image
}

#[test]
fn a_corrupted_slot_loads_the_other_and_two_load_none() {
    let mut card = fat32_card();
    let (mut older, mut newer) = (record(20), record(21));
    card.store_resume(&mut older).unwrap();
    card.store_resume(&mut newer).unwrap();

    let torn = corrupted(&card.image(), &newer);
    let mut after_cut = FatCard::new(ImageBlocks::new(torn.clone()));
    assert_eq!(after_cut.load_resume(), Ok(Some(older.clone())));
    // The next store goes over the damaged slot, numbered after the record kept.
    let mut next = record(22);
    after_cut.store_resume(&mut next).unwrap();
    assert_eq!(next.seq, 2);
    assert_eq!(slot_seqs(&after_cut.image()), [Some(1), Some(2)]);

    let mut both = FatCard::new(ImageBlocks::new(corrupted(&torn, &older)));
    assert_eq!(both.load_resume(), Ok(None));
}

#[test]
fn a_cleared_record_is_gone_and_the_next_plot_stores_afresh() {
    let mut card = fat16_card();
    for n in 1..=3 {
        card.store_resume(&mut record(n)).unwrap();
    }
    card.clear_resume().unwrap();
    assert_eq!(card.load_resume(), Ok(None));
    assert_eq!(slot_seqs(&card.image()), [None, None]);
    let mut fresh = record(1);
    card.store_resume(&mut fresh).unwrap();
    assert_eq!(FatCard::new(ImageBlocks::new(card.image())).load_resume(), Ok(Some(fresh)));
}

#[test]
fn the_plot_file_reads_on_while_records_are_stored() {
    for (kind, mut card) in [("FAT16", fat16_card()), ("FAT32", fat32_card())] {
        let unstored = lines_of(&mut card, 0);
        let file = card.files().unwrap().get(0).unwrap().clone();
        card.open(&file).unwrap();
        let mut lines = CardLines::new();
        let mut read = Vec::new();
        while let CardLine::Line { number, text } = lines.next(&mut card).unwrap() {
            read.push(String::from(text));
            let mut kept = record(number);
            kept.offset = lines.bytes_done();
            card.store_resume(&mut kept).unwrap();
            assert_eq!(card.load_resume().unwrap().map(|r| r.line), Some(number));
        }
        assert_eq!(read, unstored, "{kind}");
        card.close();
        // Both files are whole for a PC too.
        let image = card.image();
        let fs = fatfs::FileSystem::new(Cursor::new(image.clone()), fatfs::FsOptions::new()).unwrap();
        let mut plot = Vec::new();
        fs.root_dir().open_file("plot.nc").unwrap().read_to_end(&mut plot).unwrap();
        assert_eq!(plot, plot_file().as_bytes(), "{kind}");
        assert_eq!(slot_seqs(&image).iter().flatten().max(), Some(&1500), "{kind}");
    }
}

#[test]
fn a_record_file_too_short_is_filled_out_at_the_first_store() {
    let image = image_of(&[("plot.nc", b"G0 X1\n"), (RESUME_FILE_NAME, b"short")]).unwrap();
    let mut card = FatCard::new(ImageBlocks::new(image));
    assert_eq!(card.load_resume(), Ok(None));
    let mut kept = record(1);
    kept.file_bytes = 6;
    kept.offset = 6;
    card.store_resume(&mut kept).unwrap();
    assert_eq!(slot_seqs(&card.image()), [Some(1), None]);
    assert_eq!(FatCard::new(ImageBlocks::new(card.image())).load_resume(), Ok(Some(kept)));
}

#[test]
fn a_board_without_a_slot_has_no_record_to_load_or_store() {
    let mut none = NoSlot;
    assert_eq!(none.load_resume(), Err(CardError::NoCard));
    assert_eq!(none.store_resume(&mut record(1)), Err(CardError::NoCard));
}

//! The microSD card: which of its files are G-code, and their lines.
//!
//! This module owns what the plotter makes of a card: the list of its G-code files
//! ([`names`]), the lines of the file being plotted, framed by the host links' own rules
//! ([`lines`]), the resume record a plot keeps on the card ([`resume`]) and which of its lines
//! has completed for it ([`keeper`]), and the FAT volume on the card's 512-byte blocks
//! ([`fat`], through the `embedded-sdmmc` crate). The boards give the blocks: the simulator a
//! FAT image file, the F407 the card on SPI. Everything here is synchronous and owns no pin;
//! the card is reached through [`Card`], which the boards implement.

pub mod fat;
pub mod keeper;
pub mod lines;
pub mod names;
pub mod resume;
pub mod slot;

use resume::{RESUME_RECORD_BYTES, ResumeBytes, ResumeRecord, ResumeSlots};

pub use lines::{CardLine, CardLines};
pub use names::{CARD_FILES_MAX, CARD_NAME_MAX_BYTES, CardFile, CardFiles, FileName, is_gcode_name};
pub use slot::{CardFacts, CardPicture, CardProgress, CardSlot, CardStop, NoSlot, ResumeOffer};

/// Why the card gave no files or no bytes. Each says so on the LCD and in a log line; nothing
/// moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum CardError {
    /// No card in the slot (the card-detect input, or no card answered).
    NoCard,
    /// The card holds no FAT16 or FAT32 volume.
    NotFat,
    /// The card answered, but a read or a write failed (or it was removed meanwhile).
    Unreadable,
    /// The file chosen is no longer on the card.
    NoSuchFile,
}

impl CardError {
    /// What the log line says.
    pub const fn message(self) -> &'static str {
        match self {
            CardError::NoCard => "No card",
            CardError::NotFat => "Card is not FAT16/FAT32",
            CardError::Unreadable => "Card unreadable",
            CardError::NoSuchFile => "File not on the card",
        }
    }
}

/// A card slot, as the boards give it: the card's G-code files, and the bytes of one of them
/// at a time.
pub trait Card {
    /// The G-code files in the card's top folder, sorted (at most [`CARD_FILES_MAX`]).
    fn files(&mut self) -> Result<CardFiles, CardError>;
    /// Opens `file` to be read from its start (closing any file open before); gives its
    /// length in bytes.
    fn open(&mut self, file: &CardFile) -> Result<u32, CardError>;
    /// The open file's next bytes, into `buf`: how many, 0 at its end.
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, CardError>;
    /// The open file is read on from byte `offset` (at most its length).
    fn seek(&mut self, offset: u32) -> Result<(), CardError>;
    /// Closes the open file, if any.
    fn close(&mut self);

    /// Reads the resume record's file ([`resume`]) into `slots`: each slot's record bytes,
    /// zeros where the card has no file or the file no such slot. The open file stays open, and
    /// is read on from where it was. By default the slot keeps no record: [`CardError::NoCard`].
    fn read_resume(&mut self, _slots: &mut ResumeSlots) -> Result<(), CardError> {
        Err(CardError::NoCard)
    }
    /// Writes `bytes` at the start of slot `slot` of the resume record's file, and nowhere
    /// else: the other slot is not written (but for the zeros that first fill out a file made
    /// now, or one shorter than its two slots). The open file stays open, and is read on from
    /// where it was. By default the slot keeps no record: [`CardError::NoCard`].
    fn write_resume(&mut self, _slot: usize, _bytes: &ResumeBytes) -> Result<(), CardError> {
        Err(CardError::NoCard)
    }

    /// The newest valid resume record on the card, if it holds one.
    fn load_resume(&mut self) -> Result<Option<ResumeRecord>, CardError> {
        let mut slots = ResumeSlots::new();
        self.read_resume(&mut slots)?;
        Ok(slots.newest().map(|(_, record)| record))
    }

    /// Stores `record` in the slot not holding the newest valid record, numbered after it (its
    /// `seq` is set to that number): a power cut meanwhile leaves the record before it.
    fn store_resume(&mut self, record: &mut ResumeRecord) -> Result<(), CardError> {
        let mut slots = ResumeSlots::new();
        self.read_resume(&mut slots)?;
        let (slot, seq) = slots.next_write();
        record.seq = seq;
        self.write_resume(slot, &record.encode())
    }

    /// Leaves the card with no valid resume record (the plot is over): the older slot is
    /// emptied first, so a power cut meanwhile leaves the newest record, never an older one.
    fn clear_resume(&mut self) -> Result<(), CardError> {
        let mut slots = ResumeSlots::new();
        self.read_resume(&mut slots)?;
        let Some((newest, _)) = slots.newest_seq() else {
            return Ok(());
        };
        let empty = [0; RESUME_RECORD_BYTES];
        self.write_resume(1 - newest, &empty)?;
        self.write_resume(newest, &empty)
    }
}

//! The microSD card: which of its files are G-code, and their lines.
//!
//! This module owns what the plotter makes of a card: the list of its G-code files
//! ([`names`]), the lines of the file being plotted, framed by the host links' own rules
//! ([`lines`]), and the FAT volume on the card's 512-byte blocks ([`fat`], through the
//! `embedded-sdmmc` crate). The boards give the blocks: the simulator a FAT image file, the
//! F407 the card on SPI. Everything here is synchronous and owns no pin; the card is reached
//! through [`Card`], which the boards implement.

pub mod fat;
pub mod lines;
pub mod names;
pub mod resume;
pub mod slot;

pub use lines::{CardLine, CardLines};
pub use names::{CARD_FILES_MAX, CARD_NAME_MAX_BYTES, CardFile, CardFiles, FileName, is_gcode_name};
pub use slot::{CardFacts, CardPicture, CardProgress, CardSlot, CardStop, NoSlot};

/// Why the card gave no files or no bytes. Each says so on the LCD and in a log line; nothing
/// moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum CardError {
    /// No card in the slot (the card-detect input, or no card answered).
    NoCard,
    /// The card holds no FAT16 or FAT32 volume.
    NotFat,
    /// The card answered, but a read failed (or it was removed while read).
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
    /// Closes the open file, if any.
    fn close(&mut self);
}

//! The card mode's screen: the card's G-code files (read by the keypad task when the mode is
//! entered), a cursor on one, or why the card gave none.

use crate::card::{CardError, CardFile, CardFiles};
use crate::panel::keypad::Key;

use super::list;

/// What the card mode shows.
#[derive(Clone, Debug, PartialEq)]
pub struct CardList {
    /// The files read, or why none were; `None` until the card is read.
    files: Option<Result<CardFiles, CardError>>,
    /// The cursor, in the files.
    at: usize,
}

impl CardList {
    /// The card mode entered: the card is being read.
    pub const fn reading() -> Self {
        CardList { files: None, at: 0 }
    }

    /// The keypad task read the card.
    pub fn read(&mut self, files: Result<CardFiles, CardError>) {
        *self = CardList { files: Some(files), at: 0 };
    }

    /// The files, once read (`None` before, or if the card gave none).
    pub fn files(&self) -> Option<&CardFiles> {
        self.files.as_ref()?.as_ref().ok()
    }

    /// Why the card gave no files, if it did not.
    pub fn error(&self) -> Option<CardError> {
        self.files.as_ref()?.as_ref().err().copied()
    }

    /// The cursor's place in the files.
    pub fn at(&self) -> usize {
        self.at
    }

    /// `A`/`B` move the cursor (digits do not: file numbers would change as files come and go);
    /// `#` gives the file under the cursor, to plot.
    pub fn press(&mut self, key: Key) -> Option<CardFile> {
        let files = self.files()?;
        match key {
            Key::A | Key::B => {
                self.at = list::moved(self.at, files.len(), key);
                None
            }
            Key::Hash => files.get(self.at).cloned(),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn three() -> CardFiles {
        let mut files = CardFiles::new();
        for name in ["A.NC", "B.NC", "C.NC"] {
            files.offer(name, None, 1);
        }
        files
    }

    #[test]
    fn keys_move_over_the_files_and_hash_chooses_one() {
        let mut list = CardList::reading();
        assert_eq!(list.press(Key::Hash), None, "nothing to choose before the card is read");
        list.read(Ok(three()));
        for key in [Key::B, Key::B, Key::B, Key::Digit(1)] {
            assert_eq!(list.press(key), None);
        }
        assert_eq!(list.at(), 2, "stops at the last file; digits do not move");
        let _ = list.press(Key::A);
        assert_eq!(list.press(Key::Hash).map(|f| f.short), Some("B.NC".try_into().unwrap()));
    }

    #[test]
    fn a_card_without_files_chooses_nothing() {
        let mut list = CardList::reading();
        list.read(Err(CardError::NoCard));
        assert_eq!(list.error(), Some(CardError::NoCard));
        assert_eq!(list.press(Key::Hash), None);
        list.read(Ok(CardFiles::new()));
        assert_eq!(list.press(Key::Hash), None);
    }
}

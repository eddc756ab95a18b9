//! Which of a card's files are G-code, their list as the keypad shows it, and a name cut to
//! the LCD's line.

use heapless::{String, Vec};

/// Files the card's list holds: beyond this many G-code files, the first ones in name order
/// are listed. The list lives in the menu (about 1.3 KB on the board).
pub const CARD_FILES_MAX: usize = 24;
/// Longest file name kept, in bytes: more than the LCD's line shows (a long name beyond it is
/// shown by its 8.3 name).
pub const CARD_NAME_MAX_BYTES: usize = 32;
/// A short (8.3) name as `NAME.EXT`: 12 bytes.
pub const CARD_SHORT_NAME_MAX_BYTES: usize = 12;

/// The endings of G-code files, upper or lower case.
const GCODE_ENDINGS: [&str; 4] = [".gcode", ".nc", ".gc", ".ngc"];

/// A file name as shown.
pub type FileName = String<CARD_NAME_MAX_BYTES>;

/// One G-code file on the card.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CardFile {
    /// The name shown: the long name if the card has one that fits, else the 8.3 name.
    pub name: FileName,
    /// The 8.3 name (`NAME.EXT`), by which the file is opened.
    pub short: String<CARD_SHORT_NAME_MAX_BYTES>,
    /// Its length in bytes.
    pub bytes: u32,
}

/// Whether `name` ends in one of the G-code endings, in any case.
pub fn is_gcode_name(name: &str) -> bool {
    GCODE_ENDINGS.iter().any(|ending| {
        name.len() > ending.len() && {
            let start = name.len() - ending.len();
            name.is_char_boundary(start) && name[start..].eq_ignore_ascii_case(ending)
        }
    })
}

/// `name`'s first `columns` characters: what fits the LCD's line.
pub fn cut_to(name: &str, columns: usize) -> &str {
    match name.char_indices().nth(columns) {
        Some((end, _)) => &name[..end],
        None => name,
    }
}

/// The card's G-code files in name order (case-blind), at most [`CARD_FILES_MAX`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CardFiles {
    files: Vec<CardFile, CARD_FILES_MAX>,
}

impl CardFiles {
    pub const fn new() -> Self {
        CardFiles { files: Vec::new() }
    }

    /// Takes a directory entry: kept if it is a G-code file (by its long name or its 8.3
    /// name) and among the first [`CARD_FILES_MAX`] in name order.
    pub fn offer(&mut self, short: &str, long: Option<&str>, bytes: u32) {
        if !long.is_some_and(is_gcode_name) && !is_gcode_name(short) {
            return;
        }
        let shown = long.filter(|l| l.len() <= CARD_NAME_MAX_BYTES).unwrap_or(short);
        let (Ok(name), Ok(short)) = (FileName::try_from(shown), String::try_from(short)) else {
            return;
        };
        let file = CardFile { name, short, bytes };
        let at = self.files.partition_point(|f| before(&f.name, &file.name));
        if self.files.is_full() {
            if at == self.files.len() {
                return;
            }
            self.files.pop();
        }
        // Room was made above.
        let _ = self.files.insert(at, file);
    }

    pub fn len(&self) -> usize {
        self.files.len()
    }

    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }

    pub fn get(&self, index: usize) -> Option<&CardFile> {
        self.files.get(index)
    }

    pub fn iter(&self) -> impl Iterator<Item = &CardFile> {
        self.files.iter()
    }
}

/// Name order: case-blind, then by bytes.
fn before(a: &str, b: &str) -> bool {
    let blind_a = a.bytes().map(|c| c.to_ascii_lowercase());
    match blind_a.cmp(b.bytes().map(|c| c.to_ascii_lowercase())) {
        core::cmp::Ordering::Equal => a < b,
        order => order.is_lt(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gcode_endings_in_any_case_and_nothing_else() {
        for name in ["A.GCODE", "part.gcode", "X.NC", "y.nc", "Z.Gc", "w.NGC", "long name.Ngc"] {
            assert!(is_gcode_name(name), "{name}");
        }
        for name in ["README.TXT", "a.gco", "nc", ".nc", "a.ncx", "gcode", "a.g", "NC.TXT"] {
            assert!(!is_gcode_name(name), "{name}");
        }
    }

    #[test]
    fn list_keeps_gcode_files_sorted_case_blind() {
        let mut files = CardFiles::new();
        files.offer("ZEBRA.NC", None, 10);
        files.offer("NOTES.TXT", None, 5);
        files.offer("APPLE~1.GCO", Some("apple pie.gcode"), 20);
        files.offer("BIRD.GC", None, 30);
        let names: std::vec::Vec<_> = files.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, ["apple pie.gcode", "BIRD.GC", "ZEBRA.NC"]);
        assert_eq!(files.get(0).unwrap().short.as_str(), "APPLE~1.GCO");
        assert_eq!(files.get(0).unwrap().bytes, 20);
    }

    #[test]
    fn a_full_list_keeps_the_first_names() {
        let mut files = CardFiles::new();
        for i in (0..CARD_FILES_MAX + 5).rev() {
            let name = std::format!("F{i:03}.NC");
            files.offer(&name, None, 1);
        }
        assert_eq!(files.len(), CARD_FILES_MAX);
        assert_eq!(files.get(0).unwrap().name.as_str(), "F000.NC");
        let last = std::format!("F{:03}.NC", CARD_FILES_MAX - 1);
        assert_eq!(files.get(CARD_FILES_MAX - 1).unwrap().name.as_str(), last);
    }

    #[test]
    fn a_long_name_too_long_to_keep_shows_its_short_name() {
        let mut files = CardFiles::new();
        let long = "a".repeat(CARD_NAME_MAX_BYTES + 1) + ".gcode";
        files.offer("AAAAAA~1.GCO", Some(&long), 1);
        assert_eq!(files.len(), 1, "a G-code file by its long name");
        assert_eq!(files.get(0).unwrap().name.as_str(), "AAAAAA~1.GCO");
    }

    #[test]
    fn names_are_cut_to_the_line_on_character_bounds() {
        assert_eq!(cut_to("a-rather-long-name.gcode", 10), "a-rather-l");
        assert_eq!(cut_to("short.nc", 10), "short.nc");
        assert_eq!(cut_to("画画画画.nc", 2), "画画");
    }
}

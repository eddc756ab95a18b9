//! Text in format strings without core's padding code: [`Text`] writes a string as it is, and
//! [`Padded`] fits one to a width. A plain `&str` or `String` argument would bring
//! `Formatter::pad` (its width and precision handling, 640 bytes) into the image for nothing:
//! the firmware's only widths are the LCD's columns, which [`Padded`] keeps.

use core::fmt::{self, Display, Formatter, Write};

/// A string written as it is: `write!(out, "[MSG:{}]", Text(text))`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Text<'a>(pub &'a str);

impl Display for Text<'_> {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        f.write_str(self.0)
    }
}

/// A string fitted to `width` bytes: cut if longer (before the character that would not fit
/// whole), filled with spaces if shorter, on the right (`right: false`) or on the left. On the
/// LCD a byte is a column (see `panel::texts`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Padded<'a> {
    pub text: &'a str,
    pub width: usize,
    pub right: bool,
}

impl<'a> Padded<'a> {
    /// `text` then spaces up to `width` (cut to `width`).
    pub const fn left(text: &'a str, width: usize) -> Self {
        Padded { text, width, right: false }
    }

    /// Spaces then `text` up to `width` (cut to `width`).
    pub const fn right(text: &'a str, width: usize) -> Self {
        Padded { text, width, right: true }
    }
}

impl Display for Padded<'_> {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        let mut end = self.width.min(self.text.len());
        while !self.text.is_char_boundary(end) {
            end -= 1;
        }
        let text = self.text.get(..end).unwrap_or_default();
        let fill = self.width - end;
        if !self.right {
            f.write_str(text)?;
        }
        for _ in 0..fill {
            f.write_char(' ')?;
        }
        if self.right {
            f.write_str(text)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::format;

    #[test]
    fn padded_text_is_cut_or_filled_to_its_width() {
        assert_eq!(format!("[{}]", Padded::left("abc", 5)), "[abc  ]");
        assert_eq!(format!("[{}]", Padded::right("abc", 5)), "[  abc]");
        assert_eq!(format!("[{}]", Padded::left("abcdef", 4)), "[abcd]");
        assert_eq!(format!("[{}|{}]", Padded::left("", 0), Text("x y")), "[|x y]");
        // A two-byte character that would not fit whole is left out.
        assert_eq!(format!("[{}]", Padded::left("ab\u{100}", 3)), "[ab ]");
        assert_eq!(format!("[{}]", Padded::right("\u{100}c", 3)), "[\u{100}c]");
    }
}

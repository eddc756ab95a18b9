//! A card file's bytes as lines, framed by the host links' own rules
//! ([`crate::host::framing::LineAssembler`]): the same limits, the same errors as a line sent
//! over the wire, and each line numbered as an editor numbers it (CR LF is one line end).

use super::{Card, CardError};
use crate::host::GrblError;
use crate::host::framing::{LineAssembler, LineEvent};

/// Bytes read from the card at a time.
pub const CARD_CHUNK_BYTES: usize = 64;

/// What the file holds next.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CardLine<'a> {
    /// Line `number` (from 1), as the parser takes it.
    Line { number: u32, text: &'a str },
    /// Line `number` broke a framing rule: the error a link would have answered.
    Refused { number: u32, error: GrblError },
    /// The file has ended.
    End,
}

/// Reads the open file of a [`Card`] a chunk at a time and hands out its lines.
pub struct CardLines {
    assembler: LineAssembler,
    chunk: [u8; CARD_CHUNK_BYTES],
    filled: usize,
    at: usize,
    /// Lines ended so far.
    lines: u32,
    /// The byte before was a CR: an LF now ends no second line.
    after_cr: bool,
    /// The line under way has bytes.
    partial: bool,
    /// The file's end was met.
    ended: bool,
    /// Bytes taken so far.
    bytes: u32,
}

impl Default for CardLines {
    fn default() -> Self {
        Self::new()
    }
}

impl CardLines {
    pub const fn new() -> Self {
        CardLines {
            assembler: LineAssembler::new(),
            chunk: [0; CARD_CHUNK_BYTES],
            filled: 0,
            at: 0,
            lines: 0,
            after_cr: false,
            partial: false,
            ended: false,
            bytes: 0,
        }
    }

    /// Reads on from where a reader had taken `bytes_done` bytes and `lines_done` lines, the
    /// file already sought there; `after_cr` if the line before ended in a CR (as
    /// [`after_cr`](Self::after_cr) said there), so that an LF met first ends no line.
    pub fn resumed(bytes_done: u32, lines_done: u32, after_cr: bool) -> Self {
        CardLines { lines: lines_done, after_cr, bytes: bytes_done, ..CardLines::new() }
    }

    /// The last byte taken was a CR: an LF next belongs to the line it ended.
    pub const fn after_cr(&self) -> bool {
        self.after_cr
    }

    /// Lines handed out so far.
    pub const fn lines_done(&self) -> u32 {
        self.lines
    }

    /// Bytes of the file taken so far.
    pub const fn bytes_done(&self) -> u32 {
        self.bytes
    }

    /// The file's next line, reading `card` as needed. A last line without a line end is a
    /// line too.
    pub fn next<'s>(&'s mut self, card: &mut dyn Card) -> Result<CardLine<'s>, CardError> {
        loop {
            let Some(byte) = self.next_byte(card)? else {
                if self.ended {
                    return Ok(CardLine::End);
                }
                self.ended = true;
                if self.partial {
                    return Ok(self.finish(b'\n'));
                }
                return Ok(CardLine::End);
            };
            let after_cr = core::mem::replace(&mut self.after_cr, byte == b'\r');
            if byte == b'\n' && after_cr {
                continue;
            }
            if matches!(byte, b'\r' | b'\n') {
                return Ok(self.finish(byte));
            }
            self.partial = true;
            let _none = self.assembler.push(byte);
        }
    }

    /// Ends the line under way with `end` (CR or LF).
    fn finish(&mut self, end: u8) -> CardLine<'_> {
        self.partial = false;
        self.lines += 1;
        let number = self.lines;
        match self.assembler.push(end) {
            Some(LineEvent::Line(text)) => CardLine::Line { number, text },
            Some(other) => {
                CardLine::Refused { number, error: other.error().unwrap_or(GrblError::ExpectedCommandLetter) }
            }
            // A line end always ends a line.
            None => CardLine::Line { number, text: "" },
        }
    }

    /// The file's next byte, `None` at its end.
    fn next_byte(&mut self, card: &mut dyn Card) -> Result<Option<u8>, CardError> {
        if self.at == self.filled {
            if self.ended {
                return Ok(None);
            }
            self.filled = card.read(&mut self.chunk)?;
            self.at = 0;
            if self.filled == 0 {
                return Ok(None);
            }
        }
        let byte = self.chunk[self.at];
        self.at += 1;
        self.bytes += 1;
        Ok(Some(byte))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::card::{CardFile, CardFiles};

    /// A card whose one open file is `bytes`, read `step` bytes at a time; a read past
    /// `fail_at` fails as a removed card does.
    struct Bytes {
        bytes: &'static [u8],
        at: usize,
        step: usize,
        fail_at: usize,
    }

    impl Card for Bytes {
        fn files(&mut self) -> Result<CardFiles, CardError> {
            Ok(CardFiles::new())
        }
        fn open(&mut self, _: &CardFile) -> Result<u32, CardError> {
            Ok(self.bytes.len() as u32)
        }
        fn read(&mut self, buf: &mut [u8]) -> Result<usize, CardError> {
            if self.at >= self.fail_at {
                return Err(CardError::Unreadable);
            }
            let n = buf.len().min(self.step).min(self.bytes.len() - self.at);
            buf[..n].copy_from_slice(&self.bytes[self.at..self.at + n]);
            self.at += n;
            Ok(n)
        }
        fn seek(&mut self, offset: u32) -> Result<(), CardError> {
            self.at = offset as usize;
            Ok(())
        }
        fn close(&mut self) {}
    }

    fn card(bytes: &'static [u8], step: usize) -> Bytes {
        Bytes { bytes, at: 0, step, fail_at: usize::MAX }
    }

    /// Every line of `card`'s file, as owned text.
    fn all(card: &mut Bytes) -> std::vec::Vec<std::string::String> {
        all_from(&mut CardLines::new(), card)
    }

    /// Every line `lines` reads on from `card`, as owned text.
    fn all_from(lines: &mut CardLines, card: &mut Bytes) -> std::vec::Vec<std::string::String> {
        let mut out = std::vec::Vec::new();
        loop {
            match lines.next(card).unwrap() {
                CardLine::Line { number, text } => out.push(std::format!("{number}:{text}")),
                CardLine::Refused { number, error } => out.push(std::format!("{number}:{error:?}")),
                CardLine::End => return out,
            }
        }
    }

    #[test]
    fn lines_are_framed_as_over_the_wire_and_numbered_as_in_an_editor() {
        let text = b"G21 (mm)\r\nG0 X1 Y2 ; to the corner\r\n\r\nG1 X3\nG1 Y4";
        for step in [1, 3, CARD_CHUNK_BYTES] {
            let lines = all(&mut card(text, step));
            assert_eq!(lines, ["1:G21", "2:G0X1Y2", "3:", "4:G1X3", "5:G1Y4"], "read {step} at a time");
        }
    }

    #[test]
    fn a_line_too_long_or_with_a_control_byte_gets_the_links_error() {
        let long: &'static str =
            std::boxed::Box::leak(std::format!("G1X{}\nG0\x01X1\nG0X2\n", "1".repeat(200)).into_boxed_str());
        let lines = all(&mut card(long.as_bytes(), 7));
        assert_eq!(lines, ["1:LineOverflow", "2:ExpectedCommandLetter", "3:G0X2"]);
    }

    #[test]
    fn a_read_that_fails_says_so() {
        let mut failing = Bytes { bytes: b"G0X1\nG0X2\n", at: 0, step: 4, fail_at: 4 };
        let mut lines = CardLines::new();
        assert_eq!(lines.next(&mut failing), Err(CardError::Unreadable));
    }

    #[test]
    fn a_reader_resumed_after_any_line_reads_on_as_the_first_did() {
        let text = b"G21\r\nG0 X1\r\n\r\nG1 X3\n\nG1 Y4\rG1 Y5";
        let whole = all(&mut card(text, 3));
        let mut c = card(text, 3);
        let mut first = CardLines::new();
        loop {
            let (bytes, lines, after_cr) = (first.bytes_done(), first.lines_done(), first.after_cr());
            let mut again = card(text, 5);
            again.seek(bytes).unwrap();
            let mut resumed = CardLines::resumed(bytes, lines, after_cr);
            let rest = all_from(&mut resumed, &mut again);
            assert_eq!(rest, whole[lines as usize..], "resumed after line {lines}, byte {bytes}");
            assert_eq!(resumed.bytes_done(), text.len() as u32);
            if first.next(&mut c).unwrap() == CardLine::End {
                break;
            }
        }
    }

    #[test]
    fn progress_counts_lines_and_bytes() {
        let mut c = card(b"G0X1\nG0X2\n", 64);
        let mut lines = CardLines::new();
        let _ = lines.next(&mut c).unwrap();
        assert_eq!((lines.lines_done(), lines.bytes_done()), (1, 5));
        while lines.next(&mut c).unwrap() != CardLine::End {}
        assert_eq!((lines.lines_done(), lines.bytes_done()), (2, 10));
    }
}

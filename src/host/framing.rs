//! Serial framing: the host's bytes into text lines (one G-code block or `$` command each), and
//! the realtime bytes that never belong to a line.
//!
//! GRBL senders stream lines ended by LF or CR, and at any moment (even in the middle of a
//! line) send single realtime bytes: `?` status, `!` hold, `~` resume, Ctrl-X reset and GRBL's
//! extended commands in 0x80–0xFF. The serial task routes every byte through [`realtime`] first
//! and acts on the realtime ones at once; [`LineAssembler`] skips them too, so a line is the same
//! whether or not the sender slipped a `?` into it.
//!
//! As GRBL does, the assembler drops what a line does not need as the bytes arrive, and counts
//! only what it keeps against [`LINE_MAX_BYTES`]: spaces, tabs and comments (`(...)` and `;` to
//! the end) of a G-code line or a `$J=` jog, so that a long comment or a line padded with spaces
//! is no overflow, and any byte inside a comment (UTF-8 text included) is ignored. A `$` command
//! is kept as sent up to a `;` comment: the plotter's curve commands need their spaces and the
//! `$F` expression its parentheses. Leading spaces go from every line. A byte above 0x7F that is
//! not a realtime command is dropped wherever it comes, as GRBL drops it: senders that write
//! realtime commands as text send 0x91 as UTF-8, 0xC2 0x91, and the 0xC2 must not spoil the line
//! it lands in. Beyond that the assembler owns only framing (line ends, which bytes may stand in
//! a line); the parsers read the words.

use heapless::String;

use super::GrblError;
use crate::motion::overrides::OverrideCommand;

/// Longest line kept, in bytes, after dropping what the module documentation says. GRBL keeps
/// 80; a few more leave room for the spaces of the plotter's `$` commands.
pub const LINE_MAX_BYTES: usize = 96;

/// A byte that acts at once instead of being part of a line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Realtime {
    /// `?`: send a status report.
    StatusQuery,
    /// `!`: feed hold.
    FeedHold,
    /// `~`: cycle start / resume.
    CycleStart,
    /// 0x18 (Ctrl-X): soft reset.
    Reset,
    /// 0x84: the safety door: a hold, reported as `Door` until resumed.
    SafetyDoor,
    /// 0x85: cancel the jog in progress.
    JogCancel,
    /// 0x90–0x97, 0x99–0x9D: change the feed, rapid or spindle override.
    Override(OverrideCommand),
    /// One of GRBL's other extended realtime bytes (spindle stop 0x9E, coolant toggles
    /// 0xA0/0xA1): the plotter has no use for it and ignores it, as GRBL would on a machine
    /// without that feature.
    Unsupported(u8),
}

/// The realtime command `byte` stands for, if any.
pub const fn realtime(byte: u8) -> Option<Realtime> {
    Some(match byte {
        b'?' => Realtime::StatusQuery,
        b'!' => Realtime::FeedHold,
        b'~' => Realtime::CycleStart,
        0x18 => Realtime::Reset,
        0x84 => Realtime::SafetyDoor,
        0x85 => Realtime::JogCancel,
        0x9E | 0xA0 | 0xA1 => Realtime::Unsupported(byte),
        _ => match OverrideCommand::from_byte(byte) {
            Some(command) => Realtime::Override(command),
            None => return None,
        },
    })
}

/// What a finished line turned out to be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum LineEvent<'a> {
    /// A complete line, without its line end; may be empty (answer `ok`, as GRBL does).
    Line(&'a str),
    /// The line was longer than [`LINE_MAX_BYTES`]; all of it was dropped (`error:11`).
    Overflow,
    /// The line held this control byte (the first one); all of it was dropped (`error:1`).
    BadByte(u8),
}

impl LineEvent<'_> {
    /// The error to answer for a refused line; `None` for a line to execute.
    pub const fn error(&self) -> Option<GrblError> {
        match self {
            LineEvent::Line(_) => None,
            LineEvent::Overflow => Some(GrblError::LineOverflow),
            LineEvent::BadByte(_) => Some(GrblError::ExpectedCommandLetter),
        }
    }
}

/// Collects bytes into lines; see the module documentation.
///
/// A line ends at LF or CR, each on its own, as in GRBL: CRLF ends a line and then an empty one,
/// and GRBL answers both (senders send LF). A byte above 0x7F that is not realtime is dropped.
/// Every other byte belongs to the line: outside comments, printable ASCII (and tab, in a `$`
/// command) is kept; a control byte marks the whole line as refused. A line whose kept bytes grow past [`LINE_MAX_BYTES`] is dropped up to its end
/// and reported once, as [`LineEvent::Overflow`], when that end arrives. A soft reset byte
/// (0x18) drops the partial line, as GRBL's reset flushes its receive buffer.
#[derive(Clone, Debug)]
pub struct LineAssembler {
    /// The kept bytes: printable ASCII and tab only, so a `String` without validation.
    line: String<LINE_MAX_BYTES>,
    kind: Kind,
    comment: Comment,
    overflow: bool,
    bad_byte: Option<u8>,
    /// A line was handed out by the previous `push`; the buffer starts over at the next byte.
    handed_out: bool,
}

/// What the line under way is, as far as its first bytes tell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// Nothing kept yet: spaces are dropped, the first other byte decides.
    Start,
    /// A `$` kept: the next byte tells a jog (`$J`) from a `$` command.
    Dollar,
    /// G-code or a `$J=` jog: spaces, tabs and comments are dropped.
    Gcode,
    /// A `$` command: kept as sent, up to a `;` comment.
    Command,
}

/// Whether the byte under way lies in a comment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Comment {
    None,
    /// Inside `(...)`, up to the `)`.
    Paren,
    /// After `;`, up to the line end.
    ToEnd,
}

impl Default for LineAssembler {
    fn default() -> Self {
        Self::new()
    }
}

impl LineAssembler {
    pub const fn new() -> Self {
        LineAssembler {
            line: String::new(),
            kind: Kind::Start,
            comment: Comment::None,
            overflow: false,
            bad_byte: None,
            handed_out: false,
        }
    }

    /// Drops the partial line (after a soft reset, or when the link reconnects).
    pub fn clear(&mut self) {
        self.start_line();
        self.handed_out = false;
    }

    fn start_line(&mut self) {
        self.line.clear();
        self.kind = Kind::Start;
        self.comment = Comment::None;
        self.overflow = false;
        self.bad_byte = None;
    }

    /// Takes one byte; returns an event when it ended a line. The returned line borrows the
    /// assembler's buffer and is valid until the next `push`.
    pub fn push(&mut self, byte: u8) -> Option<LineEvent<'_>> {
        if self.handed_out {
            self.start_line();
            self.handed_out = false;
        }
        if let Some(rt) = realtime(byte) {
            if rt == Realtime::Reset {
                self.clear();
            }
            return None;
        }
        match byte {
            b'\r' | b'\n' => {
                self.handed_out = true;
                Some(self.finish())
            }
            _ => {
                self.take(byte);
                None
            }
        }
    }

    /// A byte of the line under way, not a line end: dropped, kept, or refusing the line.
    fn take(&mut self, byte: u8) {
        if byte > 0x7F {
            // Not realtime (the caller took those): dropped, in a comment or not.
            return;
        }
        match self.comment {
            Comment::ToEnd => return,
            Comment::Paren => {
                if byte == b')' {
                    self.comment = Comment::None;
                }
                return;
            }
            Comment::None => {}
        }
        let kind = match (self.kind, byte) {
            (Kind::Start, b' ' | b'\t') => return,
            (Kind::Start, b'$') => Kind::Dollar,
            (Kind::Start, _) => Kind::Gcode,
            (Kind::Dollar, b'J' | b'j') => Kind::Gcode,
            (Kind::Dollar, _) => Kind::Command,
            (kind, _) => kind,
        };
        self.kind = kind;
        match (kind, byte) {
            (Kind::Gcode, b' ' | b'\t') => {}
            (Kind::Gcode, b'(') => self.comment = Comment::Paren,
            (_, b';') => self.comment = Comment::ToEnd,
            (Kind::Command, b'\t') | (_, 0x20..=0x7E) => self.keep(byte),
            _ => {
                if self.bad_byte.is_none() {
                    self.bad_byte = Some(byte);
                }
            }
        }
    }

    fn keep(&mut self, byte: u8) {
        if self.line.push(char::from(byte)).is_err() {
            self.overflow = true;
        }
    }

    fn finish(&self) -> LineEvent<'_> {
        if self.overflow {
            LineEvent::Overflow
        } else if let Some(b) = self.bad_byte {
            LineEvent::BadByte(b)
        } else {
            LineEvent::Line(self.line.as_str())
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::string::{String, ToString};
    use std::vec::Vec;

    /// Feeds `bytes` and collects every event, lines as owned strings.
    fn feed(asm: &mut LineAssembler, bytes: &[u8]) -> Vec<Result<String, LineEvent<'static>>> {
        let mut out = Vec::new();
        for &b in bytes {
            match asm.push(b) {
                Some(LineEvent::Line(l)) => out.push(Ok(l.to_string())),
                Some(LineEvent::Overflow) => out.push(Err(LineEvent::Overflow)),
                Some(LineEvent::BadByte(b)) => out.push(Err(LineEvent::BadByte(b))),
                None => {}
            }
        }
        out
    }

    fn lines(v: &[&str]) -> Vec<Result<String, LineEvent<'static>>> {
        v.iter().map(|s| Ok(s.to_string())).collect()
    }

    #[test]
    fn lf_and_cr_each_end_a_line_as_in_grbl() {
        let mut a = LineAssembler::new();
        assert_eq!(feed(&mut a, b"G0 X1\nG0 X2\rG0 X4\n"), lines(&["G0X1", "G0X2", "G0X4"]));
        // CRLF is a line and an empty one: GRBL answers `ok` twice.
        assert_eq!(feed(&mut a, b"G0 X3\r\n"), lines(&["G0X3", ""]));
        assert_eq!(feed(&mut a, b"$$\r"), lines(&["$$"]));
        assert_eq!(feed(&mut a, b"\n"), lines(&[""]));
        // A blank line is a line: GRBL answers it with `ok`, and senders count on that.
        assert_eq!(feed(&mut a, b"A\n\rB\n"), lines(&["A", "", "B"]));
    }

    #[test]
    fn realtime_bytes_mid_line_are_not_part_of_it() {
        let mut a = LineAssembler::new();
        assert_eq!(feed(&mut a, b"G1 X?1!0~ Y\x855\x91\n"), lines(&["G1X10Y5"]));
        assert_eq!(realtime(b'?'), Some(Realtime::StatusQuery));
        assert_eq!(realtime(b'!'), Some(Realtime::FeedHold));
        assert_eq!(realtime(b'~'), Some(Realtime::CycleStart));
        assert_eq!(realtime(0x18), Some(Realtime::Reset));
        assert_eq!(realtime(0x85), Some(Realtime::JogCancel));
        assert_eq!(realtime(0x91), Some(Realtime::Override(OverrideCommand::Feed(10))));
        assert_eq!(realtime(0x97), Some(Realtime::Override(OverrideCommand::Rapid(25))));
        assert_eq!(realtime(0x9D), Some(Realtime::Override(OverrideCommand::Spindle(-1))));
        assert_eq!(realtime(0x9E), Some(Realtime::Unsupported(0x9E)));
        assert_eq!(realtime(0xA0), Some(Realtime::Unsupported(0xA0)));
        assert_eq!(realtime(b'G'), None);
        assert_eq!(realtime(b'\n'), None);
    }

    #[test]
    fn reset_drops_the_partial_line() {
        let mut a = LineAssembler::new();
        assert_eq!(feed(&mut a, b"G1 X100\x18G0 X0\n"), lines(&["G0X0"]));
    }

    #[test]
    fn an_overlong_line_is_reported_once_and_the_next_line_is_intact() {
        let mut a = LineAssembler::new();
        let mut input = std::vec![b'X'; LINE_MAX_BYTES * 3];
        input.extend_from_slice(b"\nG0 X1\n");
        assert_eq!(feed(&mut a, &input), std::vec![Err(LineEvent::Overflow), Ok("G0X1".to_string())]);
    }

    #[test]
    fn a_line_of_exactly_the_maximum_length_is_kept() {
        let mut a = LineAssembler::new();
        let mut input = std::vec![b'9'; LINE_MAX_BYTES];
        input.push(b'\n');
        let got = feed(&mut a, &input);
        assert_eq!(got, std::vec![Ok("9".repeat(LINE_MAX_BYTES))]);
        input.insert(0, b'9');
        assert_eq!(feed(&mut a, &input), std::vec![Err(LineEvent::Overflow)]);
    }

    #[test]
    fn bytes_above_0x7f_are_dropped_and_control_bytes_refuse_the_line_without_eating_the_next() {
        let mut a = LineAssembler::new();
        // "°" in UTF-8 is C2 B0; neither byte is a GRBL realtime command: both are dropped.
        let got = feed(&mut a, "G0 X1°\nG0 X2\n$S A5°\n(é) G1 X4\n".as_bytes());
        assert_eq!(got, ["G0X1", "G0X2", "$S A5", "G1X4"].map(|l| Ok(l.to_string())));
        // The override 0x91 sent as UTF-8 text, 0xC2 0x91, in the middle of a line: the 0x91
        // acts (the caller takes realtime bytes first), the 0xC2 leaves no trace.
        let got = feed(&mut a, b"G1 X\xC2\x915\n");
        assert_eq!(got, std::vec![Ok("G1X5".to_string())]);
        let got = feed(&mut a, b"G0\x07X1\n\tG0\tX3\n");
        assert_eq!(got, std::vec![Err(LineEvent::BadByte(0x07)), Ok("G0X3".to_string())]);
        assert_eq!(LineEvent::BadByte(7).error(), Some(GrblError::ExpectedCommandLetter));
        assert_eq!(LineEvent::Overflow.error().map(GrblError::code), Some(11));
        assert_eq!(LineEvent::Line("").error(), None);
    }

    #[test]
    fn comments_and_spaces_are_dropped_before_the_length_counts() {
        let mut a = LineAssembler::new();
        let long = "c".repeat(100);
        let input = std::format!("({long})\nG1 X2 Y2 ;{long}\nG1{}X1 Y1\nG1 X7 ; café\n", " ".repeat(90));
        assert_eq!(feed(&mut a, input.as_bytes()), lines(&["", "G1X2Y2", "G1X1Y1", "G1X7"]));
        // A comment in the middle, with any bytes in it; an unclosed one ends with its line.
        assert_eq!(feed(&mut a, "G0 (é\x07 x) X1\nG0 X2 (open\nG0 X3\n".as_bytes()), lines(&["G0X1", "G0X2", "G0X3"]));
        // Jogs are G-code.
        assert_eq!(feed(&mut a, b"  $J=G91 X1 (step) F100\n"), lines(&["$J=G91X1F100"]));
    }

    #[test]
    fn a_dollar_command_keeps_its_spaces_and_parentheses_up_to_a_semicolon() {
        let mut a = LineAssembler::new();
        let got = feed(&mut a, " $F X0 U10 Y=sqrt(x+1) ; café\n$S\tA5\n$$\n".as_bytes());
        assert_eq!(got, lines(&["$F X0 U10 Y=sqrt(x+1) ", "$S\tA5", "$$"]));
    }

    #[test]
    fn lines_never_exceed_the_buffer_whatever_the_bytes() {
        use proptest::prelude::*;
        proptest!(|(bytes in proptest::collection::vec(any::<u8>(), 0..400))| {
            let mut a = LineAssembler::new();
            for b in bytes {
                if let Some(LineEvent::Line(l)) = a.push(b) {
                    prop_assert!(l.len() <= LINE_MAX_BYTES);
                    prop_assert!(l.bytes().all(|c| c == b'\t' || (0x20..=0x7E).contains(&c)));
                    prop_assert!(l.bytes().all(|c| realtime(c).is_none()));
                }
            }
        });
    }
}

//! The serial line framing: any bytes a host may send, realtime bytes anywhere among them.
//!
//! Checks, besides that nothing panics: every line end (CR or LF) gets exactly one event and
//! nothing else gets one (every line a sender sends gets one answer); a line is at most
//! `LINE_MAX_BYTES` of printable ASCII (tab in a `$` command), never holds a realtime byte, a
//! comment or a line end, and starts with no space; a realtime byte slipped anywhere changes no
//! line; after a soft reset (0x18) the lines are those of a fresh assembler.
#![no_main]

use libfuzzer_sys::fuzz_target;
use servoplot::host::framing::{LINE_MAX_BYTES, LineAssembler, LineEvent, Realtime, realtime};

/// A line event, owned, to compare runs.
#[derive(Debug, PartialEq)]
enum Event {
    Line(String),
    Overflow,
    BadByte(u8),
}

fn events(bytes: impl IntoIterator<Item = u8>) -> Vec<Event> {
    let mut assembler = LineAssembler::new();
    let mut out = Vec::new();
    for byte in bytes {
        if let Some(event) = assembler.push(byte) {
            out.push(match event {
                LineEvent::Line(line) => Event::Line(line.to_owned()),
                LineEvent::Overflow => Event::Overflow,
                LineEvent::BadByte(b) => Event::BadByte(b),
            });
        }
    }
    out
}

fn check_line(line: &str) {
    assert!(line.len() <= LINE_MAX_BYTES, "{} bytes kept", line.len());
    assert!(line.bytes().all(|b| b == b'\t' || (0x20..=0x7E).contains(&b)), "{line:?}");
    assert!(line.bytes().all(|b| realtime(b).is_none()), "{line:?} holds a realtime byte");
    assert!(!line.starts_with([' ', '\t']), "{line:?}");
    if line.starts_with('$') && !line[1..].starts_with(['J', 'j']) {
        assert!(!line.contains(';'), "a comment kept in {line:?}");
    } else {
        assert!(!line.contains([' ', '\t', '(', ';']), "a space or comment kept in {line:?}");
    }
}

fuzz_target!(|data: &[u8]| {
    let got = events(data.iter().copied());
    let line_ends = data.iter().filter(|&&b| b == b'\r' || b == b'\n').count();
    assert_eq!(got.len(), line_ends, "one event per line end");
    for event in &got {
        match event {
            Event::Line(line) => check_line(line),
            Event::BadByte(b) => assert!(*b < 0x20 || *b == 0x7F, "byte {b:#04x} refused"),
            Event::Overflow => {}
        }
    }

    // The realtime bytes other than a reset, and what is dropped anyway (bytes above 0x7F), taken
    // out: the same lines.
    let plain = data.iter().copied().filter(|&b| b <= 0x7F && matches!(realtime(b), None | Some(Realtime::Reset)));
    assert_eq!(events(plain), got, "a realtime byte changed a line");

    // After the last soft reset, the lines of a fresh assembler.
    if let Some(reset) = data.iter().rposition(|&b| realtime(b) == Some(Realtime::Reset)) {
        let after = data[reset + 1..].iter().filter(|&&b| b == b'\r' || b == b'\n').count();
        assert_eq!(events(data[reset + 1..].iter().copied()), got[got.len() - after..], "a reset kept a partial line");
    }
});

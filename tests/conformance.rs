//! GRBL 1.1 conformance: transcripts of what senders (UGS, cncjs, bCNC, GRBL's stream.py) send,
//! with the answers GRBL 1.1's documented interface gives, replayed through the simulator.
//!
//! Each file in `tests/conformance/` is one session:
//!
//! - `> line` is a line the sender streams, GRBL's way: sent once the line before it is
//!   answered;
//! - `@ms bytes` sends `bytes` at `ms` milliseconds of virtual time, flow control or not
//!   (realtime bytes, a paste); `\xNN`, `\n` and `\r` stand for bytes;
//! - `< text` is the next line the plotter writes, exactly; `*` in it stands for any text, and
//!   `<* text` for as many such lines as come (none included);
//! - `#` starts a comment.
//!
//! Every line the plotter writes must be matched, in order, and nothing may be left over.
//! Where servoplot deliberately differs from GRBL, the README's table says so; the transcripts
//! hold servoplot's answers there.

use std::path::Path;

use servoplot::sim::{self, SimConfig, serial::SimSerial};

/// One expected line: a pattern, once or repeated.
enum Expect {
    Once(String),
    Any(String),
}

struct Transcript {
    sent: String,
    timed: Vec<(u64, u8)>,
    expected: Vec<(usize, Expect)>,
}

fn unescape(text: &str) -> Vec<u8> {
    let mut out = Vec::new();
    let mut rest = text.as_bytes();
    while let Some((&b, tail)) = rest.split_first() {
        rest = tail;
        if b != b'\\' {
            out.push(b);
            continue;
        }
        match rest.split_first() {
            Some((b'n', t)) => {
                out.push(b'\n');
                rest = t;
            }
            Some((b'r', t)) => {
                out.push(b'\r');
                rest = t;
            }
            Some((b'x', t)) if t.len() >= 2 => {
                let hex = std::str::from_utf8(&t[..2]).unwrap();
                out.push(u8::from_str_radix(hex, 16).unwrap_or_else(|_| panic!("bad escape \\x{hex}")));
                rest = &t[2..];
            }
            _ => out.push(b'\\'),
        }
    }
    out
}

fn parse(text: &str) -> Transcript {
    let mut t = Transcript { sent: String::new(), timed: Vec::new(), expected: Vec::new() };
    for (n, line) in text.lines().enumerate() {
        let n = n + 1;
        if let Some(l) = line.strip_prefix("> ") {
            t.sent += l;
            t.sent.push('\n');
        } else if let Some(l) = line.strip_prefix("<* ") {
            t.expected.push((n, Expect::Any(l.to_string())));
        } else if let Some(l) = line.strip_prefix("< ").or(line.strip_prefix("<").filter(|l| l.is_empty())) {
            t.expected.push((n, Expect::Once(l.to_string())));
        } else if let Some(l) = line.strip_prefix('@') {
            let (ms, bytes) = l.split_once(' ').unwrap_or_else(|| panic!("line {n}: @ms bytes"));
            let ms: u64 = ms.parse().unwrap_or_else(|_| panic!("line {n}: bad time {ms}"));
            t.timed.extend(unescape(bytes).into_iter().map(|b| (ms * 1000, b)));
        } else if !(line.is_empty() || line.starts_with('#')) {
            panic!("line {n}: {line:?} is not a transcript line");
        }
    }
    t
}

/// `text` matches `pattern`, `*` standing for any text.
fn matches(pattern: &str, text: &str) -> bool {
    let mut parts = pattern.split('*');
    let first = parts.next().unwrap_or("");
    let Some(mut rest) = text.strip_prefix(first) else { return false };
    let parts: Vec<&str> = parts.collect();
    for (i, part) in parts.iter().enumerate() {
        if i == parts.len() - 1 {
            return rest.ends_with(part) && rest.len() >= part.len();
        }
        match rest.find(part) {
            Some(at) => rest = &rest[at + part.len()..],
            None => return false,
        }
    }
    rest.is_empty()
}

fn replay(path: &Path) {
    let t = parse(&std::fs::read_to_string(path).unwrap());
    let serial = t.timed.iter().fold(SimSerial::with_input(t.sent.as_bytes()), |s, &(at, b)| s.with_byte_at(at, b));
    let report = sim::run(SimConfig { serial, ..SimConfig::default() });
    let name = path.display();
    assert!(!report.timed_out, "{name}: the machine came to rest");
    let output = report.answers();
    let got: Vec<&str> = output.split("\r\n").collect();
    // Everything ends with a line end: the last piece is empty.
    let got = &got[..got.len() - 1];
    let mut at = 0;
    for (n, expect) in &t.expected {
        match expect {
            Expect::Once(p) => {
                assert!(at < got.len(), "{name}:{n}: expected {p:?}, the output ended\n{output}");
                assert!(matches(p, got[at]), "{name}:{n}: expected {p:?}, got {:?}\n{output}", got[at]);
                at += 1;
            }
            Expect::Any(p) => {
                while at < got.len() && matches(p, got[at]) {
                    at += 1;
                }
            }
        }
    }
    assert_eq!(&got[at..], &[] as &[&str], "{name}: more output than expected\n{output}");
}

#[test]
fn every_transcript_gets_grbls_answers() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/conformance");
    let mut files: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    files.sort();
    assert!(files.len() >= 10, "the transcripts are there");
    for file in files {
        replay(&file);
    }
}

#[test]
fn patterns_match_as_documented() {
    assert!(matches("<Idle|MPos:*|FS:0,0>", "<Idle|MPos:1.000,2.000,0.000|FS:0,0>"));
    assert!(matches("ok", "ok"));
    assert!(!matches("ok", "ok2"));
    assert!(matches("*", ""));
    assert!(matches("a*b*c", "aXbYc"));
    assert!(!matches("a*b*c", "aXbY"));
    assert_eq!(unescape("\\x18?\\n"), [0x18, b'?', b'\n']);
}

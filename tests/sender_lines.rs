//! What a sender or a terminal sees of its lines, on the simulated board: every line gets
//! exactly one answer, in order, however it is sent, and GRBL's rules for what a line holds.

use servoplot::geom::Point;
use servoplot::sim::{self, SimConfig, SimReport, serial::SimSerial};

/// Bytes pasted at `t_us`, all at once, ignoring flow control.
fn paste(serial: SimSerial, t_us: u64, text: &str) -> SimSerial {
    text.bytes().fold(serial, |s, b| s.with_byte_at(t_us, b))
}

fn run(serial: SimSerial) -> SimReport {
    let report = sim::run(SimConfig { serial, ..SimConfig::default() });
    assert!(!report.timed_out, "the machine came to rest: {}", report.answers());
    report
}

/// The answers to lines (`ok`, `error:N`), in order, without pushed messages and reports.
fn answers(report: &SimReport) -> Vec<String> {
    let text = report.answers();
    text.lines().filter(|l| *l == "ok" || l.starts_with("error:")).map(str::to_string).collect()
}

/// `G1 X<k> Y<k>` for k in `range`, one line each: every line's target is a point of its own.
fn diagonal_lines(range: std::ops::RangeInclusive<u32>) -> String {
    range.map(|k| format!("G1 X{k}.000 Y{k}.000\n")).collect()
}

/// Every line pasted gets one answer, in order; a line answered `ok` is drawn, one answered
/// `error:100` (dropped: the receive buffer was full) is not; a line sent afterwards is answered
/// and drawn as usual.
fn check_paste(count: u32) {
    let first = "G1 X50 F1200\n";
    let pasted = diagonal_lines(10..=9 + count);
    let serial = SimSerial::with_input(first.as_bytes());
    let serial = paste(serial, 1_000, &pasted);
    // Long after the paste has been dealt with.
    let report = run(paste(serial, 600_000_000, "G1 X1 Y1\n"));
    let got = answers(&report);
    assert_eq!(got.len() as u32, count + 2, "one answer per line: {}", report.answers());
    assert_eq!(got[0], "ok");
    assert_eq!(got[got.len() - 1], "ok", "the line sent later: {}", report.answers());
    let path = report.path();
    let mut from = 0;
    for (k, answer) in (10..=9 + count).zip(&got[1..got.len() - 1]) {
        let target = Point::new(k as i32 * 100, k as i32 * 100);
        let reached = path[from..].iter().position(|p| *p == target);
        match answer.as_str() {
            "ok" => from += reached.unwrap_or_else(|| panic!("line {k} was answered ok but not drawn")),
            "error:100" => assert_eq!(reached, None, "line {k} was refused but drawn"),
            other => panic!("line {k}: {other}"),
        }
    }
    assert_eq!(report.position, Point::new(100, 100));
}

#[test]
fn a_paste_of_28_lines_while_busy_runs_every_line() {
    check_paste(28);
    let report = run(paste(SimSerial::with_input(b"G1 X50 F1200\n"), 1_000, &diagonal_lines(10..=37)));
    assert_eq!(answers(&report), vec!["ok"; 29], "{}", report.answers());
    assert!(!report.answers().contains("Receive buffer full"));
}

#[test]
fn a_paste_beyond_the_receive_buffer_answers_every_line_in_order() {
    for count in [60, 150, 400] {
        check_paste(count);
    }
    let report = run(paste(SimSerial::with_input(b"G1 X50 F1200\n"), 1_000, &diagonal_lines(10..=409)));
    let got = answers(&report);
    assert!(got.iter().any(|a| a == "error:100"), "the paste overflowed: {}", report.answers());
    assert!(!got.iter().any(|a| a == "error:11"), "no line was too long: {}", report.answers());
    // Said once, before the first of them.
    let text = report.answers();
    let said = "[MSG:Receive buffer full: lines dropped, each answered error:100; use a streaming sender]";
    assert_eq!(text.matches(said).count(), 1, "{text}");
    assert!(text.find(said) < text.find("error:100"), "{text}");
}

#[test]
fn crlf_is_answered_as_grbl_answers_it_twice_even_beyond_the_buffer() {
    // CR ends the line and LF an empty one: two answers, as GRBL gives them.
    let report = run(SimSerial::with_input(b"G1 X1 F600\r\n"));
    assert_eq!(answers(&report), ["ok", "ok"], "{}", report.answers());
    let pasted = diagonal_lines(10..=209).replace('\n', "\r\n");
    let serial = paste(SimSerial::with_input(b"G1 X50 F1200\n"), 1_000, &pasted);
    let report = run(paste(serial, 900_000_000, "G1 X1 Y1\r\n"));
    assert_eq!(answers(&report).len(), 1 + 2 * 200 + 2, "{}", report.answers());
    assert_eq!(report.position, Point::new(100, 100));
}

#[test]
fn comments_and_spaces_do_not_count_toward_the_line_length() {
    let long = "c".repeat(100);
    let program = format!("({long})\nG1 X2 Y2 ;{long}\nG1{}X1 Y1\nG1 X7 ; café\n", " ".repeat(90));
    let report = run(SimSerial::with_input(program.as_bytes()));
    assert_eq!(answers(&report), vec!["ok"; 4], "{}", report.answers());
    assert_eq!(report.position, Point::new(700, 100));
}

#[test]
fn a_number_with_an_exponent_is_a_bad_number() {
    for line in ["$S A5 W1e9 L10\n", "$F X0 U1e9 Y=x\n", "G1 X1e3\n", "G1 X1E-3\n"] {
        let report = run(SimSerial::with_input(line.as_bytes()));
        assert_eq!(answers(&report), vec!["error:2"], "{line}: {}", report.answers());
        assert!(report.path().len() <= 1, "{line} moved");
    }
}

#[test]
fn check_mode_checks_every_line_and_moves_nothing() {
    // As GRBL's stream.py -c runs a file: `$C`, the file, `$C`; then a real move.
    let program = "$C\nG91 G1 X150 F3000\nG1 X100\n$O R10\n$S A5 W100 L10\nG4 P1\nM0\nG1 Y-5\n";
    let serial = SimSerial::with_input(program.as_bytes()).with_byte_at(50_000, b'?');
    let report = run(paste(serial, 100_000, "$C\nG1 X1\n"));
    let text = report.answers();
    // X150 then X100 more leaves the travel: the parser plans on in check mode.
    assert_eq!(answers(&report), ["ok", "ok", "error:15", "ok", "error:33", "ok", "ok", "ok", "ok", "ok"], "{text}");
    assert!(text.contains("[MSG:Enabled]\r\nok\r\n"), "{text}");
    assert!(text.contains("<Check|"), "{text}");
    // Leaving it answers the line, then starts over like a reset.
    assert!(text.contains("[MSG:Disabled]\r\nok\r\n\r\nGrbl 1.1h"), "{text}");
    // Nothing moved but the last line, from where the pen really was, in absolute mode again.
    assert!(report.path().iter().all(|p| p.y == 0 && (0..=100).contains(&p.x)), "{:?}", report.path().last());
    assert_eq!(report.position, Point::new(100, 0));
}

#[test]
fn check_mode_is_entered_only_at_rest() {
    let serial = SimSerial::with_input(b"G1 X50 F600\n").with_byte_at(1_000_000, b'$').with_byte_at(1_000_000, b'C');
    let report = run(serial.with_byte_at(1_000_000, b'\n'));
    assert_eq!(answers(&report), ["ok", "error:8"], "{}", report.answers());
    assert_eq!(report.position, Point::new(5_000, 0));
}

#[test]
fn startup_blocks_run_after_every_reset() {
    let serial = SimSerial::with_input(b"$N\n$N0=G20 G91 (inches, relative)\n$N1=G1 X1 F100\n$N\n");
    let serial = paste(serial, 100_000, "\x18");
    let serial = paste(serial, 200_000, "G1 X1 F100\n");
    let serial = paste(paste(paste(serial, 30_000_000, "$RST=*\n"), 31_000_000, "\x18"), 32_000_000, "$N\n");
    let report = run(serial);
    let text = report.answers();
    assert!(
        text.starts_with(
            "\r\nGrbl 1.1h ['$' for help]\r\n$N0=\r\n$N1=\r\nok\r\nok\r\nerror:3\r\n$N0=G20G91\r\n$N1=\r\nok\r\n"
        ),
        "{text}"
    );
    // The reset runs the block: the next line moves one inch, relative.
    assert!(text.contains("\r\nGrbl 1.1h ['$' for help]\r\n>G20G91:ok\r\nok\r\n"), "{text}");
    assert_eq!(report.position, Point::new(2_540, 0));
    // `$RST=*` forgets them: the next reset runs nothing.
    assert!(text.ends_with("ok\r\n\r\nGrbl 1.1h ['$' for help]\r\n$N0=\r\n$N1=\r\nok\r\n"), "{text}");
}

//! The USB port's own flow control, on the simulated board: the port holds the host back while
//! the plotter has no room, so a paste written all at once, without waiting for answers, runs
//! every line; and a host opening the port (DTR set) is greeted with the banner, nothing reset.

use servoplot::geom::Point;
use servoplot::sim::serial::SimSerial;

mod support;
use support::links::{line_answers, paste, run};

/// Targets of a serpentine hatch inside the travel, 0.5 mm apart: `rows` rows of 100 points,
/// every other row drawn back, each point a short move from the one before, in steps.
fn hatch(rows: i32) -> Vec<Point> {
    (0..rows)
        .flat_map(|row| {
            (0..100).map(move |i| {
                let i = if row % 2 == 0 { i } else { 99 - i };
                Point::new(1_000 + i * 50, 1_000 + row * 50)
            })
        })
        .collect()
}

#[test]
fn a_paste_of_100_kb_over_usb_runs_every_line() {
    let targets = hatch(61);
    let text = lines_to(&targets);
    assert!(text.len() >= 100_000, "{} bytes", text.len());
    let usb = paste(SimSerial::default(), 1_000, text.as_bytes());
    let report = run(SimSerial::default(), usb.clone());
    let answers = report.usb_answers();
    assert_eq!(line_answers(&answers), vec!["ok"; targets.len()], "{}", &answers[..answers.len().min(2_000)]);
    assert!(!answers.contains("Receive buffer full"), "{}", &answers[..answers.len().min(2_000)]);
    // The port held the host's writes back: most of the paste waited in the host, unread.
    assert!(usb.most_unread() > 90_000, "{} bytes waited", usb.most_unread());
    // Every line was drawn, in order, and the pen ends at the last line's target.
    let path = report.path();
    let mut from = 0;
    for (k, target) in targets.iter().enumerate() {
        let reached = path[from..].iter().position(|p| p == target);
        from += reached.unwrap_or_else(|| panic!("line {k} was answered ok but not drawn: {target:?}"));
    }
    assert_eq!(report.position, *targets.last().unwrap());
    assert_eq!(*path.last().unwrap(), report.position);
}

#[test]
fn a_host_opening_the_port_gets_the_banner_and_nothing_is_reset() {
    // Relative moves: a reset would bring back G90, and the last line would go elsewhere.
    let usb = || paste(paste(SimSerial::default(), 0, b"G91\nG1 X50 F600\n"), 2_000_000, b"G1 Y1\n");
    let reference = run(SimSerial::default(), usb());
    let opened = usb().with_opening_at(1_000_000);
    let report = run(SimSerial::default(), opened.clone());
    let banner = "Grbl 1.1h ['$' for help]";
    let text = report.usb_answers();
    assert_eq!(text.matches(banner).count(), 2, "power-on and opening: {text}");
    let greeted: Vec<u64> = opened.timed_lines().into_iter().filter(|(_, l)| l == banner).map(|(t, _)| t).collect();
    assert!((1_000_000..1_010_000).contains(&greeted[1]), "greeted when the port opened: {greeted:?}");
    assert_eq!(line_answers(&text), ["ok"; 3], "{text}");
    assert!(!report.answers().contains("Reset"), "the UART was told of no reset: {}", report.answers());
    // The move under way went on, and the next line planned on from it.
    let pulses_between =
        |from: u64, to: u64| report.trace.pulses.iter().filter(|p| (from..to).contains(&p.t_us)).count();
    assert!(pulses_between(900_000, 1_000_000) > 0 && pulses_between(1_000_000, 1_100_000) > 0, "moving through it");
    assert_eq!(report.path(), reference.path());
    assert_eq!(report.last_pulse_us(), reference.last_pulse_us());
    assert_eq!(report.position, Point::new(5_000, 100));
}

#[test]
fn a_host_closing_the_port_and_opening_it_again_is_greeted_again() {
    // The line cut off by the closing is dropped; the banner comes before the next session's
    // answers.
    let usb = paste(SimSerial::default(), 0, b"G1 X5 F3000\nG1 Y");
    let usb = paste(usb.with_closing_at(100_000).with_opening_at(150_000), 200_000, b"G1 X7\n");
    let report = run(SimSerial::default(), usb);
    let text = report.usb_answers();
    assert_eq!(line_answers(&text), ["ok"; 2], "{text}");
    let reopened = text.rfind("Grbl 1.1h").expect("a banner");
    assert!(text.matches("Grbl 1.1h").count() == 2 && reopened < text.rfind("ok").unwrap(), "{text}");
    assert_eq!(report.position, Point::new(700, 0));
}

/// `G1` lines to each of `targets`, in mm.
fn lines_to(targets: &[Point]) -> String {
    targets.iter().map(|p| format!("G1 X{:.2} Y{:.2}\n", p.x as f64 / 100.0, p.y as f64 / 100.0)).collect()
}

#[test]
fn realtime_bytes_behind_a_usb_paste_act_once_read_and_the_uart_is_never_held_up() {
    let targets = hatch(20);
    let text = lines_to(&targets);
    let reference = run(SimSerial::default(), paste(SimSerial::default(), 1_000, text.as_bytes()));
    // A hold from the UART while the USB paste waits in the host acts at once.
    let uart = SimSerial::default().with_byte_at(2_000_000, b'!').with_byte_at(4_000_000, b'~');
    let usb = paste(SimSerial::default(), 1_000, text.as_bytes());
    let report = run(uart, usb.clone());
    let pulses_between =
        |from: u64, to: u64| report.trace.pulses.iter().filter(|p| (from..to).contains(&p.t_us)).count();
    assert!(pulses_between(1_900_000, 2_000_000) > 0, "drawing when the hold came");
    assert_eq!(pulses_between(2_200_000, 4_000_000), 0, "held at once");
    assert_eq!(report.path(), reference.path());
    assert_eq!(line_answers(&report.usb_answers()), vec!["ok"; targets.len()]);
    // A `?` written on the USB link right behind the paste is answered once the lines before it
    // have been read: near the end of the drawing, never lost.
    let usb = paste(SimSerial::default(), 1_000, text.as_bytes()).with_byte_at(1_000, b'?');
    let report = run(SimSerial::default(), usb.clone());
    let answered = usb.timed_lines().into_iter().find(|(_, l)| l.starts_with('<')).expect("the ? was answered");
    let oks_before = usb.timed_lines().iter().filter(|(t, l)| *t <= answered.0 && l == "ok").count();
    assert!(oks_before > targets.len() / 2, "answered after {oks_before} lines: {answered:?}");
    assert_eq!(line_answers(&report.usb_answers()), vec!["ok"; targets.len()]);
    assert_eq!(report.path(), reference.path());
}

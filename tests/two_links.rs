//! Two host links, the board's UART and its USB port, on the simulated board: each line is
//! answered on the link it came on, both links' lines go through one parser with one planned
//! position, and realtime bytes act whatever link they come on.

use servoplot::geom::Point;
use servoplot::sim::serial::SimSerial;

mod support;
use support::links::{line_answers, paste, run};

#[test]
fn every_line_is_answered_on_the_link_it_came_on() {
    let uart = SimSerial::with_input(b"G1 X10 F3000\nG1 X20\n");
    let usb = paste(SimSerial::default(), 50_000, b"G4 P0.1\n$I\nG1 X30\n");
    let report = run(uart, usb);
    let (uart_text, usb_text) = (report.answers(), report.usb_answers());
    assert_eq!(line_answers(&uart_text), ["ok"; 2], "{uart_text}");
    assert_eq!(line_answers(&usb_text), ["ok"; 3], "{usb_text}");
    assert!(usb_text.contains("[VER:"), "{usb_text}");
    assert!(!uart_text.contains("[VER:"), "{uart_text}");
    assert_eq!(report.position, Point::new(3000, 0));
}

#[test]
fn a_usb_line_starts_where_the_uart_lines_left_the_pen() {
    // Sent while the UART's move is still under way: the parser has planned to its end (and
    // keeps its feed rate), whichever link the next line comes on.
    let uart = SimSerial::with_input(b"G1 X10 F3000\n");
    let usb = paste(SimSerial::default(), 10_000, b"G1 Y5\n");
    let report = run(uart, usb);
    assert_eq!(line_answers(&report.usb_answers()), ["ok"], "{}", report.usb_answers());
    assert_eq!(report.position, Point::new(1000, 500));
    let path = report.path();
    let corner = path.iter().position(|p| *p == Point::new(1000, 0)).expect("the pen reached X10 first");
    assert!(path[..corner].iter().all(|p| p.y == 0), "no Y step before X10");
    assert!(path[corner..].iter().all(|p| p.x == 1000), "then straight up");
}

#[test]
fn a_status_query_is_answered_on_the_link_that_asked() {
    let uart = SimSerial::with_input(b"G1 X20 F600\n");
    let usb = paste(SimSerial::default(), 500_000, b"?");
    let uart = paste(uart, 1_000_000, b"?");
    let report = run(uart, usb);
    let (uart_text, usb_text) = (report.answers(), report.usb_answers());
    assert_eq!(usb_text.matches('<').count(), 1, "{usb_text}");
    assert_eq!(uart_text.matches('<').count(), 1, "{uart_text}");
    assert!(usb_text.contains("<Run|MPos:"), "{usb_text}");
}

#[test]
fn a_reset_on_the_usb_link_stops_the_uart_move_and_greets_the_usb_link() {
    let uart = || SimSerial::with_input(b"G1 X100 F3000\n");
    let reference = run(uart(), SimSerial::default());
    let report = run(uart(), paste(SimSerial::default(), 500_000, b"\x18"));
    let stop = report.position;
    assert!(stop.y == 0 && 0 < stop.x && stop.x < 3000, "stopped on the way: {stop:?}");
    assert!(report.last_pulse_us() < reference.last_pulse_us() / 2);
    let (uart_text, usb_text) = (report.answers(), report.usb_answers());
    assert_eq!(usb_text.matches("Grbl 1.1").count(), 2, "power-on and reset: {usb_text}");
    assert_eq!(uart_text.matches("Grbl 1.1").count(), 1, "{uart_text}");
    assert_eq!(line_answers(&uart_text), ["ok"], "{uart_text}");
    assert!(uart_text.contains("[MSG:Reset from another host link]"), "{uart_text}");
}

#[test]
fn closing_the_usb_port_drops_the_line_it_was_sending() {
    let usb = paste(SimSerial::default(), 0, b"G1 X5 F3000\nG1 Y");
    let usb = paste(usb.with_closing_at(100_000), 200_000, b"G1 X7\n");
    let report = run(SimSerial::with_input(b"G4 P0.5\n"), usb);
    assert_eq!(line_answers(&report.usb_answers()), ["ok"; 2], "{}", report.usb_answers());
    assert_eq!(line_answers(&report.answers()), ["ok"], "{}", report.answers());
    assert_eq!(report.position, Point::new(700, 0));
}

//! A setting never strands the pen outside the travel: a change that would leave it outside
//! while it is inside (the travel made smaller, soft limits turned on) is refused, and the pen
//! can always be moved.

use servoplot::geom::Point;
use servoplot::sim::{self, SimConfig, SimReport, serial::SimSerial};

fn run(program: &str) -> SimReport {
    let report = sim::run(SimConfig { serial: SimSerial::with_input(program.as_bytes()), ..SimConfig::default() });
    assert!(!report.timed_out, "{}", report.answers());
    report
}

/// The answers, banner and status reports left out.
fn answers(report: &SimReport) -> Vec<String> {
    report.answers().lines().skip(2).filter(|l| !l.starts_with('<')).map(str::to_string).collect()
}

const REFUSED: [&str; 2] = ["[MSG:The pen would be outside the travel: setting refused]", "error:15"];

#[test]
fn a_smaller_travel_that_would_leave_the_pen_outside_is_refused_and_the_pen_moves_on() {
    // Soft limits on, the pen at X 150 of ±200; a dwell lets each setting find the machine at rest.
    let report = run("$20=1\nG0 X150\nG4 P0\n$130=100\nG0 X0\nG4 P0\n$130=100\nG0 X90\n");
    assert_eq!(answers(&report), ["ok", "ok", "ok", REFUSED[0], REFUSED[1], "ok", "ok", "ok", "ok"]);
    assert_eq!(report.position, Point::new(9_000, 0));
    assert_eq!(report.settings.max_travel_mm[0], 100.0);
}

#[test]
fn soft_limits_turned_on_with_the_pen_outside_the_travel_are_refused() {
    let report = run("$20=0\n$130=100\nG0 X150\nG4 P0\n$20=1\nG0 X0\nG4 P0\n$20=1\nG0 X50\n");
    assert_eq!(answers(&report), ["ok", "ok", "ok", "ok", REFUSED[0], REFUSED[1], "ok", "ok", "ok", "ok"]);
    assert_eq!(report.position, Point::new(5_000, 0));
    assert!(report.settings.soft_limits);
}

#[test]
fn a_setting_sent_right_behind_a_move_waits_for_it_and_never_changes_under_it() {
    // Sent without waiting: the setting is taken once the pen stands at X 150, and refused there;
    // no alarm, nothing dropped.
    let report = run("$20=1\nG0 X150\n$130=100\nG0 X0\n");
    assert_eq!(answers(&report), ["ok", "ok", REFUSED[0], REFUSED[1], "ok"]);
    assert!(!report.answers().contains("ALARM"), "{}", report.answers());
    assert_eq!(report.position, Point::new(0, 0));
}

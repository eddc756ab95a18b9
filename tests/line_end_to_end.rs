//! A straight line, end to end on the simulated board: from the serial link and from the
//! keypad, checked on the pulses the servo drivers would see.

use servoplot::geom::Point;
use servoplot::sim::{self, SimReport};

fn ok_lines(report: &SimReport) -> usize {
    report.answers().lines().filter(|l| *l == "ok").count()
}

#[test]
fn g1_x10_y5_gives_1000_x_and_500_y_pulses_and_ends_at_10_5() {
    let report = sim::run_serial("G1 X10 Y5 F600\nG4 P0\n?\n");
    assert!(!report.timed_out);
    // [x forward, x back, y forward, y back]
    assert_eq!(report.trace.counts(), [1000, 0, 500, 0]);
    assert_eq!(report.position, Point::new(1000, 500));
    assert_eq!(*report.path().last().unwrap(), Point::new(1000, 500));
    let answers = report.answers();
    assert!(answers.starts_with("\r\nGrbl 1.1"), "banner first: {answers:?}");
    assert_eq!(ok_lines(&report), 3, "G1, G4 and the empty line after ?: {answers}");
    assert!(answers.contains("MPos:10.000,5.000,0.000"), "{answers}");
}

#[test]
fn a_negative_quadrant_line_returns_to_the_origin_exactly() {
    let report = sim::run_serial("G1 X-12.34 Y-5.67 F1200\nG1 X0 Y0\n");
    assert_eq!(report.trace.counts(), [1234, 1234, 567, 567]);
    assert_eq!(report.position, Point::ORIGIN);
    let path = report.path();
    assert!(path.contains(&Point::new(-1234, -567)), "the far corner was reached");
    assert_eq!(*path.last().unwrap(), Point::ORIGIN);
    assert_eq!(ok_lines(&report), 2);
}

#[test]
fn unknown_and_malformed_lines_get_errors_and_move_nothing() {
    let report = sim::run_serial("G1 X10 Y\nG7 X1\nHELLO\nG1 X1..5\nG1 X5 Y5 Y6\n");
    assert!(report.trace.pulses.is_empty(), "no pulse for bad lines");
    assert_eq!(report.position, Point::ORIGIN);
    let errors = report.answers().lines().filter(|l| l.starts_with("error:")).count();
    assert_eq!(errors, 5, "{}", report.answers());
    assert_eq!(ok_lines(&report), 0);
}

#[test]
fn an_overlong_line_is_refused_and_the_next_one_still_runs() {
    // 200 characters that count: a comment would not (it is dropped before the length counts).
    let long = format!("G1 X1.{}\nG1 X2 Y1\n", "0".repeat(200));
    let report = sim::run_serial(&long);
    let answers = report.answers();
    let replies: Vec<&str> = answers.lines().filter(|l| *l == "ok" || l.starts_with("error:")).collect();
    assert_eq!(replies, ["error:11", "ok"], "{answers}");
    assert_eq!(report.position, Point::new(200, 100));
}

#[test]
fn pulses_respect_the_driver_timing_settings() {
    let report = sim::run_serial("G1 X-3 Y2\nG1 X3 Y-2\n");
    assert!(report.trace.min_pulse_width_us.unwrap() >= 5, "pulse width >= 5 us");
    assert!(report.trace.min_dir_setup_us.unwrap() >= 10, "SIGN set >= 10 us before the pulse");
}

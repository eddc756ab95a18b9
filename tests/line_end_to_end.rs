//! A straight line, end to end on the simulated board: from the serial link and from the
//! keypad, checked on the pulses the servo drivers would see.

use servoplot::geom::{Axis, Point, TICKS_PER_US};
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
    let t = &report.trace;
    let us = |ticks: Option<u64>| ticks.unwrap() as f64 / f64::from(TICKS_PER_US);
    assert!(us(t.min_pulse_width_ticks) >= 5.0, "pulse width >= $0 (5 us)");
    assert!(us(t.min_dir_setup_ticks) >= 5.0, "SIGN set >= $200 (5 us) before the pulse");
    assert!(us(t.min_dir_hold_ticks) >= 5.0, "SIGN held >= $29 (5 us) after the pulse");
}

#[test]
fn at_200_khz_every_pulse_keeps_its_width_its_low_time_and_sign_timing_through_reversals() {
    // The drivers' limits: 2.5 µs pulses at 200 kHz, SIGN 5 µs either side; axes fast enough
    // for the pulse rate to bind, and a zigzag that reverses X at every corner.
    let setup = "$0=2.5\n$205=200000\n$200=5\n$29=5\n$100=200\n$101=200\n$110=60000\n$111=60000\n\
                 $120=10000\n$121=10000\n";
    let zigzag = "G1 X150 Y2 F60000\nG1 X0 Y4\nG1 X150 Y6\nG1 X0 Y8\n";
    let report = sim::run_serial(&format!("{setup}{zigzag}"));
    assert_eq!(report.position, Point::new(0, 1_600), "{}", report.answers());
    assert_eq!(*report.path().last().unwrap(), report.position);
    let t = &report.trace;
    // Whole ticks of 0.25 µs: the pulse 10 high, then at least 10 low.
    assert_eq!(t.min_pulse_width_ticks, Some(10));
    assert!(t.min_pulse_low_ticks.unwrap() >= 10, "{:?}", t.min_pulse_low_ticks);
    // The pen reached the drivers' rate somewhere: two pulses 5 µs apart.
    let x: Vec<u64> = t.pulses.iter().filter(|p| p.axis == Axis::X).map(|p| p.t_ticks).collect();
    assert_eq!(x.windows(2).map(|w| w[1] - w[0]).min(), Some(20));
    // SIGN of X changed at each reversal, each time 5 µs after the last pulse and 5 µs before
    // the next, timed as the board's interrupt writes it at worst.
    let x_changes: Vec<_> = t.sign_changes.iter().filter(|c| c.axis == Axis::X).collect();
    assert_eq!(x_changes.len(), 4, "{x_changes:?}");
    assert!(x_changes.windows(2).all(|w| w[0].t_ticks < w[1].t_ticks && w[0].high != w[1].high));
    assert!(t.min_dir_setup_ticks.unwrap() >= 20, "{:?}", t.min_dir_setup_ticks);
    assert!(t.min_dir_hold_ticks.unwrap() >= 20, "{:?}", t.min_dir_hold_ticks);
    assert_eq!(report.missed_updates, 0);
}

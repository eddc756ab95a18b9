//! The built-in demo (`cargo sim` with no input) does what the README says: every curve from
//! the PC, then a jog and a circle from the keypad, the keys starting once the PC's drawing is
//! done; and a keypad script given with a G-code file starts only once the file's last line is
//! answered and the motion has ended.

use servoplot::geom::Point;
use servoplot::sim::{self, KeysStart, SimConfig, keys::KeyScript, serial::SimSerial};

/// Steps per millimetre of the default settings.
const STEPS_PER_MM: i32 = 100;

#[test]
fn the_demo_jogs_right_and_draws_its_circle_there() {
    let report = sim::run(sim::cli::demo().unwrap());
    assert!(!report.timed_out);
    // The PC's drawing ends at machine (0, -30 mm); the keypad then jogs right along X.
    let jogged = report.position;
    assert_eq!(jogged.y, -30 * STEPS_PER_MM, "the jog moved along X only");
    assert!(jogged.x > 20 * STEPS_PER_MM, "the jog took the pen right: X {} steps", jogged.x);
    // The circle: radius 8 mm, starting at the pen, its centre 8 mm to the left; it ends where
    // it began. Its points are the last of the path, after the jog.
    let path = report.path();
    let centre = (f64::from(jogged.x - 8 * STEPS_PER_MM), f64::from(jogged.y));
    let on_circle = |p: &Point| ((f64::from(p.x) - centre.0).hypot(f64::from(p.y) - centre.1) - 800.0).abs() <= 0.5;
    let circle: Vec<&Point> = path.iter().rev().take_while(|p| on_circle(p)).collect();
    assert!(circle.len() >= 3000, "only {} points of the circle after the jog", circle.len());
    assert!(circle.iter().any(|p| p.x == jogged.x - 16 * STEPS_PER_MM), "the circle's far side reached");
}

#[test]
fn keys_after_a_file_start_once_its_last_line_is_answered_and_the_pen_rests() {
    // The file ends in a 2 s dwell, answered only once it is over; then the keypad puts the
    // DONE screen away and jogs +X for half a second.
    let report = sim::run(SimConfig {
        serial: SimSerial::with_input(b"G1 X10 F3000\nG4 P2\n"),
        keys: KeyScript::parse("D 1 6:500").unwrap(),
        keys_start: KeysStart::AfterSerial,
        ..SimConfig::default()
    });
    assert_eq!(report.answers().matches("ok").count(), 2, "{}", report.answers());
    let answered_us = report.serial_lines.iter().filter(|(_, l)| l == "ok").map(|(t, _)| *t).next_back().unwrap();
    let file_moved_us = report.trace.steps(report.settings.dir_invert_mask)[10 * STEPS_PER_MM as usize - 1].0;
    assert!(answered_us >= file_moved_us + 2_000_000, "the dwell answered at {answered_us} µs");
    // The jog's steps are those after the file's 10 mm.
    let steps = report.trace.steps(report.settings.dir_invert_mask);
    let jog_start_us = steps.get(10 * STEPS_PER_MM as usize).map(|(t, _)| *t).expect("the keypad jogged");
    assert!(jog_start_us > answered_us, "the jog began at {jog_start_us} µs, the dwell answered at {answered_us} µs");
    assert!(report.position.x > 10 * STEPS_PER_MM);
}

//! What the LCD says, read back from the simulated board's frames: the screen names what the
//! machine does (homing, an alarm, a lock and how to leave it, a jog slowing to a stop), the
//! key that acknowledges an abort does nothing more, and an expression's `*` reads as a
//! multiplication sign.

use servoplot::sim::{self, SimReport};

mod support;

use support::text;

/// The four lines of the last frame.
fn last_lines(report: &SimReport) -> Vec<String> {
    let (_, last) = report.frames.last().expect("the LCD was drawn");
    (0..4).map(|line| text(last, line, 24)).collect()
}

#[test]
fn a_function_preset_shows_its_star_as_a_multiplication_sign() {
    // Function mode (6), the second preset: y = 10*sin(x/5).
    let report = sim::run_keys("6 2 wait:300").unwrap();
    assert_eq!(last_lines(&report)[2], "f2 y=10*sin(x/5)");
}

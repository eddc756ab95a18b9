//! A step timer interrupt that comes a whole period late, on the simulated board: the timer
//! repeats the period it had preloaded, pulse included. The firmware counts that pulse into the
//! position, so the position stays the pulses the drivers took; it stops in an alarm at once and
//! says why, and after `$X` the machine goes on from where it really is.

use servoplot::geom::Point;
use servoplot::sim::{self, LateInterrupt, SimConfig, SimReport, serial::SimSerial};

/// Runs `lines`, then `later` (text sent at a time, µs), with the interrupt of the first update
/// event from `late_at_us` on one period late.
fn run(lines: &str, later: &[(u64, &str)], late_at_us: Option<u64>) -> SimReport {
    let mut serial = SimSerial::with_input(lines.as_bytes());
    for &(t, text) in later {
        for (k, b) in text.bytes().enumerate() {
            serial = serial.with_byte_at(t + k as u64, b);
        }
    }
    let late_interrupt = late_at_us.map(|at_us| LateInterrupt { at_us, periods: 1 });
    let report = sim::run(SimConfig { serial, late_interrupt, ..SimConfig::default() });
    assert!(!report.timed_out, "{}", report.answers());
    report
}

#[test]
fn a_late_interrupt_keeps_the_position_exact_stops_in_an_alarm_and_is_reported() {
    let line = "G1 X30 Y10 F3000\n";
    let reference = run(line, &[], None);
    let report = run(line, &[(2_000_000, "?")], Some(300_000));
    assert_eq!(report.missed_updates, 1);
    let answers = report.answers();
    assert!(answers.contains("ALARM:21\r\n[MSG:Pulse timer late"), "{answers}");
    assert!(answers.contains("<Alarm|") && answers.contains("|Mu:1>"), "{answers}");
    // Stopped part way, at once: no braking.
    let path = report.path();
    let n = path.len();
    assert!(n > 100 && n < reference.path().len() / 2, "{n} points");
    // The drivers took the steps of the line up to the late interrupt, then the repeated one
    // once more: the position counts it.
    assert_eq!(path[..n - 1], reference.path()[..n - 1]);
    assert_eq!(path[n - 1].x - path[n - 2].x, path[n - 2].x - path[n - 3].x);
    assert_eq!(path[n - 1].y - path[n - 2].y, path[n - 2].y - path[n - 3].y);
    assert_eq!(report.position, path[n - 1]);
}

#[test]
fn after_the_alarm_the_machine_goes_on_from_where_the_pulses_took_it() {
    let later = [(2_000_000, "$X\nG1 X0 Y0\n")];
    let report = run("G1 X30 Y10 F3000\n", &later, Some(300_000));
    assert_eq!(report.missed_updates, 1);
    // Back to machine zero by the counted position: where the drivers are, exactly.
    assert_eq!(report.position, Point::ORIGIN, "{}", report.answers());
    assert_eq!(report.trace.driven_steps(), [0, 0]);
}

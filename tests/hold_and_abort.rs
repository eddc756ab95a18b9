//! Hold, resume and abort on every curve type, on the simulated board: the pen stops on its
//! path without losing a step, a resume finishes the same path, an abort ends on the path, and
//! the position is the pulses emitted in every case.

use servoplot::geom::Point;
use servoplot::settings::Settings;
use servoplot::sim::{self, SimConfig, SimReport, serial::SimSerial};

/// One command per curve type the machine draws.
const CURVES: [&str; 8] = [
    "G1 X30 Y20 F3000",
    "G1 X-25 Y10 F1500",
    "G2 X20 Y0 I10 J0 F2000",
    "$O R10 S30 F2000",
    "$E A15 B8 S90 W-270 F2000",
    "$S A5 W0.5 L30 F2000",
    "$F X-10 U10 F2000 Y=x^2/20",
    "$F X0 U8 F1500 Y=3*sqrt(x)",
];

fn run(command: &str, timed: &[(u64, u8)]) -> SimReport {
    let mut serial = SimSerial::with_input(format!("{command}\n").as_bytes());
    for &(t, b) in timed {
        serial = serial.with_byte_at(t, b);
    }
    let report = sim::run(SimConfig { serial, ..SimConfig::default() });
    assert!(!report.timed_out);
    report
}

/// Longest pause between two pulses, in µs, and when it began.
fn longest_pause(report: &SimReport) -> (u64, u64) {
    let steps = report.trace.steps(0);
    steps.windows(2).map(|w| (w[1].0 - w[0].0, w[0].0)).max().unwrap_or((0, 0))
}

/// Slowest speed a step may have when the machine starts or stops: the start rate, as an
/// interval between pulses (a diagonal step covers √2 steps of path, so it may take longer).
fn start_interval_us(settings: &Settings) -> f64 {
    let steps_per_s = settings.start_rate_mm_per_min / 60.0 * settings.steps_per_mm[0];
    1e6 / steps_per_s as f64
}

#[test]
fn a_hold_stops_on_the_path_and_a_resume_finishes_it_exactly() {
    for command in CURVES {
        let reference = run(command, &[]);
        let path = reference.path();
        assert!(path.len() > 200, "{command}: a curve long enough to hold in");
        let t_hold = reference.last_pulse_us() * 2 / 5;
        let held = run(command, &[(t_hold, b'!'), (t_hold + 1_000_000, b'~')]);
        assert_eq!(held.path(), path, "{command}: the same steps in the same order");
        assert_eq!(held.position, reference.position, "{command}");
        assert_eq!(held.position, *path.last().unwrap(), "{command}: position = pulses emitted");
        let (pause_us, _) = longest_pause(&held);
        assert!(pause_us > 800_000, "{command}: the pen stood still during the hold ({pause_us} µs)");
        // It decelerated into the stop: the last interval before the pause is a start-rate one.
        let steps = held.trace.steps(0);
        let gap = steps.windows(2).position(|w| w[1].0 - w[0].0 == pause_us).unwrap();
        let before = steps[gap].0 - steps[gap - 1].0;
        assert!(
            before as f64 >= start_interval_us(&held.settings) * 0.95,
            "{command}: stopped from {before} µs per step, not from speed"
        );
    }
}

#[test]
fn an_abort_decelerates_onto_the_path_and_drops_the_rest() {
    for command in CURVES {
        let reference = run(command, &[]);
        let path = reference.path();
        let t_abort = reference.last_pulse_us() / 2;
        let aborted = run(command, &[(t_abort, 0x18)]);
        let cut = aborted.path();
        assert!(cut.len() < path.len(), "{command}: the rest was dropped");
        assert!(cut.len() > path.len() / 4, "{command}: it ran until the abort");
        assert_eq!(cut[..], path[..cut.len()], "{command}: every step taken was on the path");
        assert_eq!(aborted.position, *cut.last().unwrap(), "{command}: position = pulses emitted");
        let answers = aborted.answers();
        assert_eq!(answers.matches("Grbl 1.1").count(), 2, "{command}: a reset answers with the banner");
        let steps = aborted.trace.steps(0);
        let last = steps[steps.len() - 1].0 - steps[steps.len() - 2].0;
        assert!(last as f64 >= start_interval_us(&aborted.settings) * 0.95, "{command}: it braked ({last} µs)");
    }
}

#[test]
fn after_an_abort_the_next_line_starts_from_where_the_pen_stopped() {
    let reference = run("G1 X30 Y0 F3000", &[]);
    // The sender stops streaming at the reset; a person then types a new line.
    let mut serial = SimSerial::with_input(b"G1 X30 Y0 F3000\nG4 P1.5\nG1 X30 Y30\n")
        .with_byte_at(reference.last_pulse_us() / 2, 0x18);
    for (i, &b) in b"G1 X0 Y5\n".iter().enumerate() {
        serial = serial.with_byte_at(3_000_000 + i as u64 * 100, b);
    }
    let report = sim::run(SimConfig { serial, ..SimConfig::default() });
    assert_eq!(
        report.position,
        Point::new(0, 500),
        "the absolute target is reached from the stop point: {}",
        report.answers()
    );
}

#[test]
fn a_host_jog_reports_jog_and_a_jog_cancel_stops_it_on_its_line() {
    let serial =
        SimSerial::with_input(b"$J=G91 X20 Y10 F1200\n").with_byte_at(500_000, b'?').with_byte_at(700_000, 0x85);
    let report = sim::run(SimConfig { serial, ..SimConfig::default() });
    let answers = report.answers();
    assert!(answers.contains("<Jog|MPos:"), "{answers}");
    let p = report.position;
    assert!(p.x > 0 && p.x < 2000, "stopped part way: {p:?}");
    let off_line = (p.x as f64 - 2.0 * p.y as f64).abs() / 5f64.sqrt();
    assert!(off_line <= 0.5, "on the jog's line: {p:?}");
    assert_eq!(answers.matches("Grbl 1.1").count(), 1, "a jog cancel is no reset");
}

//! Lines a sender writes right behind a move, without waiting for its `ok`: the move is a
//! running program from the moment it is queued, as in GRBL. A jog is refused (`error:8`); a
//! line that acts at rest (`$SLP`, a setting) waits for the move to end, and the move is never
//! dropped. In an alarm, such a line acts at once.

use servoplot::geom::Point;
use servoplot::sim::flash::SimFlash;
use servoplot::sim::{self, SimConfig, SimReport, serial::SimSerial};

fn power_on(flash: SimFlash, program: &str) -> SimReport {
    let report =
        sim::run(SimConfig { flash, serial: SimSerial::with_input(program.as_bytes()), ..SimConfig::default() });
    assert!(!report.timed_out, "the machine never came to rest: {}", report.answers());
    report
}

/// The answers, the banner and status reports left out.
fn answers(report: &SimReport) -> Vec<String> {
    report.answers().lines().skip(2).filter(|l| !l.starts_with('<')).map(str::to_string).collect()
}

#[test]
fn sleep_right_behind_a_move_waits_for_it_then_turns_the_servos_off() {
    let report = power_on(SimFlash::default(), "G1 X10 Y10 F1000\n$SLP\nG0 X0\n");
    assert_eq!(answers(&report), ["ok", "[MSG:Sleeping]", "ok", "error:9"]);
    // The move was drawn to its end, and nothing after the sleep moved.
    assert_eq!(report.position, Point::new(1_000, 1_000));
    assert_eq!(report.son.last().map(|&(_, on)| on), Some(false), "SON: {:?}", report.son);
    let last_pulse_us = report.trace.pulses.last().expect("the move pulsed").t_us;
    let son_off_us = report.son.last().unwrap().0;
    assert!(
        son_off_us >= last_pulse_us,
        "the servos went off at {son_off_us} µs, the last pulse at {last_pulse_us} µs"
    );
}

#[test]
fn a_jog_right_behind_a_move_is_refused_and_the_move_goes_on() {
    let report = power_on(SimFlash::default(), "G1 X10 F1000\n$J=X0 F500\nG1 Y5\n");
    assert_eq!(answers(&report), ["ok", "error:8", "ok"]);
    assert_eq!(report.position, Point::new(1_000, 500));
}

#[test]
fn a_setting_right_behind_a_move_waits_for_it() {
    let report = power_on(SimFlash::default(), "G1 X10 F1000\n$110=5000\nG1 X20\n");
    assert_eq!(answers(&report), ["ok", "ok", "ok"]);
    assert_eq!(report.settings.max_rate_mm_per_min[0], 5000.0);
    assert_eq!(report.position, Point::new(2_000, 0));
}

#[test]
fn in_the_power_on_lock_a_setting_and_sleep_are_answered_at_once() {
    // Homing on, kept in flash: the next power-on is locked (an alarm) until `$H` or `$X`.
    let first = power_on(SimFlash::default(), "$22=1\n");
    let locked = power_on(first.flash, "$100=150\n$SLP\n");
    assert_eq!(answers(&locked), ["[MSG:'$H'|'$X' to unlock]", "ok", "[MSG:Sleeping]", "ok"]);
    assert_eq!(locked.settings.steps_per_mm[0], 150.0);
}

#[test]
fn a_queued_move_reports_run_before_its_first_pulse() {
    // The servos off at rest (`$1=0`): a move waits `$209` ms for them after it is queued.
    // Polled every 5 ms: no report between the move's `ok` and its last pulse says Idle, or a
    // sender would take the job as done.
    let polls = (900..1_300)
        .step_by(5)
        .fold(SimSerial::with_input(b"$1=0\nG4 P0.9\nG1 X10 F1000\n"), |s, ms| s.with_byte_at(ms * 1_000, b'?'));
    let report = sim::run(SimConfig { serial: polls, ..SimConfig::default() });
    assert!(!report.timed_out);
    let lines = &report.serial_lines;
    let ok_us = lines.iter().filter(|(_, l)| l == "ok").nth(2).expect("the move's ok").0;
    let first_pulse_us = report.trace.pulses.first().expect("the move pulsed").t_us;
    let last_pulse_us = report.trace.pulses.last().unwrap().t_us;
    let waiting: Vec<&String> =
        lines.iter().filter(|(t, l)| l.starts_with('<') && *t > ok_us && *t < first_pulse_us).map(|(_, l)| l).collect();
    assert!(
        !waiting.is_empty(),
        "a report falls between the ok at {ok_us} µs and the first pulse at {first_pulse_us} µs"
    );
    for (t, l) in lines.iter().filter(|(t, l)| l.starts_with('<') && *t > ok_us && *t < last_pulse_us) {
        assert!(l.starts_with("<Run|"), "at {t} µs: {l}");
    }
}

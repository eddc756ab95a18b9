//! Realtime commands against a streaming sender, on the simulated board: a hold, a resume and a
//! reset act at once whatever the stream is doing, and never leave the machine stuck.

use servoplot::geom::Point;
use servoplot::sim::{self, SimConfig, SimReport, serial::SimSerial};

/// A 20 mm square drawn as 40 short lines, as a sender streams it.
fn square_program() -> String {
    let mut g = String::from("G1 F3000\n");
    for (x0, y0, x1, y1) in [(0, 0, 20, 0), (20, 0, 20, 20), (20, 20, 0, 20), (0, 20, 0, 0)] {
        for k in 1..=10 {
            let t = k as f64 / 10.0;
            g += &format!("G1 X{:.2} Y{:.2}\n", x0 as f64 + (x1 - x0) as f64 * t, y0 as f64 + (y1 - y0) as f64 * t);
        }
    }
    g
}

fn run(program: &str, timed: &[(u64, &[u8])]) -> SimReport {
    let mut serial = SimSerial::with_input(program.as_bytes());
    for &(t, bytes) in timed {
        for &b in bytes {
            serial = serial.with_byte_at(t, b);
        }
    }
    let report = sim::run(SimConfig { serial, ..SimConfig::default() });
    assert!(!report.timed_out, "the machine came to rest: {}", report.answers());
    report
}

fn inside_the_square(report: &SimReport) -> bool {
    report.path().iter().all(|p| (0..=2000).contains(&p.x) && (0..=2000).contains(&p.y))
}

#[test]
fn a_hold_while_streaming_holds_and_a_resume_finishes_the_drawing() {
    let reference = run(&square_program(), &[]);
    let held = run(&square_program(), &[(300_000, b"!"), (2_300_000, b"~")]);
    assert_eq!(held.path(), reference.path());
    assert_eq!(held.position, Point::ORIGIN);
    assert!(held.last_pulse_us() > reference.last_pulse_us() + 1_500_000, "it stood still meanwhile");
    assert_eq!(held.answers().lines().filter(|l| *l == "ok").count(), 41);
}

#[test]
fn a_reset_while_streaming_stops_on_the_path_and_runs_nothing_queued() {
    let reference = run(&square_program(), &[]);
    let t = reference.last_pulse_us() / 3;
    let report = run(&square_program(), &[(t, b"\x18")]);
    let cut = report.path();
    assert!(cut.len() < reference.path().len() / 2);
    assert_eq!(cut[..], reference.path()[..cut.len()], "every step on the square's path");
    assert!(inside_the_square(&report));
    assert_eq!(report.answers().matches("Grbl 1.1").count(), 2);
}

#[test]
fn an_abort_is_not_undone_by_a_resume_or_a_hold_that_follows_it() {
    let reference = run(&square_program(), &[]);
    let t = reference.last_pulse_us() / 3;
    for burst in [&b"!\x18~"[..], b"\x18!", b"\x18~!~"] {
        let report = run(&square_program(), &[(t, burst)]);
        assert!(report.path().len() < reference.path().len() / 2, "{burst:?} stopped the drawing");
        assert!(inside_the_square(&report), "{burst:?}");
        assert_eq!(report.answers().matches("Grbl 1.1").count(), 2, "{burst:?}: the reset answered");
    }
}

#[test]
fn a_hold_at_a_very_slow_feed_acts_within_the_step_queue_time() {
    // 5 mm/min: 120 ms per step. Without a time bound, 32 queued steps would be 4 s.
    let report = run("G1 X0.5 F5\n", &[(3_000_000, b"!"), (6_000_000, b"?"), (7_000_000, b"~")]);
    let steps = report.trace.steps(0);
    let last_before_hold = steps.iter().rev().find(|(t, _)| *t < 6_000_000).unwrap().0;
    assert!(
        last_before_hold < 3_000_000 + 300_000,
        "stopped {} ms after the hold",
        (last_before_hold - 3_000_000) / 1000
    );
    assert!(report.answers().contains("<Hold:0|"), "{}", report.answers());
}

#[test]
fn a_hold_at_rest_is_reported_and_keeps_the_next_job_until_cycle_start() {
    let report = run("G4 P0.2\nG1 X1\n", &[(100_000, b"!"), (500_000, b"?"), (1_000_000, b"~")]);
    let answers = report.answers();
    assert!(answers.contains("<Hold:0|MPos:0.000,0.000"), "{answers}");
    assert_eq!(report.position, Point::new(100, 0));
    assert!(report.trace.pulses[0].t_us >= 1_000_000, "nothing moved before the resume");
}

/// Bytes typed or pasted at `t_us`, all at once, ignoring flow control.
fn paste(t_us: u64, text: &str) -> Vec<(u64, u8)> {
    text.bytes().map(|b| (t_us, b)).collect()
}

fn run_timed(program: &str, timed: &[(u64, u8)], keys: Option<&str>) -> SimReport {
    let mut serial = SimSerial::with_input(program.as_bytes());
    for &(t, b) in timed {
        serial = serial.with_byte_at(t, b);
    }
    let keys = keys.map(|k| servoplot::sim::keys::KeyScript::parse(k).unwrap()).unwrap_or_default();
    let report = sim::run(SimConfig { serial, keys, ..SimConfig::default() });
    assert!(!report.timed_out, "the machine came to rest: {}", report.answers());
    report
}

fn inside_the_travel(report: &SimReport) -> bool {
    let limit = (report.settings.max_travel_mm[0] * report.settings.steps_per_mm[0]) as i32;
    report.path().iter().all(|p| p.x.abs() <= limit && p.y.abs() <= limit)
}

#[test]
fn lines_streamed_behind_a_refused_curve_are_planned_from_where_the_pen_is() {
    // The function jumps 6 mm at x = 10 mm (over the 5 mm limit): it is refused before it
    // moves, so the lines streamed behind it start from where the pen really is.
    let mut g = String::from("$F X0 U50 F3000 Y=floor(x/10)*6\n");
    for k in 0..19 {
        g += if k % 2 == 0 { "G1 X50 Y31\n" } else { "G1 X50 Y30\n" };
    }
    g += "$S A1 W0.5 L-245 F3000\n"; // from X50 it ends at X-195
    let report = run_timed(&g, &[], None);
    let answers = report.answers();
    assert!(answers.contains("[MSG:Function jumps more than $204 after x=9.990]\r\nerror:33"), "{answers}");
    assert_eq!(answers.matches("ok").count(), 20, "{answers}");
    assert!(inside_the_travel(&report), "a step outside the travel");
    assert_eq!(report.position.x, -19_500);
}

#[test]
fn a_jog_cancel_makes_the_next_jog_start_from_where_the_pen_stopped() {
    let mut timed = vec![(1_000_000, 0x85)];
    timed.extend(paste(1_005_000, "$J=G91 X1 F600\n"));
    let cancelled = run_timed("$J=G91 X50 F1200\n", &[(1_000_000, 0x85)], None);
    let nudged = run_timed("$J=G91 X50 F1200\n", &timed, None);
    let stop = cancelled.position.x;
    assert!(stop < 2500, "the jog was cancelled at {stop}");
    assert!((nudged.position.x - (stop + 100)).abs() <= 1, "nudged 1 mm from {stop}: {:?}", nudged.position);
}

#[test]
fn a_jog_cancel_does_not_stop_a_keypad_drawing_after_a_host_jog() {
    let reference = run_timed("$J=G91 X10 F3000\n", &[], Some("wait:1000 3 8 # # # #"));
    let report = run_timed("$J=G91 X10 F3000\n", &[(2_317_000, 0x85)], Some("wait:1000 3 8 # # # #"));
    assert_eq!(report.path(), reference.path(), "the circle was drawn whole");
}

#[test]
fn a_hold_right_after_a_reset_still_gets_the_banner() {
    for dt in [0, 50_000, 90_000, 95_000, 120_000] {
        let timed = [(1_000_000, 0x18), (1_000_000 + dt, b'!'), (3_000_000, b'~')];
        let report = run_timed("G1 X100 F3000\n", &timed, None);
        assert_eq!(report.answers().matches("Grbl 1.1").count(), 2, "dt {dt}: {}", report.answers());
    }
}

#[test]
fn a_paste_ignoring_flow_control_during_a_hold_never_locks_the_link() {
    let lines: String = (1..=150).map(|k| format!("G1 X{} Y0\n", k % 100)).collect();
    let mut timed = paste(0, &lines);
    timed.push((1, b'!'));
    timed.extend(paste(2, &lines));
    timed.extend([(3_000_000, b'~'), (4_000_000, 0x18), (5_000_000, b'?')]);
    let report = run_timed("", &timed, None);
    let answers = report.answers();
    assert!(answers.contains("[MSG:Receive buffer full: lines dropped, each answered error:100"), "{answers}");
    assert_eq!(answers.matches("Grbl 1.1").count(), 2, "the reset got through: {answers}");
    assert!(answers.contains("<Idle|"), "the status query got through: {answers}");
    assert_eq!(report.position, *report.path().last().unwrap());
}

#[test]
fn the_safety_door_holds_reports_door_and_a_resume_finishes_the_drawing() {
    let reference = run(&square_program(), &[]);
    let door = run(&square_program(), &[(300_000, b"\x84"), (1_300_000, b"?"), (2_300_000, b"~"), (2_400_000, b"?")]);
    assert_eq!(door.path(), reference.path());
    assert!(door.last_pulse_us() > reference.last_pulse_us() + 1_500_000, "it stood still meanwhile");
    let answers = door.answers();
    assert!(answers.contains("<Door:0|"), "{answers}");
    assert!(answers.contains("<Run|"), "the resume closed the door: {answers}");
    // At rest, the door holds what comes next until `~`.
    let idle = run("G4 P0.5\nG1 X10 F3000\n", &[(100_000, b"\x84"), (2_000_000, b"~")]);
    assert!(idle.trace.pulses[0].t_us >= 2_000_000, "nothing moved before the resume");
    assert_eq!(idle.position, Point::new(1_000, 0));
}

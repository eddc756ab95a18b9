//! The machine's own inputs on the simulated plotter: a limit switch reached mid-curve, a glitch
//! on a switch, a driver alarm and the emergency stop mid-drawing. Each stops the pulses at once
//! and raises its alarm; nothing moves until `$X`, which works only once the cause is gone.

use servoplot::geom::Axis;
use servoplot::sim::inputs::{InputScript, Switches};
use servoplot::sim::{self, SimConfig, SimReport, serial::SimSerial};

/// Streams `lines`, then sends `later` (each `(time µs, text)`) byte by byte at its time.
fn run(lines: &str, later: &[(u64, &str)], switches: Option<Switches>, events: &str) -> SimReport {
    let mut serial = SimSerial::with_input(lines.as_bytes());
    for &(t, text) in later {
        for (k, b) in text.bytes().enumerate() {
            serial = serial.with_byte_at(t + k as u64, b);
        }
    }
    let events = InputScript::parse(events).unwrap();
    let report = sim::run(SimConfig { serial, switches, events, ..SimConfig::default() });
    assert!(!report.timed_out);
    report
}

/// The pulse trace's X position (in steps) after each pulse, with its time.
fn x_positions(report: &SimReport) -> Vec<(u64, i64)> {
    let mut x = 0;
    let mut out = Vec::new();
    for p in report.trace.pulses.iter().filter(|p| p.axis == Axis::X) {
        x += if p.sign_high { 1 } else { -1 };
        out.push((p.t_us, x));
    }
    out
}

/// Switches 150 mm inside each end of the ±200 mm travel: at ±50 mm (5000 steps).
const SWITCHES_AT_50_MM: Option<Switches> = Some(Switches { beyond_travel_mm: -150.0 });
const SWITCH_STEPS: i64 = 5_000;

#[test]
fn a_limit_switch_reached_mid_curve_stops_the_pulses_within_a_period_and_locks_until_unlocked() {
    // A circle of 30 mm about (30, 0) passes x = 50 mm, where the X max switch is.
    let lines = "$21=1\n$206=2\nG2 X0 Y0 I30 J0 F1200\nG1 X20 Y0\n";
    let unlock = "$X\nG1 X0 Y0 F1200\nG1 X60\n";
    let report = run(lines, &[(10_000_000, "G1 X0\n"), (20_000_000, unlock)], SWITCHES_AT_50_MM, "");
    let answers = report.answers();
    assert!(
        answers.contains("ALARM:1\r\n[MSG:Hard limit X+: position lost; move off the switch after '$X']"),
        "{answers}"
    );
    // A line sent after the trip is refused: the machine is locked.
    let after_alarm = &answers[answers.find("ALARM:1").unwrap()..];
    assert!(
        after_alarm.starts_with(
            "ALARM:1\r\n[MSG:Hard limit X+: position lost; move off the switch after '$X']\r\nerror:9\r\n"
        ),
        "{answers}"
    );

    let xs = x_positions(&report);
    let (closed_at, _) = *xs.iter().find(|&&(_, x)| x >= SWITCH_STEPS).unwrap();
    let before_unlock: Vec<_> = xs.iter().filter(|&&(t, _)| t < 20_000_000).collect();
    let &&(last_t, last_x) = before_unlock.last().unwrap();
    let period = last_t - before_unlock[before_unlock.len() - 2].0;
    // Pressed for the 2 ms debounce, then at most one more period of pulses.
    assert!(
        last_t <= closed_at + 2_000 + period,
        "switch at {closed_at} µs, last pulse {last_t} µs ({period} µs apart)"
    );
    assert!(last_t >= closed_at + 2_000 - period, "debounced, not tripped at once");
    assert!(last_x - SWITCH_STEPS < 10, "stopped just past the switch: {last_x}");

    // `$X`, then the move away from the switch runs, and the move back into it trips again.
    assert!(after_alarm.contains("[MSG:Caution: Unlocked]"), "{answers}");
    let home = xs.iter().filter(|&&(t, _)| t > 20_000_000).map(|&(_, x)| x).min().unwrap();
    assert_eq!(home, 0, "back at the origin");
    assert_eq!(after_alarm.matches("ALARM:1").count(), 2, "{answers}");
    assert!((report.position.x - SWITCH_STEPS as i32).abs() < 10, "the position is the pulses emitted");
}

#[test]
fn a_glitch_shorter_than_the_debounce_never_trips_and_a_stuck_switch_does() {
    let lines = "$21=1\n$206=3\nG1 X40 F3000\n";
    // A 2 ms glitch on the X max switch while X moves towards it.
    let glitch = run(lines, &[], None, "300 on x+\n302 off x+");
    assert!(!glitch.answers().contains("ALARM"), "{}", glitch.answers());
    assert_eq!(glitch.position.x, 4_000, "the line was drawn to its end");
    // The same switch stuck from then on: tripped 3 ms later.
    let stuck = run(lines, &[], None, "300 on x+");
    assert!(stuck.answers().contains("ALARM:1"), "{}", stuck.answers());
    let last = stuck.last_pulse_us();
    assert!((303_000..304_000).contains(&last), "last pulse at {last} µs");
    // A switch behind the pen never stops it: the X min switch stuck while X moves forward.
    let behind = run(lines, &[], None, "0 on x-");
    assert_eq!(behind.position.x, 4_000);
    assert!(!behind.answers().contains("ALARM"));
}

#[test]
fn a_driver_alarm_mid_drawing_stops_it_turns_the_servos_off_and_unlocks_once_cleared() {
    let lines = "$207=1\n$O R20 S0 F2000\n";
    let later = [(1_000_000, "$X\n"), (2_000_000, "$X\nG0 X0 Y0\n")];
    let report = run(lines, &later, None, "500 on alarm-y\n1500 off alarm-y");
    let answers = report.answers();
    assert!(
        answers.contains("ALARM:17\r\n[MSG:Driver alarm Y: servos off; clear the driver's fault, then '$X']"),
        "{answers}"
    );
    // Stopped within a period of the alarm (2 ms debounce).
    let stopped = report.trace.pulses.iter().filter(|p| p.t_us < 1_000_000).map(|p| p.t_us).max().unwrap();
    assert!((500_000..503_000).contains(&stopped), "last pulse at {stopped} µs");
    // SON: on at power-on, off after the alarm, back on after the `$X` once it was cleared.
    let son = &report.son;
    assert!(son[0].1, "SON on at power-on");
    let off = son.iter().find(|c| !c.1).unwrap().0;
    assert!((500_000..520_000).contains(&off), "SON off at {off} µs");
    let on_again = son.iter().find(|c| c.1 && c.0 > off).unwrap().0;
    assert!(on_again >= 2_000_000, "SON back on at {on_again} µs");
    // The first `$X` came while the alarm was still raised: refused.
    let first_unlock = &answers[answers.find("ALARM:17").unwrap()..];
    assert!(first_unlock.contains("[MSG:Driver alarm or e-stop still active]\r\nerror:9"), "{answers}");
    assert!(first_unlock.contains("[MSG:Caution: Unlocked]"), "{answers}");
    assert_eq!(report.position.x, 0, "moved back after the unlock: {:?}", report.position);
    assert_eq!(report.position.y, 0);
}

#[test]
fn the_emergency_stop_stops_everything_resets_the_links_and_locks() {
    let lines = "$208=1\nG1 X30 F1500\nG1 Y30\nG1 X0\n";
    let report = run(lines, &[(2_000_000, "$X\n")], None, "400 on estop\n1000 off estop");
    let answers = report.answers();
    assert!(answers.contains("ALARM:10\r\n[MSG:Emergency stop: release it, then '$X']"), "{answers}");
    let stopped = report.last_pulse_us();
    assert!((400_000..403_000).contains(&stopped), "last pulse at {stopped} µs");
    // As Ctrl-X: the banner again after the alarm.
    let after = &answers[answers.find("ALARM:10").unwrap()..];
    assert!(after.contains("Grbl 1.1h"), "{answers}");
    assert!(after.contains("[MSG:Caution: Unlocked]"), "{answers}");
    assert_eq!(report.position.y, 0, "nothing moved after the stop");
}

#[test]
fn with_an_idle_delay_the_servos_go_off_at_rest_and_come_back_before_the_next_move() {
    // $1=100: SON low 100 ms after the pen stops; $209=30: the next move waits 30 ms for the
    // drivers once SON is high again.
    let report = run("$1=100\n$209=30\nG1 X5 F3000\n", &[(2_000_000, "G1 X0\n")], None, "");
    let son = &report.son;
    let first_stop = report.trace.pulses.iter().filter(|p| p.t_us < 2_000_000).map(|p| p.t_us).max().unwrap();
    let off = son.iter().find(|c| !c.1).expect("SON went low").0;
    assert!((first_stop + 100_000..first_stop + 115_000).contains(&off), "stopped {first_stop} µs, SON off {off} µs");
    let on_again = son.iter().find(|c| c.1 && c.0 > off).expect("SON back on").0;
    assert!((2_000_000..2_015_000).contains(&on_again), "SON on at {on_again} µs");
    let next_pulse = report.trace.pulses.iter().map(|p| p.t_us).find(|&t| t > 2_000_000).unwrap();
    assert!(next_pulse >= on_again + 30_000, "first pulse {next_pulse} µs, SON on {on_again} µs");
    assert_eq!(report.position.x, 0);
    // The default, 255, keeps them on.
    let report = run("G1 X5 F3000\n", &[(2_000_000, "G1 X0\n")], None, "");
    assert!(report.son.iter().all(|c| c.1), "{:?}", report.son);
}

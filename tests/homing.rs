//! Homing (`$H`) on the simulated plotter, whose switches sit 5 mm beyond each end of the
//! ±200 mm travel the settings assume: from anywhere, the cycle finds the min switches, leaves
//! the pen a pull-off off them and puts machine zero 200 mm inside, so machine coordinates name
//! the same place whatever the pen's position at power-on. With homing on, the plotter powers
//! on locked; a cycle that cannot find its switch, or cannot leave it, or is reset, fails with
//! GRBL's alarm and moves nothing more. Soft limits (`$20`) keep drawings and jogs inside the
//! travel.

use servoplot::geom::{Axis, Point};
use servoplot::sim::inputs::{InputScript, Switches};
use servoplot::sim::{self, SimConfig, SimReport, flash::SimFlash, serial::SimSerial};

/// The switches, 5 mm (500 steps) beyond each end of the travel.
const SWITCHES: Option<Switches> = Some(Switches { beyond_travel_mm: 5.0 });
const SWITCH_STEPS: i64 = 20_500;
/// The default pull-off, 1 mm.
const PULL_OFF_STEPS: i64 = 100;

fn run_with(
    lines: &str,
    later: &[(u64, &str)],
    switches: Option<Switches>,
    events: &str,
    flash: SimFlash,
) -> SimReport {
    let mut serial = SimSerial::with_input(lines.as_bytes());
    for &(t, text) in later {
        for (k, b) in text.bytes().enumerate() {
            serial = serial.with_byte_at(t + k as u64, b);
        }
    }
    let events = InputScript::parse(events).unwrap();
    let report = sim::run(SimConfig { serial, switches, events, flash, ..SimConfig::default() });
    assert!(!report.timed_out);
    report
}

fn run(lines: &str, switches: Option<Switches>, events: &str) -> SimReport {
    run_with(lines, &[], switches, events, SimFlash::default())
}

/// Where the pulses took the pen from where it powered on, steps.
fn driven(report: &SimReport) -> (i64, i64) {
    let mut at = [0i64; 2];
    for p in &report.trace.pulses {
        at[p.axis as usize] += if p.sign_high { 1 } else { -1 };
    }
    (at[0], at[1])
}

#[test]
fn homing_from_anywhere_ends_a_pull_off_off_the_switches_with_machine_zero_in_the_middle() {
    for (x, y) in [(0.0, 0.0), (150.0, -120.0), (-199.0, 199.0), (37.5, 180.0)] {
        // `$H` runs at rest, as in GRBL: `G4 P0` waits for the move.
        let lines = format!("$22=1\nG0 X{x} Y{y}\nG4 P0\n$H\n?");
        let report = run(&lines, SWITCHES, "");
        let answers = report.answers();
        let status = "<Idle|MPos:-199.000,-199.000,0.000|FS:0,0|WCO:0.000,0.000,0.000>\r\n";
        assert!(answers.ends_with(&format!("ok\r\nok\r\nok\r\nok\r\n{status}")), "{answers}");
        assert_eq!(report.position, Point::new(-19_900, -19_900), "from ({x}, {y})");
        // The locate stops within a pulse period after the 2 ms debounce: at most a step past
        // the switch at its 100 mm/min.
        let (px, py) = driven(&report);
        let homed = PULL_OFF_STEPS - SWITCH_STEPS - 1..=PULL_OFF_STEPS - SWITCH_STEPS;
        assert!(homed.contains(&px) && homed.contains(&py), "from ({x}, {y}): ({px}, {py})");
    }
}

#[test]
fn the_last_approach_locates_slowly_and_machine_zero_is_where_the_switches_say() {
    // After homing, G0 X0 Y0 goes to machine zero: 200 mm inside the min switches, which are
    // 5 mm further out than power-on assumed.
    let report = run("$22=1\n$24=60\n$H\nG0 X0 Y0\n", SWITCHES, "");
    assert_eq!(report.position, Point::ORIGIN);
    let (px, py) = driven(&report);
    assert!((-501..=-500).contains(&px) && (-501..=-500).contains(&py), "({px}, {py})");
    // Y's locate approach, at 60 mm/min (100 pulses/s): the last pulses towards the switch 10 ms
    // apart.
    let y: Vec<_> = report.trace.pulses.iter().filter(|p| p.axis == Axis::Y && !p.sign_high).collect();
    let locate: Vec<_> = y.iter().rev().take(2).collect();
    let gap = locate[0].t_us - locate[1].t_us;
    assert!((9_900..=10_100).contains(&gap), "{gap} µs between the last locate pulses");
}

#[test]
fn with_homing_on_the_plotter_powers_on_locked_until_homed() {
    let first = run("$22=1\n", SWITCHES, "");
    let report = run_with("G1 X10 F1000\n$H\nG1 X10 F1000\n", &[], SWITCHES, "", first.flash);
    let answers = report.answers();
    assert!(
        answers.starts_with("\r\nGrbl 1.1h ['$' for help]\r\n[MSG:'$H'|'$X' to unlock]\r\nerror:9\r\nok\r\nok\r\n"),
        "{answers}"
    );
    assert_eq!(report.position, Point::new(1_000, -19_900));
}

#[test]
fn a_switch_never_found_is_alarm_9_and_one_never_released_is_alarm_8() {
    // No switches: the X seek runs 1.5 travels (600 mm) and stops.
    let report = run("$22=1\n$25=6000\n$H\nG1 X1 F100\n", None, "");
    let answers = report.answers();
    assert!(
        answers.contains("ALARM:9\r\n[MSG:Homing failed: X switch not found. '$H' or '$X']\r\nerror:9\r\nerror:9\r\n"),
        "{answers}"
    );
    assert_eq!(driven(&report), (-60_000, 0));
    // The X min switch stuck closed: found at once, still pressed after the pull-off.
    let report = run("$22=1\n$H\n", SWITCHES, "0 on x-");
    let answers = report.answers();
    assert!(answers.contains("ALARM:8\r\n[MSG:Homing failed: X switch still pressed after the pull-off."), "{answers}");
    let (px, py) = driven(&report);
    assert!((PULL_OFF_STEPS - 5..PULL_OFF_STEPS).contains(&px) && py == 0, "the pull-off after the debounce: {px}");
}

#[test]
fn a_reset_during_homing_stops_it_with_alarm_6() {
    let report = run_with("$22=1\n$H\n", &[(3_000_000, "\x18")], SWITCHES, "", SimFlash::default());
    let answers = report.answers();
    let after = &answers[answers.find("ALARM:6").expect(&answers)..];
    assert!(after.starts_with("ALARM:6\r\n[MSG:Homing failed: reset or abort during the cycle. '$H' or '$X']"));
    assert!(answers.contains("[MSG:'$H'|'$X' to unlock]"), "{answers}");
    let (px, _) = driven(&report);
    assert!((-6_000..-4_000).contains(&px), "stopped after about 3 s of the seek: {px}");
    assert!(!report.trace.pulses.iter().any(|p| p.t_us > 3_500_000), "nothing moved after the reset");
}

#[test]
fn soft_limits_refuse_what_leaves_the_travel_and_20_0_lets_it_go() {
    let report = run("G1 X250 F6000\n$J=X-250 F6000\n", None, "");
    assert_eq!(report.answers(), "\r\nGrbl 1.1h ['$' for help]\r\nerror:15\r\nerror:15\r\n");
    assert_eq!(report.position, Point::ORIGIN, "nothing moved");
    let report = run("$20=0\nG1 X250 F6000\nG4 P0\n$J=Y-250 F6000\n", None, "");
    assert_eq!(report.answers(), "\r\nGrbl 1.1h ['$' for help]\r\nok\r\nok\r\nok\r\nok\r\n");
    assert_eq!(report.position, Point::new(25_000, -25_000));
}

#[test]
fn the_keypad_homes_too_and_d_aborts_it() {
    // Homing on, kept in flash: the plotter powers on locked, and mode 8 homes it.
    let first = run("$22=1\n", SWITCHES, "");
    let keys = servoplot::sim::keys::KeyScript::parse("8").unwrap();
    let report = sim::run(SimConfig { switches: SWITCHES, flash: first.flash.clone(), keys, ..SimConfig::default() });
    assert!(!report.timed_out);
    assert_eq!(report.position, Point::new(-19_900, -19_900));
    let (px, _) = driven(&report);
    assert!((PULL_OFF_STEPS - SWITCH_STEPS - 1..=PULL_OFF_STEPS - SWITCH_STEPS).contains(&px), "{px}");
    // D a second into the seek stops it: ALARM:6, and the pen stays where the seek stopped.
    let keys = servoplot::sim::keys::KeyScript::parse("8 wait:1000 D").unwrap();
    let report = sim::run(SimConfig { switches: SWITCHES, flash: first.flash, keys, ..SimConfig::default() });
    assert!(report.answers().contains("ALARM:6"), "{}", report.answers());
    let (px, _) = driven(&report);
    assert!((-2_000..-1_000).contains(&px), "stopped a second into the 1000 mm/min seek: {px}");
}

#[test]
fn the_position_is_unknown_from_power_on_with_homing_on_and_after_a_hard_limit_until_homed() {
    use servoplot::machine::Machine;
    use servoplot::machine_io::inputs::Trip;
    use servoplot::settings::Settings;
    let machine = Machine::new(Settings { homing: true, ..Settings::default() });
    assert!(machine.status().position_lost, "powered on, not homed");
    machine.handles().unwrap().homing.set_origin(Point::new(-19_900, -19_900));
    assert!(!machine.status().position_lost, "homed");
    assert_eq!(machine.position(), Point::new(-19_900, -19_900));
    // During homing the switch an approach looks for is no loss; an e-stop is.
    assert!(machine.request_homing());
    machine.trip(Trip::Limit { axis: Axis::X, max: false });
    assert!(!machine.status().position_lost, "the switch homing looked for");
    let machine = Machine::new(Settings { homing: true, ..Settings::default() });
    machine.handles().unwrap().homing.set_origin(Point::new(-19_900, -19_900));
    assert!(machine.request_homing());
    machine.trip(Trip::EStop);
    assert!(machine.status().position_lost, "an e-stop during homing");
    let machine = Machine::new(Settings::default());
    machine.trip(Trip::Limit { axis: Axis::X, max: true });
    assert!(machine.status().position_lost, "the pulses stopped without braking");
    assert!(!Machine::new(Settings::default()).status().position_lost, "homing off: the power-on origin counts");
}

/// The pauses between homing moves (gaps of more than 100 ms between pulses), µs.
fn pauses(report: &SimReport) -> Vec<(u64, u64)> {
    let pulses = &report.trace.pulses;
    pulses.windows(2).filter(|w| w[1].t_us - w[0].t_us > 100_000).map(|w| (w[0].t_us, w[1].t_us)).collect()
}

#[test]
fn a_reset_or_an_e_stop_between_homing_moves_stops_the_cycle_and_leaves_the_machine_usable() {
    let reference = run("$22=1\n$208=1\n$H\n", SWITCHES, "");
    let (a, b) = pauses(&reference)[0];
    let pause = (a + b) / 2;
    // A reset in the pause after the X seek: ALARM:6, and not one pulse more.
    let report = run_with("$22=1\n$208=1\n$H\n", &[(pause, "\x18")], SWITCHES, "", SimFlash::default());
    assert!(report.answers().contains("ALARM:6"), "{}", report.answers());
    assert!(report.trace.pulses.iter().all(|p| p.t_us < pause), "moved after the reset");
    // The e-stop in the same pause: ALARM:10; after a reset `$X` and `$H` are answered, and
    // the second cycle homes.
    let ms = pause / 1_000;
    let events = format!("{ms} on estop\n{} off estop\n", ms + 50);
    let later = [(pause + 2_000_000, "\x18"), (pause + 3_000_000, "$X\n"), (pause + 4_000_000, "$H\n")];
    let report = run_with("$22=1\n$208=1\n$H\n", &later, SWITCHES, &events, SimFlash::default());
    let answers = report.answers();
    assert!(answers.contains("ALARM:10"), "{answers}");
    assert!(answers.ends_with("[MSG:Caution: Unlocked]\r\nok\r\nok\r\n"), "{answers}");
    assert_eq!(report.position, Point::new(-19_900, -19_900));
}

#[test]
fn host_motion_is_refused_while_the_keypad_homes() {
    let first = run("$22=1\n", SWITCHES, "");
    let keys = servoplot::sim::keys::KeyScript::parse("8").unwrap();
    let reference =
        sim::run(SimConfig { switches: SWITCHES, flash: first.flash.clone(), keys, ..SimConfig::default() });
    let (a, b) = pauses(&reference)[4];
    // A G0 in a pause of Y's cycle: refused, and the cycle still homes where the switches are.
    let mut serial = SimSerial::default();
    for (k, byte) in "G0 X50\n".bytes().enumerate() {
        serial = serial.with_byte_at((a + b) / 2 + k as u64, byte);
    }
    let keys = servoplot::sim::keys::KeyScript::parse("8").unwrap();
    let report = sim::run(SimConfig { serial, switches: SWITCHES, flash: first.flash, keys, ..SimConfig::default() });
    assert!(report.answers().ends_with("error:9\r\n"), "{}", report.answers());
    assert_eq!(report.position, Point::new(-19_900, -19_900));
    assert_eq!(driven(&report), driven(&reference), "the same pulses as without the G0");
}

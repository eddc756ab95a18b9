//! The run LED and the buzzer on the simulated plotter: the LED is lit while a drawing runs, the
//! buzzer beeps once when it ends and three times on an alarm, and `$214`/`$215` silence them.

use servoplot::sim::inputs::InputScript;
use servoplot::sim::{self, SimConfig, SimReport, serial::SimSerial};
use servoplot::tasks::servo::SERVO_ENABLE_POLL_MS;

fn run(lines: &str, events: &str) -> SimReport {
    let serial = SimSerial::with_input(lines.as_bytes());
    let events = InputScript::parse(events).unwrap();
    let report = sim::run(SimConfig { serial, events, ..SimConfig::default() });
    assert!(!report.timed_out);
    report
}

/// The times a pin went high, and how long it stayed (to the end of the run if it did not fall).
fn pulses(changes: &[(u64, bool)], end_us: u64) -> Vec<(u64, u64)> {
    let falls = changes.iter().skip(1).map(|c| c.0).chain([end_us]);
    changes.iter().zip(falls).filter(|(c, _)| c.1).map(|(c, fall)| (c.0, fall - c.0)).collect()
}

/// The task that drives both looks every 10 ms.
const LOOK_US: u64 = SERVO_ENABLE_POLL_MS * 1_000;

#[test]
fn the_led_lights_while_drawing_and_the_buzzer_beeps_once_at_the_end() {
    let report = run("G1 X20 F3000\n", "");
    let first = report.trace.pulses.first().unwrap().t_us;
    let last = report.last_pulse_us();
    let lit = pulses(&report.led, report.end_us);
    assert_eq!(lit.len(), 1, "{:?}", report.led);
    let (on, for_us) = lit[0];
    assert!(on <= first + LOOK_US && on + for_us >= last, "lit {on} µs for {for_us} µs; pulses {first}..{last} µs");
    assert!(on + for_us <= last + 2 * LOOK_US, "dark once drawn");
    let beeps = pulses(&report.buzzer, report.end_us);
    assert_eq!(beeps.len(), 1, "{:?}", report.buzzer);
    assert!(beeps[0].0 >= last && beeps[0].0 < last + 20_000, "beep at {} µs, last pulse {last} µs", beeps[0].0);
    assert!((140_000..=170_000).contains(&beeps[0].1), "a 150 ms beep: {} µs", beeps[0].1);
}

#[test]
fn an_alarm_beeps_three_times_and_both_can_be_switched_off() {
    let report = run("$208=1\nG1 X20 F600\n", "300 on estop");
    let beeps = pulses(&report.buzzer, report.end_us);
    assert_eq!(beeps.len(), 3, "{:?}", report.buzzer);
    let quiet = run("$214=0\n$215=0\n$208=1\nG1 X20 F600\n", "300 on estop");
    assert!(quiet.led.iter().all(|c| !c.1) && quiet.buzzer.iter().all(|c| !c.1));
}

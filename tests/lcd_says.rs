//! What the LCD says, read back from the simulated board's frames: the screen names what the
//! machine does (homing, an alarm, a lock and how to leave it, a jog slowing to a stop), the
//! key that acknowledges an abort does nothing more, and an expression's `*` reads as a
//! multiplication sign.

use servoplot::sim::inputs::Switches;
use servoplot::sim::keys::KeyScript;
use servoplot::sim::lcd::Frame;
use servoplot::sim::serial::SimSerial;
use servoplot::sim::{self, SimConfig, SimReport};

mod support;

use support::text;

/// A frame's four lines.
fn lines(frame: &Frame) -> Vec<String> {
    (0..4).map(|line| text(frame, line, 24)).collect()
}

/// The four lines of the last frame.
fn last_lines(report: &SimReport) -> Vec<String> {
    lines(&report.frames.last().expect("the LCD was drawn").1)
}

/// Every frame's lines from `from_ms` on (virtual time).
fn lines_from(report: &SimReport, from_ms: u64) -> Vec<Vec<String>> {
    report.frames.iter().filter(|(t, _)| *t >= from_ms * 1_000).map(|(_, f)| lines(f)).collect()
}

/// Sets `settings` on the host link and powers the board off; then powers it on with them and
/// types `keys` (the first one 2.5 s in, past the splash), limit switches `switches_mm` beyond
/// the travel.
fn power_on_with(settings: &str, keys: &str, switches_mm: f32) -> SimReport {
    let first = sim::run_serial(settings);
    assert!(!first.answers().contains("error"), "{}", first.answers());
    let report = sim::run(SimConfig {
        flash: first.flash,
        keys: KeyScript::parse(&format!("wait:2500 {keys}")).unwrap(),
        switches: Some(Switches { beyond_travel_mm: switches_mm }),
        serial: SimSerial::default(),
        ..SimConfig::default()
    });
    assert!(!report.timed_out);
    report
}

#[test]
fn homing_from_the_keypad_says_homing_and_the_key_after_its_abort_does_not_home_again() {
    // Homing on: the plotter powers on locked and says how to unlock.
    let locked = power_on_with("$22=1\n", "wait:100", 5.0);
    assert_eq!(last_lines(&locked)[3], "Locked: 8 home, or $X");
    // 8 homes; D half a second in aborts it; # a second later is only the acknowledgment.
    let report = power_on_with("$22=1\n", "8 wait:500 D wait:1000 # wait:1000", 5.0);
    let homing: Vec<_> = lines_from(&report, 2_600).into_iter().take_while(|l| l[0].ends_with("HOME")).collect();
    assert!(!homing.is_empty());
    // Until D, which is said while the machine stops.
    assert!(homing.iter().all(|l| l[2] == "Homing" && ["D abort", "Aborted"].contains(&l[3].as_str())), "{homing:?}");
    assert_eq!(homing[0][3], "D abort");
    assert!(report.answers().contains("ALARM:6"), "{}", report.answers());
    let last_pulse_ms = report.trace.pulses.last().unwrap().t_us / 1_000;
    assert!(last_pulse_ms < 3_500, "moved on at {last_pulse_ms} ms: homing ran again");
    let end = last_lines(&report);
    assert_eq!((end[0].as_str(), end[3].as_str()), ("SERVOPLOT          ALARM", "Homing aborted"));
}

#[test]
fn a_drawing_stopped_by_a_limit_switch_ends_in_alarm_not_done() {
    // Hard limits on, the switches 150 mm inside the travel: a 100 mm line from x 0 trips X+ at 50 mm.
    let report = power_on_with("$21=1\n", "2 1 0 0 # 0 # # wait:4000", -150.0);
    assert!(report.answers().contains("ALARM:1"), "{}", report.answers());
    // The run screen, its text left of the path drawn.
    let (_, last) = report.frames.last().unwrap();
    assert_eq!(text(last, 0, 18), "Line 100,0   ALARM");
    assert_eq!(text(last, 3, 18), "Limit X+: $X");
}

#[test]
fn a_function_preset_shows_its_star_as_a_multiplication_sign() {
    // Function mode (6), the second preset: y = 10*sin(x/5).
    let report = sim::run_keys("6 2 wait:300").unwrap();
    assert_eq!(last_lines(&report)[2], "f2 y=10*sin(x/5)");
}

#[test]
fn a_released_jog_says_stopping_until_the_title_says_idle() {
    // Jog mode (1), hold 6 (+X) for a second: the pen slows to a stop after the release.
    let report = sim::run_keys("1 6:1000 wait:1000").unwrap();
    let after: Vec<_> = report
        .frames
        .iter()
        .map(|(_, f)| lines(f))
        .skip_while(|l| !l[2].starts_with("Moving"))
        .skip_while(|l| l[2].starts_with("Moving"))
        .collect();
    let (stopping, rest) = after.split_at(after.iter().position(|l| l[0].ends_with("IDLE")).unwrap());
    assert!(!stopping.is_empty(), "the release came before the pen stopped");
    for l in stopping {
        assert_eq!((l[0].ends_with(" JOG"), l[2].as_str(), l[3].as_str()), (true, "Stopping", "D abort"));
    }
    assert!(rest.iter().all(|l| l[2] == "2 +Y 8 -Y 4 -X 6 +X"), "{rest:?}");
}

//! The GRBL settings senders read and write back, each as it means on a plotter: `$13` reports
//! in inches, `$2` and `$4` are taken at 0 only (PULS and SON are active high), `$6` and `$12`
//! are kept with no effect, and `$30`/`$31`/`$32` set the pen (see tests/pen_lift.rs).

use servoplot::sim::{self, SimConfig, SimReport, serial::SimSerial};

fn run(serial: SimSerial) -> SimReport {
    let report = sim::run(SimConfig { serial, ..SimConfig::default() });
    assert!(!report.timed_out, "{}", report.answers());
    report
}

fn lines(report: &SimReport) -> Vec<String> {
    report.answers().lines().map(str::to_string).collect()
}

#[test]
fn every_setting_a_sender_looks_for_is_listed() {
    let report = run(SimSerial::with_input(b"$$\n"));
    let ids: Vec<u16> =
        lines(&report).iter().filter_map(|l| l.strip_prefix('$')?.split('=').next()?.parse().ok()).collect();
    for id in [
        0, 1, 2, 3, 4, 5, 6, 10, 11, 12, 13, 20, 21, 22, 23, 24, 25, 26, 27, 30, 31, 32, 100, 101, 110, 111, 120, 121,
        130, 131,
    ] {
        assert!(ids.contains(&id), "${id} missing from $$: {ids:?}");
    }
    let l = lines(&report);
    for line in ["$2=0", "$4=0", "$6=0", "$12=0.002", "$13=0", "$30=1000.000", "$31=0.000", "$32=0"] {
        assert!(l.contains(&line.to_string()), "{line} missing: {l:?}");
    }
}

#[test]
fn with_13_set_status_and_coordinate_data_are_in_inches() {
    // G54 at X 2.54 mm, the pen at work X 25.4 mm, Y -12.7 mm; a report once it stands there.
    let serial = SimSerial::with_input(b"$13=1\n$10=0\nG10 L2 P1 X2.54\nG1 X25.4 Y-12.7 F1270\n$#\n")
        .with_byte_at(500_000, b'?')
        .with_byte_at(3_000_000, b'?');
    let report = run(serial);
    let l = lines(&report);
    let moving = l.iter().find(|l| l.starts_with("<Run|")).expect("a report while moving");
    assert!(moving.contains("|FS:50.0,0"), "1270 mm/min is 50 in/min: {moving}");
    let at_rest = l.iter().rfind(|l| l.starts_with("<Idle|")).expect("a report at rest");
    assert!(at_rest.starts_with("<Idle|WPos:1.0000,-0.5000,0.0000|"), "{at_rest}");
    assert!(l.contains(&"[G54:0.1000,0.0000,0.0000]".to_string()), "{l:?}");
    assert!(l.contains(&"[TLO:0.0000]".to_string()), "{l:?}");
    // Back to millimetres.
    let mm = run(SimSerial::with_input(b"$13=0\nG1 X25.4 F1270\n").with_byte_at(3_000_000, b'?'));
    assert!(lines(&mm).iter().any(|l| l.starts_with("<Idle|MPos:25.400,0.000,0.000|")), "{:?}", lines(&mm));
}

#[test]
fn an_inverted_puls_or_son_is_refused_and_the_rest_is_kept_with_no_effect() {
    let report = run(SimSerial::with_input(b"$2=1\n$4=1\n$6=1\n$12=0.01\n$32=1\n$31=1000\n"));
    let l = lines(&report);
    assert_eq!(&l[2..], ["error:3", "error:3", "ok", "ok", "ok", "error:3"], "$31 at $30 is refused");
    assert_eq!((report.settings.step_invert_mask, report.settings.son_invert), (0, false));
    assert!(report.settings.probe_invert && report.settings.laser_mode);
    assert_eq!(report.settings.arc_tolerance_mm, 0.01);
}

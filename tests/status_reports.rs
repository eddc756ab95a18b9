//! Status reports as a sender polling `?` sees them, on the simulated board: the pen's real
//! speed, GRBL's occasional `WCO:` and `Ov:` fields, and what `$10` chooses.

use servoplot::sim::{self, SimConfig, SimReport, serial::SimSerial};

/// Runs `program` (sent line by line) with `?` sent at each of `polls_us`.
fn run(program: &str, polls_us: &[u64]) -> SimReport {
    let serial = polls_us.iter().fold(SimSerial::with_input(program.as_bytes()), |s, &t| s.with_byte_at(t, b'?'));
    let report = sim::run(SimConfig { serial, ..SimConfig::default() });
    assert!(!report.timed_out, "the machine came to rest: {}", report.answers());
    report
}

/// The status reports, in order.
fn reports(report: &SimReport) -> Vec<String> {
    report.answers().lines().filter(|l| l.starts_with('<')).map(str::to_string).collect()
}

#[test]
fn fs_is_the_speed_of_the_pen_now() {
    // 1200 mm/min along X; then a rapid at X's max rate, 6000 mm/min.
    let report = run("G1 X100 F1200\nG0 X150\n", &[2_000_000, 3_500_000, 5_400_000]);
    let r = reports(&report);
    assert!(r[0].starts_with("<Run|") && r[0].contains("|FS:1200,0"), "{r:?}");
    assert!(r[1].contains("|FS:1200,0"), "{r:?}");
    assert!(r[2].contains("|FS:6000,0"), "the rapid: {r:?}");
    // Nothing once held, and nothing at rest.
    let serial = SimSerial::with_input(b"G1 X100 F1200\n").with_byte_at(2_000_000, b'!').with_byte_at(2_500_000, b'?');
    let held = sim::run(SimConfig { serial: serial.with_byte_at(3_000_000, b'~'), ..SimConfig::default() });
    let r = reports(&held);
    assert!(r[0].starts_with("<Hold:0|") && r[0].contains("|FS:0,0"), "{r:?}");
    let r = reports(&run("G1 X1 F1200\n", &[5_000_000]));
    assert!(r[0].starts_with("<Idle|") && r[0].contains("|FS:0,0"), "{r:?}");
}

#[test]
fn wco_comes_first_and_after_every_change_then_ov_on_the_next_report() {
    // Polls every 100 ms while a move runs (busy: `WCO:` every 30 reports), a `G92` once it has
    // ended, and one more poll.
    let serial = (1..=14).fold(SimSerial::with_input(b"G1 X10 F3000\n"), |s, k| s.with_byte_at(k * 100_000, b'?'));
    let serial = b"G92 X0 Y0\n".iter().fold(serial, |s, &b| s.with_byte_at(1_500_000, b));
    let report = sim::run(SimConfig { serial: serial.with_byte_at(2_000_000, b'?'), ..SimConfig::default() });
    let r = reports(&report);
    assert_eq!(r.len(), 15, "{r:?}");
    assert!(r[0].starts_with("<Run|") && r[0].ends_with("|WCO:0.000,0.000,0.000>"), "{r:?}");
    assert!(r[1].ends_with("|Ov:100,100,100>"), "{r:?}");
    assert!(r[2..14].iter().all(|l| !l.contains("WCO") && !l.contains("Ov")), "{r:?}");
    assert_eq!(r[14], "<Idle|MPos:10.000,0.000,0.000|FS:0,0|WCO:10.000,0.000,0.000>", "{r:?}");
}

#[test]
fn dollar_10_chooses_work_or_machine_position_and_the_buffer_state() {
    let wpos = run("G1 X10 F3000\nG92 X2\nG4 P0\n$10=0\n", &[2_000_000]);
    assert!(reports(&wpos)[0].starts_with("<Idle|WPos:2.000,0.000,0.000|FS:0,0"), "{:?}", reports(&wpos));
    let bf = run("$10=3\n", &[1_000_000]);
    assert!(reports(&bf)[0].starts_with("<Idle|MPos:0.000,0.000,0.000|Bf:16,128|FS:0,0"), "{:?}", reports(&bf));
}

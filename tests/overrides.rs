//! GRBL's override bytes sent while a drawing runs, on the simulated board: the status reports
//! show them, the pen's speed follows them, and the path is the same steps as without them.

use servoplot::geom::{Axis, Point};
use servoplot::sim::{self, SimConfig, SimReport, serial::SimSerial};

/// A line along X at 1200 mm/min (20 mm/s), then a circle of 15 mm radius at the same feed.
const PROGRAM: &str = "G1 X60 F1200\n$O R15\n";

/// Runs `program` with each of `timed` (µs, byte) sent at its time.
fn run(program: &str, timed: &[(u64, u8)]) -> SimReport {
    let serial = timed.iter().fold(SimSerial::with_input(program.as_bytes()), |s, &(t, b)| s.with_byte_at(t, b));
    let report = sim::run(SimConfig { serial, ..SimConfig::default() });
    assert!(!report.timed_out, "the machine came to rest: {}", report.answers());
    report
}

/// The status reports, in order.
fn reports(report: &SimReport) -> Vec<String> {
    report.answers().lines().filter(|l| l.starts_with('<')).map(str::to_string).collect()
}

/// The `FS:` speed of a status report, mm/min.
fn fs(report: &str) -> f64 {
    let field = report.split('|').find_map(|f| f.strip_prefix("FS:")).unwrap();
    field.split(',').next().unwrap().parse().unwrap()
}

/// The pen's speed along X from the pulses between `from_us` and `to_us`, mm/min (100 steps/mm).
fn x_speed_mm_per_min(report: &SimReport, from_us: u64, to_us: u64) -> f64 {
    let times: Vec<u64> = report
        .trace
        .pulses
        .iter()
        .filter(|p| p.axis == Axis::X && (from_us..to_us).contains(&p.t_us))
        .map(|p| p.t_us)
        .collect();
    let span_s = (times[times.len() - 1] - times[0]) as f64 / 1e6;
    (times.len() - 1) as f64 / 100.0 / span_s * 60.0
}

#[test]
fn a_lower_feed_override_mid_drawing_is_reported_and_followed_on_the_same_path() {
    // `?` at 0.4 s (first report: WCO) and 0.6 s (Ov), 0x92 (−10 %) at 1 s, `?` at 1.5 s.
    let polls = [(400_000, b'?'), (600_000, b'?'), (1_000_000, 0x92), (1_500_000, b'?')];
    let slower = run(PROGRAM, &polls);
    let r = reports(&slower);
    assert!(r[1].starts_with("<Run|") && r[1].ends_with("|FS:1200,0|Ov:100,100,100>"), "{r:?}");
    assert!(r[2].starts_with("<Run|") && r[2].ends_with("|Ov:90,100,100>"), "{r:?}");
    // 90 % of 1200 mm/min, as the last pulse interval tells (555 or 556 µs).
    assert!((fs(&r[2]) - 1080.0).abs() <= 2.0, "{r:?}");
    let v = x_speed_mm_per_min(&slower, 1_100_000, 2_500_000);
    assert!((v - 1080.0).abs() < 1080.0 * 0.002, "{v} mm/min");

    // The same steps as without the override, to the same end; only later.
    let plain = run(PROGRAM, &[]);
    assert_eq!(slower.path(), plain.path());
    assert_eq!(slower.position, Point::new(6_000, 0));
    assert!(slower.last_pulse_us() > plain.last_pulse_us() + 700_000, "the rest of it at 90 %");
}

#[test]
fn overrides_take_effect_within_one_refill_and_stay_within_the_machines_limits() {
    // Twice the feed on the line (2400 mm/min, within X's 6000), back to 100 % on the circle.
    let mut timed: Vec<(u64, u8)> = std::iter::repeat_n(0x91, 10).map(|b| (500_000, b)).collect();
    timed.push((1_200_000, 0x90));
    let report = run(PROGRAM, &timed);
    let v = x_speed_mm_per_min(&report, 600_000, 1_100_000);
    assert!((v - 2400.0).abs() < 2400.0 * 0.002, "{v} mm/min");
    assert_eq!(report.path(), run(PROGRAM, &[]).path());
    // 10 % is the floor; the pen crawls, and a reset ends the drawing and restores 100 %.
    let mut timed: Vec<(u64, u8)> = std::iter::repeat_n(0x92, 12).map(|b| (500_000, b)).collect();
    timed.extend([(1_500_000, 0x18), (2_500_000, b'?'), (2_700_000, b'?')]);
    let report = run(PROGRAM, &timed);
    let v = x_speed_mm_per_min(&report, 700_000, 1_400_000);
    assert!((v - 120.0).abs() < 120.0 * 0.002, "{v} mm/min");
    let r = reports(&report);
    assert!(r[1].starts_with("<Idle|") && r[1].ends_with("|Ov:100,100,100>"), "{r:?}");
}

#[test]
fn the_rapid_override_slows_rapids_and_a_jog_takes_no_override() {
    // A rapid along X runs at its max rate, 6000 mm/min; at 25 %, 1500.
    let report = run("G0 X150\n", &[(300_000, 0x97), (300_000, 0x92), (1_000_000, b'?'), (1_200_000, b'?')]);
    let v = x_speed_mm_per_min(&report, 600_000, 2_000_000);
    assert!((v - 1500.0).abs() < 1500.0 * 0.002, "{v} mm/min");
    let r = reports(&report);
    assert!(r[1].ends_with("|Ov:90,25,100>"), "{r:?}");
    // 25 % of 6000 mm/min, as the last pulse interval tells: 1600 ticks, now and then 1601
    // (the cruise's fraction of a tick).
    assert!((fs(&r[1]) - 1500.0).abs() <= 2.0, "{r:?}");
    // A jog keeps its own feed whatever the overrides.
    let report = run("$J=G91 X50 F1200\n", &[(100_000, 0x97), (100_000, 0x92), (100_000, 0x92), (1_000_000, b'?')]);
    let v = x_speed_mm_per_min(&report, 500_000, 2_000_000);
    assert!((v - 1200.0).abs() < 1200.0 * 0.002, "{v} mm/min");
    assert!(reports(&report)[0].starts_with("<Jog|") && reports(&report)[0].contains("|FS:1200,0|"));
}

#[test]
fn overrides_sent_as_bytes_or_as_utf8_text_act_mid_file_and_every_line_runs() {
    // A streamed file of 40 short moves. Some senders write the override bytes as text, so
    // above 0x7F they arrive UTF-8 encoded (0x91 as 0xC2 0x91); GRBL drops the stray 0xC2.
    let file: String = (0..40).map(|i| format!("G1 X{} Y{} F1200\n", 5 + i % 7, 3 + i % 5)).collect();
    let lines = file.lines().count();
    // Feed +10 % twice, rapid 50 % then 25 %, spindle +10 % twice: once raw, once as text.
    let timed: Vec<(u64, u8)> = [
        (300_000, &[0x91][..]),
        (350_000, &[0xC2, 0x91]),
        (400_000, &[0x96]),
        (450_000, &[0xC2, 0x97]),
        (500_000, &[0x9A]),
        (550_000, &[0xC2, 0x9A]),
        // The first report carries the work offset, the second the overrides.
        (700_000, b"?"),
        (750_000, b"?"),
    ]
    .iter()
    .flat_map(|&(t, bytes)| bytes.iter().map(move |&b| (t, b)))
    .collect();
    let report = run(&file, &timed);
    let answers = report.answers();
    assert_eq!(answers.lines().filter(|l| *l == "ok").count(), lines, "{answers}");
    assert!(!answers.contains("error"), "{answers}");
    assert!(reports(&report)[1].ends_with("|Ov:120,25,120>"), "{:?}", reports(&report));
    // The same steps to the same end as without the overrides.
    let plain = run(&file, &[]);
    assert_eq!(report.path(), plain.path());
    assert_eq!(report.position, plain.position);
}

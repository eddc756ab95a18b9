//! The speed a status report gives (`FS:`) is the pen's speed along its path: at cruise, the
//! programmed feed times the override, whatever the line's direction, the curve (circle, arc,
//! ellipse, sine, function) or the method.

use servoplot::sim::{self, SimConfig, serial::SimSerial};

/// The `FS:` speeds of the status reports of `program` asked at `at_us`, mm/min.
fn readings(program: &str, at_us: &[u64]) -> Vec<f64> {
    let serial = at_us.iter().fold(SimSerial::with_input(program.as_bytes()), |s, &t| s.with_byte_at(t, b'?'));
    let report = sim::run(SimConfig { serial, ..SimConfig::default() });
    assert!(!report.timed_out, "{}", report.answers());
    report
        .answers()
        .lines()
        .filter(|l| l.starts_with("<Run"))
        .map(|l| {
            let field = l.split('|').find_map(|f| f.strip_prefix("FS:")).unwrap();
            field.split(',').next().unwrap().parse().unwrap()
        })
        .collect()
}

#[test]
fn the_speed_read_at_cruise_is_the_feed_on_every_direction_curve_and_method() {
    // Asked every 50 ms from 0.6 s, well into each drawing's cruise (the default acceleration,
    // 500 mm/s², reaches 50 mm/s in 0.1 s).
    let at: Vec<u64> = (0..10).map(|k| 600_000 + 50_000 * k).collect();
    for method in ["$202=0", "$202=1"] {
        for (drawing, feed) in [
            ("G1 X150 F3000", 3000.0),
            ("G1 X100 Y50 F3000", 3000.0),
            ("G1 X80 Y80 F3000", 3000.0),
            ("G1 X40 Y90 F2400", 2400.0),
            ("G1 X-100 Y-30 F1200", 1200.0),
            ("G1 F1200\n$O R40", 1200.0),
            ("G1 F1500\n$E A60 B30", 1500.0),
            ("G1 F1200\n$S A5 W0.1 L150", 1200.0),
            ("G1 F1200\n$O R40 S30 W250", 1200.0),
            ("G1 F1200\n$F X-60 U60 Y=10*sin(x/10)", 1200.0),
        ] {
            let program = format!("{method}\n{drawing}\n");
            let got = readings(&program, &at);
            assert_eq!(got.len(), at.len(), "{program}: {got:?}");
            for v in &got {
                assert!((v - feed).abs() <= feed * 0.01, "{program}: {got:?}, {feed} mm/min");
            }
        }
    }
}

//! A reset drops what it should: a line that changes what a power cycle keeps runs only with
//! the machine at rest, so a reset while it waits drops it unrun, unanswered and unsaved; every
//! line either got its answer before the reset or is dropped with it.

use servoplot::sim::{self, SimConfig, SimReport, serial::SimSerial};

/// `program` sent at once, Ctrl-X at `reset_us`, then `after` sent at 2 s.
fn run(program: &str, reset_us: u64, after: &str) -> SimReport {
    let serial = after.bytes().fold(SimSerial::with_input(program.as_bytes()).with_byte_at(reset_us, 0x18), |s, b| {
        s.with_byte_at(2_000_000, b)
    });
    let report = sim::run(SimConfig { serial, ..SimConfig::default() });
    assert!(!report.timed_out, "{}", report.answers());
    report
}

fn lines(report: &SimReport) -> Vec<String> {
    report.answers().lines().filter(|l| !l.is_empty() && !l.starts_with('<')).map(str::to_string).collect()
}

#[test]
fn a_work_offset_waiting_for_the_motion_is_dropped_by_a_reset() {
    // GRBL's banner, the move's ok; the G10 waits for the pen and is dropped with the reset.
    let report = run("G1 X50 F1000\nG10 L20 P1 X7 Y7\n", 500_000, "$#\n");
    let got = lines(&report);
    assert_eq!(got[..3], ["Grbl 1.1h ['$' for help]", "ok", "Grbl 1.1h ['$' for help]"], "{got:?}");
    assert!(got.contains(&"[G54:0.000,0.000,0.000]".to_string()), "{got:?}");
    assert!(report.flash.operations_at_us().is_empty(), "nothing saved");
}

#[test]
fn without_a_reset_the_offset_is_taken_where_the_pen_stands() {
    let report = run("G1 X50 F1000\nG10 L20 P1 X7 Y7\n", 9_000_000, "$#\n");
    let got = lines(&report);
    assert_eq!(got[..3], ["Grbl 1.1h ['$' for help]", "ok", "ok"], "{got:?}");
    assert!(got.contains(&"[G54:43.000,-7.000,0.000]".to_string()), "{got:?}");
}

#[test]
fn a_startup_block_or_a_setting_waiting_for_the_motion_is_dropped_by_a_reset() {
    for line in ["$N0=G20", "$110=4000", "$I=plotter"] {
        let report = run(&format!("G1 X50 F1000\n{line}\n"), 500_000, "$N\n");
        let got = lines(&report);
        assert_eq!(got[..3], ["Grbl 1.1h ['$' for help]", "ok", "Grbl 1.1h ['$' for help]"], "{line}: {got:?}");
        assert!(got.contains(&"$N0=".to_string()), "{line}: {got:?}");
        assert_eq!(report.settings.max_rate_mm_per_min[0], 6000.0, "{line}");
        assert!(report.flash.operations_at_us().is_empty(), "{line}: nothing saved");
    }
}

#[test]
fn at_any_instant_a_line_is_answered_and_kept_or_dropped_unrun() {
    // The move takes about 3 s: resets before, during and after it.
    let (mut kept_lines, mut dropped_lines) = (0, 0);
    for reset_ms in (100..4_000).step_by(300) {
        for (line, kept) in [
            ("G10 L20 P1 X7 Y7", "[G54:43.000,-7.000,0.000]"),
            ("G28.1", "[G28:50.000,0.000,0.000]"),
            ("$110=4000", "$110=4000.000"),
            ("$N0=G20", "$N0=G20"),
        ] {
            let report = run(&format!("G1 X50 F1000\n{line}\n"), reset_ms * 1000, "$#\n$$\n$N\n");
            let got = lines(&report);
            let answered = got[2] == "ok";
            assert_eq!(got.contains(&kept.to_string()), answered, "{line}, reset at {reset_ms} ms: {got:?}");
            assert_eq!(!report.flash.operations_at_us().is_empty(), answered, "{line}, reset at {reset_ms} ms: saved");
            (kept_lines, dropped_lines) =
                if answered { (kept_lines + 1, dropped_lines) } else { (kept_lines, dropped_lines + 1) };
        }
    }
    assert!(kept_lines >= 4 && dropped_lines >= 20, "{kept_lines} kept, {dropped_lines} dropped");
}

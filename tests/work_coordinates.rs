//! Work coordinates end to end on the simulated board, as a sender uses them: "zero here"
//! (`G10 L20 P1 X0 Y0`), absolute moves in work coordinates, a second system, `$#`, and a soft
//! reset that keeps the systems.

use servoplot::geom::Point;
use servoplot::sim::{self, SimReport};

/// The `[...]` lines the firmware wrote after the `n`th banner (0: power-on, 1: the first reset).
fn bracket_lines_after_banner(report: &SimReport, n: usize) -> Vec<String> {
    let answers = report.answers();
    let part = answers.split("Grbl 1.1h").nth(n + 1).unwrap_or_else(|| panic!("banner {n}: {answers}"));
    part.lines().filter(|l| l.starts_with('[')).map(str::to_string).collect()
}

fn parameters(g54: &str, g55: &str, g28: &str, g92: &str) -> Vec<String> {
    let zero = "0.000,0.000,0.000";
    [("G54", g54), ("G55", g55), ("G56", zero), ("G57", zero), ("G58", zero), ("G59", zero)]
        .into_iter()
        .chain([("G28", g28), ("G30", zero), ("G92", g92)])
        .map(|(name, xyz)| format!("[{name}:{xyz}]"))
        .chain(["[TLO:0.000]".to_string(), "[PRB:0.000,0.000,0.000:0]".to_string()])
        .collect()
}

#[test]
fn a_senders_session_with_work_coordinates_and_a_reset() {
    let session = [
        "G0 X10 Y5",          // machine (10, 5)
        "G10 L20 P1 X0 Y0",   // zero here: G54 = (10, 5)
        "G0 X20 Y-3",         // work (20, -3) = machine (30, 2)
        "G92 X0 Y0",          // G92 = (20, -3) on top of G54
        "G0 X1 Y1",           // machine (31, 3)
        "G10 L2 P2 X-50 Y50", // G55 = (-50, 50)
        "G55 G0 X0 Y0",       // machine (-50 + 20, 50 - 3) = (-30, 47)
        "G28.1",              // G28 = (-30, 47)
        "G54 G0 X0 Y0",       // back to machine (30, 2)
        "G4 P0",              // wait until the pen is there
        "$#",
        "\x18$#", // reset: G54, G55 and G28 stay, G92 goes
        "$G",
        "G0 X0 Y0", // work (0, 0) of G54: machine (10, 5)
        "G4 P0",
        "?",
        "?",
    ];
    let report = sim::run_serial(&(session.join("\n") + "\n"));
    assert!(!report.timed_out, "{}", report.answers());
    let answers = report.answers();
    assert!(!answers.contains("error:"), "{answers}");

    let path = report.path();
    let visit = |p: Point, from: usize| -> usize {
        from + path[from..].iter().position(|q| *q == p).unwrap_or_else(|| panic!("{p:?} not reached after {from}"))
    };
    let mut at = visit(Point::new(1000, 500), 0);
    for p in [(3000, 200), (3100, 300), (-3000, 4700), (3000, 200), (1000, 500)] {
        at = visit(Point::new(p.0, p.1), at);
    }
    assert_eq!(report.position, Point::new(1000, 500));

    let before = bracket_lines_after_banner(&report, 0);
    assert_eq!(
        before,
        parameters("10.000,5.000,0.000", "-50.000,50.000,0.000", "-30.000,47.000,0.000", "20.000,-3.000,0.000")
    );
    let after = bracket_lines_after_banner(&report, 1);
    let mut expected =
        parameters("10.000,5.000,0.000", "-50.000,50.000,0.000", "-30.000,47.000,0.000", "0.000,0.000,0.000");
    expected.push("[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F3000 S0]".to_string());
    assert_eq!(after, expected, "{answers}");
    // The first status report after the reset carries the work offset, G54's; the next the
    // overrides, as after power-on.
    let reports: Vec<&str> = answers.lines().filter(|l| l.starts_with('<')).collect();
    assert_eq!(
        reports,
        [
            "<Idle|MPos:10.000,5.000,0.000|FS:0,0|WCO:10.000,5.000,0.000>",
            "<Idle|MPos:10.000,5.000,0.000|FS:0,0|Ov:100,100,100>"
        ]
    );
}

#[test]
fn status_reports_carry_the_work_offset_when_it_changes() {
    let report = sim::run_serial(
        "?
?
G0 X10 Y5
G10 L20 P1 X0 Y0
G4 P0
?
G92 X-1
?
?
G55
?
",
    );
    let answers = report.answers();
    let reports: Vec<&str> = answers.lines().filter(|l| l.starts_with('<')).collect();
    assert_eq!(
        reports,
        [
            // At power-on, as GRBL does.
            "<Idle|MPos:0.000,0.000,0.000|FS:0,0|WCO:0.000,0.000,0.000>",
            "<Idle|MPos:0.000,0.000,0.000|FS:0,0|Ov:100,100,100>",
            "<Idle|MPos:10.000,5.000,0.000|FS:0,0|WCO:10.000,5.000,0.000>",
            "<Idle|MPos:10.000,5.000,0.000|FS:0,0|WCO:11.000,5.000,0.000>",
            "<Idle|MPos:10.000,5.000,0.000|FS:0,0>",
            // G55 (offset zero) with the G92 offset on top.
            "<Idle|MPos:10.000,5.000,0.000|FS:0,0|WCO:1.000,0.000,0.000>",
        ],
        "{answers}"
    );
}

//! Tests of the work coordinate systems G54–G59, G10 L2 / L20, G28 / G30 and G92 on top of
//! them: the machine positions lines reach, `$#` and `$G`, GRBL's error numbers, that a refused
//! line changes nothing and that a reset keeps the stored data.

extern crate std;

use super::*;
use crate::host::report;
use std::string::String;

fn g54() -> WorkSystem {
    WorkSystem::G54
}

fn system(gcode: u16) -> WorkSystem {
    WorkSystem::from_gcode(gcode).unwrap()
}

/// The two rapid moves of a G28 or G30 through an intermediate point, in steps.
fn two_rapids(from: Point, via: (i32, i32), to: (i32, i32)) -> Vec<Command> {
    let via_point = Point::new(via.0, via.1);
    std::vec![
        line_from(from, via.0, via.1, Feed::Rapid, JobKind::Draw),
        line_from(via_point, to.0, to.1, Feed::Rapid, JobKind::Draw),
    ]
}

fn text(f: impl FnOnce(&mut String) -> core::fmt::Result) -> String {
    let mut s = String::new();
    f(&mut s).unwrap();
    s
}

#[test]
fn g10_l20_makes_the_pen_the_work_origin() {
    let mut g = GcodeState::new();
    assert_line(&mut g, "G0 X10 Y5", 1000, 500, Feed::Rapid);
    // A sender's "zero here" button.
    assert_eq!(run(&mut g, "G10 L20 P1 X0 Y0"), Ok(Vec::new()));
    assert_eq!(g.offsets().system_mm(g54()), [10.0, 5.0]);
    assert_eq!(g.work_offset_mm(), [10.0, 5.0]);
    assert_eq!(g.planned_position(), Point::new(1000, 500), "G10 moves nothing");
    // Absolute targets are work coordinates now: machine = work + offset.
    assert_line(&mut g, "G0 X20 Y-3", 3000, 200, Feed::Rapid);
    assert_line(&mut g, "G1 X0 Y0 F600", 1000, 500, feed(600.0));
    let (shape, _, end) = curve(&mut g, "G2 X10 Y0 I5 J0");
    assert_eq!(shape, Shape::Arc { center: Point::new(1500, 500), to: end, rotation: Rotation::Clockwise });
    assert_eq!(end, Point::new(2000, 500));
    // Relative moves and G53 do not see the offset.
    assert_line(&mut g, "G91 G0 X1 Y1", 2100, 600, Feed::Rapid);
    assert_line(&mut g, "G90 G53 G0 X0 Y0", 0, 0, Feed::Rapid);
    // One axis only: the other keeps its offset.
    assert_line(&mut g, "G0 X7", 1700, 0, Feed::Rapid);
    assert_eq!(run(&mut g, "G10 L20 P1 X0"), Ok(Vec::new()));
    assert_eq!(g.offsets().system_mm(g54()), [17.0, 5.0]);
    // In inches, the values are inches: the pen at work X = 1 in is 25.4 mm right of the origin.
    assert_eq!(run(&mut g, "G20 G10 L20 P0 X1"), Ok(Vec::new()));
    assert_eq!(g.offsets().system_mm(g54()), [17.0 - 25.4, 5.0]);
}

#[test]
fn g10_l2_sets_any_system_and_g54_to_g59_select_it() {
    let mut g = GcodeState::new();
    for p in 1..=6u16 {
        let line = std::format!("G10 L2 P{p} X{} Y-{}", p * 10, p);
        assert_eq!(run(&mut g, &line), Ok(Vec::new()), "{line}");
    }
    assert_eq!(g.work_system(), g54());
    assert_eq!(g.work_offset_mm(), [10.0, -1.0]);
    for n in 55..=59u16 {
        let p = (n - 53) as i32;
        let line = std::format!("G{n} G0 X1 Y1");
        assert_line(&mut g, &line, (p * 10 + 1) * 100, (1 - p) * 100, Feed::Rapid);
        assert_eq!(g.work_system(), system(n));
        assert_eq!(g.offsets().system_mm(system(n)), [(p * 10) as f32, -p as f32]);
    }
    // P0 is the active system (G59 here); an omitted axis keeps its value.
    assert_eq!(run(&mut g, "G10 L2 P0 Y2.5"), Ok(Vec::new()));
    assert_eq!(g.offsets().system_mm(system(59)), [60.0, 2.5]);
    // Setting another system leaves the active offset alone.
    assert_eq!(run(&mut g, "G10 L2 P1 X-1"), Ok(Vec::new()));
    assert_eq!(g.work_offset_mm(), [60.0, 2.5]);
    // A selection in the line applies to its own target, and stays.
    assert_line(&mut g, "G54 G0 X0 Y0", -100, -100, Feed::Rapid);
    assert_eq!(g.work_system(), g54());
    // In inches.
    assert_eq!(run(&mut g, "G20 G10 L2 P2 X1 Y-1"), Ok(Vec::new()));
    assert_eq!(g.offsets().system_mm(system(55)), [25.4, -25.4]);
}

#[test]
fn g92_applies_on_top_of_the_active_system() {
    let mut g = GcodeState::new();
    ok_all(&mut g, &["G10 L2 P1 X10 Y10"]);
    assert_line(&mut g, "G0 X15 Y20", 2500, 3000, Feed::Rapid);
    // G92 makes the pen work (0, 0) through the active system: G92 = machine - G54 - work.
    ok_all(&mut g, &["G92 X0 Y0"]);
    assert_eq!(g.offsets().g92_mm(), [15.0, 20.0]);
    assert_eq!(g.work_offset_mm(), [25.0, 30.0]);
    assert_line(&mut g, "G0 X1", 2600, 3000, Feed::Rapid);
    // It applies to whichever system is selected.
    assert_line(&mut g, "G55 G0 X0 Y0", 1500, 2000, Feed::Rapid);
    // G92 with a system selected in the same line measures from that system.
    ok_all(&mut g, &["G54 G92 X0 Y0"]);
    assert_eq!(g.offsets().g92_mm(), [5.0, 10.0]);
    // G10 L20 under G92: the system takes what G92 does not already shift.
    ok_all(&mut g, &["G10 L20 P1 X2 Y3"]);
    assert_eq!(g.offsets().system_mm(g54()), [8.0, 7.0]);
    assert_eq!(run(&mut g, "G0 X2 Y3"), Ok(Vec::new()), "the pen is at work (2, 3) already");
    ok_all(&mut g, &["G92.1"]);
    assert_eq!(g.work_offset_mm(), [8.0, 7.0]);
}

#[test]
fn g10_follows_grbls_rules_and_error_numbers() {
    let mut g = GcodeState::new();
    ok_all(&mut g, &["G0 X1 Y1", "G10 L2 P3 X4 Y4"]);
    refused(&mut g, "G10 L2 P1", 26);
    refused(&mut g, "G10 L20 P1 F100", 26);
    refused(&mut g, "G10 P1 X0", 28);
    refused(&mut g, "G10 L2 X0", 28);
    refused(&mut g, "G10 X0", 28);
    refused(&mut g, "G10 L2 P7 X0", 29);
    refused(&mut g, "G10 L2 P1.5 X0", 29);
    refused(&mut g, "G10 L2 P-1 X0", 4);
    refused(&mut g, "G10 L1 P1 X0", 20);
    refused(&mut g, "G10 L2.5 P1 X0", 20);
    refused(&mut g, "G10 L3 P1 X0", 20);
    refused(&mut g, "G10 L2 P1 R5 X0", 20);
    refused(&mut g, "G10 L20 P1 R5 X0", 36);
    refused(&mut g, "G10 L2 P1 X0 I1", 36);
    refused(&mut g, "G10.1 L2 P1 X0", 23);
    refused(&mut g, "G10 L2 P1 X0 G0", 24);
    refused(&mut g, "G1 G10 L2 P1 X0", 24);
    refused(&mut g, "G10 L2 P1 G92 X0", 24);
    refused(&mut g, "G10 L2 P1 X0 G4", 21);
    refused(&mut g, "G54 G55", 21);
    refused(&mut g, "G0 X1 L2", 36);
    // G80 allows no axis words, not even G10's.
    ok_all(&mut g, &["G80"]);
    refused(&mut g, "G10 L2 P1 X0", 31);
    // A Z word alone sets nothing on this machine, but counts as an axis word.
    ok_all(&mut g, &["G0", "G10 L2 P1 Z5"]);
    assert_eq!(g.offsets().system_mm(g54()), [0.0, 0.0]);
}

#[test]
fn a_refused_line_leaves_every_offset_as_it_was() {
    let mut g = GcodeState::new();
    ok_all(&mut g, &["G0 X3 Y4", "G10 L2 P1 X1 Y1", "G10 L2 P2 X2 Y2", "G28.1", "G30.1", "G92 X0"]);
    // `refused` compares the whole state: modes, planned position and every offset.
    refused(&mut g, "G55 G0 X250", 15);
    refused(&mut g, "G10 L20 P1 X0 T300", 38);
    refused(&mut g, "G10 L2 P2 X9 S-1", 4);
    refused(&mut g, "G28.1 G0 X300", 15);
    refused(&mut g, "G30.1 M3 M4", 21);
    refused(&mut g, "G92.1 G2 X1", 35);
    refused(&mut g, "G56 G28 X250", 15);
    refused_in(&mut g, "G10 L20 P1 X0", RunState::Alarm, 9);
    refused_in(&mut g, "$RST=#", RunState::Run, 8);
    assert_eq!(g.work_system(), g54());
}

#[test]
fn g28_and_g30_rapid_to_their_stored_positions() {
    let mut g = GcodeState::new();
    ok_all(&mut g, &["G0 X-20 Y30", "G28.1", "G1 X5 Y5 F500", "G30.1"]);
    assert_eq!(g.offsets().stored_mm(StoredPosition::G28), [-20.0, 30.0]);
    assert_eq!(g.offsets().stored_mm(StoredPosition::G30), [5.0, 5.0]);
    // Stored in machine coordinates: no offset moves them.
    ok_all(&mut g, &["G10 L2 P1 X100 Y0", "G92 X0"]);
    assert_line(&mut g, "G28", -2000, 3000, Feed::Rapid);
    assert_eq!(g.motion_mode(), MotionMode::Linear, "G28 leaves the motion mode alone");
    assert_line(&mut g, "G30", 500, 500, Feed::Rapid);
    assert_eq!(run(&mut g, "G30"), Ok(Vec::new()), "already there");
    // Through an intermediate point (work coordinates: G54 X100 and G92 X-95 make X-50
    // machine -45): only the axes named go on to the stored position.
    let from = g.planned_position();
    assert_eq!(run(&mut g, "G28 X-50"), Ok(two_rapids(from, (-4500, 500), (-2000, 500))));
    assert_eq!(g.planned_position(), Point::new(-2000, 500));
    let from = g.planned_position();
    assert_eq!(run(&mut g, "G91 G30 X1 Y1"), Ok(two_rapids(from, (-1900, 600), (500, 500))));
    // Z words only: nothing of X or Y moves.
    assert_eq!(run(&mut g, "G90 G28 Z5"), Ok(Vec::new()));
    assert_eq!(g.planned_position(), Point::new(500, 500));
    // G28.1 with axis words stores the position first, then moves in the motion mode (work X90
    // is machine X95).
    assert_line(&mut g, "G28.1 X90", 9500, 500, feed(500.0));
    assert_eq!(g.offsets().stored_mm(StoredPosition::G28), [5.0, 5.0]);
    assert_line(&mut g, "G28", 500, 500, Feed::Rapid);
    // Under G80 G28 may move, but takes no axis words.
    ok_all(&mut g, &["G0 X0 Y0", "G80"]);
    assert_eq!(g.planned_position(), Point::new(500, 0));
    refused(&mut g, "G28 X0", 31);
    assert_line(&mut g, "G30", 500, 500, Feed::Rapid);
    refused(&mut g, "G28 G0 X1", 24);
    refused(&mut g, "G0 G30", 24);
    refused(&mut g, "G28 G92 X1", 24);
    refused(&mut g, "G28 G53", 21);
    refused(&mut g, "G28.2", 20);
    // Either move beyond the travel refuses the line.
    ok_all(&mut g, &["G0 X0 Y0"]);
    refused(&mut g, "G30 X300", 15);
    refused(&mut g, "G91 G28 Y-250", 15);
}

#[test]
fn jogs_use_the_work_coordinates_and_curves_start_at_the_pen() {
    let mut g = GcodeState::new();
    ok_all(&mut g, &["G10 L2 P1 X10 Y-10"]);
    let jog = |from: (i32, i32), x, y| line_from(Point::new(from.0, from.1), x, y, feed(100.0), JobKind::Jog);
    assert_eq!(run(&mut g, "$J=X0 Y0 F100"), Ok(std::vec![jog((0, 0), 1000, -1000)]));
    assert_eq!(run(&mut g, "$J=G53 X0 F100"), Ok(std::vec![jog((1000, -1000), 0, -1000)]));
    assert_eq!(run(&mut g, "$J=G91 X1 F100"), Ok(std::vec![jog((0, -1000), 100, -1000)]));
    refused(&mut g, "$J=G55 X0 F100", 16);
    refused(&mut g, "$J=G10 L2 P1 X0 F100", 16);
    refused(&mut g, "$J=G28 F100", 16);
    // A curve command draws from the pen whatever the offsets are.
    let (shape, _, end) = curve(&mut g, "$O R10");
    assert_eq!(shape, Shape::Arc { center: Point::new(-900, -1000), to: end, rotation: Rotation::CounterClockwise });
    assert_eq!(end, Point::new(100, -1000));
}

#[test]
fn parser_state_and_parameters_report_the_coordinate_data() {
    let s = settings();
    let mut g = GcodeState::new();
    ok_all(&mut g, &["G0 X10 Y5", "G10 L20 P1 X0 Y0", "G10 L2 P2 X-50 Y50.5", "G55 G0 X0 Y0", "G28.1"]);
    ok_all(&mut g, &["G1 X1 F200", "G30.1", "G92 X0 Y-1"]);
    let expected = "[G54:10.000,5.000,0.000]\r\n\
                    [G55:-50.000,50.500,0.000]\r\n\
                    [G56:0.000,0.000,0.000]\r\n\
                    [G57:0.000,0.000,0.000]\r\n\
                    [G58:0.000,0.000,0.000]\r\n\
                    [G59:0.000,0.000,0.000]\r\n\
                    [G28:-50.000,50.500,0.000]\r\n\
                    [G30:-49.000,50.500,0.000]\r\n\
                    [G92:1.000,1.000,0.000]\r\n\
                    [TLO:0.000]\r\n\
                    [PRB:0.000,0.000,0.000:0]\r\n";
    assert_eq!(text(|o| report::parameters(o, &g, &Settings::default())), expected);
    assert_eq!(text(|o| report::parser_state(o, &g, &s)), "[GC:G1 G55 G17 G21 G90 G94 M5 M9 T0 F200 S0]\r\n");
    ok_all(&mut g, &["G59"]);
    assert!(text(|o| report::parser_state(o, &g, &s)).starts_with("[GC:G1 G59 G17 "));
    // Program end selects G54 again (GRBL's rule) and keeps the data.
    ok_all(&mut g, &["M2"]);
    assert!(text(|o| report::parser_state(o, &g, &s)).starts_with("[GC:G1 G54 G17 "));
    assert_eq!(text(|o| report::parameters(o, &g, &Settings::default())), expected);
}

#[test]
fn a_reset_keeps_the_systems_and_stored_positions_but_not_g92() {
    let s = settings();
    let mut g = GcodeState::new();
    ok_all(&mut g, &["G0 X10 Y5", "G10 L20 P1 X0 Y0", "G10 L2 P6 X3 Y3", "G28.1", "G0 X1", "G30.1"]);
    ok_all(&mut g, &["G92 X0 Y0", "G59", "G91"]);
    let kept = *g.offsets();
    g.reset(Point::new(123, 456), &s);
    assert_eq!(g.planned_position(), Point::new(123, 456));
    assert_eq!((g.work_system(), g.distance()), (g54(), Distance::Absolute));
    assert_eq!(g.offsets().system_mm(g54()), [10.0, 5.0]);
    assert_eq!(g.offsets().system_mm(system(59)), [3.0, 3.0]);
    assert_eq!(g.offsets().stored_mm(StoredPosition::G28), [10.0, 5.0]);
    assert_eq!(g.offsets().stored_mm(StoredPosition::G30), [11.0, 5.0]);
    assert_eq!(g.offsets().g92_mm(), [0.0, 0.0]);
    assert_eq!(g.offsets(), &kept.after_reset());
    assert_eq!(g.work_offset_mm(), [10.0, 5.0]);
    // So work (0, 0) is where it was before the reset.
    assert_line(&mut g, "G0 X0 Y0", 1000, 500, Feed::Rapid);
}

#[test]
fn restoring_parameters_clears_every_offset() {
    let s = settings();
    for what in ["#", "*"] {
        let mut g = GcodeState::new();
        ok_all(&mut g, &["G0 X10 Y5", "G10 L20 P1 X0 Y0", "G10 L2 P2 X1", "G28.1", "G30.1", "G92 X1"]);
        ok_all(&mut g, &["G55"]);
        let line = std::format!("$RST={what}");
        g.execute(&line, &s, RunState::Idle).unwrap();
        assert_eq!(g.offsets(), &Offsets::new(), "{line}");
        assert_eq!(g.work_offset_mm(), [0.0, 0.0]);
        assert_eq!(g.planned_position(), Point::new(1000, 500));
    }
    let mut g = GcodeState::new();
    ok_all(&mut g, &["G10 L2 P1 X1", "G28.1"]);
    let before = *g.offsets();
    g.execute("$RST=$", &s, RunState::Idle).unwrap();
    assert_eq!(g.offsets(), &before, "$RST=$ restores settings only");
}

#[test]
fn random_coordinate_blocks_keep_the_plan_consistent() {
    use proptest::prelude::*;
    const COMMANDS: [&str; 16] = [
        "G0", "G1", "G10", "G28", "G30", "G28.1", "G30.1", "G54", "G55", "G59", "G91", "G90", "G92", "G92.1", "G53",
        "M2",
    ];
    const LETTERS: [char; 5] = ['X', 'Y', 'Z', 'L', 'P'];
    let s = settings();
    let value = prop_oneof![(-3000i32..3000).prop_map(|v| v as f32 / 20.0), (0i32..25).prop_map(|v| v as f32)];
    let word = (0..COMMANDS.len() + LETTERS.len(), value).prop_map(|(i, v)| match COMMANDS.get(i) {
        Some(c) => String::from(*c),
        None => std::format!("{}{}", LETTERS[i - COMMANDS.len()], v),
    });
    let program = proptest::collection::vec(proptest::collection::vec(word, 1..5), 1..12);
    let accepted = core::cell::Cell::new(0u32);
    proptest!(ProptestConfig::with_cases(500), |(lines in program)| {
        let mut g = GcodeState::new();
        for words in lines {
            let line = words.join(" ");
            let before = g;
            match g.execute(&line, &s, RunState::Idle) {
                Err(_) => prop_assert_eq!(&g, &before, "{}", line),
                Ok(cmds) => {
                    accepted.set(accepted.get() + 1);
                    // The moves chain from the old planned position to the new one.
                    let mut at = before.planned_position();
                    for c in cmds {
                        if let Command::Job(j) = c {
                            prop_assert_eq!(j.drawing.start(), at, "{}", line);
                            at = j.drawing.end();
                            prop_assert!(at.x.abs() <= 20_000 && at.y.abs() <= 20_000, "{} -> {:?}", line, at);
                        }
                    }
                    prop_assert_eq!(at, g.planned_position(), "{}", line);
                    let [sx, sy] = g.offsets().system_mm(g.work_system());
                    let [gx, gy] = g.offsets().g92_mm();
                    prop_assert_eq!(g.work_offset_mm(), [sx + gx, sy + gy]);
                }
            }
        }
    });
    let accepted = accepted.get();
    assert!(accepted > 500, "only {accepted} lines accepted: the generator tests too little");
}

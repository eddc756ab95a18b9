//! Tests of the G-code and `$` command parser: what each line hands to the machine, in steps,
//! and that a refused line changes nothing.

extern crate std;

use super::*;
use crate::geom::Rotation;
use crate::motion::interp::Shape;
use std::vec::Vec;

/// Default settings: 100 steps/mm on both axes, ±200 mm travel, default feed 3000 mm/min.
fn settings() -> Settings {
    Settings::default()
}

fn run_in(g: &mut GcodeState, line: &str, state: RunState) -> Result<Vec<Command>, GrblError> {
    g.execute(line, &settings(), state).map(|c| c.into_iter().collect())
}

fn run(g: &mut GcodeState, line: &str) -> Result<Vec<Command>, GrblError> {
    run_in(g, line, RunState::Idle)
}

/// Runs lines that must all succeed.
fn ok_all(g: &mut GcodeState, lines: &[&str]) {
    for l in lines {
        if let Err(e) = run(g, l) {
            panic!("{l:?} refused with {e:?}");
        }
    }
}

/// Asserts that `line` is refused with GRBL error `code` and that nothing changed.
fn refused_in(g: &mut GcodeState, line: &str, state: RunState, code: u8) {
    let before = *g;
    match run_in(g, line, state) {
        Err(e) => assert_eq!(e.code(), code, "{line:?} gave {e:?}"),
        Ok(c) => panic!("{line:?} accepted: {c:?}"),
    }
    assert_eq!(*g, before, "{line:?} changed the state");
}

fn refused(g: &mut GcodeState, line: &str, code: u8) {
    refused_in(g, line, RunState::Idle, code);
}

/// A straight job from `from` to (`x`, `y`) steps.
fn line_from(from: Point, x: i32, y: i32, feed: Feed, kind: JobKind) -> Command {
    let drawing = crate::motion::drawing::build(&Request::Straight { to: Point::new(x, y) }, from, &settings());
    Command::Job(Job { drawing: drawing.unwrap().unwrap(), feed, kind, pen: None, raise_after: false })
}

/// Runs `l` and asserts that it hands out exactly one straight job, from where the parser
/// planned the pen, to (`x`, `y`) steps at `feed`.
fn assert_line(g: &mut GcodeState, l: &str, x: i32, y: i32, feed: Feed) {
    let from = g.planned_position();
    assert_eq!(run(g, l), Ok(std::vec![line_from(from, x, y, feed, JobKind::Draw)]), "{l:?}");
}

fn feed(f: f32) -> Feed {
    Feed::MmPerMin(f)
}

/// The single curve a line produced.
fn curve(g: &mut GcodeState, l: &str) -> (Shape, Feed, Point) {
    match run(g, l) {
        Ok(mut c) if c.len() == 1 => match c.remove(0) {
            Command::Job(job) => (job.drawing.shape().clone(), job.feed, job.drawing.end()),
            other => panic!("{l:?} gave {other:?}"),
        },
        other => panic!("{l:?} gave {other:?}"),
    }
}

// ----- words and numbers -------------------------------------------------------------------

#[test]
fn words_ignore_case_spaces_comments_and_line_numbers() {
    let mut g = GcodeState::new();
    assert_line(&mut g, "n10 g1x10 y-1.5 (pen down) f600 ; go", 1000, -150, feed(600.0));
    assert_line(&mut g, "G 0 X 1 0 Y.5", 1000, 50, Feed::Rapid);
    assert_line(&mut g, "G0X+2(unclosed comment runs to the end Y9", 200, 50, Feed::Rapid);
    assert_eq!(g.planned_position(), Point::new(200, 50));
}

#[test]
fn empty_comment_and_percent_lines_do_nothing() {
    let mut g = GcodeState::new();
    for l in ["", "   ", "(just a comment)", "; another", "%", "N5"] {
        assert_eq!(run(&mut g, l), Ok(Vec::new()), "{l:?}");
    }
    // Even in alarm: GRBL answers ok to empty lines whatever the state.
    assert_eq!(run_in(&mut g, "(comment)", RunState::Alarm), Ok(Vec::new()));
    assert_eq!(g, GcodeState::new());
}

#[test]
fn malformed_words_are_refused_with_grbls_numbers() {
    let mut g = GcodeState::new();
    ok_all(&mut g, &["G1 X10 Y10 F500"]);
    refused(&mut g, "G0 X", 2);
    refused(&mut g, "G0 X1.2.3", 2);
    refused(&mut g, "G0 X--1", 2);
    refused(&mut g, "G0 X1-", 2);
    refused(&mut g, "G0 X.", 2);
    refused(&mut g, ".5 G0", 1);
    // Spaces vanish before words are read: this is G0.5, not G0 and a stray number.
    refused(&mut g, "G0 .5", 23);
    refused(&mut g, "10 G0", 1);
    refused(&mut g, "G0 X1 #", 1);
    refused(&mut g, "G0 X1 Q2", 20);
    refused(&mut g, "G0 X1 X2", 25);
    refused(&mut g, "G1 X1 F-5", 4);
    refused(&mut g, "N10000000 G0 X1", 27);
    refused(&mut g, "T256", 38);
    // A number long enough to leave f32 is refused, not turned into infinity.
    let huge = std::format!("G0 X{}", "9".repeat(60));
    refused(&mut g, &huge, 2);
    // An absurd but finite one is just outside the travel.
    refused(&mut g, "G0 X99999999999999999999", 15);
}

#[test]
fn modal_group_and_command_rules() {
    let mut g = GcodeState::new();
    refused(&mut g, "G0 G1 X1", 21);
    refused(&mut g, "G20 G21", 21);
    refused(&mut g, "G90 G91", 21);
    refused(&mut g, "M3 M5", 21);
    refused(&mut g, "M0 M2", 21);
    refused(&mut g, "G4 P1 G92 X0", 21);
    refused(&mut g, "G1.5 X1", 23);
    refused(&mut g, "M3.1", 23);
    refused(&mut g, "G18", 20);
    refused(&mut g, "G19", 20);
    refused(&mut g, "G28.2", 20);
    refused(&mut g, "G38.2 X1", 20);
    refused(&mut g, "G59.1", 20);
    refused(&mut g, "G93", 20);
    refused(&mut g, "M7", 20);
    refused(&mut g, "M6", 20);
    refused(&mut g, "G92 G0 X1", 24);
    refused(&mut g, "G1 G92 X1", 24);
    refused(&mut g, "G0 X1 P2", 36);
    refused(&mut g, "G1 X1 R5", 36);
    refused(&mut g, "I5", 36);
    refused(&mut g, "G92", 26);
    refused(&mut g, "G4", 28);
    refused(&mut g, "G4 P-1", 4);
    refused(&mut g, "G4 P4000", 38);
    ok_all(&mut g, &["G80"]);
    refused(&mut g, "X1", 31);
    refused(&mut g, "Z1", 31);
    refused(&mut g, "G53 X1", 30);
    // The usual CAM header is accepted and changes nothing that moves.
    assert_eq!(run(&mut g, "G90 G94 G17 G21 G40 G49 G54 G61 G91.1 M5 M9"), Ok(Vec::new()));
}

// ----- motion ------------------------------------------------------------------------------

#[test]
fn motion_mode_and_feed_are_modal() {
    let mut g = GcodeState::new();
    // No F yet: the default feed rate ($203) applies.
    assert_line(&mut g, "G1 X10", 1000, 0, feed(3000.0));
    assert_line(&mut g, "Y5 F600", 1000, 500, feed(600.0));
    assert_line(&mut g, "X0", 0, 500, feed(600.0));
    assert_line(&mut g, "G0 Y0", 0, 0, Feed::Rapid);
    assert_line(&mut g, "X3", 300, 0, Feed::Rapid);
    // G1 alone only selects the mode.
    assert_eq!(run(&mut g, "G1"), Ok(Vec::new()));
    assert_eq!(g.motion_mode(), MotionMode::Linear);
    // A move that ends on its own step hands out nothing but is still planned.
    assert_eq!(run(&mut g, "X3.004"), Ok(Vec::new()));
    assert_eq!(g.position_mm, [3.004, 0.0]);
}

#[test]
fn an_explicit_zero_feed_is_undefined() {
    let mut g = GcodeState::new();
    refused(&mut g, "G1 X1 F0", 22);
    ok_all(&mut g, &["G0 F0"]);
    refused(&mut g, "G1 X1", 22);
    refused(&mut g, "G2 X1 I1", 22);
    assert_line(&mut g, "G0 X1", 100, 0, Feed::Rapid);
    assert_line(&mut g, "G1 X2 F100", 200, 0, feed(100.0));
}

#[test]
fn g91_moves_are_relative_and_do_not_drift() {
    let mut g = GcodeState::new();
    ok_all(&mut g, &["G91 G0 X10 Y10", "X10 Y-5"]);
    assert_eq!(g.planned_position(), Point::new(2000, 500));
    // Ten moves of 0.4 step each: rounding each move would never leave the spot.
    let mut handed_out = Vec::new();
    for _ in 0..10 {
        handed_out.extend(run(&mut g, "G1 X0.004 F100").unwrap());
    }
    assert_eq!(g.planned_position(), Point::new(2004, 500));
    assert_eq!(handed_out.last(), Some(&line_from(Point::new(2003, 500), 2004, 500, feed(100.0), JobKind::Draw)));
    assert_eq!(handed_out.len(), 4, "one job per step reached");
}

#[test]
fn g20_converts_inches_for_axes_offsets_and_feed() {
    let mut g = GcodeState::new();
    assert_line(&mut g, "G20 G1 X1 Y-0.5 F10", 2540, -1270, feed(254.0));
    assert_eq!(g.units(), Units::Inch);
    let (shape, _, end) = curve(&mut g, "G2 X1.5 Y-0.5 I0.25");
    assert_eq!(shape, Shape::Arc { center: Point::new(3175, -1270), to: end, rotation: Rotation::Clockwise });
    assert_eq!(end, Point::new(3810, -1270));
    // Back to millimetres: the planned position is where the inches left it.
    assert_line(&mut g, "G21 G91 G0 X1", 3910, -1270, Feed::Rapid);
}

#[test]
fn z_words_are_accepted_and_move_nothing() {
    let mut g = GcodeState::new();
    assert_eq!(run(&mut g, "G0 Z5"), Ok(Vec::new()));
    assert_eq!(run(&mut g, "G1 Z-1 F300"), Ok(Vec::new()));
    assert_eq!(g.feed_mm_per_min(&settings()), 300.0);
    assert_line(&mut g, "G1 X10 Z-1", 1000, 0, feed(300.0));
    assert_eq!(run(&mut g, "G92 Z0"), Ok(Vec::new()));
    assert_eq!(g.work_offset_mm(), [0.0, 0.0]);
    refused(&mut g, "G2 Z1 I1", 32);
    assert_eq!(g.planned_position(), Point::new(1000, 0));
}

#[test]
fn travel_limits_refuse_targets_and_change_nothing() {
    let mut g = GcodeState::new();
    assert_line(&mut g, "G0 X200 Y-200", 20_000, -20_000, Feed::Rapid);
    refused(&mut g, "G0 X200.1", 15);
    refused(&mut g, "G1 Y-250", 15);
    refused(&mut g, "G91 G0 X0.01", 15);
    assert_eq!(g.planned_position(), Point::new(20_000, -20_000));
    assert_eq!(g.distance(), Distance::Absolute);
}

#[test]
fn arcs_with_centre_offsets() {
    let mut g = GcodeState::new();
    let (shape, f, end) = curve(&mut g, "G2 X20 Y0 I10 J0 F500");
    assert_eq!(
        shape,
        Shape::Arc { center: Point::new(1000, 0), to: Point::new(2000, 0), rotation: Rotation::Clockwise }
    );
    assert_eq!((f, end), (feed(500.0), Point::new(2000, 0)));
    let (shape, ..) = curve(&mut g, "G3 X0 I-10");
    assert_eq!(
        shape,
        Shape::Arc { center: Point::new(1000, 0), to: Point::ORIGIN, rotation: Rotation::CounterClockwise }
    );
    assert_eq!(g.motion_mode(), MotionMode::ArcCcw);
    // A full circle: the end is the start.
    let (shape, _, end) = curve(&mut g, "G91 G2 X0 Y0 I0 J-5");
    assert_eq!(shape, Shape::Arc { center: Point::new(0, -500), to: Point::ORIGIN, rotation: Rotation::Clockwise });
    assert_eq!(end, Point::ORIGIN);
    // The end 0.05 mm off a 10 mm circle: more than 0.1 % of the radius.
    refused(&mut g, "G90 G2 X20 Y1 I10", 33);
    // 0.004 mm off is within GRBL's tolerance.
    assert!(run(&mut g, "G90 G2 X20 Y0.3 I10").is_ok());
    refused(&mut g, "G2 X1", 35);
    refused(&mut g, "G2 X1 K1", 35);
    refused(&mut g, "G2 I1 J1", 26);
}

#[test]
fn arcs_with_a_radius() {
    let mut g = GcodeState::new();
    // Chord (0,0)→(10,10): the clockwise short arc turns about (10,0)...
    let (shape, ..) = curve(&mut g, "G2 X10 Y10 R10");
    assert_eq!(
        shape,
        Shape::Arc { center: Point::new(1000, 0), to: Point::new(1000, 1000), rotation: Rotation::Clockwise }
    );
    // ...a negative R takes the long way, about (0,10) when starting back from (0,0).
    ok_all(&mut g, &["G0 X0 Y0"]);
    let (shape, ..) = curve(&mut g, "G2 X10 Y10 R-10");
    assert_eq!(
        shape,
        Shape::Arc { center: Point::new(0, 1000), to: Point::new(1000, 1000), rotation: Rotation::Clockwise }
    );
    // Back from (10,10) to (0,0) counter-clockwise, the short way: about (10,0).
    let (shape, ..) = curve(&mut g, "G3 X0 Y0 R10");
    assert_eq!(
        shape,
        Shape::Arc { center: Point::new(1000, 0), to: Point::ORIGIN, rotation: Rotation::CounterClockwise }
    );
    refused(&mut g, "G2 X10 Y0 R4.9", 34);
    refused(&mut g, "G2 X0 Y0 R5", 33);
    refused(&mut g, "G2 X10 R5 I5", 36);
}

#[test]
fn arcs_are_checked_against_the_travel_along_their_whole_sweep() {
    let mut g = GcodeState::new();
    ok_all(&mut g, &["G0 X195 Y0"]);
    // Counter-clockwise from the bottom to the top of a 6 mm circle bulges to x = 201.
    refused(&mut g, "G3 X195 Y12 I0 J6", 15);
    // Clockwise it bulges to x = 189: fine.
    let (shape, ..) = curve(&mut g, "G2 X195 Y12 I0 J6");
    assert_eq!(
        shape,
        Shape::Arc { center: Point::new(19_500, 600), to: Point::new(19_500, 1200), rotation: Rotation::Clockwise }
    );
    refused(&mut g, "G91 G2 X0 Y0 I0 J-150", 15);
}

#[test]
fn circles_become_ellipses_in_steps_when_the_axes_differ() {
    let mut s = settings();
    s.set(101, 50.0).unwrap();
    let mut g = GcodeState::new();
    let cmds = g.execute("G2 X20 Y0 I10 F500", &s, RunState::Idle).unwrap();
    let expected = Shape::Ellipse {
        center: Point::new(1000, 0),
        a_steps: 1000,
        b_steps: 500,
        to: Point::new(2000, 0),
        rotation: Rotation::Clockwise,
    };
    match cmds.collect::<Vec<_>>().as_slice() {
        [Command::Job(job)] => {
            assert_eq!(job.drawing.shape(), &expected);
            assert_eq!((job.feed, job.drawing.end()), (feed(500.0), Point::new(2000, 0)));
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn g92_offsets_the_work_coordinates_and_g53_bypasses_them() {
    let mut g = GcodeState::new();
    ok_all(&mut g, &["G0 X10 Y-5", "G92 X0 Y0"]);
    assert_eq!(g.work_offset_mm(), [10.0, -5.0]);
    assert_eq!(g.planned_position(), Point::new(1000, -500));
    assert_line(&mut g, "G0 X1", 1100, -500, Feed::Rapid);
    assert_line(&mut g, "G53 G0 X0 Y0", 0, 0, Feed::Rapid);
    // G53 lasts one line.
    assert_line(&mut g, "X0", 1000, 0, Feed::Rapid);
    // The travel limits are the machine's, not the work coordinates'.
    refused(&mut g, "G0 X195", 15);
    assert_eq!(run(&mut g, "G92.1"), Ok(Vec::new()));
    assert_line(&mut g, "G0 X195", 19_500, 0, Feed::Rapid);
}

#[test]
fn dwell_motion_and_stop_of_one_line_come_out_in_order() {
    let mut g = GcodeState::new();
    ok_all(&mut g, &["G91"]);
    assert_eq!(
        run(&mut g, "G4 P0.25 G1 X10 F300 M2"),
        Ok(std::vec![
            Command::Dwell { ms: 250 },
            line_from(Point::ORIGIN, 1000, 0, feed(300.0), JobKind::Draw),
            Command::ProgramEnd
        ])
    );
    // Program end restores G90 and G1 (GRBL's rule) but keeps F.
    assert_eq!(g.distance(), Distance::Absolute);
    assert_eq!(g.motion_mode(), MotionMode::Linear);
    assert_eq!(g.feed_mm_per_min(&settings()), 300.0);
    assert_eq!(run(&mut g, "M0"), Ok(std::vec![Command::Pause]));
    assert_eq!(run(&mut g, "M1"), Ok(Vec::new()));
    assert_eq!(run(&mut g, "M3 S1000"), Ok(Vec::new()));
    assert_eq!(g.spindle(), Spindle::Cw);
    assert_eq!(run(&mut g, "M30"), Ok(std::vec![Command::ProgramEnd]));
    assert_eq!(g.spindle(), Spindle::Off);
}

#[test]
fn settings_are_checked_before_they_are_handed_out() {
    let mut g = GcodeState::new();
    assert_eq!(run(&mut g, "$110 = 5000"), Ok(std::vec![Command::SetSetting { id: 110, value: 5000.0 }]));
    refused(&mut g, "$100=0", 3);
    refused(&mut g, "$100=-5", 4);
    refused(&mut g, "$202=0.5", 3);
    refused(&mut g, "$999=1", 3);
    refused(&mut g, "$99999999=1", 3);
    refused(&mut g, "$100=abc", 2);
    refused(&mut g, "$100", 3);
    refused(&mut g, "$1x0=5", 3);
}

#[test]
fn changing_steps_per_mm_keeps_the_pen_on_its_step() {
    let mut s = settings();
    let mut g = GcodeState::new();
    g.execute("G0 X10", &s, RunState::Idle).unwrap();
    let cmds = g.execute("$100=80", &s, RunState::Idle).unwrap();
    assert_eq!(cmds.collect::<Vec<_>>(), std::vec![Command::SetSetting { id: 100, value: 80.0 }]);
    s.set(100, 80.0).unwrap();
    assert_eq!(g.planned_position(), Point::new(1000, 0));
    assert_eq!(g.position_mm, [12.5, 0.0]);
    let cmds = g.execute("G91 G0 X1", &s, RunState::Idle).unwrap();
    let from = Point::new(1000, 0);
    let drawing =
        crate::motion::drawing::build(&Request::Straight { to: Point::new(1080, 0) }, from, &s).unwrap().unwrap();
    assert_eq!(cmds.collect::<Vec<_>>(), std::vec![Command::Job(Job::draw(drawing, Feed::Rapid))]);
}

#[test]
fn restoring_defaults() {
    let mut s = settings();
    s.set(100, 50.0).unwrap();
    let mut g = GcodeState::new();
    g.execute("G0 X10", &s, RunState::Idle).unwrap();
    g.execute("G92 X0", &s, RunState::Idle).unwrap();
    assert_eq!(g.execute("$RST=#", &s, RunState::Idle).map(|c| c.len()), Ok(0));
    assert_eq!(g.work_offset_mm(), [0.0, 0.0]);
    let cmds = g.execute("$RST=$", &s, RunState::Idle).unwrap();
    assert_eq!(cmds.collect::<Vec<_>>(), std::vec![Command::RestoreSettings { startup_lines: false }]);
    // Still on step 500, now 5 mm at the default 100 steps/mm.
    assert_eq!(g.position_mm, [5.0, 0.0]);
}

#[test]
fn jogs_follow_grbls_rules_and_leave_the_modes_alone() {
    let mut g = GcodeState::new();
    let jog = |from: (i32, i32), x, y, f| line_from(Point::new(from.0, from.1), x, y, feed(f), JobKind::Jog);
    assert_eq!(run(&mut g, "$J=G91 X1 F600"), Ok(std::vec![jog((0, 0), 100, 0, 600.0)]));
    assert_eq!(run_in(&mut g, "$J=G91 Y-2 F600", RunState::Jog), Ok(std::vec![jog((100, 0), 100, -200, 600.0)]));
    assert_eq!(run(&mut g, "$J=X5 Y5 F100"), Ok(std::vec![jog((100, -200), 500, 500, 100.0)]));
    assert_eq!(run(&mut g, "$J=G20 G91 X1 F10"), Ok(std::vec![jog((500, 500), 3040, 500, 254.0)]));
    assert_eq!((g.distance(), g.units()), (Distance::Absolute, Units::Mm));
    assert_eq!(g.feed_mm_per_min(&settings()), 3000.0, "a jog's F is not modal");
    assert_eq!(run(&mut g, "$J=G91 Z1 F100"), Ok(Vec::new()));
    refused(&mut g, "$J=X1", 22);
    refused(&mut g, "$J=X1 F0", 22);
    refused(&mut g, "$J=G1 X1 F100", 16);
    refused(&mut g, "$J=G91 X1 F100 S5", 16);
    refused(&mut g, "$J=G4 P1 F100", 16);
    refused(&mut g, "$J=M3 X1 F100", 16);
    refused(&mut g, "$J=F100", 26);
    refused(&mut g, "$J=G91 X300 F100", 15);
    ok_all(&mut g, &["G92 X0"]);
    assert_eq!(run(&mut g, "$J=G53 X5 F100"), Ok(std::vec![jog((3040, 500), 500, 500, 100.0)]));
}

// ----- plotter curves ----------------------------------------------------------------------

#[test]
fn circle_command_draws_from_the_pen() {
    let mut g = GcodeState::new();
    let (shape, f, end) = curve(&mut g, "$O R10");
    assert_eq!(
        shape,
        Shape::Arc { center: Point::new(-1000, 0), to: Point::ORIGIN, rotation: Rotation::CounterClockwise }
    );
    assert_eq!((f, end), (feed(3000.0), Point::ORIGIN));
    // Pen at 90° on the circle, a quarter clockwise: ends at 0°.
    let (shape, f, end) = curve(&mut g, "$o r10 s90 w-90 f600");
    assert_eq!(
        shape,
        Shape::Arc { center: Point::new(0, -1000), to: Point::new(1000, -1000), rotation: Rotation::Clockwise }
    );
    assert_eq!((f, end), (feed(600.0), Point::new(1000, -1000)));
    assert_eq!(g.planned_position(), end);
    assert_eq!(g.feed_mm_per_min(&settings()), 600.0, "F of a curve command is modal");
    // Millimetres whatever G20 says.
    ok_all(&mut g, &["G20"]);
    let (shape, ..) = curve(&mut g, "$O R1 W180");
    assert_eq!(
        shape,
        Shape::Arc { center: Point::new(900, -1000), to: Point::new(800, -1000), rotation: Rotation::CounterClockwise }
    );
    refused(&mut g, "$O", 28);
    refused(&mut g, "$O R-1", 4);
    refused(&mut g, "$O R0", 33);
    refused(&mut g, "$O R0.001", 33);
    refused(&mut g, "$O R5 W361", 33);
    refused(&mut g, "$O R5 X1", 36);
    refused(&mut g, "$O R5 R6", 25);
    refused(&mut g, "$O R150", 15);
    assert_eq!(run(&mut g, "$O R5 W0"), Ok(Vec::new()));
}

#[test]
fn ellipse_command() {
    let mut g = GcodeState::new();
    let (shape, _, end) = curve(&mut g, "$E A20 B10");
    let full = Shape::Ellipse {
        center: Point::new(-2000, 0),
        a_steps: 2000,
        b_steps: 1000,
        to: Point::ORIGIN,
        rotation: Rotation::CounterClockwise,
    };
    assert_eq!((shape, end), (full, Point::ORIGIN));
    let (shape, _, end) = curve(&mut g, "$E A20 B10 S0 W90");
    assert_eq!(end, Point::new(-2000, 1000));
    assert_eq!(
        shape,
        Shape::Ellipse {
            center: Point::new(-2000, 0),
            a_steps: 2000,
            b_steps: 1000,
            to: end,
            rotation: Rotation::CounterClockwise
        }
    );
    // Continue a quarter more from where the pen is now (parametric 90°), clockwise back.
    let (_, _, end) = curve(&mut g, "$E A20 B10 S90 W-90");
    assert_eq!(end, Point::ORIGIN);
    refused(&mut g, "$E A10", 28);
    refused(&mut g, "$E A-1 B1", 4);
    refused(&mut g, "$E A0 B1", 33);
    refused(&mut g, "$E A1 B1 W-400", 33);
    refused(&mut g, "$E A1 B1 Q1", 36);
    // The far side of this ellipse is 300 mm left of the pen.
    refused(&mut g, "$E A150 B1", 15);
}

#[test]
fn sine_command() {
    let mut g = GcodeState::new();
    // A quarter period (ω = π/10 rad/mm, 5 mm): ends at the crest, A above the pen.
    let (shape, _, end) = curve(&mut g, "$S A5 W0.31415927 L5");
    match shape {
        Shape::Sine { amplitude_steps, omega_rad_per_step, phase_rad, length_steps } => {
            assert_eq!((amplitude_steps, phase_rad, length_steps), (500.0, 0.0, 500));
            assert!((omega_rad_per_step - 0.0031415927).abs() < 1e-9);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(end, Point::new(500, 500));
    // Leftwards with a 90° phase: y = 5·(cos(ωu) − 1), a quarter period down to -5.
    let (_, _, end) = curve(&mut g, "$S A5 W0.31415927 P90 L-5");
    assert_eq!(end, Point::new(0, 0));
    refused(&mut g, "$S A5 W1", 28);
    refused(&mut g, "$S A5 L1", 28);
    refused(&mut g, "$S A5 W1 L1 S10", 36);
    // y swings ±250 mm: outside the ±200 mm travel even though both ends are inside.
    refused(&mut g, "$S A250 W1 L10", 15);
    refused(&mut g, "$S A1 W1 L300", 15);
    assert_eq!(run(&mut g, "$S A5 W1 L0"), Ok(Vec::new()));
}

#[test]
fn a_sine_steeper_than_the_jump_limit_is_refused() {
    let mut g = GcodeState::new();
    // y swings ±200 mm, inside the travel, but ω = 1000 rad/mm puts 400 mm strokes between
    // neighbouring X steps.
    refused(&mut g, "$S A200 W1000 L100", 33);
    // The steepest rise per X step is A·ω steps (here, with equal steps/mm on both axes):
    // 510 is over the 5 mm (500-step) limit, 490 under it.
    refused(&mut g, "$S A100 W5.1 L10", 33);
    let (_, _, end) = curve(&mut g, "$S A100 W4.9 L10");
    assert_eq!(end.x, 1000);
    // The limit is `$204`.
    let mut s = settings();
    s.max_jump_mm = 10.0;
    let mut g = GcodeState::new();
    assert!(g.execute("$S A100 W5.1 L10", &s, RunState::Idle).is_ok());
    s.max_jump_mm = 1.0;
    let before = g;
    assert_eq!(
        g.execute("$S A10 W11 L10", &s, RunState::Idle).map(|_| ()),
        Err(GrblError::Drawing(crate::motion::drawing::DrawError::TooSteep))
    );
    assert_eq!(g, before);
    // Nothing to draw, nothing to refuse.
    assert_eq!(run(&mut GcodeState::new(), "$S A200 W1000 L0.001"), Ok(Vec::new()));
}

#[test]
fn arcs_too_small_for_their_interpolator_are_refused() {
    let mut g = GcodeState::new();
    // Radius half a step: the centre rounds onto the start or the end, which no interpolator
    // can draw; the parser refuses them rather than plan a curve the motion would refuse.
    refused(&mut g, "G2 X0.01 Y0 R0.005", 33);
    refused(&mut g, "G2 X0.01 Y0 I0.005", 33);
    refused(&mut g, "$O R0.005 S45 W360", 33);
    refused(&mut g, "$E A0.005 B0.005 S45", 33);
    // A step or two of radius draws.
    let (shape, _, end) = curve(&mut g, "G2 X0.02 Y0 R0.015");
    assert_eq!(shape, Shape::Arc { center: Point::new(1, -1), to: Point::new(2, 0), rotation: Rotation::Clockwise });
    assert_eq!(end, Point::new(2, 0));
    let (_, _, end) = curve(&mut g, "$O R0.01");
    assert_eq!(end, Point::new(2, 0));
    // An I/J end within GRBL's radius tolerance (0.1 % of r) but off the circle: 0.08 mm at
    // r = 90 mm. GRBL accepts it; the arc is drawn on its circle and the pen ends there, where
    // the parser then plans it.
    ok_all(&mut g, &["G0 X0 Y0"]);
    let (_, _, end) = curve(&mut g, "G91 G2 X180.08 Y0 I90");
    assert_eq!(end, Point::new(18_000, 0));
    assert_eq!(g.planned_position(), end);
    refused(&mut g, "G91 G2 X181 Y0 I90", 33);
}

#[test]
fn ellipses_larger_than_their_interpolator_takes_are_refused() {
    // At 100 steps/mm a semi-axis of 2700 mm is 270_000 steps, beyond the ellipse
    // interpolator's MAX_ELLIPSE_AXIS_STEPS (262_144); a short arc of it stays inside the travel.
    let mut g = GcodeState::new();
    refused(&mut g, "$E A2700 B1000 S90 W1", 33);
    assert!(run(&mut g, "$E A2600 B1000 S90 W1").is_ok());
}

#[test]
fn function_command() {
    let mut g = GcodeState::new();
    ok_all(&mut g, &["G0 X10 Y10"]);
    let (shape, f, end) = curve(&mut g, "$F X-2 U2 F600 Y=x^2");
    match &shape {
        Shape::Function { expr, x0_mm, x1_mm } => {
            assert_eq!((*x0_mm, *x1_mm), (-2.0, 2.0));
            assert_eq!(expr.eval(3.0), Ok(9.0));
        }
        other => panic!("{other:?}"),
    }
    // (x0, f(x0)) = (-2, 4) sits at the pen; (2, 4) is 4 mm to its right.
    assert_eq!((f, end), (feed(600.0), Point::new(1400, 1000)));
    let (_, _, end) = curve(&mut g, "$f x0 u10 y = x/2 ; half slope");
    assert_eq!(end, Point::new(2400, 1500));
    // A `y` in a comment before `Y=` is not the expression's.
    let (_, _, end) = curve(&mut g, "$F (my parabola) X0 U1 Y=-x");
    assert_eq!(end, Point::new(2500, 1400));
    assert_eq!(g.planned_position(), end);
}

#[test]
fn function_command_errors() {
    let mut g = GcodeState::new();
    // The `(` opened at column 15 is never closed.
    let before = g;
    let e = run(&mut g, "$F X0 U1 Y=sin(x").unwrap_err();
    assert_eq!(e, GrblError::Expression { column: 15, kind: crate::motion::expr::ParseErrorKind::MismatchedParen });
    assert_eq!(e.code(), 2);
    assert_eq!(g, before);
    let e = run(&mut g, "  $F X0 U1 Y= foo").unwrap_err();
    assert_eq!(e, GrblError::Expression { column: 15, kind: crate::motion::expr::ParseErrorKind::UnknownName });
    let e = run(&mut g, "$F X-1 U1 Y=sqrt(x)").unwrap_err();
    assert_eq!(e, GrblError::FunctionUndefined { x_mm: -1.0, error: crate::motion::expr::EvalError::SqrtOfNegative });
    assert_eq!(e.code(), 33);
    assert_eq!(g, before);
    // y = 100·x climbs 1000 mm over 10 mm.
    refused(&mut g, "$F X0 U10 Y=100*x", 15);
    refused(&mut g, "$F X0 Y=x", 28);
    refused(&mut g, "$F U1 Y=x", 28);
    refused(&mut g, "$F X0 U1", 28);
    refused(&mut g, "$F X0 U1 Q2 Y=x", 36);
    refused(&mut g, "$F X0 U1 Y x", 2);
    refused(&mut g, "$F X0 U1 Y=", 2);
    assert_eq!(run(&mut g, "$F X1 U1 Y=x"), Ok(Vec::new()));
}

// ----- position bookkeeping ----------------------------------------------------------------

#[test]
fn sync_and_reset_take_the_machines_position() {
    let s = settings();
    let mut g = GcodeState::new();
    g.execute("G91 G1 X50 F100", &s, RunState::Idle).unwrap();
    g.execute("G92 X0", &s, RunState::Idle).unwrap();
    // A jog cancel stopped the pen early at step 1234.
    g.sync_position(Point::new(1234, -5), &s);
    assert_eq!(g.planned_position(), Point::new(1234, -5));
    assert_eq!(
        g.execute("X1", &s, RunState::Idle).unwrap().collect::<Vec<_>>(),
        std::vec![line_from(Point::new(1234, -5), 1334, -5, feed(100.0), JobKind::Draw)]
    );
    g.reset(Point::new(7, 8), &s);
    assert_eq!(g.planned_position(), Point::new(7, 8));
    assert_eq!(
        (g.distance(), g.motion_mode(), g.work_offset_mm()),
        (Distance::Absolute, MotionMode::Rapid, [0.0, 0.0])
    );
}

#[test]
fn no_line_panics_and_a_refused_line_changes_nothing() {
    use proptest::prelude::*;
    let alphabet: Vec<char> = "GMXYZIJKRFPSNTAUWLEO$=.-+ ()%;01234567890xy^*/".chars().collect();
    let s = settings();
    proptest!(ProptestConfig::with_cases(2000), |(picks in proptest::collection::vec(0..alphabet.len(), 0..40),
                                                  start in (-15_000i32..15_000, -15_000i32..15_000))| {
        let text: std::string::String = picks.iter().map(|&i| alphabet[i]).collect();
        let mut g = GcodeState::new();
        g.sync_position(Point::new(start.0, start.1), &s);
        let before = g;
        match g.execute(&text, &s, RunState::Idle) {
            Err(_) => prop_assert_eq!(&g, &before),
            Ok(cmds) => {
                // Every move ends inside the travel; the last where the parser now plans the pen.
                let limit = 20_000;
                let mut last = None;
                for c in cmds {
                    if let Command::Job(j) = &c {
                        let to = j.drawing.end();
                        prop_assert!(to.x.abs() <= limit && to.y.abs() <= limit, "{} -> {:?}", text, to);
                        last = Some(to);
                    }
                }
                if let Some(to) = last {
                    prop_assert_eq!(to, g.planned_position());
                }
            }
        }
    });
}

#[test]
fn random_gcode_blocks_keep_the_plan_consistent() {
    use proptest::prelude::*;
    const COMMANDS: [&str; 12] = ["G0", "G1", "G2", "G3", "G90", "G91", "G20", "G21", "G92", "G53", "M2", "G4"];
    const LETTERS: [char; 8] = ['X', 'Y', 'Z', 'I', 'J', 'R', 'F', 'P'];
    let s = settings();
    let word = (0..COMMANDS.len() + LETTERS.len(), -3000i32..3000).prop_map(|(i, v)| {
        if i < COMMANDS.len() {
            std::string::String::from(COMMANDS[i])
        } else {
            std::format!("{}{}", LETTERS[i - COMMANDS.len()], v as f32 / 20.0)
        }
    });
    let program = proptest::collection::vec(proptest::collection::vec(word, 1..5), 1..12);
    let accepted = core::cell::Cell::new(0u32);
    proptest!(ProptestConfig::with_cases(500), |(lines in program)| {
        let mut g = GcodeState::new();
        for words in lines {
            let text = words.join(" ");
            let before = g;
            match g.execute(&text, &s, RunState::Idle) {
                Err(_) => prop_assert_eq!(&g, &before, "{}", text),
                Ok(cmds) => {
                    accepted.set(accepted.get() + 1);
                    for c in cmds {
                        let end = match &c {
                            Command::Job(j) => Some(j.drawing.end()),
                            _ => None,
                        };
                        if let Some(end) = end {
                            prop_assert!(end.x.abs() <= 20_000 && end.y.abs() <= 20_000, "{} -> {:?}", text, end);
                            prop_assert_eq!(end, g.planned_position(), "{}", text);
                        }
                        if let Command::Job(j) = &c
                            && let Shape::Arc { to, .. } = j.drawing.shape()
                        {
                            prop_assert_eq!(*to, j.drawing.end());
                        }
                    }
                }
            }
        }
    });
    let accepted = accepted.get();
    assert!(accepted > 500, "only {accepted} lines accepted: the generator tests too little");
}

mod coordinates;
mod pending;
mod system;

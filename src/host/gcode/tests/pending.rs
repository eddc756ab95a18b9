//! Tests of a line in its two phases: parsed and checked, its curve built a slice at a time, and
//! only then kept. Nothing of the line is kept before; a curve refused as it is walked changes
//! nothing; slices build what one go builds.

extern crate std;

use super::*;
use crate::motion::drawing::DrawError;
use crate::motion::interp::{CurveError, ShapeKind};

/// Parses `line` into a pending line and walks its curve in slices of `slice` steps' worth; the
/// slices it took.
fn walk(g: &GcodeState, line: &str, state: RunState, slice: u32, pending: &mut Pending) -> usize {
    g.parse(line, &settings(), state, pending).unwrap();
    let mut slices = 1;
    while !pending.advance(slice).done {
        slices += 1;
    }
    slices
}

#[test]
fn a_curve_is_built_slice_by_slice_and_its_line_kept_only_then() {
    let s = settings();
    let mut g = GcodeState::new();
    g.execute("G0 X10 Y5", &s, RunState::Idle).unwrap();
    let before = g;
    let mut pending = Pending::new();
    let slices = walk(&g, "$O R20 F1000", RunState::Idle, 256, &mut pending);
    assert!(slices > 20, "a circle of 16,000 steps in {slices} slices");
    assert_eq!(g, before, "nothing kept while the curve was built");
    let sliced: Vec<Command> = g.commit(&mut pending, &s).unwrap().collect();
    // The same job and the same state as the line run in one go.
    let mut one_go = before;
    let whole: Vec<Command> = one_go.execute("$O R20 F1000", &s, RunState::Idle).unwrap().collect();
    assert_eq!(sliced, whole);
    assert_eq!(g, one_go);
    assert_eq!(g.feed_mm_per_min(&s), 1000.0, "the line's F word kept with it");
    assert_eq!(g.planned_position(), Point::new(1000, 500), "a full circle ends where it began");
}

#[test]
fn a_curve_refused_as_it_is_walked_changes_nothing() {
    let s = settings();
    let mut g = GcodeState::new();
    let before = g;
    let mut pending = Pending::new();
    // Defined where it starts (the line is accepted), undefined after x = 1 (the walk finds it).
    walk(&g, "$F X0 U2 F500 Y=sqrt(1-x)", RunState::Idle, 64, &mut pending);
    match g.commit(&mut pending, &s) {
        Err(GrblError::Drawing(DrawError::Fails { x_mm, error: CurveError::Domain })) => {
            assert!((x_mm - 1.0).abs() <= 0.011, "{x_mm}")
        }
        other => panic!("{:?}", other.map(|c| c.len())),
    }
    assert_eq!(g, before, "not even the F word");
}

#[test]
fn a_line_without_a_curve_is_built_at_once_and_a_line_needs_no_walk() {
    let s = settings();
    let g = GcodeState::new();
    let mut pending = Pending::new();
    for line in ["G90", "G1 X150 Y-80 F600", "G28"] {
        g.parse(line, &s, RunState::Idle, &mut pending).unwrap();
        let slice = pending.advance(1);
        assert!(slice.done && slice.steps == 0, "{line}: {slice:?}");
    }
    // A curve takes its steps; the slice says of what.
    g.parse("$S A10 W0.3 L60", &s, RunState::Idle, &mut pending).unwrap();
    let slice = pending.advance(100);
    assert_eq!((slice.kind, slice.done), (ShapeKind::Sine, false));
    assert!(slice.steps > 0 && slice.x_steps > 0);
}

#[test]
fn check_mode_builds_and_checks_a_curve_and_runs_nothing() {
    let s = settings();
    let mut g = GcodeState::new();
    let mut pending = Pending::new();
    walk(&g, "G2 X20 Y0 I10 F500", RunState::Check, 512, &mut pending);
    assert_eq!(g.commit(&mut pending, &s).map(|c| c.len()), Ok(0));
    assert_eq!(g.planned_position(), Point::new(2000, 0), "planned on from the arc's end");
    // One that would leave the travel is refused as it is walked.
    walk(&g, "$F X0 U30 Y=x^2/2", RunState::Check, 512, &mut pending);
    assert_eq!(g.commit(&mut pending, &s).map(|c| c.len()), Err(GrblError::TravelExceeded));
}

#[test]
fn a_startup_block_that_would_draw_a_curve_is_refused_unbuilt() {
    let s = settings();
    let mut g = GcodeState::new();
    refused(&mut g, "$N0=G2 X10 I5", 3);
    refused(&mut g, "$N1=G1 X10", 3);
    assert_eq!(
        run(&mut g, "$N0=G91 G21"),
        Ok(std::vec![Command::StoreStartupLine {
            index: 0,
            line: crate::host::startup::ascii_line(b"G91G21").unwrap()
        }])
    );
    assert_eq!(g.run_startup_block("G2 X10 I5", &s), Err(GrblError::InvalidStatement));
    assert_eq!(g, GcodeState::new(), "nothing kept");
}

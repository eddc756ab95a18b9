//! The builder: exact ends and boxes taken from the curve, the travel, and what the lattice
//! cannot draw.

extern crate std;

use super::*;
use crate::geom::Step;
use crate::motion::interp::{Interpolator, Method};
use proptest::prelude::*;

fn settings() -> Settings {
    Settings::default() // 100 steps/mm, ±200 mm travel, 5 mm jump limit
}

fn ellipse(a_mm: f32, b_mm: f32, start_deg: f32, sweep_deg: f32) -> Request {
    Request::Ellipse(EllipseParams { a_mm, b_mm, start_deg, sweep_deg })
}

fn sine(amplitude_mm: f32, omega_rad_per_mm: f32, length_mm: f32) -> Request {
    Request::Sine(SineParams { amplitude_mm, omega_rad_per_mm, phase_deg: 0.0, length_mm })
}

fn function(text: &str, x0_mm: f32, x1_mm: f32) -> Request {
    Request::Function { expr: crate::motion::expr::parse(text).unwrap(), x0_mm, x1_mm }
}

/// Every lattice point the drawing's own curve visits, from its start.
fn walk(d: &Drawing) -> std::vec::Vec<Point> {
    let mut curve = d.clone().into_curve();
    let mut at = d.start();
    let mut points = std::vec![at];
    while let Some(step) = curve.next_step().expect("a built drawing runs to its end") {
        at = at.stepped(step);
        points.push(at);
    }
    points
}

#[test]
fn the_end_and_the_box_are_the_curves_own() {
    let s = settings();
    let start = Point::new(1234, -567);
    for request in [
        Request::Straight { to: Point::new(-3000, 4000) },
        ellipse(20.0, 20.0, 30.0, 250.0),
        ellipse(30.0, 15.0, 0.0, 360.0),
        sine(10.0, 0.3, 60.0),
        function("sqrt(x)", 0.0, 10.005),
        function("acos(x/20)*5", 0.0, 0.015),
    ] {
        let d = build(&request, start, &s).unwrap().unwrap();
        let points = walk(&d);
        assert_eq!(d.start(), start);
        assert_eq!(d.end(), *points.last().unwrap(), "{request:?}");
        assert_eq!(d.steps(), points.len() as u64 - 1);
        let min = Point::new(points.iter().map(|p| p.x).min().unwrap(), points.iter().map(|p| p.y).min().unwrap());
        let max = Point::new(points.iter().map(|p| p.x).max().unwrap(), points.iter().map(|p| p.y).max().unwrap());
        assert_eq!(d.bounds(), Bounds { min, max }, "{request:?}");
    }
}

#[test]
fn what_leaves_the_travel_is_refused() {
    let s = settings();
    // A circle of radius 150 mm centred 150 mm left of a pen at X 100 mm reaches X −200 mm;
    // from a step further left, one step more.
    let pen = Point::new(9_999, 0);
    assert_eq!(build(&ellipse(150.0, 150.0, 0.0, 360.0), pen, &s), Err(DrawError::Travel));
    assert!(build(&ellipse(150.0, 150.0, 0.0, 360.0), Point::new(10_000, 0), &s).unwrap().is_some());
    // A function that leaves between any samples one might take.
    assert_eq!(build(&function("x^2/2", 0.0, 30.0), Point::ORIGIN, &s), Err(DrawError::Travel));
    assert_eq!(build(&Request::Straight { to: Point::new(0, 20_001) }, Point::ORIGIN, &s), Err(DrawError::Travel));
}

#[test]
fn what_the_lattice_cannot_draw_is_refused() {
    let s = settings();
    // A semi-axis of 0.009 mm is under a step: the reported drives to X −300 mm and a 40 mm
    // back-and-forth line.
    assert_eq!(build(&ellipse(150.0, 0.009, 0.0, -30.0), Point::ORIGIN, &s), Err(DrawError::TooFine));
    assert_eq!(build(&ellipse(20.0, 0.009, 0.0, -30.0), Point::ORIGIN, &s), Err(DrawError::TooFine));
    // ω = 100 rad/mm at 100 steps/mm is a wave every 6.3 steps.
    assert_eq!(build(&sine(5.0, 100.0, 10.0), Point::ORIGIN, &s), Err(DrawError::TooFine));
    // A sine steeper than the jump limit between two columns.
    assert_eq!(build(&sine(100.0, 6.3, 10.0), Point::ORIGIN, &s), Err(DrawError::TooSteep));
    // Shorter than a step: nothing to draw.
    assert_eq!(build(&sine(5.0, 0.1, 0.004), Point::ORIGIN, &s), Ok(None));
}

#[test]
fn a_function_that_changes_faster_than_its_steps_is_refused() {
    let s = settings();
    // A wave of 0.01 mm, one step: its columns are nearly flat, the curve between them is not.
    assert_eq!(build(&function("sin(x*628.3)*3", 0.0, 5.0), Point::ORIGIN, &s), Err(DrawError::TooFine));
    // Two waves a step, and one wave in 0.8 of a step (its columns show a wave four times
    // longer); a wave on a slope, whose columns rise evenly.
    for text in ["sin(x*1256.6)*3", "sin(x*785.4)*3", "x*10+sin(x*628.3)*3"] {
        assert_eq!(build(&function(text, 0.0, 5.0), Point::ORIGIN, &s), Err(DrawError::TooFine), "{text}");
    }
    // Ten and three steps per wave draw, as `$S` draws them (at eight and more), and a
    // wiggle of under a step draws flat.
    for text in ["sin(x*62.83)*3", "sin(x*209.4)*0.3", "x+sin(x*628.3)*0.004"] {
        assert!(build(&function(text, 0.0, 5.0), Point::ORIGIN, &s).unwrap().is_some(), "{text}");
    }
}

#[test]
fn a_function_defined_up_to_its_ends_is_checked_only_within_them() {
    // sqrt(x1 - x) is undefined just past x1: the points evaluated inside the X steps stay
    // within the range, however they round (past 131,072 X steps, here without soft limits,
    // the last one can round to x0 + (x1 - x0), which need not be x1).
    let s = Settings { soft_limits: false, ..settings() };
    for (x0, x1) in [(-0.1f32, 1400.3f32), (0.2, 1500.7), (-3.3, 1313.37), (1400.3, -0.1), (1313.37, -3.3)] {
        let toward_x1 = if x1 > x0 { std::format!("{x1}-x") } else { std::format!("x-{x1}") };
        let f = function(&std::format!("sqrt({toward_x1})"), x0, x1);
        assert!(build(&f, Point::ORIGIN, &s).unwrap().is_some(), "x from {x0} to {x1}");
    }
}

#[test]
fn a_function_too_far_from_zero_for_single_precision_is_refused() {
    let s = settings();
    // At x = 10,000,000 mm f32 numbers are 1 mm apart: 100 steps.
    let far = function("(x-10000000)*4", 10_000_000.0, 10_000_020.0);
    assert_eq!(build(&far, Point::ORIGIN, &s), Err(DrawError::Imprecise));
    // A value of 10,000,000 mm is as coarse.
    assert_eq!(build(&function("10000000+sin(x)", 0.0, 5.0), Point::ORIGIN, &s), Err(DrawError::Imprecise));
    // At x = 1000 mm they are 0.00006 mm apart: it draws, the line of slope 4 it is.
    let near = build(&function("(x-1000)*4", 1000.0, 1020.0), Point::ORIGIN, &s).unwrap().unwrap();
    assert_eq!(near.end(), Point::new(2000, 8000));
    assert_eq!(build(&function("1000+sin(x)", 0.0, 5.0), Point::ORIGIN, &s).map(|d| d.is_some()), Ok(true));
    // The limit: x to 20,971 mm at 100 steps/mm, a quarter step of f32 spacing.
    assert!(build(&function("x-20000", 20_000.0, 20_010.0), Point::ORIGIN, &s).unwrap().is_some());
    assert_eq!(build(&function("x-22000", 22_000.0, 22_010.0), Point::ORIGIN, &s), Err(DrawError::Imprecise));
}

#[test]
fn a_function_that_fails_part_way_is_refused_with_where() {
    let s = settings();
    match build(&function("sqrt(1-x)", 0.0, 2.0), Point::ORIGIN, &s) {
        Err(DrawError::Fails { x_mm, error: CurveError::Domain }) => assert!((x_mm - 1.0).abs() <= 0.011, "{x_mm}"),
        other => panic!("{other:?}"),
    }
    match build(&function("floor(x)*6", 0.0, 10.0), Point::ORIGIN, &s) {
        Err(DrawError::Fails { x_mm, error: CurveError::Jump }) => assert!((x_mm - 1.0).abs() <= 0.011, "{x_mm}"),
        other => panic!("{other:?}"),
    }
}

/// Every step `curve` hands out in batches of `batch` steps, and how it ended.
fn run_out(curve: &mut Curve, start: Point, batch: usize) -> (std::vec::Vec<Point>, Result<(), CurveError>) {
    let mut buf = std::vec![Step::new(0, 0); batch];
    let mut path = std::vec![start];
    loop {
        let filled = curve.fill(&mut buf);
        for step in &buf[..filled.steps] {
            path.push(path.last().unwrap().stepped(*step));
        }
        if let Some(end) = filled.end {
            return (path, end);
        }
    }
}

#[test]
fn the_guard_stops_a_curve_at_the_edge() {
    // Curves set up past the builder (as a defect upstream would) on a ±10 mm travel: each
    // takes the very steps it takes without the limit, up to the last point inside, and stops
    // there, at the edge, with `Travel`, in batches of any size.
    let mut s = settings();
    s.max_travel_mm = [10.0, 10.0];
    let free = Settings { max_travel_mm: [1_000.0, 1_000.0], ..settings() };
    let start = Point::new(300, -200);
    let shapes = [
        Shape::Straight { to: Point::new(5_000, 0) },
        Shape::Straight { to: Point::new(-4_000, -3_000) },
        // 15 mm amplitude: its first crest is 3 mm beyond the edge.
        Shape::Sine { amplitude_steps: 1_500.0, omega_rad_per_step: 0.002, phase_rad: 0.0, length_steps: 1_500 },
        // y = x² rises 2 mm per mm at x = 1: it leaves the top at x ≈ 3.5 mm.
        Shape::Function { expr: crate::motion::expr::parse("x^2").unwrap(), x0_mm: 0.0, x1_mm: 5.0 },
        Shape::Ellipse {
            center: Point::new(300, 0),
            a_steps: 1_600,
            b_steps: 200,
            to: start,
            rotation: Rotation::CounterClockwise,
        },
    ];
    for shape in &shapes {
        let (whole, _) = run_out(&mut Curve::new(shape, start, &free).unwrap(), start, 64);
        let edge = whole.iter().position(|p| p.x.abs() > 1_000 || p.y.abs() > 1_000).unwrap();
        for batch in [1, 7, 700] {
            let mut curve = Curve::new(shape, start, &s).unwrap();
            let (path, end) = run_out(&mut curve, start, batch);
            assert_eq!(end, Err(CurveError::Travel), "{shape:?}");
            assert_eq!(path[..], whole[..edge], "{shape:?} in batches of {batch}");
            let last = *path.last().unwrap();
            assert_eq!(last.x.abs().max(last.y.abs()), 1_000, "{shape:?} stops at the edge");
            assert_eq!(curve.next_step(), Ok(None));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

    /// Random curves of every kind from random pens: whatever is built stays inside the travel,
    /// step by step, and ends where it says.
    #[test]
    fn nothing_built_leaves_the_travel(
        kind in 0..3u8,
        a in 0.001f32..400.0,
        b in 0.001f32..400.0,
        start_deg in -360.0f32..360.0,
        sweep_deg in -360.0f32..360.0,
        omega in 0.0f32..200.0,
        x in -20_000i32..=20_000,
        y in -20_000i32..=20_000,
    ) {
        let mut s = settings();
        s.max_travel_mm = [200.0, 200.0];
        let request = match kind {
            0 => ellipse(a, b, start_deg, if sweep_deg == 0.0 { 360.0 } else { sweep_deg }),
            1 => sine(a.min(300.0), omega, b - 200.0),
            _ => function("x^3/4000", -a.min(100.0), b.min(100.0)),
        };
        let pen = Point::new(x, y);
        if let Ok(Some(d)) = build(&request, pen, &s) {
            let points = walk(&d);
            let [lx, ly] = s.travel_steps();
            for p in &points {
                prop_assert!(p.x.abs() <= lx && p.y.abs() <= ly, "{:?} from {:?} reaches {:?}", request, pen, p);
            }
            prop_assert_eq!(*points.last().unwrap(), d.end());
        }
    }
}

/// Builds `request` from `start` in slices of `slice` steps' worth, handing each slice to `each`
/// with the lattice points it walked.
fn sliced(
    request: &Request,
    start: Point,
    slice: u32,
    mut each: impl FnMut(&Slice, &[Point]),
) -> Result<Option<Drawing>, DrawError> {
    let Some(mut builder) = Builder::new(request, start, &settings())? else { return Ok(None) };
    loop {
        let mut points = std::vec![];
        let s = builder.advance_with(slice, &mut |p| points.push(p));
        each(&s, &points);
        if s.done {
            return builder.finish().map(Some);
        }
    }
}

#[test]
fn slices_build_what_one_go_builds() {
    let start = Point::new(-1234, 567);
    for request in [
        ellipse(20.0, 20.0, 30.0, 250.0),
        ellipse(30.0, 15.0, 0.0, 360.0),
        sine(10.0, 0.3, 60.0),
        function("20*exp(-x^2/200)", -30.0, 30.0),
        function("sqrt(1-x)", 0.0, 2.0),
        ellipse(150.0, 0.009, 0.0, -30.0),
    ] {
        let whole = build(&request, start, &settings());
        for slice in [1, 7, 64, 2048] {
            let mut path = std::vec![start];
            let built = sliced(&request, start, slice, |_, points| path.extend_from_slice(points));
            assert_eq!(built, whole, "{request:?} in slices of {slice}");
            if let Ok(Some(d)) = &built {
                assert_eq!((path.len() as u64 - 1, *path.last().unwrap()), (d.steps(), d.end()));
                assert_eq!(&path, &walk(d), "{request:?}: every lattice point, in order");
            }
        }
    }
}

#[test]
fn a_slice_does_about_as_much_work_whatever_it_walks() {
    // A step is worth one; an X step of a function one more per operation of its expression
    // (as compiled: 6 and 4 here) and evaluation (at the column and between columns), of a sine
    // four more: a slice of `BUILD_SLICE_STEPS` steps' worth walks many steps of a steep curve
    // and few of a flat one.
    let per_op = builder::FUNCTION_EVALUATIONS_PER_X_STEP;
    let cases = [
        (function("20*exp(-x^2/200)", -30.0, 30.0), 6, 6 * per_op),
        (function("sin(x/2)*100", -30.0, 30.0), 4, 4 * per_op),
        (sine(10.0, 0.3, 60.0), 0, 4),
        (ellipse(30.0, 15.0, 0.0, 360.0), 0, 0),
    ];
    for (request, ops, evaluation) in cases {
        let mut slices = 0;
        sliced(&request, Point::ORIGIN, BUILD_SLICE_STEPS, |s, _| {
            slices += 1;
            assert_eq!(u32::from(s.expr_ops), ops, "{request:?}");
            let work = s.steps + s.x_steps * evaluation;
            // The last batch of a slice may reach one step's worth past it.
            assert!(work <= BUILD_SLICE_STEPS + 1 + evaluation, "{request:?}: {s:?}");
            assert!(s.done || work >= BUILD_SLICE_STEPS, "{request:?}: a slice cut short: {s:?}");
            assert!(s.x_steps <= s.steps);
        })
        .unwrap()
        .unwrap();
        assert!(slices > 2, "{request:?}");
    }
}

#[test]
fn a_line_is_checked_from_its_ends_without_a_walk() {
    let s = settings();
    for (to, method, steps) in
        [(Point::new(300, -400), Method::Classic, 700), (Point::new(300, -400), Method::Diagonal, 400)]
    {
        let s = Settings { method, ..s };
        let mut builder = Builder::new(&Request::Straight { to }, Point::ORIGIN, &s).unwrap().unwrap();
        let slice = builder.advance(1);
        assert!(slice.done && slice.steps == 0, "{slice:?}");
        let d = builder.finish().unwrap();
        assert_eq!((d.steps(), d.end()), (steps, to));
        assert_eq!(d.steps(), walk(&d).len() as u64 - 1, "as many steps as its curve takes");
        assert_eq!(d.bounds(), Bounds { min: Point::new(0, -400), max: Point::new(300, 0) });
        // Spent: finishing it again is refused.
        assert!(builder.finish().is_err());
    }
    let beyond = Builder::new(&Request::Straight { to: Point::new(0, 20_001) }, Point::ORIGIN, &s);
    assert_eq!(beyond.unwrap().unwrap().finish().err(), Some(DrawError::Travel));
}

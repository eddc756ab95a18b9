//! The function curve against its ideal in `f64`: shapes, ends, errors on the way (domain,
//! division, jump, travel), tangents and parameters.

extern crate std;
use super::*;
use crate::expr::parse;
use crate::interp::explicit::test_support::*;
use crate::interp::explicit::{RowRange, nearest_step};
use crate::interp::{CurveError, CurveSetupError, Interpolator, Method};
use std::vec::Vec;

const METHODS: [Method; 2] = [Method::Classic, Method::Diagonal];
const ANY: RowRange = RowRange::ANY;

/// Runs `src` over [x0, x1] mm at `spm` steps/mm; returns the walk and the ideal values
/// (steps, relative) at its columns computed by `f`.
fn draw(
    src: &str,
    x0: f64,
    x1: f64,
    spm: f64,
    max_jump: i32,
    method: Method,
    f: impl Fn(f64) -> f64,
) -> (Walk, Vec<f64>, i32) {
    let mut interp = FunctionInterp::new(parse(src).unwrap(), x0, x1, [spm, spm], max_jump, ANY, method).unwrap();
    let n = ((x1 - x0) * spm).round() as i32;
    let dir = if n < 0 { -1 } else { 1 };
    let h: Vec<f64> = (0..=n.abs())
        .map(|k| {
            let x = x0 + (x1 - x0) * k as f64 / n.abs() as f64;
            (f(x) - f(x0)) * spm
        })
        .collect();
    let w = walk(&mut interp, method, 1_000_000);
    assert_eq!(interp.position(), w.last());
    (w, h, dir)
}

#[test]
fn a_parabola_dips_to_its_vertex_and_returns() {
    for method in METHODS {
        // x²/10 on [-10, 10] mm at 20 steps/mm: from (-10, 10) mm down to (0, 0) and up again.
        let (w, h, dir) = draw("x^2/10", -10.0, 10.0, 20.0, 100, method, |x| x * x / 10.0);
        assert_eq!(w.end, Ok(()));
        assert_eq!(w.last(), Point::new(400, 0));
        let lowest = w.path.iter().map(|p| p.y).min();
        assert_eq!(lowest, Some(-200));
        assert!(w.path.contains(&Point::new(200, -200)));
        assert!(max_deviation(&w.path, dir, &h) <= max_deviation_for(method) + FLOAT_SLACK_STEPS);
        assert_meets_every_column(&w.path, dir, &h);
    }
}

#[test]
fn x1_below_x0_draws_toward_minus_x() {
    for method in METHODS {
        let (w, h, dir) = draw("x^2/10", 10.0, -10.0, 20.0, 100, method, |x| x * x / 10.0);
        assert_eq!(dir, -1);
        assert_eq!(w.last(), Point::new(-400, 0));
        assert!(w.path.iter().all(|p| p.x <= 0));
        assert!(w.path.contains(&Point::new(-200, -200)));
        assert!(max_deviation(&w.path, dir, &h) <= max_deviation_for(method) + FLOAT_SLACK_STEPS);
    }
}

#[test]
fn a_square_root_is_followed_up_its_vertical_start() {
    for method in METHODS {
        // sqrt(x) on [0, 4] mm at 10 steps/mm: 40 columns, ends 20 steps up; the first column
        // alone rises 3.16 steps.
        let (w, h, dir) = draw("sqrt(x)", 0.0, 4.0, 10.0, 100, method, libm::sqrt);
        assert_eq!(w.last(), Point::new(40, 20));
        assert!(w.path.contains(&Point::new(1, 3)));
        assert!(w.path.iter().take_while(|p| p.x == 0).count() >= 2, "no climb in the first column");
        assert!(max_deviation(&w.path, dir, &h) <= max_deviation_for(method) + FLOAT_SLACK_STEPS);
        assert_meets_every_column(&w.path, dir, &h);
    }
}

#[test]
fn one_over_x_stops_before_zero() {
    for method in METHODS {
        // Generous jump limit: the curve reaches x = -0.1 mm and fails on the division at 0.
        let mut interp =
            FunctionInterp::new(parse("1/x").unwrap(), -1.0, 1.0, [10.0, 10.0], 1000, ANY, method).unwrap();
        let w = walk(&mut interp, method, 10_000);
        assert_eq!(w.end, Err(CurveError::DivisionByZero));
        // x = -0.1 mm: 1/x - 1/x0 = -10 + 1 = -9 mm.
        assert_eq!(w.last(), Point::new(9, -90));
        assert!(w.path.iter().all(|p| p.x <= 9));
        // A tighter limit stops it earlier, at the first rise of more than 30 steps.
        let mut interp = FunctionInterp::new(parse("1/x").unwrap(), -1.0, 1.0, [10.0, 10.0], 30, ANY, method).unwrap();
        let w = walk(&mut interp, method, 10_000);
        assert_eq!(w.end, Err(CurveError::Jump));
        // -1/0.3 → -1/0.2 falls 16.7 steps; -1/0.2 → -1/0.1 falls 50.
        assert_eq!(w.last(), Point::new(8, -40));
        assert!(w.path.iter().all(|p| p.x <= 8));
    }
}

#[test]
fn tan_stops_at_its_pole_as_a_jump() {
    for method in METHODS {
        // tan(x) on [1, 2] mm at 100 steps/mm: x = 1.57 gives 1255.8 mm, x = 1.58 gives
        // -108.6 mm; a 1000-step jump limit stops it before the pole.
        let mut interp =
            FunctionInterp::new(parse("tan(x)").unwrap(), 1.0, 2.0, [100.0, 100.0], 1000, ANY, method).unwrap();
        let w = walk(&mut interp, method, 1_000_000);
        assert_eq!(w.end, Err(CurveError::Jump));
        let last = w.last();
        assert!(last.x < 57, "reached column {} past tan's steepest", last.x);
        assert!(w.path.iter().all(|p| (1.0 + p.x as f64 / 100.0) < core::f64::consts::FRAC_PI_2));
        let ideal = (libm::tan(1.0 + last.x as f64 / 100.0) - libm::tan(1.0)) * 100.0;
        assert!((last.y as f64 - ideal).abs() <= 0.5 + FLOAT_SLACK_STEPS);
        // Without a jump limit a pole between two columns goes unseen: over [0, π] at one
        // step/mm the columns are 0, π/3, 2π/3 and π, drawn as their polyline. Hence the limit.
        let mut interp = FunctionInterp::new(
            parse("tan(x)").unwrap(),
            0.0,
            core::f64::consts::PI,
            [1.0, 1.0],
            i32::MAX,
            ANY,
            method,
        )
        .unwrap();
        assert_eq!(walk(&mut interp, method, 100_000).end, Ok(()));
        // Started exactly at π/2, the pole is an error and nothing moves.
        let at_pole = FunctionInterp::new(
            parse("tan(x)").unwrap(),
            core::f64::consts::FRAC_PI_2,
            3.0,
            [1.0, 1.0],
            10,
            ANY,
            method,
        );
        assert_eq!(at_pole.err(), Some(CurveSetupError::Start(CurveError::DivisionByZero)));
    }
}

#[test]
fn a_square_root_leaving_its_domain_ends_at_the_edge() {
    for method in METHODS {
        // sqrt(-1-x) is defined for x <= -1: from x = -3 mm it climbs down to x = -1 mm
        // (column 20 at 10 steps/mm) and fails at the next column.
        let mut interp =
            FunctionInterp::new(parse("sqrt(-1-x)").unwrap(), -3.0, 0.0, [10.0, 10.0], 1000, ANY, method).unwrap();
        let w = walk(&mut interp, method, 10_000);
        assert_eq!(w.end, Err(CurveError::Domain));
        assert_eq!(w.last(), Point::new(20, (-libm::sqrt(2.0) * 10.0).round() as i32));
        assert!(w.path.iter().all(|p| p.x <= 20));
        // Started outside the domain, it does not start at all.
        let outside = FunctionInterp::new(parse("sqrt(-1-x)").unwrap(), 0.0, 1.0, [10.0, 10.0], 1000, ANY, method);
        assert_eq!(outside.err(), Some(CurveSetupError::Start(CurveError::Domain)));
    }
}

#[test]
fn a_function_leaving_the_travel_part_way_stops_at_the_last_column_inside() {
    // y = 250·sin²(πx/2) mm on [0, 4] mm at 100 steps/mm, the pen at row 1_000 of a ±20_000-row
    // travel: rows above 19_000 (relative) are outside. The first hump (up to 25_000 rows)
    // passes them, at most 393 rows per column, within the 500-row jump limit.
    let (spm, start_y, limit) = (100.0, 1_000, 20_000);
    let rows = RowRange::within_travel(start_y, limit);
    let row = |k: i32| {
        let s = libm::sin(core::f64::consts::PI * (k as f64 / spm) / 2.0);
        nearest_step(250.0 * s * s * spm)
    };
    let first_out = (0..=400).find(|&k| row(k) > 19_000).unwrap();
    let last_in = first_out - 1;
    for method in METHODS {
        let e = parse("250*sin(pi*x/2)^2").unwrap();
        let mut interp = FunctionInterp::new(e, 0.0, 4.0, [spm, spm], 500, rows, method).unwrap();
        assert_eq!(interp.nominal_end(), Ok(Point::new(400, 0)), "its end is inside");
        let w = walk(&mut interp, method, 1_000_000);
        assert_eq!(w.end, Err(CurveError::Travel));
        assert_eq!(w.last(), Point::new(last_in, row(last_in)));
        assert!(w.path.iter().all(|p| p.x <= last_in), "stepped toward column {first_out}");
        assert!(w.path.iter().all(|p| (start_y + p.y).abs() <= limit), "a step outside the travel");
        // Without the limit it draws both humps to its end.
        let e = parse("250*sin(pi*x/2)^2").unwrap();
        let mut free = FunctionInterp::new(e, 0.0, 4.0, [spm, spm], 500, ANY, method).unwrap();
        assert_eq!(walk(&mut free, method, 1_000_000).end, Ok(()));
    }
}

#[test]
fn a_realistic_expression_is_drawn_end_to_end() {
    let src = "2.5*sin(2*pi*x/40) * exp(-x/100) + 0.1*x";
    let f = |x: f64| 2.5 * libm::sin(2.0 * core::f64::consts::PI * x / 40.0) * libm::exp(-x / 100.0) + 0.1 * x;
    for method in METHODS {
        let (w, h, dir) = draw(src, 0.0, 100.0, 80.0, 400, method, f);
        assert_eq!(w.end, Ok(()));
        assert_eq!(w.last(), Point::new(8000, ((f(100.0) - f(0.0)) * 80.0).round() as i32));
        assert!(max_deviation(&w.path, dir, &h) <= max_deviation_for(method) + FLOAT_SLACK_STEPS);
        assert_meets_every_column(&w.path, dir, &h);
    }
}

#[test]
fn steps_per_mm_differ_per_axis() {
    // y = x/2 on [0, 10] mm at 40 X steps/mm and 100 Y steps/mm: 400 columns, 500 rows.
    let mut interp =
        FunctionInterp::new(parse("x/2").unwrap(), 0.0, 10.0, [40.0, 100.0], 10, ANY, Method::Diagonal).unwrap();
    let w = walk(&mut interp, Method::Diagonal, 10_000);
    assert_eq!(w.last(), Point::new(400, 500));
    assert_eq!(w.steps(), 500);
}

#[test]
fn the_tangent_follows_the_curve_in_the_direction_of_travel() {
    let e = parse("x^2/10").unwrap();
    // At x = -10 mm the slope is 2x/10 = -2.
    let mut fwd = FunctionInterp::new(e.clone(), -10.0, 10.0, [20.0, 20.0], 100, ANY, Method::Diagonal).unwrap();
    let t = fwd.tangent();
    let want = (1.0 / 5f32.sqrt(), -2.0 / 5f32.sqrt());
    assert!((t.x - want.0).abs() < 0.01 && (t.y - want.1).abs() < 0.01, "{t:?}");
    // At the vertex it is level.
    while fwd.position().x < 200 {
        fwd.next_step().unwrap();
    }
    assert!(fwd.tangent().x > 0.999, "{:?}", fwd.tangent());
    // Drawn from x = 10 mm toward -x, the curve falls to the left.
    let back = FunctionInterp::new(e, 10.0, -10.0, [20.0, 20.0], 100, ANY, Method::Classic).unwrap();
    let t = back.tangent();
    assert!((t.x + want.0).abs() < 0.01 && (t.y - want.1).abs() < 0.01, "{t:?}");
}

#[test]
fn bad_parameters_are_refused_and_an_empty_range_takes_no_step() {
    let e = parse("x").unwrap();
    let new = |x0: f64, x1: f64, spm: [f64; 2], jump: i32| {
        FunctionInterp::new(e.clone(), x0, x1, spm, jump, ANY, Method::Diagonal).err()
    };
    assert_eq!(new(f64::NAN, 1.0, [10.0, 10.0], 10), Some(CurveSetupError::BadParameter));
    assert_eq!(new(0.0, f64::INFINITY, [10.0, 10.0], 10), Some(CurveSetupError::BadParameter));
    assert_eq!(new(0.0, 1.0, [0.0, 10.0], 10), Some(CurveSetupError::BadParameter));
    assert_eq!(new(0.0, 1.0, [10.0, -1.0], 10), Some(CurveSetupError::BadParameter));
    assert_eq!(new(0.0, 1.0, [10.0, 10.0], -1), Some(CurveSetupError::BadParameter));
    assert_eq!(new(-1e6, 1e6, [10.0, 10.0], 10), Some(CurveSetupError::OutOfRange));
    let mut empty = FunctionInterp::new(e, 3.0, 3.0, [10.0, 10.0], 10, ANY, Method::Classic).unwrap();
    assert_eq!(empty.next_step(), Ok(None));
}

//! The function curve against its ideal in `f64`: shapes, ends, errors on the way (domain,
//! division, jump, travel), tangents, parameters, the columns' precision along the range,
//! cancellation far from zero, kinks, and `fill` in batches against `next_step`.

extern crate std;
use super::*;
use crate::motion::expr::parse;
use crate::motion::interp::explicit::test_support::*;
use proptest::prelude::*;
use std::vec::Vec;

const METHODS: [Method; 2] = [Method::Classic, Method::Diagonal];

/// Runs `src` over [x0, x1] mm at `spm` steps/mm; returns the walk and the ideal values
/// (steps, relative) at its columns computed by `f`.
fn draw(
    src: &str,
    x0: f32,
    x1: f32,
    spm: f32,
    max_jump: i32,
    method: Method,
    f: impl Fn(f64) -> f64,
) -> (Walk, Vec<f64>, i32) {
    let interp = FunctionInterp::new(parse(src).unwrap(), x0, x1, [spm, spm], max_jump, method).unwrap();
    let (x0, x1, spm) = (f64::from(x0), f64::from(x1), f64::from(spm));
    let n = ((x1 - x0) * spm).round() as i32;
    let dir = if n < 0 { -1 } else { 1 };
    let h: Vec<f64> = (0..=n.abs())
        .map(|k| {
            let x = x0 + (x1 - x0) * k as f64 / n.abs() as f64;
            (f(x) - f(x0)) * spm
        })
        .collect();
    let steps = assert_same_in_batches(&interp, 1_000_000);
    let end = interp.nominal_end();
    let mut interp = interp;
    let w = walk(&mut interp, method, 1_000_000);
    assert_eq!(interp.position(), w.last());
    assert_eq!(steps, w.steps());
    if w.end.is_ok() {
        assert_eq!(end, Ok(w.last()), "the nominal end is where the steps end");
    }
    (w, h, dir)
}

/// The float slack for a function whose values reach `largest_mm` at `spm` steps/mm.
fn slack(largest_mm: f64, spm: f64) -> f64 {
    float_slack_steps(largest_mm * spm)
}

#[test]
fn a_parabola_dips_to_its_vertex_and_returns() {
    for method in METHODS {
        // x²/10 on [-10, 10] mm at 20 steps/mm: from (-10, 10) mm down to (0, 0) and up again.
        let (w, h, dir) = draw("x^2/10", -10.0, 10.0, 20.0, 100, method, |x| x * x / 10.0);
        let slack = slack(10.0, 20.0);
        assert_eq!(w.end, Ok(()));
        assert_eq!(w.last(), Point::new(400, 0));
        let lowest = w.path.iter().map(|p| p.y).min();
        assert_eq!(lowest, Some(-200));
        assert!(w.path.contains(&Point::new(200, -200)));
        assert!(max_deviation(&w.path, dir, &h) <= max_deviation_for(method) + slack);
        assert_meets_every_column(&w.path, dir, &h, slack);
    }
}

#[test]
fn x1_below_x0_draws_toward_minus_x() {
    for method in METHODS {
        let (w, h, dir) = draw("x^2/10", 10.0, -10.0, 20.0, 100, method, |x| x * x / 10.0);
        let slack = slack(10.0, 20.0);
        assert_eq!(dir, -1);
        assert_eq!(w.last(), Point::new(-400, 0));
        assert!(w.path.iter().all(|p| p.x <= 0));
        assert!(w.path.contains(&Point::new(-200, -200)));
        assert!(max_deviation(&w.path, dir, &h) <= max_deviation_for(method) + slack);
    }
}

#[test]
fn a_square_root_is_followed_up_its_vertical_start() {
    for method in METHODS {
        // sqrt(x) on [0, 4] mm at 10 steps/mm: 40 columns, ends 20 steps up; the first column
        // alone rises 3.16 steps.
        let (w, h, dir) = draw("sqrt(x)", 0.0, 4.0, 10.0, 100, method, libm::sqrt);
        let slack = slack(2.0, 10.0);
        assert_eq!(w.last(), Point::new(40, 20));
        assert!(w.path.contains(&Point::new(1, 3)));
        assert!(w.path.iter().take_while(|p| p.x == 0).count() >= 2, "no climb in the first column");
        assert!(max_deviation(&w.path, dir, &h) <= max_deviation_for(method) + slack);
        assert_meets_every_column(&w.path, dir, &h, slack);
    }
}

#[test]
fn one_over_x_stops_before_zero() {
    for method in METHODS {
        // Generous jump limit: the curve reaches x = -0.1 mm and fails on the division at 0.
        let mut interp = FunctionInterp::new(parse("1/x").unwrap(), -1.0, 1.0, [10.0, 10.0], 1000, method).unwrap();
        let w = walk(&mut interp, method, 10_000);
        assert_eq!(w.end, Err(CurveError::DivisionByZero));
        // x = -0.1 mm: 1/x - 1/x0 = -10 + 1 = -9 mm.
        assert_eq!(w.last(), Point::new(9, -90));
        assert!(w.path.iter().all(|p| p.x <= 9));
        // A tighter limit stops it earlier, at the first rise of more than 30 steps.
        let mut interp = FunctionInterp::new(parse("1/x").unwrap(), -1.0, 1.0, [10.0, 10.0], 30, method).unwrap();
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
        let mut interp = FunctionInterp::new(parse("tan(x)").unwrap(), 1.0, 2.0, [100.0, 100.0], 1000, method).unwrap();
        let w = walk(&mut interp, method, 1_000_000);
        assert_eq!(w.end, Err(CurveError::Jump));
        let last = w.last();
        assert!(last.x < 57, "reached column {} past tan's steepest", last.x);
        assert!(w.path.iter().all(|p| (1.0 + p.x as f64 / 100.0) < core::f64::consts::FRAC_PI_2));
        let ideal = (libm::tan(1.0 + last.x as f64 / 100.0) - libm::tan(1.0)) * 100.0;
        assert!((last.y as f64 - ideal).abs() <= 0.5 + slack(1_300.0, 100.0));
        // Without a jump limit a pole between two columns goes unseen: over [0, π] at one
        // step/mm the columns are 0, π/3, 2π/3 and π, drawn as their polyline. Hence the limit.
        let mut interp =
            FunctionInterp::new(parse("tan(x)").unwrap(), 0.0, core::f32::consts::PI, [1.0, 1.0], i32::MAX, method)
                .unwrap();
        assert_eq!(walk(&mut interp, method, 100_000).end, Ok(()));
        // Started exactly at π/2, the pole is an error and nothing moves.
        let at_pole =
            FunctionInterp::new(parse("tan(x)").unwrap(), core::f32::consts::FRAC_PI_2, 3.0, [1.0, 1.0], 10, method);
        assert_eq!(at_pole.err(), Some(CurveSetupError::Start(CurveError::DivisionByZero)));
    }
}

#[test]
fn a_square_root_leaving_its_domain_ends_at_the_edge() {
    for method in METHODS {
        // sqrt(-1-x) is defined for x <= -1: from x = -3 mm it climbs down to x = -1 mm
        // (column 20 at 10 steps/mm) and fails at the next column.
        let mut interp =
            FunctionInterp::new(parse("sqrt(-1-x)").unwrap(), -3.0, 0.0, [10.0, 10.0], 1000, method).unwrap();
        let w = walk(&mut interp, method, 10_000);
        assert_eq!(w.end, Err(CurveError::Domain));
        assert_eq!(w.last(), Point::new(20, (-libm::sqrt(2.0) * 10.0).round() as i32));
        assert!(w.path.iter().all(|p| p.x <= 20));
        // Started outside the domain, it does not start at all.
        let outside = FunctionInterp::new(parse("sqrt(-1-x)").unwrap(), 0.0, 1.0, [10.0, 10.0], 1000, method);
        assert_eq!(outside.err(), Some(CurveSetupError::Start(CurveError::Domain)));
    }
}

#[test]
fn a_realistic_expression_is_drawn_end_to_end() {
    let src = "2.5*sin(2*pi*x/40) * exp(-x/100) + 0.1*x";
    let f = |x: f64| 2.5 * libm::sin(2.0 * core::f64::consts::PI * x / 40.0) * libm::exp(-x / 100.0) + 0.1 * x;
    for method in METHODS {
        let (w, h, dir) = draw(src, 0.0, 100.0, 80.0, 400, method, f);
        let slack = slack(13.0, 80.0);
        assert_eq!(w.end, Ok(()));
        assert_eq!(w.last(), Point::new(8000, ((f(100.0) - f(0.0)) * 80.0).round() as i32));
        assert!(max_deviation(&w.path, dir, &h) <= max_deviation_for(method) + slack);
        assert_meets_every_column(&w.path, dir, &h, slack);
    }
}

#[test]
fn steps_per_mm_differ_per_axis() {
    // y = x/2 on [0, 10] mm at 40 X steps/mm and 100 Y steps/mm: 400 columns, 500 rows.
    let mut interp =
        FunctionInterp::new(parse("x/2").unwrap(), 0.0, 10.0, [40.0, 100.0], 10, Method::Diagonal).unwrap();
    let w = walk(&mut interp, Method::Diagonal, 10_000);
    assert_eq!(w.last(), Point::new(400, 500));
    assert_eq!(w.steps(), 500);
}

#[test]
fn the_tangent_follows_the_curve_in_the_direction_of_travel() {
    let e = parse("x^2/10").unwrap();
    // At x = -10 mm the slope is 2x/10 = -2.
    let mut fwd = FunctionInterp::new(e.clone(), -10.0, 10.0, [20.0, 20.0], 100, Method::Diagonal).unwrap();
    let t = fwd.tangent();
    let want = (1.0 / 5f32.sqrt(), -2.0 / 5f32.sqrt());
    assert!((t.x - want.0).abs() < 0.01 && (t.y - want.1).abs() < 0.01, "{t:?}");
    // At the vertex it is level.
    while fwd.position().x < 200 {
        fwd.next_step().unwrap();
    }
    assert!(fwd.tangent().x > 0.999, "{:?}", fwd.tangent());
    // Drawn from x = 10 mm toward -x, the curve falls to the left.
    let back = FunctionInterp::new(e, 10.0, -10.0, [20.0, 20.0], 100, Method::Classic).unwrap();
    let t = back.tangent();
    assert!((t.x + want.0).abs() < 0.01 && (t.y - want.1).abs() < 0.01, "{t:?}");
}

#[test]
fn bad_parameters_are_refused_and_an_empty_range_takes_no_step() {
    let e = parse("x").unwrap();
    let new = |x0: f32, x1: f32, spm: [f32; 2], jump: i32| {
        FunctionInterp::new(e.clone(), x0, x1, spm, jump, Method::Diagonal).err()
    };
    assert_eq!(new(f32::NAN, 1.0, [10.0, 10.0], 10), Some(CurveSetupError::BadParameter));
    assert_eq!(new(0.0, f32::INFINITY, [10.0, 10.0], 10), Some(CurveSetupError::BadParameter));
    assert_eq!(new(0.0, 1.0, [0.0, 10.0], 10), Some(CurveSetupError::BadParameter));
    assert_eq!(new(0.0, 1.0, [10.0, -1.0], 10), Some(CurveSetupError::BadParameter));
    assert_eq!(new(0.0, 1.0, [10.0, 10.0], -1), Some(CurveSetupError::BadParameter));
    assert_eq!(new(-1e6, 1e6, [10.0, 10.0], 10), Some(CurveSetupError::OutOfRange));
    let mut empty = FunctionInterp::new(e, 3.0, 3.0, [10.0, 10.0], 10, Method::Classic).unwrap();
    assert_eq!(empty.next_step(), Ok(None));
}

#[test]
fn columns_keep_their_precision_along_the_whole_range() {
    // ±250 mm at 200 steps/mm: 100_000 columns. Each is within 2⁻²³·(|x1 - x0| + |x|) of its
    // ideal place, the last as well as the first.
    for (x0, x1, spm) in
        [(-250.0f32, 250.0f32, 200.0f32), (400.0, -100.0, 200.0), (0.1, 0.3, 80.0), (-3.0, 997.0, 100.0)]
    {
        let f = FunctionInterp::new(parse("x").unwrap(), x0, x1, [spm, spm], 10, Method::Diagonal).unwrap();
        let g = &f.curve_fn();
        let n = g.columns;
        assert_eq!(n as f64, ((f64::from(x1) - f64::from(x0)) * f64::from(spm)).abs().round());
        let (x0, x1) = (f64::from(x0), f64::from(x1));
        let bound = |x: f64| ((x1 - x0).abs() + x.abs()) / (1u32 << 23) as f64;
        let mut worst = 0.0f64;
        for k in (0..=n).step_by(7).chain([n - 1, n]) {
            let ideal = x0 + (x1 - x0) * k as f64 / n as f64;
            let error = (f64::from(g.x_mm(k)) - ideal).abs();
            assert!(error <= bound(ideal), "column {k} of {n}: {} for {ideal}", g.x_mm(k));
            worst = worst.max(error / bound(ideal));
        }
        assert_eq!((g.x_mm(0), g.x_mm(n)), (x0 as f32, x1 as f32), "the ends are exact");
        assert!(worst > 0.0 || n < 100, "a suspiciously exact range");
    }
}

#[test]
fn a_curve_far_from_zero_is_drawn_as_near_it() {
    // The same sine 1000 mm up: g(k) - g(0) is taken in millimetres before the scale, so only
    // the values' own rounding (2⁻²⁴·1024 mm, 0.005 step at 80 steps/mm) separates the two.
    for method in METHODS {
        let f = |x: f64| 1000.0 + libm::sin(x);
        let (w, h, dir) = draw("1000 + sin(x)", -10.0, 10.0, 80.0, 100, method, f);
        let slack = slack(1001.0, 80.0);
        assert!(slack < 0.05);
        assert_eq!(w.end, Ok(()));
        assert!(max_deviation(&w.path, dir, &h) <= max_deviation_for(method) + slack);
        assert_meets_every_column(&w.path, dir, &h, slack);
        // Rows differ only where a value lies within that rounding of a half step.
        let (near, ..) = draw("sin(x)", -10.0, 10.0, 80.0, 100, method, libm::sin);
        let far: std::collections::HashSet<Point> = w.path.iter().copied().collect();
        let differ = near.path.iter().filter(|p| !far.contains(p)).count();
        assert!(differ * 50 <= w.path.len(), "{differ} of {} points differ", w.path.len());
    }
}

#[test]
fn a_function_kinks_where_its_slope_jumps_and_fill_stops_there() {
    // |x| turns at x = 0 (column 100 at 10 steps/mm); floor(x) rises a whole millimetre (10
    // rows) in the column before each integer x, so it turns up where that column starts and
    // level again where it ends. Each kink is reached by the last step of a column.
    for method in METHODS {
        for (src, x0, x1, kinks_at) in [
            ("abs(x)", -10.0, 10.0, &[100][..]),
            ("2*abs(x-1)", -2.0, 3.0, &[30]),
            ("floor(x)", 0.5, 4.5, &[4, 5, 14, 15, 24, 25, 34, 35]),
        ] {
            let interp = FunctionInterp::new(parse(src).unwrap(), x0, x1, [10.0, 10.0], 100, method).unwrap();
            let (events, _) = reference(interp.clone(), 100_000);
            let mut at = Point::ORIGIN;
            let mut columns = Vec::new();
            for e in &events {
                match e {
                    Event::Step(s) => at = at.stepped(*s),
                    Event::Kink(_) => columns.push(at.x),
                    Event::End(end) => assert_eq!(*end, Ok(())),
                }
            }
            assert_eq!(columns, kinks_at, "{src} ({method:?})");
            assert_same_in_batches(&interp, 100_000);
            // A buffer larger than the curve stops at the first kink.
            let mut interp = interp;
            let mut buf = [Step::NONE; 1000];
            let filled = interp.fill(&mut buf);
            assert!(filled.kink.is_some() && filled.end.is_none(), "{filled:?}");
            assert_eq!(interp.position().x, kinks_at[0]);
        }
        // A smooth function has none.
        let smooth = FunctionInterp::new(parse("x^2/10").unwrap(), -10.0, 10.0, [20.0, 20.0], 100, method).unwrap();
        let (events, _) = reference(smooth, 100_000);
        assert!(!events.iter().any(|e| matches!(e, Event::Kink(_))));
    }
}

#[test]
fn errors_end_a_batch_where_next_step_meets_them() {
    for method in METHODS {
        for (src, x0, x1, jump) in [
            ("1/x", -1.0, 1.0, 1000),
            ("1/x", -1.0, 1.0, 30),
            ("sqrt(-1-x)", -3.0, 0.0, 1000),
            ("tan(x)", 1.0, 2.0, 1000),
        ] {
            let interp = FunctionInterp::new(parse(src).unwrap(), x0, x1, [10.0, 10.0], jump, method).unwrap();
            assert_same_in_batches(&interp, 100_000);
        }
    }
}

#[test]
fn checked_between_columns_a_function_takes_the_same_steps() {
    for (src, x0, x1) in BATCH_EXPRESSIONS {
        for method in METHODS {
            let interp = FunctionInterp::new(parse(src).unwrap(), x0, x1, [20.0, 20.0], 500, method).unwrap();
            let plain = walk(&mut interp.clone(), method, 1_000_000);
            let checked = walk(&mut interp.check_between_columns(), method, 1_000_000);
            assert_eq!((&checked.path, checked.end), (&plain.path, plain.end), "{src}");
        }
    }
}

#[test]
fn checked_between_columns_a_wave_of_a_step_ends_at_once() {
    // sin(x*628.3)*3 at 100 steps/mm: a wave every step, 300 steps high.
    for method in METHODS {
        let interp = FunctionInterp::new(parse("sin(x*628.3)*3").unwrap(), 0.0, 5.0, [100.0, 100.0], 500, method);
        let plain = walk(&mut interp.clone().unwrap(), method, 1_000_000);
        assert_eq!((plain.end, plain.last().x), (Ok(()), 500), "unchecked, drawn nearly flat");
        assert!(plain.path.iter().all(|p| p.y.abs() <= 30));
        let checked = walk(&mut interp.unwrap().check_between_columns(), method, 1_000_000);
        assert_eq!(checked.end, Err(CurveError::Aliased));
        assert!(checked.last().x <= 3, "ends within a few columns: {:?}", checked.last());
    }
}

#[test]
fn single_precision_error_grows_with_the_numbers_not_the_range() {
    let spm = [100.0, 100.0];
    // 20 mm at x = 10,000,000 mm: 2⁻²³ of it is 1.2 mm, 119 steps.
    let [x, _] = f32_error_steps(10_000_000.0, 10_000_020.0, 0.0, spm);
    assert!((x - 119.2).abs() < 0.1, "{x}");
    // The same range at x = 1000 mm: 0.012 step; from 0, 0.0002.
    let [x, y] = f32_error_steps(1000.0, 1020.0, 80.0, spm);
    assert!(x < 0.013 && x > 0.012 && y < 0.004, "{x} {y}");
    let [x, _] = f32_error_steps(0.0, 20.0, 0.0, spm);
    assert!(x < 0.0005, "{x}");
    // Values of 10,000,000 mm are 2⁻²¹ of it apart at worst: 477 steps.
    let [_, y] = f32_error_steps(0.0, 5.0, 10_000_000.0, spm);
    assert!((y - 476.8).abs() < 0.1, "{y}");
    assert!(
        f32_error_steps(0.0, f32::INFINITY, 0.0, spm)[0].is_nan()
            || f32_error_steps(0.0, f32::INFINITY, 0.0, spm)[0] > F32_ERROR_MAX_STEPS
    );
}

/// Expressions of every kind for the batch property.
const BATCH_EXPRESSIONS: [(&str, f32, f32); 6] = [
    ("20*exp(-x^2/200)", -30.0, 30.0),
    ("x^3/400", -30.0, 30.0),
    ("sin(x)*x/10", 30.0, -30.0),
    ("abs(x)+floor(x/3)", -8.0, 8.0),
    ("sqrt(4-x)", 0.0, 6.0),
    ("3*sin(7*x)", 0.0, 20.0),
];

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// `fill` in random batch sizes, mixed with `next_step`, hands out exactly the steps and
    /// the end of `next_step` alone.
    #[test]
    fn fill_in_random_batches_is_next_step(
        which in 0usize..BATCH_EXPRESSIONS.len(),
        sizes in batch_sizes(),
        spm in 5.0f32..40.0,
        diagonal: bool,
    ) {
        let (src, x0, x1) = BATCH_EXPRESSIONS[which];
        let method = if diagonal { Method::Diagonal } else { Method::Classic };
        let interp = FunctionInterp::new(parse(src).unwrap(), x0, x1, [spm, spm], 500, method).unwrap();
        assert_same_steps_in_batches(&interp, &sizes, 1_000_000);
    }
}

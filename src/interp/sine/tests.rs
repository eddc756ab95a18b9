//! The sine against its ideal in `f64`: the bounds, the exact end, the limits (jump, travel,
//! parameters) and tangents.

extern crate std;
use super::*;
use crate::interp::explicit::test_support::*;
use core::f64::consts::{FRAC_PI_2, PI};
use proptest::prelude::*;
use std::vec::Vec;

const METHODS: [Method; 2] = [Method::Classic, Method::Diagonal];

/// f(x) - f(0) at the columns 0..=|length|, in the direction of travel.
fn ideal(a: f64, omega: f64, phase: f64, length: i32) -> Vec<f64> {
    let dir = if length < 0 { -1.0 } else { 1.0 };
    let f = |x: f64| a * libm::sin(omega * x + phase);
    (0..=length.abs()).map(|k| f(dir * k as f64) - f(0.0)).collect()
}

/// Draws the sine with both methods and checks everything a user would see: neighbour
/// steps, the deviation bound, every column met, the exact end and the number of steps.
fn check_sine(a: f64, omega: f64, phase: f64, length: i32) -> Result<(), TestCaseError> {
    let h = ideal(a, omega, phase, length);
    let dir = if length < 0 { -1 } else { 1 };
    let n = length.abs();
    let rows: Vec<i32> = h.iter().map(|&v| libm::floor(v + 0.5) as i32).collect();
    let rises: Vec<i32> = rows.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    // |A·ω| rows bounds the rise from one column to the next, so this jump limit never stops it.
    let max_jump = libm::ceil(libm::fabs(a * omega)) as i32;
    for method in METHODS {
        let mut sine = SineInterp::new(a, omega, phase, length, max_jump, RowRange::ANY, method).unwrap();
        let end = sine.end();
        let expected_steps: i32 = match method {
            Method::Classic => n + rises.iter().sum::<i32>(),
            Method::Diagonal => rises.iter().map(|&d| d.max(1)).sum(),
        };
        let w = walk(&mut sine, method, expected_steps as usize);
        prop_assert_eq!(w.end, Ok(()));
        prop_assert_eq!(w.last(), end);
        prop_assert_eq!(end.x, length);
        prop_assert!((end.y as f64 - h[n as usize]).abs() <= 0.5 + FLOAT_SLACK_STEPS, "{:?} vs {}", end, h[n as usize]);
        prop_assert_eq!(w.steps(), expected_steps as usize);
        let dev = max_deviation(&w.path, dir, &h);
        prop_assert!(dev <= max_deviation_for(method) + FLOAT_SLACK_STEPS, "{:?} deviates {}", method, dev);
        assert_meets_every_column(&w.path, dir, &h);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// Gentle to very steep (up to 750 steps per column), either direction, any phase.
    #[test]
    fn short_sines_of_any_steepness(a in -500.0f64..500.0, omega in -1.5f64..1.5, phase in -7.0f64..7.0, length in -400i32..400) {
        check_sine(a, omega, phase, length)?;
    }

    /// Long, smooth curves of a few periods.
    #[test]
    fn long_smooth_sines(a in -5_000.0f64..5_000.0, omega in -0.02f64..0.02, phase in -7.0f64..7.0, length in -5_000i32..5_000) {
        check_sine(a, omega, phase, length)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(8))]

    /// The machine's full range: ±100_000 steps long, amplitude up to 100_000 steps, up to
    /// two periods (so that a case stays under a million steps).
    #[test]
    fn machine_sized_sines_do_not_overflow(
        a in -100_000.0f64..100_000.0,
        periods in 0.0f64..2.0,
        phase in -PI..PI,
        length in 90_000i32..=100_000,
        backwards: bool,
    ) {
        let omega = 2.0 * PI * periods / length as f64;
        check_sine(a, omega, phase, if backwards { -length } else { length })?;
    }
}

#[test]
fn one_period_peaks_and_troughs_where_the_sine_does() {
    for method in METHODS {
        // A = 10, one period over 40 steps.
        let mut sine = SineInterp::new(10.0, 2.0 * PI / 40.0, 0.0, 40, i32::MAX, RowRange::ANY, method).unwrap();
        let w = walk(&mut sine, method, 200);
        assert_eq!(w.last(), Point::new(40, 0));
        assert_eq!(w.path.iter().map(|p| p.y).max(), Some(10));
        assert_eq!(w.path.iter().map(|p| p.y).min(), Some(-10));
        assert!(w.path.contains(&Point::new(10, 10)) && w.path.contains(&Point::new(30, -10)));
        // Drawn toward -x it first falls: sin(-ωk) < 0.
        let mut back = SineInterp::new(10.0, 2.0 * PI / 40.0, 0.0, -40, i32::MAX, RowRange::ANY, method).unwrap();
        let w = walk(&mut back, method, 200);
        assert_eq!(w.last(), Point::new(-40, 0));
        assert!(w.path.contains(&Point::new(-10, -10)) && w.path.contains(&Point::new(-30, 10)));
    }
}

#[test]
fn a_sine_steeper_than_the_jump_limit_stops_before_its_first_steep_chord() {
    for method in METHODS {
        // A = 1000 rows, ω = 1 rad/step: the first column is already 841 rows up.
        let mut sine = SineInterp::new(1000.0, 1.0, 0.0, 100, 500, RowRange::ANY, method).unwrap();
        let w = walk(&mut sine, method, 10);
        assert_eq!((w.end, w.steps()), (Err(CurveError::Jump), 0));
        // A = 100 rows, ω = 0.05 rad/step from the crest (phase 90°): level at first, steepest
        // (|A·ω| = 5 rows per column) a quarter period later. A limit of 4 stops it on the way
        // down, at the column before the first rise of 5...
        let (a, omega, phase) = (100.0, 0.05, FRAC_PI_2);
        let rows: Vec<i32> = ideal(a, omega, phase, 200).iter().map(|&v| nearest_step(v)).collect();
        let first = rows.windows(2).position(|w| (w[1] - w[0]).abs() > 4).unwrap();
        let mut sine = SineInterp::new(a, omega, phase, 200, 4, RowRange::ANY, method).unwrap();
        let w = walk(&mut sine, method, 10_000);
        assert_eq!(w.end, Err(CurveError::Jump));
        assert_eq!(w.last(), Point::new(first as i32, rows[first]));
        assert!(w.path.iter().all(|p| p.x <= first as i32));
        // ...and a limit of |A·ω| lets it through.
        let mut sine = SineInterp::new(a, omega, phase, 200, 5, RowRange::ANY, method).unwrap();
        assert_eq!(walk(&mut sine, method, 10_000).end, Ok(()));
        assert_eq!(
            SineInterp::new(a, omega, phase, 200, -1, RowRange::ANY, method).err(),
            Some(CurveSetupError::BadParameter)
        );
    }
}

#[test]
fn a_sine_leaving_the_travel_stops_at_the_last_column_inside() {
    // A = 100 rows, half a period over 200 columns, from a pen at row 50 of a ±120-row
    // travel: rows -170..=70 relative. The crest, 100 rows up, is outside.
    let (start_y, limit) = (50, 120);
    let rows = RowRange::within_travel(start_y, limit);
    let h: Vec<i32> = ideal(100.0, PI / 200.0, 0.0, 200).iter().map(|&v| nearest_step(v)).collect();
    let first_out = h.iter().position(|&r| r > 70).unwrap();
    for method in METHODS {
        let mut sine = SineInterp::new(100.0, PI / 200.0, 0.0, 200, i32::MAX, rows, method).unwrap();
        assert_eq!(sine.end(), Point::new(200, 0), "its end is inside");
        let w = walk(&mut sine, method, 10_000);
        assert_eq!(w.end, Err(CurveError::Travel));
        assert_eq!(w.last(), Point::new(first_out as i32 - 1, h[first_out - 1]));
        assert!(w.path.iter().all(|p| (start_y + p.y).abs() <= limit), "a step outside the travel");
    }
}

#[test]
fn the_curve_starts_at_the_pen_whatever_the_phase() {
    // cos-shaped: f(0) = 5, so the path starts at 0 and falls to -10 at half a period.
    let mut sine = SineInterp::new(5.0, PI / 20.0, FRAC_PI_2, 40, i32::MAX, RowRange::ANY, Method::Diagonal).unwrap();
    let w = walk(&mut sine, Method::Diagonal, 200);
    assert_eq!(w.path[0], Point::ORIGIN);
    assert!(w.path.contains(&Point::new(20, -10)));
    assert_eq!(w.last(), Point::new(40, 0));
    assert!(w.path.iter().all(|p| p.y <= 0));
}

#[test]
fn the_tangent_points_along_the_travel() {
    // A·ω = 1: at the start the curve rises at 45°.
    let sine = SineInterp::new(10.0, 0.1, 0.0, 100, i32::MAX, RowRange::ANY, Method::Diagonal).unwrap();
    let t = sine.tangent();
    let s = core::f32::consts::FRAC_1_SQRT_2;
    assert!((t.x - s).abs() < 0.01 && (t.y - s).abs() < 0.01, "{t:?}");
    // Toward -x it falls to the left.
    let sine = SineInterp::new(10.0, 0.1, 0.0, -100, i32::MAX, RowRange::ANY, Method::Classic).unwrap();
    let t = sine.tangent();
    assert!((t.x + s).abs() < 0.01 && (t.y + s).abs() < 0.01, "{t:?}");
    // At the crest (x = π/2/ω ≈ 15.7) it is level.
    let mut sine = SineInterp::new(10.0, 0.1, 0.0, 100, i32::MAX, RowRange::ANY, Method::Diagonal).unwrap();
    while sine.position().x < 15 {
        sine.next_step().unwrap();
    }
    assert!(sine.tangent().x > 0.99, "{:?}", sine.tangent());
}

#[test]
fn bad_parameters_are_refused_and_length_zero_takes_no_step() {
    let new =
        |a: f64, w: f64, p: f64, l: i32| SineInterp::new(a, w, p, l, i32::MAX, RowRange::ANY, Method::Diagonal).err();
    assert_eq!(new(f64::NAN, 0.1, 0.0, 10), Some(CurveSetupError::BadParameter));
    assert_eq!(new(1.0, f64::INFINITY, 0.0, 10), Some(CurveSetupError::BadParameter));
    assert_eq!(new(1.0, 0.1, f64::NEG_INFINITY, 10), Some(CurveSetupError::BadParameter));
    assert_eq!(new(1.0, 1e308, 0.0, 10), Some(CurveSetupError::BadParameter));
    assert_eq!(new(MAX_SINE_AMPLITUDE_STEPS * 1.01, 0.1, 0.0, 10), Some(CurveSetupError::OutOfRange));
    assert_eq!(new(1.0, 0.1, 0.0, -MAX_CURVE_OFFSET_STEPS - 1), Some(CurveSetupError::OutOfRange));
    for method in METHODS {
        let mut sine = SineInterp::new(100.0, 0.3, 1.0, 0, i32::MAX, RowRange::ANY, method).unwrap();
        assert_eq!(sine.end(), Point::ORIGIN);
        assert_eq!(sine.next_step(), Ok(None));
    }
}

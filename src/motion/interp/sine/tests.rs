//! The sine against its ideal in `f64`: every column within the stated error however far along
//! the curve (the fixed-point phase), the bounds, the exact end, steps and kinks in batches,
//! the limits (jump, travel, parameters), tangents, and the phase conversion itself.

extern crate std;
use super::*;
use crate::motion::interp::explicit::test_support::*;
use core::f64::consts::PI;
use proptest::prelude::*;
use std::vec::Vec;

const METHODS: [Method; 2] = [Method::Classic, Method::Diagonal];

/// Bound on a column value's error per step of amplitude (see the module documentation).
const VALUE_ERROR_PER_AMPLITUDE_STEP: f64 = 1.0 / (1u32 << 21) as f64;

/// f(x) - f(0) at the columns 0..=|length|, in the direction of travel.
fn ideal(a: f64, omega: f64, phase: f64, length: i32) -> Vec<f64> {
    let dir = if length < 0 { -1.0 } else { 1.0 };
    let f = |x: f64| a * libm::sin(omega * x + phase);
    (0..=length.abs()).map(|k| f(dir * k as f64) - f(0.0)).collect()
}

/// The values the sine steps by, as computed.
fn computed(sine: &SineInterp) -> Vec<f64> {
    let n = sine.end().x.abs();
    (0..=n).map(|k| f64::from(sine.curve.offset_steps(k).unwrap())).collect()
}

fn rounded(h: &[f64]) -> Vec<i32> {
    h.iter().map(|&v| libm::floor(v + 0.5) as i32).collect()
}

/// Draws the sine with both methods and checks everything a user would see: neighbour
/// steps, every value within the stated error of the ideal, the deviation bound, every column
/// met, the exact end, the number of steps, and the same steps, kinks and tangents in batches.
fn check_sine(a: f64, omega: f64, phase: f64, length: i32) -> Result<(), TestCaseError> {
    let (a, omega, phase) = (a as f32, omega as f32, phase as f32);
    let h = ideal(f64::from(a), f64::from(omega), f64::from(phase), length);
    let dir = if length < 0 { -1 } else { 1 };
    let n = length.abs();
    // The chain's own rounding (2⁻²³ of values up to 2|A|) besides the values' error.
    let slack = float_slack_steps(2.0 * f64::from(a));
    // What fits the jump limit never stops at a jump.
    let max_jump = libm::ceilf((a * omega).abs() + a.abs() * SINE_RISE_ERROR_PER_AMPLITUDE_STEP) as i32;
    for method in METHODS {
        let sine = SineInterp::new(a, omega, phase, length, max_jump, method).unwrap();
        let used = computed(&sine);
        let error = used.iter().zip(&h).map(|(u, i)| (u - i).abs()).fold(0.0, f64::max);
        prop_assert!(
            error <= f64::from(a).abs() * VALUE_ERROR_PER_AMPLITUDE_STEP + 1e-30,
            "values {} off (A = {})",
            error,
            a
        );
        let rows = rounded(&used);
        let rises: Vec<i32> = rows.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
        let end = sine.end();
        let expected_steps: i32 = match method {
            Method::Classic => n + rises.iter().sum::<i32>(),
            Method::Diagonal => rises.iter().map(|&d| d.max(1)).sum(),
        };
        prop_assert_eq!(assert_same_in_batches(&sine, expected_steps as usize), expected_steps as usize);
        let mut sine = sine;
        let w = walk(&mut sine, method, expected_steps as usize);
        prop_assert_eq!(w.end, Ok(()));
        prop_assert_eq!(w.last(), end);
        prop_assert_eq!(end, Point::new(length, rows[n as usize]));
        prop_assert!((end.y as f64 - h[n as usize]).abs() <= 0.5 + slack, "{:?} vs {}", end, h[n as usize]);
        prop_assert_eq!(w.steps(), expected_steps as usize);
        let dev = max_deviation(&w.path, dir, &h);
        prop_assert!(dev <= max_deviation_for(method) + slack, "{:?} deviates {}", method, dev);
        assert_meets_every_column(&w.path, dir, &h, slack);
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

    /// Hundreds to thousands of radians along ±100_000 steps, from any phase: the last
    /// columns are as exact as the first.
    #[test]
    fn long_fast_sines_stay_exact_to_their_end(
        a in -300.0f64..300.0,
        omega in 0.001f64..0.05,
        phase in -1_000.0f64..1_000.0,
        length in 90_000i32..=100_000,
        backwards: bool,
    ) {
        check_sine(a, omega, phase, if backwards { -length } else { length })?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// `fill` in random batch sizes, mixed with `next_step`, hands out exactly the steps and
    /// the end of `next_step` alone.
    #[test]
    fn fill_in_random_batches_is_next_step(
        a in -2_000.0f32..2_000.0,
        omega in -0.5f32..0.5,
        phase in -7.0f32..7.0,
        length in -3_000i32..3_000,
        max_jump in prop_oneof![Just(i32::MAX), 1i32..200],
        sizes in batch_sizes(),
        diagonal: bool,
    ) {
        let method = if diagonal { Method::Diagonal } else { Method::Classic };
        let sine = SineInterp::new(a, omega, phase, length, max_jump, method).unwrap();
        assert_same_steps_in_batches(&sine, &sizes, 10_000_000);
    }

    /// The phase in fixed point is the angle modulo a turn, to 2⁻⁶² turn for any f32 below
    /// 2²⁴ rad; the sine of it within 1.5e-7 of the true one, at any column.
    #[test]
    fn the_phase_is_exact_at_any_column(
        omega in -3.0f32..3.0,
        phase in -1e4f32..1e4,
        column in 0i32..=MAX_CURVE_OFFSET_STEPS,
    ) {
        for rad in [omega, phase] {
            let turns = turns_q64(rad) as f64 / 18_446_744_073_709_551_616.0;
            let want = (f64::from(rad) / (2.0 * PI)).rem_euclid(1.0);
            let d = (turns - want).abs();
            prop_assert!(d.min(1.0 - d) < 1e-15 * (1.0 + f64::from(rad).abs()), "{} rad: {} turn, not {}", rad, turns, want);
        }
        let f = SineFn { amplitude_steps: 1.0, phase_turns: turns_q64(phase), turns_per_column: turns_q64(omega) };
        let theta = f64::from(phase) + f64::from(omega) * f64::from(column);
        let v = sin_turns(f.turns(column));
        prop_assert!((f64::from(v) - libm::sin(theta)).abs() <= 1.5e-7, "sin {} = {}", theta, v);
    }
}

#[test]
fn the_phase_conversion_covers_every_exponent() {
    for rad in [0.0f32, -0.0, 1e-45, -1e-45, 1e-38, 1e-10, 0.5, 1.0, -1.0, 3.0, 1e5, -1e5, 8_388_607.5, 16_777_216.0] {
        let turns = turns_q64(rad) as f64 / 18_446_744_073_709_551_616.0;
        let want = (f64::from(rad) / (2.0 * PI)).rem_euclid(1.0);
        // The f64 reference itself is good to 1e-16 of the turns.
        let d = (turns - want).abs();
        assert!(d.min(1.0 - d) < 1e-15 * (1.0 + f64::from(rad).abs()), "{rad} rad: {turns} turn, not {want}");
    }
    // Beyond 2²⁴ rad the product needs bits the constant lacks: still a fraction of a turn.
    for rad in [1e10f32, -3e38, f32::MAX] {
        let _ = turns_q64(rad);
    }
    // Quarter turns land on exact quadrants.
    assert_eq!(sin_turns(0), 0.0);
    assert_eq!(sin_turns(1 << 62), 1.0);
    assert_eq!(sin_turns(2 << 62), 0.0);
    assert_eq!(sin_turns(3 << 62), -1.0);
}

#[test]
fn one_period_peaks_and_troughs_where_the_sine_does() {
    use core::f32::consts::PI;
    for method in METHODS {
        // A = 10, one period over 40 steps.
        let mut sine = SineInterp::new(10.0, 2.0 * PI / 40.0, 0.0, 40, i32::MAX, method).unwrap();
        let w = walk(&mut sine, method, 200);
        assert_eq!(w.last(), Point::new(40, 0));
        assert_eq!(w.path.iter().map(|p| p.y).max(), Some(10));
        assert_eq!(w.path.iter().map(|p| p.y).min(), Some(-10));
        assert!(w.path.contains(&Point::new(10, 10)) && w.path.contains(&Point::new(30, -10)));
        // Drawn toward -x it first falls: sin(-ωk) < 0.
        let mut back = SineInterp::new(10.0, 2.0 * PI / 40.0, 0.0, -40, i32::MAX, method).unwrap();
        let w = walk(&mut back, method, 200);
        assert_eq!(w.last(), Point::new(-40, 0));
        assert!(w.path.contains(&Point::new(-10, -10)) && w.path.contains(&Point::new(-30, 10)));
    }
}

#[test]
fn a_sine_steeper_than_the_jump_limit_stops_before_its_first_steep_chord() {
    for method in METHODS {
        // A = 1000 rows, ω = 1 rad/step: the first column is already 841 rows up.
        let mut sine = SineInterp::new(1000.0, 1.0, 0.0, 100, 500, method).unwrap();
        let w = walk(&mut sine, method, 10);
        assert_eq!((w.end, w.steps()), (Err(CurveError::Jump), 0));
        // A = 100 rows, ω = 0.05 rad/step from the crest (phase 90°): level at first, steepest
        // (|A·ω| = 5 rows per column) a quarter period later. A limit of 4 stops it on the way
        // down, at the column before the first rise of 5...
        let (a, omega, phase) = (100.0f32, 0.05f32, core::f32::consts::FRAC_PI_2);
        let rows = rounded(&ideal(f64::from(a), f64::from(omega), f64::from(phase), 200));
        let first = rows.windows(2).position(|w| (w[1] - w[0]).abs() > 4).unwrap();
        let mut sine = SineInterp::new(a, omega, phase, 200, 4, method).unwrap();
        let w = walk(&mut sine, method, 10_000);
        assert_eq!(w.end, Err(CurveError::Jump));
        assert_eq!(w.last(), Point::new(first as i32, rows[first]));
        assert!(w.path.iter().all(|p| p.x <= first as i32));
        // ...and a limit of |A·ω| lets it through.
        let mut sine = SineInterp::new(a, omega, phase, 200, 5, method).unwrap();
        assert_eq!(walk(&mut sine, method, 10_000).end, Ok(()));
        assert_eq!(SineInterp::new(a, omega, phase, 200, -1, method).err(), Some(CurveSetupError::BadParameter));
    }
}

#[test]
fn the_curve_starts_at_the_pen_whatever_the_phase() {
    use core::f32::consts::{FRAC_PI_2, PI};
    // cos-shaped: f(0) = 5, so the path starts at 0 and falls to -10 at half a period.
    let mut sine = SineInterp::new(5.0, PI / 20.0, FRAC_PI_2, 40, i32::MAX, Method::Diagonal).unwrap();
    let w = walk(&mut sine, Method::Diagonal, 200);
    assert_eq!(w.path[0], Point::ORIGIN);
    assert!(w.path.contains(&Point::new(20, -10)));
    assert_eq!(w.last(), Point::new(40, 0));
    assert!(w.path.iter().all(|p| p.y <= 0));
}

#[test]
fn the_tangent_points_along_the_travel() {
    // A·ω = 1: at the start the curve rises at 45°.
    let sine = SineInterp::new(10.0, 0.1, 0.0, 100, i32::MAX, Method::Diagonal).unwrap();
    let t = sine.tangent();
    let s = core::f32::consts::FRAC_1_SQRT_2;
    assert!((t.x - s).abs() < 0.01 && (t.y - s).abs() < 0.01, "{t:?}");
    // Toward -x it falls to the left.
    let sine = SineInterp::new(10.0, 0.1, 0.0, -100, i32::MAX, Method::Classic).unwrap();
    let t = sine.tangent();
    assert!((t.x + s).abs() < 0.01 && (t.y + s).abs() < 0.01, "{t:?}");
    // At the crest (x = π/2/ω ≈ 15.7) it is level.
    let mut sine = SineInterp::new(10.0, 0.1, 0.0, 100, i32::MAX, Method::Diagonal).unwrap();
    while sine.position().x < 15 {
        sine.next_step().unwrap();
    }
    assert!(sine.tangent().x > 0.99, "{:?}", sine.tangent());
}

#[test]
fn a_smooth_sine_has_no_kinks_and_a_sampled_one_does() {
    // Many steps per radian: the chords turn by far less than the kink chord.
    for method in METHODS {
        let sine = SineInterp::new(1_000.0, 0.003, 0.0, 6_000, i32::MAX, method).unwrap();
        let (events, _) = reference(sine.clone(), 100_000);
        assert!(!events.iter().any(|e| matches!(e, Event::Kink(_))));
        assert_same_in_batches(&sine, 100_000);
        // Five columns a period: the chords turn sharply where the sine changes direction,
        // twice a period.
        let sine = SineInterp::new(20.0, 2.0 * core::f32::consts::PI / 5.0, 0.3, 50, i32::MAX, method).unwrap();
        let (events, _) = reference(sine.clone(), 100_000);
        assert!(events.iter().filter(|e| matches!(e, Event::Kink(_))).count() >= 20);
        assert_same_in_batches(&sine, 100_000);
    }
}

#[test]
fn what_fits_the_jump_limit_never_jumps() {
    let settings = crate::settings::Settings::default();
    let limit = jump_limit_steps(settings.max_jump_mm, settings.steps_per_mm[1]);
    // |A·ω| just under the limit fits; exactly at it, the values' error leaves no room.
    assert!(fits_jump_limit(10_000.0, (limit as f32 - 0.1) / 10_000.0, &settings));
    assert!(!fits_jump_limit(10_000.0, limit as f32 / 10_000.0, &settings));
    assert!(!fits_jump_limit(10_000.0, (limit as f32 + 0.1) / 10_000.0, &settings));
    for (a, omega) in [(10_000.0f32, 0.049_99f32), (100.0, 4.999), (400_000.0, 0.001_249), (-250.0, -1.999)] {
        assert!(fits_jump_limit(a, omega, &settings), "{a}·{omega}");
        for method in METHODS {
            let mut sine = SineInterp::new(a, omega, 0.7, 3_000, limit, method).unwrap();
            assert_eq!(walk(&mut sine, method, 100_000_000).end, Ok(()), "{a}·{omega}");
        }
    }
}

#[test]
fn bad_parameters_are_refused_and_length_zero_takes_no_step() {
    let new = |a: f32, w: f32, p: f32, l: i32| SineInterp::new(a, w, p, l, i32::MAX, Method::Diagonal).err();
    assert_eq!(new(f32::NAN, 0.1, 0.0, 10), Some(CurveSetupError::BadParameter));
    assert_eq!(new(1.0, f32::INFINITY, 0.0, 10), Some(CurveSetupError::BadParameter));
    assert_eq!(new(1.0, 0.1, f32::NEG_INFINITY, 10), Some(CurveSetupError::BadParameter));
    assert_eq!(new(1.0, 1e38, 0.0, 10), Some(CurveSetupError::BadParameter));
    assert_eq!(new(MAX_SINE_AMPLITUDE_STEPS * 1.01, 0.1, 0.0, 10), Some(CurveSetupError::OutOfRange));
    assert_eq!(new(1.0, 0.1, 0.0, -MAX_CURVE_OFFSET_STEPS - 1), Some(CurveSetupError::OutOfRange));
    // The largest amplitude reaches exactly the largest offset, and no further.
    assert_eq!(new(MAX_SINE_AMPLITUDE_STEPS, core::f32::consts::PI, -core::f32::consts::FRAC_PI_2, 1), None);
    for method in METHODS {
        let mut sine = SineInterp::new(100.0, 0.3, 1.0, 0, i32::MAX, method).unwrap();
        assert_eq!(sine.end(), Point::ORIGIN);
        assert_eq!(sine.next_step(), Ok(None));
    }
}

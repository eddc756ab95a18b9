//! The chain over sampled values: every column met, the deviation bounds, the exact end, the
//! limits (jump, travel, overflow, failing columns), batches against single steps, kinks, and
//! the precision of the `f32` values up to the machine's full range.

extern crate std;
use super::test_support::*;
use super::*;
use proptest::prelude::*;
use std::vec::Vec;

const METHODS: [Method; 2] = [Method::Classic, Method::Diagonal];

/// Curve values at columns 0..=n: a random walk mixing flat, steep and exactly-half rises,
/// from an arbitrary origin, as `f32` (what a curve's g hands out).
fn sampled_curve() -> impl Strategy<Value = Vec<f32>> {
    let rise = prop_oneof![-1.2f64..1.2, -60.0f64..60.0, (-40i32..40).prop_map(|k| k as f64 + 0.5), Just(0.0),];
    (proptest::collection::vec(rise, 0..80), -5_000.0f64..5_000.0).prop_map(|(rises, origin)| {
        let mut g = Vec::from([origin]);
        for r in rises {
            g.push(g[g.len() - 1] + r);
        }
        g.into_iter().map(|v| v as f32).collect()
    })
}

/// g over samples (steps per unit `scale`), failing with `fail` at column `fail_at`.
#[derive(Clone)]
struct Sampled<'a> {
    g: &'a [f32],
    scale: f32,
    fail_at: Option<(usize, CurveError)>,
}

impl CurveFn for Sampled<'_> {
    fn y(&self, column: i32) -> Result<f32, CurveError> {
        match self.fail_at {
            Some((at, e)) if at == column as usize => Err(e),
            _ => Ok(self.g[column as usize]),
        }
    }

    fn y_steps_per_unit(&self) -> f32 {
        self.scale
    }
}

fn sampled(g: &[f32], fail_at: Option<(usize, CurveError)>) -> Sampled<'_> {
    Sampled { g, scale: 1.0, fail_at }
}

/// h(k) as the curve computes it: the exact value of the `f32` it steps by.
fn computed(g: &[f32], scale: f32) -> Vec<f64> {
    g.iter().map(|&v| f64::from((v - g[0]) * scale)).collect()
}

/// h(k) from the samples exactly.
fn ideal(g: &[f32], scale: f32) -> Vec<f64> {
    g.iter().map(|&v| (f64::from(v) - f64::from(g[0])) * f64::from(scale)).collect()
}

fn rounded(h: &[f64]) -> Vec<i32> {
    h.iter().map(|&v| libm::floor(v + 0.5) as i32).collect()
}

/// The largest |g|, in steps.
fn magnitude(g: &[f32], scale: f32) -> f64 {
    g.iter().map(|&v| f64::from(v).abs() * f64::from(scale).abs()).fold(0.0, f64::max)
}

/// Walks the curve over `g` both ways with both methods and checks what every explicit curve
/// promises: the exact end on the computed values, every column met, the deviation bounds
/// (from the computed and from the ideal values, within `slack`), the number of steps, and
/// the same steps, kinks and tangents in batches.
fn check_curve(g: &[f32], scale: f32, backwards: bool, slack: f64) -> Result<(), TestCaseError> {
    let n = g.len() as i32 - 1;
    let dir = if backwards { -1 } else { 1 };
    let (h, exact) = (computed(g, scale), ideal(g, scale));
    let r = rounded(&h);
    let rises: Vec<i32> = r.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    for method in METHODS {
        let g = Sampled { g, scale, fail_at: None };
        let curve = ExplicitCurve::new(g, dir * n, i32::MAX, method).unwrap();
        prop_assert_eq!(curve.nominal_end(), Ok(Point::new(dir * n, r[n as usize])));
        let steps = assert_same_in_batches(&curve, 10_000_000);
        let mut curve = curve;
        let w = walk(&mut curve, method, 10_000_000);
        prop_assert_eq!(w.end, Ok(()));
        prop_assert_eq!(w.last(), Point::new(dir * n, r[n as usize]));
        prop_assert_eq!(curve.position(), w.last());
        for values in [&h, &exact] {
            assert_meets_every_column(&w.path, dir, values, slack);
            let dev = max_deviation(&w.path, dir, values);
            prop_assert!(dev <= max_deviation_for(method) + slack, "{:?} deviates {}", method, dev);
        }
        let expected_steps: i32 = match method {
            Method::Classic => n + rises.iter().sum::<i32>(),
            Method::Diagonal => rises.iter().map(|&d| d.max(1)).sum(),
        };
        prop_assert_eq!(w.steps(), expected_steps as usize);
        prop_assert_eq!(steps, w.steps());
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn explicit_curves_meet_every_column_stay_close_and_end_exactly(g in sampled_curve(), backwards: bool) {
        check_curve(&g, 1.0, backwards, float_slack_steps(magnitude(&g, 1.0)))?;
    }

    #[test]
    fn a_jump_ends_the_curve_before_any_of_its_steps(g in sampled_curve(), max_jump in 0i32..30, backwards: bool) {
        let n = g.len() as i32 - 1;
        let dir = if backwards { -1 } else { 1 };
        let r = rounded(&computed(&g, 1.0));
        let first_jump = r.windows(2).position(|w| (w[1] - w[0]).abs() > max_jump);
        for method in METHODS {
            let mut curve = ExplicitCurve::new(sampled(&g, None), dir * n, max_jump, method).unwrap();
            let w = walk(&mut curve, method, 100_000);
            match first_jump {
                None => prop_assert_eq!(w.last(), Point::new(dir * n, r[n as usize])),
                Some(k) => {
                    prop_assert_eq!(w.end, Err(CurveError::Jump));
                    prop_assert_eq!(w.last(), Point::new(dir * k as i32, r[k]));
                    prop_assert!(w.path.iter().all(|p| p.x * dir <= k as i32), "stepped into the jump");
                }
            }
        }
    }

    #[test]
    fn a_failing_column_ends_the_curve_at_the_column_before(g in sampled_curve(), at in 0usize..80, which in 0usize..3) {
        let n = g.len() - 1;
        let at = at % (n + 1);
        let err = [CurveError::Domain, CurveError::DivisionByZero, CurveError::Overflow][which];
        let r = rounded(&computed(&g, 1.0));
        for method in METHODS {
            match ExplicitCurve::new(sampled(&g, Some((at, err))), n as i32, i32::MAX, method) {
                Err(e) => prop_assert_eq!((e, at), (CurveSetupError::Start(err), 0)),
                Ok(mut curve) => {
                    assert_same_in_batches(&curve, 100_000);
                    let w = walk(&mut curve, method, 100_000);
                    prop_assert_eq!(w.end, Err(err));
                    prop_assert_eq!(w.last(), Point::new(at as i32 - 1, r[at - 1]));
                    prop_assert!(w.path.iter().all(|p| (p.x as usize) < at));
                }
            }
        }
    }
}

/// Values at the machine's full range: a random walk from anywhere within ±100_000 steps,
/// rising up to 300 rows a column, so that the values reach ±130_000 steps.
fn machine_sized_curve() -> impl Strategy<Value = Vec<f32>> {
    let rise = prop_oneof![-1.2f64..1.2, -300.0f64..300.0];
    (proptest::collection::vec(rise, 1..100), -100_000.0f64..100_000.0).prop_map(|(rises, origin)| {
        let mut g = Vec::from([origin]);
        for r in rises {
            g.push(g[g.len() - 1] + r);
        }
        g.into_iter().map(|v| v as f32).collect()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Far from zero the `f32` values are 1/128 step apart: the bounds hold within the stated
    /// slack (0.06 step at 130_000).
    #[test]
    fn machine_sized_values_keep_the_bounds_within_the_float_slack(g in machine_sized_curve(), backwards: bool) {
        check_curve(&g, 1.0, backwards, float_slack_steps(magnitude(&g, 1.0)))?;
    }
}

/// One rounding relative to h: 2⁻²³.
const H_RELATIVE_SLACK: f64 = 1.0 / (1u32 << 23) as f64;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// A small curve far from zero in its own unit (millimetres at 80 steps/mm, 100_000 steps
    /// from zero): g is subtracted before the scale, so nothing is lost to the cancellation and
    /// the curve is as exact as a curve near zero.
    #[test]
    fn a_curve_far_from_zero_loses_nothing_to_cancellation(
        wiggle in proptest::collection::vec(-0.1f64..0.1, 1..200),
        backwards: bool,
    ) {
        let g: Vec<f32> = wiggle.iter().scan(1_250.0f64, |y, d| { *y += d; Some(*y as f32) }).collect();
        let largest = computed(&g, 80.0).iter().fold(0.0f64, |m, h| m.max(h.abs()));
        check_curve(&g, 80.0, backwards, FLOAT_SLACK_MIN_STEPS + largest * H_RELATIVE_SLACK)?;
    }
}

#[test]
fn rounding_to_rows_is_exact_with_ties_toward_plus_y() {
    for (h, r) in [
        (0.0, 0),
        (0.5, 1),
        (-0.5, 0),
        (0.499_999_97, 0),
        (-0.500_000_06, -1),
        (1.5, 2),
        (-1.5, -1),
        (2.499_999_8, 2),
        (-2.5, -2),
        (99_999.5, 100_000),
        (-99_999.5, -99_999),
        (99_999.49, 99_999),
        (1_000_000.0, 1_000_000),
        (-1_000_000.0, -1_000_000),
        (-999_999.5, -999_999),
    ] {
        assert_eq!(nearest_step(h), r, "{h}");
        assert_eq!(f64::from(r), libm::floor(f64::from(h) + 0.5), "{h}");
    }
    for h in [-3.0f32, -2.75, -0.25, -1e-30, 0.0, 1e-30, 0.75, 7.0] {
        assert_eq!(floor_steps(h) as f32, libm::floorf(h), "{h}");
    }
}

#[test]
fn the_jump_limit_is_at_least_one_row() {
    // The jump limit: `$204` in rows, at least one.
    assert_eq!(jump_limit_steps(5.0, 100.0), 500);
    assert_eq!(jump_limit_steps(0.001, 100.0), 1);
    assert_eq!(jump_limit_steps(0.0, 100.0), 1);
}

#[test]
fn a_steep_rise_advances_x_halfway_up() {
    // One column rising four rows: the chord (0,0)-(1,4) crosses the middle at row 2.
    let g = [0.0, 4.0];
    let mut diagonal = ExplicitCurve::new(sampled(&g, None), 1, i32::MAX, Method::Diagonal).unwrap();
    let w = walk(&mut diagonal, Method::Diagonal, 10);
    let pts = |v: &[(i32, i32)]| v.iter().map(|&(x, y)| Point::new(x, y)).collect::<Vec<_>>();
    assert_eq!(w.path, pts(&[(0, 0), (0, 1), (1, 2), (1, 3), (1, 4)]));
    // Classic goes through the corner nearer to the chord: up two, across, up two.
    let mut classic = ExplicitCurve::new(sampled(&g, None), 1, i32::MAX, Method::Classic).unwrap();
    let w = walk(&mut classic, Method::Classic, 10);
    assert_eq!(w.path, pts(&[(0, 0), (0, 1), (0, 2), (1, 2), (1, 3), (1, 4)]));
    // Falling, toward -x: the same, mirrored.
    let g = [0.0, -4.0];
    let mut diagonal = ExplicitCurve::new(sampled(&g, None), -1, i32::MAX, Method::Diagonal).unwrap();
    let w = walk(&mut diagonal, Method::Diagonal, 10);
    assert_eq!(w.path, pts(&[(0, 0), (0, -1), (-1, -2), (-1, -3), (-1, -4)]));
}

#[test]
fn values_beyond_the_machine_overflow_and_bad_parameters_are_refused() {
    let g = [0.0, 10.0, 2e6];
    for method in METHODS {
        let mut curve = ExplicitCurve::new(sampled(&g, None), 2, i32::MAX, method).unwrap();
        let w = walk(&mut curve, method, 100);
        assert_eq!((w.end, w.last()), (Err(CurveError::Overflow), Point::new(1, 10)));
        let f = |_| Ok(0.0);
        assert_eq!(ExplicitCurve::new(f, 10, -1, method).err(), Some(CurveSetupError::BadParameter));
        assert_eq!(
            ExplicitCurve::new(f, MAX_CURVE_OFFSET_STEPS + 1, 0, method).err(),
            Some(CurveSetupError::OutOfRange)
        );
        assert_eq!(ExplicitCurve::new(f, i32::MIN, 0, method).err(), Some(CurveSetupError::OutOfRange));
        let nan = |_| Ok(f32::NAN);
        assert_eq!(ExplicitCurve::new(nan, 10, 0, method).err(), Some(CurveSetupError::Start(CurveError::Overflow)));
        let infinite_scale = Sampled { g: &g, scale: f32::INFINITY, fail_at: None };
        assert_eq!(ExplicitCurve::new(infinite_scale, 2, 0, method).err(), Some(CurveSetupError::BadParameter));
    }
}

#[test]
fn a_kink_ends_a_batch_right_after_the_step_that_reaches_it() {
    // |x - 5| over ten columns: down one row a column, then up, the turn at column 5.
    let g: Vec<f32> = (0..=10).map(|k: i32| (k - 5).abs() as f32).collect();
    for method in METHODS {
        let mut curve = ExplicitCurve::new(sampled(&g, None), 10, i32::MAX, method).unwrap();
        let before = curve.tangent();
        let mut buf = [Step::NONE; 64];
        let filled = curve.fill(&mut buf);
        let s = core::f32::consts::FRAC_1_SQRT_2;
        assert!((before.x - s).abs() < 1e-6 && (before.y + s).abs() < 1e-6, "{before:?}");
        assert_eq!(filled, Filled::kink(filled.steps, before));
        assert_eq!(curve.position(), Point::new(5, -5), "stopped where the direction turns");
        let after = curve.tangent();
        assert!((after.x - s).abs() < 1e-6 && (after.y - s).abs() < 1e-6, "{after:?}");
        // Then on to the end without another kink.
        let rest = curve.fill(&mut buf);
        assert_eq!(rest.end, Some(Ok(())));
        assert_eq!(curve.position(), Point::new(10, 0));
    }
    // A gentle bend is no kink: slopes 0.05 apart turn by less than the chord.
    let g: Vec<f32> = (0..=40).map(|k: i32| 0.025 * (k * k) as f32).collect();
    for method in METHODS {
        let mut curve = ExplicitCurve::new(sampled(&g, None), 40, i32::MAX, method).unwrap();
        let mut buf = [Step::NONE; 500];
        let filled = curve.fill(&mut buf);
        assert_eq!(filled.end, Some(Ok(())));
        assert_eq!(filled.kink, None);
    }
}

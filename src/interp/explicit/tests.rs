//! The chain over sampled values: every column met, the deviation bounds, the exact end, and
//! the limits (jump, travel, overflow, failing columns).

extern crate std;
use super::test_support::*;
use super::*;
use proptest::prelude::*;
use std::vec::Vec;

const METHODS: [Method; 2] = [Method::Classic, Method::Diagonal];
const ANY: RowRange = RowRange::ANY;

/// Curve values at columns 0..=n: a random walk mixing flat, steep and exactly-half rises,
/// from an arbitrary origin.
fn sampled_curve() -> impl Strategy<Value = Vec<f64>> {
    let rise = prop_oneof![-1.2f64..1.2, -60.0f64..60.0, (-40i32..40).prop_map(|k| k as f64 + 0.5), Just(0.0),];
    (proptest::collection::vec(rise, 0..80), -5_000.0f64..5_000.0).prop_map(|(rises, origin)| {
        let mut g = Vec::from([origin]);
        for r in rises {
            g.push(g[g.len() - 1] + r);
        }
        g
    })
}

/// The core over samples `g` (absolute values), failing with `fail` at column `fail_at`.
fn sampled(g: &[f64], fail_at: Option<(usize, CurveError)>) -> impl Fn(i32) -> Result<f64, CurveError> + '_ {
    move |c| match fail_at {
        Some((at, e)) if at == c as usize => Err(e),
        _ => Ok(g[c as usize]),
    }
}

fn relative(g: &[f64]) -> Vec<f64> {
    g.iter().map(|v| v - g[0]).collect()
}

fn rounded(h: &[f64]) -> Vec<i32> {
    h.iter().map(|&v| libm::floor(v + 0.5) as i32).collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn explicit_curves_meet_every_column_stay_close_and_end_exactly(g in sampled_curve(), backwards: bool) {
        let n = g.len() as i32 - 1;
        let dir = if backwards { -1 } else { 1 };
        let h = relative(&g);
        let r = rounded(&h);
        let rises: Vec<i32> = r.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
        for method in METHODS {
            let mut curve = ExplicitCurve::new(sampled(&g, None), dir * n, i32::MAX, ANY, method).unwrap();
            let w = walk(&mut curve, method, 100_000);
            prop_assert_eq!(w.end, Ok(()));
            prop_assert_eq!(w.last(), Point::new(dir * n, r[n as usize]));
            prop_assert_eq!(curve.position(), w.last());
            assert_meets_every_column(&w.path, dir, &h);
            let dev = max_deviation(&w.path, dir, &h);
            prop_assert!(dev <= max_deviation_for(method) + FLOAT_SLACK_STEPS, "{:?} deviates {}", method, dev);
            let expected_steps: i32 = match method {
                Method::Classic => n + rises.iter().sum::<i32>(),
                Method::Diagonal => rises.iter().map(|&d| d.max(1)).sum(),
            };
            prop_assert_eq!(w.steps(), expected_steps as usize);
        }
    }

    #[test]
    fn a_jump_ends_the_curve_before_any_of_its_steps(g in sampled_curve(), max_jump in 0i32..30, backwards: bool) {
        let n = g.len() as i32 - 1;
        let dir = if backwards { -1 } else { 1 };
        let r = rounded(&relative(&g));
        let first_jump = r.windows(2).position(|w| (w[1] - w[0]).abs() > max_jump);
        for method in METHODS {
            let mut curve = ExplicitCurve::new(sampled(&g, None), dir * n, max_jump, ANY, method).unwrap();
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
        let r = rounded(&relative(&g));
        for method in METHODS {
            match ExplicitCurve::new(sampled(&g, Some((at, err))), n as i32, i32::MAX, ANY, method) {
                Err(e) => prop_assert_eq!((e, at), (CurveSetupError::Start(err), 0)),
                Ok(mut curve) => {
                    let w = walk(&mut curve, method, 100_000);
                    prop_assert_eq!(w.end, Err(err));
                    prop_assert_eq!(w.last(), Point::new(at as i32 - 1, r[at - 1]));
                    prop_assert!(w.path.iter().all(|p| (p.x as usize) < at));
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// No step ever leaves the rows: the curve ends, with the first error met (a jump is
    /// reported before the travel), at the last column before the first column that jumps
    /// or lies outside them.
    #[test]
    fn a_column_outside_the_rows_ends_the_curve_at_the_last_column_inside(
        g in sampled_curve(),
        below in 0i32..300,
        above in 0i32..300,
        max_jump in prop_oneof![Just(i32::MAX), 0i32..30],
        backwards: bool,
    ) {
        let n = g.len() as i32 - 1;
        let dir = if backwards { -1 } else { 1 };
        let r = rounded(&relative(&g));
        let rows = RowRange { min: -below, max: above };
        let jumps = |k: usize| (r[k] - r[k - 1]).abs() > max_jump;
        let first = (1..r.len()).find(|&k| jumps(k) || !rows.contains(r[k]));
        for method in METHODS {
            let mut curve = ExplicitCurve::new(sampled(&g, None), dir * n, max_jump, rows, method).unwrap();
            let w = walk(&mut curve, method, 100_000);
            prop_assert!(w.path.iter().all(|p| rows.contains(p.y)), "a step outside {:?}", rows);
            match first {
                None => prop_assert_eq!((w.end, w.last()), (Ok(()), Point::new(dir * n, r[n as usize]))),
                Some(k) => {
                    let error = if jumps(k) { CurveError::Jump } else { CurveError::Travel };
                    prop_assert_eq!(w.end, Err(error));
                    prop_assert_eq!(w.last(), Point::new(dir * (k as i32 - 1), r[k - 1]));
                    prop_assert!(w.path.iter().all(|p| p.x * dir < k as i32), "stepped toward column {}", k);
                }
            }
        }
    }
}

#[test]
fn the_row_range_is_the_travel_seen_from_the_start() {
    assert_eq!(RowRange::within_travel(0, 20_000), RowRange { min: -20_000, max: 20_000 });
    assert_eq!(RowRange::within_travel(5_000, 20_000), RowRange { min: -25_000, max: 15_000 });
    assert_eq!(RowRange::within_travel(-20_000, 20_000), RowRange { min: 0, max: 40_000 });
    // Beyond i32: clamped, never wrapped.
    assert_eq!(RowRange::within_travel(i32::MIN, i32::MAX), RowRange { min: 1, max: i32::MAX });
    // A start outside the travel: only the rows back inside.
    assert_eq!(RowRange::within_travel(20_005, 20_000), RowRange { min: -40_005, max: -5 });
    assert!(!RowRange::within_travel(0, -1).contains(0));
    assert!(RowRange::ANY.contains(i32::MIN) && RowRange::ANY.contains(i32::MAX));
    // The jump limit: `$204` in rows, at least one.
    assert_eq!(jump_limit_steps(5.0, 100.0), 500);
    assert_eq!(jump_limit_steps(0.001, 100.0), 1);
    assert_eq!(jump_limit_steps(0.0, 100.0), 1);
}

#[test]
fn a_steep_rise_advances_x_halfway_up() {
    // One column rising four rows: the chord (0,0)-(1,4) crosses the middle at row 2.
    let g = [0.0, 4.0];
    let mut diagonal = ExplicitCurve::new(sampled(&g, None), 1, i32::MAX, ANY, Method::Diagonal).unwrap();
    let w = walk(&mut diagonal, Method::Diagonal, 10);
    let pts = |v: &[(i32, i32)]| v.iter().map(|&(x, y)| Point::new(x, y)).collect::<Vec<_>>();
    assert_eq!(w.path, pts(&[(0, 0), (0, 1), (1, 2), (1, 3), (1, 4)]));
    // Classic goes through the corner nearer to the chord: up two, across, up two.
    let mut classic = ExplicitCurve::new(sampled(&g, None), 1, i32::MAX, ANY, Method::Classic).unwrap();
    let w = walk(&mut classic, Method::Classic, 10);
    assert_eq!(w.path, pts(&[(0, 0), (0, 1), (0, 2), (1, 2), (1, 3), (1, 4)]));
}

#[test]
fn values_beyond_the_machine_overflow_and_bad_parameters_are_refused() {
    let g = [0.0, 10.0, 2e6];
    for method in METHODS {
        let mut curve = ExplicitCurve::new(sampled(&g, None), 2, i32::MAX, ANY, method).unwrap();
        let w = walk(&mut curve, method, 100);
        assert_eq!((w.end, w.last()), (Err(CurveError::Overflow), Point::new(1, 10)));
        let f = |_| Ok(0.0);
        assert_eq!(ExplicitCurve::new(f, 10, -1, ANY, method).err(), Some(CurveSetupError::BadParameter));
        assert_eq!(
            ExplicitCurve::new(f, MAX_CURVE_OFFSET_STEPS + 1, 0, ANY, method).err(),
            Some(CurveSetupError::OutOfRange)
        );
        assert_eq!(ExplicitCurve::new(f, i32::MIN, 0, ANY, method).err(), Some(CurveSetupError::OutOfRange));
        let nan = |_| Ok(f64::NAN);
        assert_eq!(
            ExplicitCurve::new(nan, 10, 0, ANY, method).err(),
            Some(CurveSetupError::Start(CurveError::Overflow))
        );
    }
}

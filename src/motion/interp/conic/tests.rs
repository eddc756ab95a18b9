//! Quiet runs against the rules: [`Tracer::fill`] and [`Tracer::next_step`], in any mix and
//! whatever the batch sizes, must hand out exactly the steps [`Tracer::step`] takes alone
//! (which never runs), with the same tangents and the same `F` between them, on every kind of
//! trace.

extern crate std;
use super::*;
use crate::geom::Point;
use crate::motion::interp::arc::ArcInterp;
use crate::motion::interp::ellipse::{EllipseInterp, MAX_ELLIPSE_AXIS_STEPS};
use crate::motion::interp::{Interpolator, Method};
use Method::{Classic, Diagonal};
use Rotation::{Clockwise as Cw, CounterClockwise as Ccw};
use proptest::prelude::*;
use std::vec::Vec;

/// Steps of the rules alone (no quiet runs), and the tangent before each.
fn by_the_rules(mut tracer: Tracer, cap: usize) -> (Vec<Step>, Vec<Tangent>) {
    let (mut steps, mut tangents) = (Vec::new(), Vec::new());
    loop {
        tangents.push(tracer.tangent());
        match tracer.step() {
            Some(s) => steps.push(s),
            None => break,
        }
        assert!(steps.len() <= cap, "no end after {cap} steps");
    }
    (steps, tangents)
}

/// Steps of `curve` taken through `fill` in batches of the sizes `sizes` gives in turn (0
/// included), one step through `next_step` wherever `sizes` says `ONE_BY_NEXT_STEP`; checks
/// the tangent before each against `tangents` and the `F` the curve reports against `fs`.
fn in_batches<I: Interpolator>(
    mut curve: I,
    f: impl Fn(&I) -> i64,
    sizes: &[usize],
    cap: usize,
    tangents: &[Tangent],
    fs: &[i64],
) -> Vec<Step> {
    let mut buf = [Step::NONE; 64];
    let mut steps = Vec::new();
    for k in 0.. {
        let at = steps.len();
        assert_eq!(curve.tangent(), tangents[at.min(tangents.len() - 1)], "tangent before step {at}");
        assert_eq!(f(&curve), fs[at.min(fs.len() - 1)], "F before step {at}");
        let size = sizes[k % sizes.len()];
        if size == ONE_BY_NEXT_STEP {
            match curve.next_step() {
                Ok(Some(s)) => steps.push(s),
                Ok(None) => break,
                Err(e) => panic!("{e:?}"),
            }
            continue;
        }
        let n = size.min(buf.len());
        let filled = curve.fill(&mut buf[..n]);
        assert!(filled.steps <= n);
        steps.extend_from_slice(&buf[..filled.steps]);
        match filled.end {
            None => assert_eq!(filled.steps, n, "a batch short of its end"),
            Some(Ok(())) => break,
            Some(Err(e)) => panic!("{e:?}"),
        }
        assert!(steps.len() <= cap, "no end after {cap} steps");
    }
    // Ended for good.
    assert_eq!(curve.fill(&mut buf[..4]), Filled::ended(0, Ok(())));
    assert_eq!(curve.next_step(), Ok(None));
    steps
}

/// In a list of batch sizes: one step through `next_step` instead of `fill`.
const ONE_BY_NEXT_STEP: usize = usize::MAX;

/// The steps and tangents of the rules alone, and `F` before each step.
fn reference(tracer: &Tracer, cap: usize) -> (Vec<Step>, Vec<Tangent>, Vec<i64>) {
    let mut t = tracer.clone();
    let mut fs = std::vec![t.discriminant()];
    let (steps, tangents) = by_the_rules(tracer.clone(), cap);
    for _ in &steps {
        t.step();
        fs.push(t.discriminant());
    }
    (steps, tangents, fs)
}

/// Batches, `next_step` and the rules alone agree: steps, tangents and `F`.
fn check_same<I: Interpolator + Clone>(curve: I, tracer: impl Fn(&I) -> &Tracer, sizes: &[usize], cap: usize) -> usize {
    let (steps, tangents, fs) = reference(tracer(&curve), cap);
    let f = |c: &I| tracer(c).discriminant();
    for sizes in [sizes, &[ONE_BY_NEXT_STEP][..]] {
        let batched = in_batches(curve.clone(), f, sizes, cap, &tangents, &fs);
        if let Some(i) = (0..steps.len().min(batched.len())).find(|&i| steps[i] != batched[i]) {
            panic!("step {i} of {}: by the rules {:?}, in batches {:?} ({sizes:?})", steps.len(), steps[i], batched[i]);
        }
        assert_eq!(batched.len(), steps.len(), "different lengths ({sizes:?})");
    }
    steps.len()
}

fn arc(a: &ArcInterp) -> &Tracer {
    a.tracer()
}

fn ellipse(e: &EllipseInterp) -> &Tracer {
    e.tracer()
}

const SIZES: [&[usize]; 4] = [&[16], &[1], &[64], &[3, 0, 7, ONE_BY_NEXT_STEP, 16, 5, 2, 64, ONE_BY_NEXT_STEP, 13]];

#[test]
fn textbook_and_tip_cases_are_the_same_in_batches() {
    for sizes in SIZES {
        for method in [Classic, Diagonal] {
            for rotation in [Ccw, Cw] {
                // Full circles from each axis, off the axes, of radius 1 to 40.
                for r in 1..=40 {
                    for s in [Point::new(r, 0), Point::new(0, -r), Point::new(r / 2 + 1, r / 3 - 2)] {
                        let arc = ArcInterp::new(s, Point::ORIGIN, s, rotation, method).unwrap();
                        check_same(arc, self::arc, sizes, 100_000);
                    }
                }
                // Thin and flat ellipses, whose tips are climbed, and ordinary ones.
                for (a, b) in [(2, 50), (50, 2), (1, 300), (300, 1), (5, 3), (40, 39), (250, 120)] {
                    let s = Point::new(a, 0);
                    let e = EllipseInterp::new(s, Point::ORIGIN, a, b, s, rotation, method).unwrap();
                    check_same(e, ellipse, sizes, 100_000);
                    let e = EllipseInterp::new(s, Point::ORIGIN, a, b, Point::new(-a, 0), rotation, method).unwrap();
                    check_same(e, ellipse, sizes, 100_000);
                }
            }
        }
    }
}

#[test]
fn the_largest_curves_are_the_same_in_batches() {
    let m = MAX_ELLIPSE_AXIS_STEPS;
    let sizes: &[usize] = &[16, 5, 64];
    for method in [Classic, Diagonal] {
        let s = Point::new(100_000, 0);
        check_same(ArcInterp::new(s, Point::ORIGIN, s, Ccw, method).unwrap(), arc, sizes, 1_000_000);
        let e = EllipseInterp::new(Point::new(m, 0), Point::ORIGIN, m, m - 1, Point::new(0, -m + 2), Cw, method);
        check_same(e.unwrap(), ellipse, sizes, 3_000_000);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, failure_persistence: None, ..ProptestConfig::default() })]

    /// Random arcs, ends anywhere within the tolerance, random batch sizes.
    #[test]
    fn random_arcs_are_the_same_in_batches(
        sx in -300i32..300, sy in -300i32..300, ex in -302i32..302, ey in -302i32..302,
        sizes in proptest::collection::vec(prop_oneof![0usize..40, Just(ONE_BY_NEXT_STEP)], 1..6), ccw: bool, classic: bool,
    ) {
        let (method, rotation) = (if classic { Classic } else { Diagonal }, if ccw { Ccw } else { Cw });
        prop_assume!(sizes.iter().any(|&n| n > 0));
        if let Ok(arc) = ArcInterp::new(Point::new(sx, sy), Point::ORIGIN, Point::new(ex, ey), rotation, method) {
            check_same(arc, self::arc, &sizes, 100_000);
        }
    }

    /// Random ellipses and elliptic arcs, from points near them (within the tolerance or not).
    #[test]
    fn random_ellipses_are_the_same_in_batches(
        a in 1i32..200, b in 1i32..200, t0 in 0.0f64..7.0, t1 in 0.0f64..7.0,
        d in (-2i32..=2, -2i32..=2, -2i32..=2, -2i32..=2),
        sizes in proptest::collection::vec(prop_oneof![0usize..40, Just(ONE_BY_NEXT_STEP)], 1..6), ccw: bool, classic: bool,
    ) {
        let (method, rotation) = (if classic { Classic } else { Diagonal }, if ccw { Ccw } else { Cw });
        prop_assume!(sizes.iter().any(|&n| n > 0));
        let at = |t: f64, dx: i32, dy: i32| {
            Point::new(libm::round(a as f64 * libm::cos(t)) as i32 + dx, libm::round(b as f64 * libm::sin(t)) as i32 + dy)
        };
        let (s, e) = (at(t0, d.0, d.1), at(t1, d.2, d.3));
        if let Ok(el) = EllipseInterp::new(s, Point::ORIGIN, a, b, e, rotation, method) {
            check_same(el, ellipse, &sizes, 100_000);
        }
    }
}

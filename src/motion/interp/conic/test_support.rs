//! Helpers shared by the circle and ellipse tests: walking a trace, the ideal curves' step counts
//! and how far a traced path strays from its curve.

extern crate std;
use crate::geom::{Point, Step};
use crate::motion::interp::Interpolator;
use std::vec::Vec;

/// Error bounds the tests hold the methods to, in steps.
pub const CLASSIC_BOUND_STEPS: f64 = 1.0;
pub const DIAGONAL_BOUND_STEPS: f64 = 0.5;
/// Bounds on the distance from the ideal curve to the traced polyline, in steps.
pub fn path_bound(method: crate::motion::interp::Method) -> f64 {
    match method {
        crate::motion::interp::Method::Classic => CLASSIC_PATH_BOUND_STEPS,
        crate::motion::interp::Method::Diagonal => DIAGONAL_PATH_BOUND_STEPS,
    }
}
pub const CLASSIC_PATH_BOUND_STEPS: f64 = 1.0;
pub const DIAGONAL_PATH_BOUND_STEPS: f64 = 0.5;
/// Float tolerance of the distance measurement itself.
pub const MEASURE_TOLERANCE_STEPS: f64 = 1e-9;

/// A traced path: every point from the start, the steps, and which points the straight
/// finish produced.
pub struct Walk {
    pub points: Vec<Point>,
    pub steps: Vec<Step>,
    pub tail: Vec<bool>,
}

impl Walk {
    pub fn last(&self) -> Point {
        *self.points.last().unwrap()
    }
    pub fn len(&self) -> usize {
        self.steps.len()
    }
    pub fn tail_len(&self) -> usize {
        self.tail.iter().filter(|t| **t).count()
    }
}

/// Runs `interp` from `start` to its end (at most `cap` steps), checking that every step
/// goes to a lattice neighbour, that a classic trace never moves both axes, and that the
/// interpolator keeps answering `None` at the end.
pub fn walk<I: Interpolator>(
    interp: &mut I,
    start: Point,
    classic: bool,
    tail_steps: impl Fn(&I) -> u32,
    cap: usize,
) -> Walk {
    let mut w = Walk { points: Vec::from([start]), steps: Vec::new(), tail: Vec::from([false]) };
    let mut p = start;
    let mut tails = tail_steps(interp);
    while let Some(s) = interp.next_step().unwrap() {
        assert!(s.is_neighbour(), "{s:?} after {} steps is not a step to a neighbour", w.len());
        if classic {
            assert!(!s.is_diagonal(), "classic moved both axes at {p:?}");
        }
        p = p.stepped(s);
        let t = tail_steps(interp);
        w.points.push(p);
        w.steps.push(s);
        w.tail.push(t != tails);
        tails = t;
        assert!(w.len() <= cap, "no end after {cap} steps");
    }
    for _ in 0..3 {
        assert_eq!(interp.next_step(), Ok(None), "steps after the end");
    }
    w
}

/// L1 (classic) and L∞ (diagonal) lengths of the parametric curve `f` over `[t0, t1]`: the
/// analytic step counts of a monotone lattice path following it.
pub fn ideal_lengths(f: impl Fn(f64) -> (f64, f64), t0: f64, t1: f64, samples: usize) -> (f64, f64) {
    let (mut l1, mut linf) = (0.0, 0.0);
    let mut prev = f(t0);
    for i in 1..=samples {
        let p = f(t0 + (t1 - t0) * i as f64 / samples as f64);
        let (dx, dy) = ((p.0 - prev.0).abs(), (p.1 - prev.1).abs());
        l1 += dx + dy;
        linf += dx.max(dy);
        prev = p;
    }
    (l1, linf)
}

/// Quadrant boundaries (axes) an ideal arc from angle `a0` sweeping `t` radians in
/// direction `sign` crosses.
pub fn axes_crossed(a0: f64, t: f64, sign: f64) -> f64 {
    use core::f64::consts::FRAC_PI_2;
    if sign > 0.0 {
        libm::floor((a0 + t) / FRAC_PI_2) - libm::floor(a0 / FRAC_PI_2)
    } else {
        libm::ceil(a0 / FRAC_PI_2) - libm::ceil((a0 - t) / FRAC_PI_2)
    }
}

/// Largest difference between a trace's step count and the ideal arc's L1 / L∞ length:
/// the lattice path meets each axis up to a step away from the ideal curve (counted on
/// both sides of it), and its ends are lattice points.
pub fn count_slack(axes: f64) -> f64 {
    2.0 + 2.0 * axes
}

/// Largest distance from the ideal curve `f` over `[t0, t1]` (sampled at least every
/// `1/8` step) to the traced polyline through `points`: how far the drawing strays from the
/// curve seen from the curve (cut-off tips show here, not in the points' own distances).
/// Distances above [`FAR_STEPS`] report as `FAR_STEPS`.
pub fn curve_to_path(points: &[Point], f: impl Fn(f64) -> (f64, f64), t0: f64, t1: f64, samples: usize) -> f64 {
    use std::collections::HashMap;
    const CELL: i32 = 4;
    let mut cells: HashMap<(i32, i32), Vec<usize>> = HashMap::new();
    for (i, p) in points.iter().enumerate() {
        cells.entry((p.x.div_euclid(CELL), p.y.div_euclid(CELL))).or_default().push(i);
    }
    let seg = |i: usize, q: (f64, f64)| {
        let a = points[i];
        let b = points[(i + 1).min(points.len() - 1)];
        let (ax, ay, bx, by) = (a.x as f64, a.y as f64, b.x as f64, b.y as f64);
        let (dx, dy) = (bx - ax, by - ay);
        let l2 = dx * dx + dy * dy;
        let t = if l2 > 0.0 { (((q.0 - ax) * dx + (q.1 - ay) * dy) / l2).clamp(0.0, 1.0) } else { 0.0 };
        libm::hypot(q.0 - (ax + t * dx), q.1 - (ay + t * dy))
    };
    let mut worst: f64 = 0.0;
    for k in 0..=samples {
        let q = f(t0 + (t1 - t0) * k as f64 / samples as f64);
        let (cx, cy) = ((libm::floor(q.0) as i32).div_euclid(CELL), (libm::floor(q.1) as i32).div_euclid(CELL));
        let mut best = FAR_STEPS;
        for gx in cx - 2..=cx + 2 {
            for gy in cy - 2..=cy + 2 {
                for &i in cells.get(&(gx, gy)).map(|v| &v[..]).unwrap_or(&[]) {
                    best = best.min(seg(i, q));
                    if i > 0 {
                        best = best.min(seg(i - 1, q));
                    }
                }
            }
        }
        worst = worst.max(best);
    }
    worst
}

/// Longest trace whose curve-to-path distance is measured (the largest curves are checked
/// point by point only).
pub const STRAY_CHECK_MAX_STEPS: usize = 50_000;

/// Most curve samples a check takes (large curves are sampled more coarsely).
pub const CURVE_SAMPLES_MAX: usize = 100_000;

/// Cap of [`curve_to_path`].
pub const FAR_STEPS: f64 = 4.0;

/// Travel angle from angle `a` to angle `b` in the direction `sign` (+1 CCW), in (0, 2π].
pub fn travel(a: f64, b: f64, sign: f64) -> f64 {
    use core::f64::consts::TAU;
    let mut d = ((b - a) * sign) % TAU;
    if d <= 1e-12 {
        d += TAU;
    }
    d
}

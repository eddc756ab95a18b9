extern crate std;
use super::*;
use crate::motion::interp::arc::ArcInterp;
use crate::motion::interp::arc::offset;
use crate::motion::interp::conic::test_support::*;
use Method::{Classic, Diagonal};
use Rotation::{Clockwise as Cw, CounterClockwise as Ccw};
use core::f64::consts::{PI, TAU};
use proptest::prelude::*;
use reference::{distance_to_ellipse, nearest_on_ellipse};
use std::vec::Vec;

/// The distance and nearest point in `f64` (as the firmware computed them before it went
/// single precision): the tests' measure of how far a point lies from an ellipse, itself
/// checked against brute force below.
mod reference {
    /// Bisection rounds of [`root`]; enough to exhaust `f64` precision.
    const DISTANCE_ITERATIONS: u32 = 200;

    /// Euclidean distance from `(x, y)` (relative to the centre) to the ellipse with semi-axes
    /// `a` along X and `b` along Y (both > 0).
    pub(super) fn distance_to_ellipse(a: f64, b: f64, x: f64, y: f64) -> f64 {
        let (px, py) = nearest_on_ellipse(a, b, x, y);
        libm::hypot(px - x, py - y)
    }

    /// The point of the ellipse with semi-axes `a` along X and `b` along Y (both > 0) nearest to
    /// `(x, y)` (relative to the centre); in the same closed quadrant (a zero coordinate counts as
    /// positive where the nearest point leaves the axis).
    ///
    /// The nearest point `p` satisfies `p = (a²x/(t + a²), b²y/(t + b²))` for the root `t` of a
    /// monotone function, found by bisection (D. Eberly, "Distance from a Point to an Ellipse").
    pub(super) fn nearest_on_ellipse(a: f64, b: f64, x: f64, y: f64) -> (f64, f64) {
        // Work in the first quadrant with the major axis first.
        let swap = a < b;
        let (e0, e1, y0, y1) =
            if swap { (b, a, libm::fabs(y), libm::fabs(x)) } else { (a, b, libm::fabs(x), libm::fabs(y)) };
        let (x0, x1) = if y1 > 0.0 {
            if y0 > 0.0 {
                let (z0, z1) = (y0 / e0, y1 / e1);
                let g = z0 * z0 + z1 * z1 - 1.0;
                if g == 0.0 {
                    (y0, y1)
                } else {
                    let r0 = (e0 / e1) * (e0 / e1);
                    let s = root(r0, z0, z1, g);
                    (r0 * y0 / (s + r0), y1 / (s + 1.0))
                }
            } else {
                (0.0, e1)
            }
        } else {
            let (numer, denom) = (e0 * y0, e0 * e0 - e1 * e1);
            if numer < denom {
                let xde0 = numer / denom;
                (e0 * xde0, e1 * libm::sqrt(1.0 - xde0 * xde0))
            } else {
                (e0, 0.0)
            }
        };
        let (px, py) = if swap { (x1, x0) } else { (x0, x1) };
        (libm::copysign(px, if x < 0.0 { -1.0 } else { 1.0 }), libm::copysign(py, if y < 0.0 { -1.0 } else { 1.0 }))
    }

    /// The root `s` of `(r0·z0/(s + r0))² + (z1/(s + 1))² = 1` by bisection.
    fn root(r0: f64, z0: f64, z1: f64, g: f64) -> f64 {
        let n0 = r0 * z0;
        let mut s0 = z1 - 1.0;
        let mut s1 = if g < 0.0 { 0.0 } else { libm::hypot(n0, z1) - 1.0 };
        let mut s = 0.0;
        for _ in 0..DISTANCE_ITERATIONS {
            s = 0.5 * (s0 + s1);
            if s == s0 || s == s1 {
                break;
            }
            let (ratio0, ratio1) = (n0 / (s + r0), z1 / (s + 1.0));
            let g = ratio0 * ratio0 + ratio1 * ratio1 - 1.0;
            if g > 0.0 {
                s0 = s;
            } else if g < 0.0 {
                s1 = s;
            } else {
                break;
            }
        }
        s
    }
}

impl EllipseInterp {
    fn tail_steps(&self) -> u32 {
        self.tracer.tail_steps()
    }
}

fn trace(e: &mut EllipseInterp, start: Point, a: i32, b: i32, method: Method) -> Walk {
    walk(e, start, method == Classic, EllipseInterp::tail_steps, 16 * (a as usize + b as usize) + 64)
}

fn off(p: Point, c: Point, a: i32, b: i32) -> f64 {
    let d = offset(p, c);
    distance_to_ellipse(a as f64, b as f64, d.0 as f64, d.1 as f64)
}

/// True when `p` and `q` lie on one ray from `c`.
fn same_ray(p: Point, q: Point, c: Point) -> bool {
    let (u, v) = (offset(p, c), offset(q, c));
    u.0 * v.1 == u.1 * v.0 && u.0 * v.0 + u.1 * v.1 > 0
}

/// Parametric angle of the point of the ellipse nearest to `start`. A start on an axis
/// inside a thin tip is as near to both sides of the tip: the tip counts as behind it.
fn start_param(start: Point, c: Point, a: i32, b: i32, sign: f64) -> f64 {
    let d = offset(start, c);
    let (x, y) = nearest_on_ellipse(a as f64, b as f64, d.0 as f64, d.1 as f64);
    let at = |x: f64, y: f64| libm::atan2(y / b as f64, x / a as f64);
    let t = at(x, y);
    let other = if d.0 == 0 && x != 0.0 {
        at(-x, y)
    } else if d.1 == 0 && y != 0.0 {
        at(x, -y)
    } else {
        return t;
    };
    // The later of the two in the direction of travel.
    if travel(t, other, sign) < PI { other } else { t }
}

/// Travel from parametric angle `t0` to the point of the ellipse nearest to `end`. An end
/// on an axis inside a thin tip is as near to both sides of the tip: the first one reached.
fn end_travel(t0: f64, end: Point, c: Point, a: i32, b: i32, sign: f64) -> f64 {
    let d = offset(end, c);
    let (x, y) = nearest_on_ellipse(a as f64, b as f64, d.0 as f64, d.1 as f64);
    let at = |x: f64, y: f64| travel(t0, libm::atan2(y / b as f64, x / a as f64), sign);
    let mut t = at(x, y);
    if d.0 == 0 && x != 0.0 {
        t = t.min(at(-x, y));
    }
    if d.1 == 0 && y != 0.0 {
        t = t.min(at(x, -y));
    }
    t
}

/// Length along the long axis of the tips where the ellipse is narrower than a step on
/// either side of that axis.
fn tip_steps(a: i32, b: i32) -> f64 {
    let (long, short) = (a.max(b) as f64, a.min(b) as f64);
    long * (1.0 - libm::sqrt(1.0 - 1.0 / (short * short)))
}

fn bound(method: Method) -> f64 {
    let b = if method == Classic { CLASSIC_BOUND_STEPS } else { DIAGONAL_BOUND_STEPS };
    b + MEASURE_TOLERANCE_STEPS
}

/// Checks a finished trace: exact end; every point after the start (which may lie off the
/// ellipse) within the method's bound of the true ellipse, checking every `every`-th point;
/// the straight finish short and within the bound plus the end's own distance; and the step
/// count against the L1 / L∞ length of the ideal elliptic arc.
#[allow(clippy::too_many_arguments)]
fn check(
    w: &Walk,
    start: Point,
    c: Point,
    a: i32,
    b: i32,
    end: Point,
    rotation: Rotation,
    method: Method,
    every: usize,
) {
    assert_eq!(w.last(), end, "did not end on the end point");
    let bnd = bound(method);
    let end_off = off(end, c, a, b);
    for (i, (p, tail)) in w.points.iter().zip(&w.tail).enumerate().skip(1) {
        if i % every != 0 && !tail && i + 1 != w.points.len() {
            continue;
        }
        let d = off(*p, c, a, b);
        if *tail {
            assert!(d <= bnd + end_off, "finish point {p:?} is {d} off (end {end_off} off)");
        } else {
            assert!(d <= bnd, "point {i} {p:?} is {d} off the ellipse ({method:?}, a {a}, b {b})");
        }
    }
    // Along a thin tip the geometric angle says little about progress: the end's ray can
    // be reached early and the rest of the way is finished straight.
    let tip = tip_steps(a, b);
    let thin = tip >= 0.5;
    if !thin {
        assert!(w.tail_len() <= ARC_END_TOLERANCE_STEPS as usize + 2, "finish of {} steps", w.tail_len());
    }
    let sign = if rotation == Ccw { 1.0 } else { -1.0 };
    let t0 = start_param(start, c, a, b, sign);
    let sweep = if same_ray(start, end, c) { TAU } else { end_travel(t0, end, c, a, b, sign) };
    let (af, bf) = (a as f64, b as f64);
    let (l1, linf) = ideal_lengths(
        |t| (af * libm::cos(t0 + sign * t), bf * libm::sin(t0 + sign * t)),
        0.0,
        sweep,
        4096.max(8 * (a + b) as usize),
    );
    let analytic = if method == Classic { l1 } else { linf };
    // Start and end each lie up to a step off the ideal curve.
    let axes = axes_crossed(t0, sweep, sign);
    let mut slack = count_slack(axes) + 2.0;
    if thin {
        // Tips are climbed and descended on the axis: up to twice their length each.
        slack += 4.0 * (tip + 1.0) * (axes + 1.0);
    }
    assert!((w.len() as f64 - analytic).abs() <= slack, "{} steps, analytic {analytic} ± {slack}", w.len());
    if w.len() > STRAY_CHECK_MAX_STEPS {
        return;
    }
    let (cx, cy) = (c.x as f64, c.y as f64);
    let h = curve_to_path(
        &w.points,
        |t| (cx + af * libm::cos(t0 + sign * t), cy + bf * libm::sin(t0 + sign * t)),
        0.0,
        sweep,
        (4 * l1 as usize + 64).min(CURVE_SAMPLES_MAX),
    );
    let start_off = off(start, c, a, b);
    assert!(
        h <= path_bound(method) + end_off.max(start_off) + MEASURE_TOLERANCE_STEPS,
        "the curve strays {h} from the path ({method:?}, a {a}, b {b})"
    );
}

/// The distance to an ellipse by brute force: a fine parametric sampling refined by ternary
/// search.
fn brute_distance(a: f64, b: f64, x: f64, y: f64) -> f64 {
    let d = |t: f64| libm::hypot(a * libm::cos(t) - x, b * libm::sin(t) - y);
    let n = 20_000;
    let k = (0..n).min_by(|i, j| d(TAU * *i as f64 / n as f64).total_cmp(&d(TAU * *j as f64 / n as f64))).unwrap();
    let (mut lo, mut hi) = (TAU * (k as f64 - 1.0) / n as f64, TAU * (k as f64 + 1.0) / n as f64);
    for _ in 0..200 {
        let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
        if d(m1) < d(m2) { hi = m2 } else { lo = m1 }
    }
    d(0.5 * (lo + hi))
}

/// How far the firmware's `f32` distance may be from the true one: `f32`'s relative precision
/// on the distance itself, whatever the size of the ellipse.
fn f32_distance_tolerance(want: f64) -> f64 {
    2e-6 * want.max(1.0)
}

#[test]
fn the_distance_to_an_ellipse_is_the_true_euclidean_distance() {
    let cases = [
        (5.0, 3.0, 6.0, 1.0),
        (5.0, 3.0, 0.0, 0.0),
        (5.0, 3.0, 4.0, 0.0),
        (5.0, 3.0, 0.0, -2.5),
        (3.0, 5.0, 1.0, 4.0),
        (100.0, 1.0, 99.0, 1.0),
        (100.0, 1.0, -50.0, 0.3),
        (1.0, 100.0, 0.2, -99.0),
        (7.0, 7.0, 3.0, 4.0),
        (200_000.0, 100_000.0, 150_001.0, 66_143.0),
        (2.0, 1.0, 1.0, 0.0),
    ];
    for (a, b, x, y) in cases {
        let (got, want) = (distance_to_ellipse(a, b, x, y), brute_distance(a, b, x, y));
        assert!((got - want).abs() <= 1e-6 * want.max(1.0), "a {a} b {b} ({x}, {y}): {got} vs {want}");
    }
    // The firmware's, at lattice points: the cases above (scaled to the lattice where they were
    // fractional), points off the axes, on them, inside thin ellipses and far away, and points
    // near the largest ellipses, where `f32` coordinates are coarse (1/64 step) but the
    // distance must not be.
    let m = MAX_ELLIPSE_AXIS_STEPS;
    let lattice: [(i32, i32, i64, i64); 22] = [
        (5, 3, 6, 1),
        (5, 3, 0, 0),
        (5, 3, 4, 0),
        (10, 6, 0, -5),
        (3, 5, 1, 4),
        (100, 1, 99, 1),
        (1000, 10, -500, 3),
        (10, 1000, 2, -990),
        (7, 7, 3, 4),
        (200_000, 100_000, 150_001, 66_143),
        (2, 1, 1, 0),
        (300, 2, 0, 0),
        (300, 2, -299, 0),
        (300, 2, 290, 1),
        (5, 3, 60, -70),
        (5, 3, 1 << 31, -(1 << 31)),
        (m, m, m as i64 + 2, 0),
        (m, m - 1, 185_363, -185_363),
        (m, m / 2, 185_364, 92_682),
        (m, 7, -m as i64 + 1, 1),
        (1, m, 1, m as i64 - 3),
        (m, 100_000, 0, -100_001),
    ];
    for (a, b, x, y) in lattice {
        let want = brute_distance(a as f64, b as f64, x as f64, y as f64);
        let d = foot(a, b, (x, y));
        let got = math::hypot(d.0, d.1) as f64;
        assert!((got - want).abs() <= f32_distance_tolerance(want), "a {a} b {b} ({x}, {y}): {got} vs {want}");
    }
}

#[test]
fn the_nearest_point_is_exact_near_the_largest_ellipses() {
    // Every lattice point within two steps of sampled points of large ellipses: the offset to the
    // nearest point against the `f64` reference.
    let m = MAX_ELLIPSE_AXIS_STEPS;
    for (a, b) in [(m, m), (m, m - 1), (m, m / 3), (m / 3, m), (m, 1), (3, m), (150_001, 149_999)] {
        for k in 0..97 {
            let t = TAU * k as f64 / 97.0 + 0.001;
            let (cx, cy) = (libm::round(a as f64 * libm::cos(t)) as i64, libm::round(b as f64 * libm::sin(t)) as i64);
            for dx in -2..=2 {
                for dy in -2..=2 {
                    let (x, y) = (cx + dx, cy + dy);
                    let (nx, ny) = nearest_on_ellipse(a as f64, b as f64, x as f64, y as f64);
                    let want = (nx - x as f64, ny - y as f64);
                    let got = foot(a, b, (x, y));
                    let err = libm::hypot(got.0 as f64 - want.0, got.1 as f64 - want.1);
                    assert!(err <= 1e-5, "a {a} b {b} ({x}, {y}): {got:?} vs {want:?}");
                }
            }
        }
    }
}

#[test]
fn classic_first_quadrant_follows_the_textbook() {
    // a = 5, b = 3, F = 9x² + 25y² − 225 from (5, 0) to (0, 3): F >= 0 → −X, F < 0 → +Y.
    let c = Point::new(-300, 40);
    let at = |x, y| Point::new(c.x + x, c.y + y);
    let mut e = EllipseInterp::new(at(5, 0), c, 5, 3, at(0, 3), Ccw, Classic).unwrap();
    let (mut steps, mut fs) = (Vec::new(), Vec::new());
    while let Some(s) = e.next_step().unwrap() {
        steps.push(s);
        fs.push(e.tracer.discriminant());
    }
    use Step as S;
    assert_eq!(steps, [S::XN, S::YP, S::YP, S::XN, S::YP, S::XN, S::XN, S::XN]);
    assert_eq!(fs, [-81, -56, 19, -44, 81, 36, 9, 0]);
}

/// The textbook ellipse tables, literally (F recomputed at every point).
fn table_walk(a: i64, b: i64, start: (i64, i64), end: (i64, i64), rotation: Rotation, full: bool) -> Vec<Step> {
    use Step as S;
    let (mut x, mut y) = start;
    let mut steps = Vec::new();
    loop {
        let f = b * b * x * x + a * a * y * y - a * a * b * b;
        let (ge, lt) = match rotation {
            Ccw if x > 0 && y >= 0 => (S::XN, S::YP),
            Ccw if x <= 0 && y > 0 => (S::YN, S::XN),
            Ccw if x < 0 && y <= 0 => (S::XP, S::YN),
            Ccw => (S::YP, S::XP),
            Cw if x >= 0 && y > 0 => (S::YN, S::XP),
            Cw if x < 0 && y >= 0 => (S::XP, S::YP),
            Cw if x <= 0 && y < 0 => (S::YP, S::XN),
            Cw => (S::XN, S::YN),
        };
        let s = if f >= 0 { ge } else { lt };
        x += s.x as i64;
        y += s.y as i64;
        steps.push(s);
        assert!(steps.len() <= 20 * (a + b) as usize, "table walk did not end");
        if (x, y) == end && (!full || steps.len() > 4) {
            return steps;
        }
    }
}

#[test]
fn classic_matches_the_tables_in_every_quadrant_and_direction() {
    for a in 2..=12i64 {
        for b in 2..=12i64 {
            if tip_steps(a as i32, b as i32) >= 0.5 {
                continue; // the tables cut thin tips; see `thin_tips_are_drawn_not_cut`
            }
            let axes = [(a, 0), (0, b), (-a, 0), (0, -b)];
            for rotation in [Ccw, Cw] {
                for (i, s) in axes.iter().enumerate() {
                    for k in 1..=4 {
                        let e = if rotation == Ccw { axes[(i + k) % 4] } else { axes[(i + 4 - k) % 4] };
                        let (start, end) = (Point::new(s.0 as i32, s.1 as i32), Point::new(e.0 as i32, e.1 as i32));
                        let mut el =
                            EllipseInterp::new(start, Point::ORIGIN, a as i32, b as i32, end, rotation, Classic)
                                .unwrap();
                        let w = trace(&mut el, start, a as i32, b as i32, Classic);
                        assert_eq!(
                            w.steps,
                            table_walk(a, b, *s, e, rotation, k == 4),
                            "a {a} b {b} from {s:?}, {k} quarters {rotation:?}"
                        );
                        assert_eq!(w.len() as i64, (a + b) * k as i64, "a + b per quarter");
                    }
                }
            }
        }
    }
}

#[test]
fn thin_tips_are_drawn_not_cut() {
    // a = 2, b = 50: the literal tables step onto the Y axis at y = 44 and leave it at once,
    // cutting 6 steps off each tip; the trace climbs to the tip and comes back.
    let (a, b) = (2, 50);
    let s = Point::new(a, 0);
    // The literal first and second quadrant tables, 60 steps from (2, 0).
    let (mut x, mut y) = (a as i64, 0i64);
    let mut table = Vec::new();
    for _ in 0..60 {
        let f = (b * b) as i64 * x * x + (a * a) as i64 * y * y - (a * a * b * b) as i64;
        let (ge, lt) = if x > 0 { (Step::XN, Step::YP) } else { (Step::YN, Step::XN) };
        let st = if f >= 0 { ge } else { lt };
        (x, y) = (x + st.x as i64, y + st.y as i64);
        table.push((x, y));
    }
    assert!(table.contains(&(0, 44)) && table.contains(&(-1, 44)), "{table:?}");
    assert!(!table.contains(&(0, 47)), "the tables reach the tip after all");
    for method in [Classic, Diagonal] {
        let mut e = EllipseInterp::new(s, Point::ORIGIN, a, b, s, Ccw, method).unwrap();
        let w = trace(&mut e, s, a, b, method);
        assert!(w.points.contains(&Point::new(0, b)) && w.points.contains(&Point::new(0, -b)), "{method:?} cut a tip");
        check(&w, s, Point::ORIGIN, a, b, s, Ccw, method, 1);
    }
}

#[test]
fn full_ellipses_take_4_a_plus_b_classic_and_about_4_hypot_diagonal_steps() {
    for (a, b) in [(1, 1), (1, 5), (5, 1), (10, 3), (3, 10), (40, 39), (100, 7), (250, 120), (1, 300), (300, 2)] {
        for rotation in [Ccw, Cw] {
            for s in [Point::new(a, 0), Point::new(0, -b)] {
                let c = Point::new(12, -7);
                let start = Point::new(c.x + s.x, c.y + s.y);
                for method in [Classic, Diagonal] {
                    let mut e = EllipseInterp::new(start, c, a, b, start, rotation, method).unwrap();
                    let w = trace(&mut e, start, a, b, method);
                    assert_eq!(w.last(), start);
                    check(&w, start, c, a, b, start, rotation, method, 1);
                    if method == Classic {
                        assert_eq!(w.len(), 4 * (a + b) as usize, "a {a} b {b}");
                    } else {
                        let analytic = 4.0 * libm::hypot(a as f64, b as f64);
                        assert!((w.len() as f64 - analytic).abs() <= 4.0, "a {a} b {b}: {} vs {analytic}", w.len());
                    }
                }
            }
        }
    }
}

#[test]
fn a_circle_is_an_ellipse_with_equal_axes() {
    for (x, y) in [(9, 0), (0, -9), (3, 4), (-12, 5), (20, -21)] {
        let s = Point::new(x, y);
        let r = libm::sqrt((x * x + y * y) as f64) as i32;
        for rotation in [Ccw, Cw] {
            for method in [Classic, Diagonal] {
                let end = Point::new(-y, x);
                let mut arc = ArcInterp::new(s, Point::ORIGIN, end, rotation, method).unwrap();
                let mut el = EllipseInterp::new(s, Point::ORIGIN, r, r, end, rotation, method).unwrap();
                loop {
                    let step = arc.next_step().unwrap();
                    assert_eq!(step, el.next_step().unwrap());
                    assert_eq!(arc.tangent(), el.tangent());
                    if step.is_none() {
                        break;
                    }
                }
            }
        }
    }
}

#[test]
fn bad_ellipses_are_refused() {
    let (s, c) = (Point::new(10, 0), Point::ORIGIN);
    assert_eq!(EllipseInterp::new(s, c, 0, 5, s, Ccw, Classic).err(), Some(ArcError::ZeroRadius));
    assert_eq!(EllipseInterp::new(s, c, 10, -5, s, Ccw, Classic).err(), Some(ArcError::ZeroRadius));
    assert_eq!(EllipseInterp::new(c, c, 10, 5, s, Ccw, Classic).err(), Some(ArcError::ZeroRadius));
    assert_eq!(EllipseInterp::new(Point::new(13, 0), c, 10, 5, s, Ccw, Classic).err(), Some(ArcError::StartOffCurve));
    assert!(EllipseInterp::new(Point::new(12, 0), c, 10, 5, s, Ccw, Classic).is_ok());
    assert_eq!(EllipseInterp::new(s, c, 10, 5, Point::new(0, 8), Ccw, Classic).err(), Some(ArcError::EndOffCurve));
    assert!(EllipseInterp::new(s, c, 10, 5, Point::new(0, 7), Cw, Diagonal).is_ok());
    assert_eq!(EllipseInterp::new(Point::new(2, 0), c, 2, 1, c, Ccw, Classic).err(), Some(ArcError::EndOffCurve));
    let far = MAX_ELLIPSE_AXIS_STEPS + 1;
    assert_eq!(EllipseInterp::new(Point::new(far, 0), c, far, 5, s, Ccw, Classic).err(), Some(ArcError::TooLarge));
    let corner = Point::new(i32::MIN, i32::MAX);
    assert_eq!(
        EllipseInterp::new(corner, Point::new(i32::MAX, 0), 100, 100, corner, Ccw, Classic).err(),
        Some(ArcError::StartOffCurve)
    );
}

#[test]
fn the_tangent_follows_the_ellipse_in_the_direction_of_travel() {
    let (a, b) = (60, 25);
    for rotation in [Ccw, Cw] {
        for method in [Classic, Diagonal] {
            let c = Point::new(3, 4);
            let s = Point::new(c.x - a, c.y);
            let mut e = EllipseInterp::new(s, c, a, b, s, rotation, method).unwrap();
            let mut p = s;
            let sign = if rotation == Ccw { 1.0 } else { -1.0 };
            loop {
                let t = e.tangent();
                let (x, y) = ((p.x - c.x) as f32, (p.y - c.y) as f32);
                // ∝ (−a²y, b²x) counter-clockwise, negated clockwise.
                let (wx, wy) = (-((a * a) as f32) * y * sign, (b * b) as f32 * x * sign);
                let n = (wx * wx + wy * wy).sqrt();
                assert!((t.x - wx / n).abs() < 1e-5 && (t.y - wy / n).abs() < 1e-5, "{t:?} at {p:?}");
                let Some(step) = e.next_step().unwrap() else { break };
                assert!(t.x * step.x as f32 + t.y * step.y as f32 >= 0.0, "step {step:?} against the tangent at {p:?}");
                p = p.stepped(step);
            }
        }
    }
}

#[test]
fn the_largest_ellipses_do_not_overflow() {
    let c = Point::new(-100_000, 100_000);
    let cases = [
        (200_000, 100_000, Point::new(100_000, 100_000), Point::new(100_000, 100_000), Ccw),
        (100_000, 200_000, Point::new(-100_000, -100_000), Point::new(-100_000, -100_000), Cw),
        (200_000, 1, Point::new(100_000, 100_000), Point::new(-300_000, 100_000), Cw),
        (
            MAX_ELLIPSE_AXIS_STEPS,
            MAX_ELLIPSE_AXIS_STEPS / 2,
            Point::new(c.x + MAX_ELLIPSE_AXIS_STEPS, c.y),
            Point::new(c.x, c.y + MAX_ELLIPSE_AXIS_STEPS / 2),
            Ccw,
        ),
    ];
    for (a, b, start, end, rotation) in cases {
        for method in [Classic, Diagonal] {
            let mut e = EllipseInterp::new(start, c, a, b, end, rotation, method).unwrap();
            let w = trace(&mut e, start, a, b, method);
            check(&w, start, c, a, b, end, rotation, method, 17);
            if (a, b) == (200_000, 100_000) {
                // The full ellipse from an axis: exactly 4(a + b) classic steps,
                // 4·√(a² + b²) ± 4 diagonal ones.
                let analytic = if method == Classic { 1_200_000.0 } else { 4.0 * libm::hypot(2e5, 1e5) };
                let slack = if method == Classic { 0.0 } else { 4.0 };
                assert!((w.len() as f64 - analytic).abs() <= slack, "{method:?}: {} steps", w.len());
            }
        }
    }
}

fn rounded(c: Point, a: i32, b: i32, t: f64) -> Point {
    Point::new(c.x + libm::round(a as f64 * libm::cos(t)) as i32, c.y + libm::round(b as f64 * libm::sin(t)) as i32)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

    /// Random elliptic arcs between lattice points rounded from random parametric angles.
    #[test]
    fn random_elliptic_arcs_stay_on_the_ellipse_and_end_exactly(
        cx in -100_000i32..100_000, cy in -100_000i32..100_000, a in 1i32..300, b in 1i32..300,
        t0 in 0.0f64..TAU, t1 in 0.0f64..TAU, ccw: bool, classic: bool,
    ) {
        let (c, method, rotation) = (Point::new(cx, cy), if classic { Classic } else { Diagonal }, if ccw { Ccw } else { Cw });
        let (start, end) = (rounded(c, a, b, t0), rounded(c, a, b, t1));
        prop_assume!(start != c && end != c);
        prop_assume!(end == start || !same_ray(start, end, c), "distinct ends on one ray mean a full turn");
        let mut e = EllipseInterp::new(start, c, a, b, end, rotation, method).unwrap();
        let w = trace(&mut e, start, a, b, method);
        check(&w, start, c, a, b, end, rotation, method, 1);
    }

    /// Very flat ellipses, where one region of the curve is shorter than a step.
    #[test]
    fn flat_ellipses_stay_on_the_ellipse(
        long in 20i32..600, short in 1i32..4, along_x: bool, t0 in 0.0f64..TAU, full: bool, t1 in 0.0f64..TAU,
        ccw: bool, classic: bool,
    ) {
        let (a, b) = if along_x { (long, short) } else { (short, long) };
        let (method, rotation) = (if classic { Classic } else { Diagonal }, if ccw { Ccw } else { Cw });
        let c = Point::new(5, -5);
        let start = rounded(c, a, b, t0);
        let end = if full { start } else { rounded(c, a, b, t1) };
        prop_assume!(start != c && end != c);
        prop_assume!(end == start || !same_ray(start, end, c), "distinct ends on one ray mean a full turn");
        let mut e = EllipseInterp::new(start, c, a, b, end, rotation, method).unwrap();
        let w = trace(&mut e, start, a, b, method);
        check(&w, start, c, a, b, end, rotation, method, 1);
    }

    /// Garbage in never panics and never hangs.
    #[test]
    fn any_input_is_refused_or_drawn(
        s in any::<(i32, i32)>(), c in any::<(i32, i32)>(), e in any::<(i32, i32)>(), a in any::<i32>(), b in any::<i32>(),
        ccw: bool, classic: bool,
    ) {
        let (method, rotation) = (if classic { Classic } else { Diagonal }, if ccw { Ccw } else { Cw });
        let (s, c, e) = (Point::new(s.0, s.1), Point::new(c.0, c.1), Point::new(e.0, e.1));
        if let Ok(mut el) = EllipseInterp::new(s, c, a, b, e, rotation, method)
            && a < 5000
            && b < 5000
        {
            trace(&mut el, s, a, b, method);
        }
    }
}

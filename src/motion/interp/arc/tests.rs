extern crate std;
use super::*;
use crate::motion::interp::conic::cross;
use crate::motion::interp::conic::test_support::*;
use Method::{Classic, Diagonal};
use Rotation::{Clockwise as Cw, CounterClockwise as Ccw};
use core::f64::consts::{SQRT_2, TAU};
use proptest::prelude::*;
use std::vec::Vec;

impl ArcInterp {
    fn tail_steps(&self) -> u32 {
        self.tracer.tail_steps()
    }
}

fn trace(arc: &mut ArcInterp, start: Point, center: Point, method: Method) -> Walk {
    let r = libm::sqrt(r2(start, center) as f64) as usize;
    walk(arc, start, method == Classic, ArcInterp::tail_steps, 16 * r + 64)
}

fn r2(p: Point, c: Point) -> i64 {
    let d = offset(p, c);
    d.0 * d.0 + d.1 * d.1
}

/// Distance of `p` from the circle around `c` through `s`.
fn off_circle(p: Point, c: Point, s: Point) -> f64 {
    (libm::sqrt(r2(p, c) as f64) - libm::sqrt(r2(s, c) as f64)).abs()
}

fn bound(method: Method) -> f64 {
    let b = match method {
        Classic => CLASSIC_BOUND_STEPS,
        Diagonal => DIAGONAL_BOUND_STEPS,
    };
    b + MEASURE_TOLERANCE_STEPS
}

fn angle(p: Point, c: Point) -> f64 {
    let d = offset(p, c);
    libm::atan2(d.1 as f64, d.0 as f64)
}

/// Checks a finished arc: exact end, every curve point within the method's bound, the
/// straight finish short and within the bound plus the end's own distance, and the step
/// count against the ideal arc's L1 / L∞ length.
fn check_arc(w: &Walk, start: Point, center: Point, end: Point, rotation: Rotation, method: Method) {
    assert_eq!(w.last(), end, "did not end on the end point");
    let b = bound(method);
    let end_off = off_circle(end, center, start);
    for (p, tail) in w.points.iter().zip(&w.tail) {
        let d = off_circle(*p, center, start);
        if *tail {
            assert!(d <= b + end_off, "finish point {p:?} is {d} off (end {end_off} off)");
        } else {
            assert!(d <= b, "{p:?} is {d} off the circle ({method:?})");
        }
    }
    assert!(w.tail_len() <= ARC_END_TOLERANCE_STEPS as usize + 2, "finish of {} steps", w.tail_len());
    let sign = if rotation == Ccw { 1.0 } else { -1.0 };
    let a0 = angle(start, center);
    let sweep = travel(a0, angle(end, center), sign);
    let r = libm::sqrt(r2(start, center) as f64);
    let (l1, linf) = ideal_lengths(
        |t| (r * libm::cos(a0 + sign * t), r * libm::sin(a0 + sign * t)),
        0.0,
        sweep,
        4096.max(8 * r as usize),
    );
    let analytic = if method == Classic { l1 } else { linf };
    let slack = count_slack(axes_crossed(a0, sweep, sign));
    assert!((w.len() as f64 - analytic).abs() <= slack, "{} steps, analytic {analytic} ± {slack}", w.len());
    if w.len() > STRAY_CHECK_MAX_STEPS {
        return;
    }
    let (cx, cy) = (center.x as f64, center.y as f64);
    let h = curve_to_path(
        &w.points,
        |t| (cx + r * libm::cos(a0 + sign * t), cy + r * libm::sin(a0 + sign * t)),
        0.0,
        sweep,
        (4 * l1 as usize + 64).min(CURVE_SAMPLES_MAX),
    );
    assert!(
        h <= path_bound(method) + end_off + MEASURE_TOLERANCE_STEPS,
        "the curve strays {h} from the path ({method:?})"
    );
}

#[test]
fn classic_first_quadrant_counter_clockwise_follows_the_textbook() {
    // NR1 from A(4, 0) to B(0, 4): F0 = 0 → −X (F = −7) → +Y (−6) → +Y (−3) → +Y (2) → −X (−3)
    // → +Y (4) → −X (1) → −X (0); 2R = 8 steps.
    let c = Point::new(100, -50);
    let at = |x, y| Point::new(c.x + x, c.y + y);
    let mut arc = ArcInterp::new(at(4, 0), c, at(0, 4), Ccw, Classic).unwrap();
    let (mut steps, mut fs) = (Vec::new(), Vec::new());
    while let Some(s) = arc.next_step().unwrap() {
        steps.push(s);
        fs.push(arc.tracer.discriminant());
    }
    use Step as S;
    assert_eq!(steps, [S::XN, S::YP, S::YP, S::YP, S::XN, S::YP, S::XN, S::XN]);
    assert_eq!(fs, [-7, -6, -3, 2, -3, 4, 1, 0]);
}

#[test]
fn first_quadrant_arc_of_radius_five_step_by_step() {
    let mut arc = ArcInterp::new(Point::new(5, 0), Point::ORIGIN, Point::new(0, 5), Ccw, Classic).unwrap();
    let w = trace(&mut arc, Point::new(5, 0), Point::ORIGIN, Classic);
    use Step as S;
    assert_eq!(w.steps, [S::XN, S::YP, S::YP, S::YP, S::XN, S::YP, S::XN, S::YP, S::XN, S::XN]);
    // Diagonal: the nearest lattice point of each row (below 45°) or column (above).
    let mut arc = ArcInterp::new(Point::new(5, 0), Point::ORIGIN, Point::new(0, 5), Ccw, Diagonal).unwrap();
    let w = trace(&mut arc, Point::new(5, 0), Point::ORIGIN, Diagonal);
    let expected = [(5, 0), (5, 1), (5, 2), (4, 3), (3, 4), (2, 5), (1, 5), (0, 5)].map(|(x, y)| Point::new(x, y));
    assert_eq!(w.points, expected);
}

/// The textbook tables, literally: the quadrant by the signs of (x, y) with the axis that
/// the direction of travel leaves from, then the move for F >= 0 and for F < 0.
fn table_move(x: i64, y: i64, f: i64, rotation: Rotation) -> Step {
    use Step as S;
    // (move for F >= 0, move for F < 0)
    let (ge, lt) = match rotation {
        Ccw if x > 0 && y >= 0 => (S::XN, S::YP), // NR1
        Ccw if x <= 0 && y > 0 => (S::YN, S::XN), // NR2
        Ccw if x < 0 && y <= 0 => (S::XP, S::YN), // NR3
        Ccw => (S::YP, S::XP),                    // NR4
        Cw if x >= 0 && y > 0 => (S::YN, S::XP),  // SR1
        Cw if x < 0 && y >= 0 => (S::XP, S::YP),  // SR2
        Cw if x <= 0 && y < 0 => (S::YP, S::XN),  // SR3
        Cw => (S::XN, S::YN),                     // SR4
    };
    if f >= 0 { ge } else { lt }
}

/// Walks the literal tables (F recomputed from scratch at every point) until `end`.
fn table_walk(start: (i64, i64), end: (i64, i64), rotation: Rotation, full: bool, cap: usize) -> Vec<Step> {
    let r2 = start.0 * start.0 + start.1 * start.1;
    let (mut x, mut y) = start;
    let mut steps = Vec::new();
    loop {
        let s = table_move(x, y, x * x + y * y - r2, rotation);
        x += s.x as i64;
        y += s.y as i64;
        steps.push(s);
        assert!(steps.len() <= cap, "table walk did not reach {end:?}");
        if (x, y) == end && (!full || steps.len() > 4) {
            return steps;
        }
    }
}

#[test]
fn classic_matches_the_tables_in_every_quadrant_and_direction() {
    for r in 2..=25i64 {
        let axes = [(r, 0), (0, r), (-r, 0), (0, -r)];
        for rotation in [Ccw, Cw] {
            for (i, s) in axes.iter().enumerate() {
                // Quarter, half and three-quarter arcs, and the full circle.
                for k in 1..=4 {
                    let e = if rotation == Ccw { axes[(i + k) % 4] } else { axes[(i + 4 - k) % 4] };
                    let start = Point::new(s.0 as i32, s.1 as i32);
                    let end = Point::new(e.0 as i32, e.1 as i32);
                    let mut arc = ArcInterp::new(start, Point::ORIGIN, end, rotation, Classic).unwrap();
                    let w = trace(&mut arc, start, Point::ORIGIN, Classic);
                    let expected = table_walk(*s, e, rotation, k == 4, 10 * r as usize);
                    assert_eq!(w.steps, expected, "r {r} from {s:?} {k} quarters {rotation:?}");
                    assert_eq!(w.len() as i64, 2 * r * k as i64, "classic takes 2R per quarter");
                    assert_eq!(w.tail_len(), 0);
                }
            }
        }
    }
    // Starts off the axes: every lattice point of a few circles, full turns.
    for (x, y) in [(3, 4), (-4, 3), (-3, -4), (4, -3), (5, 12), (-12, -5), (1, 1), (2, -7), (-6, 9)] {
        for rotation in [Ccw, Cw] {
            let start = Point::new(x as i32, y as i32);
            let mut arc = ArcInterp::new(start, Point::ORIGIN, start, rotation, Classic).unwrap();
            let w = trace(&mut arc, start, Point::ORIGIN, Classic);
            assert_eq!(w.steps, table_walk((x, y), (x, y), rotation, true, 200), "from ({x}, {y}) {rotation:?}");
        }
    }
}

#[test]
fn full_circles_take_8r_classic_and_about_4_root_2_r_diagonal_steps() {
    for r in 1..=40 {
        for (x, y) in [(r, 0), (0, r), (-r, 0), (0, -r)] {
            for rotation in [Ccw, Cw] {
                let c = Point::new(-17, 33);
                let start = Point::new(c.x + x, c.y + y);
                let mut arc = ArcInterp::new(start, c, start, rotation, Classic).unwrap();
                let w = trace(&mut arc, start, c, Classic);
                assert_eq!(w.len(), 8 * r as usize, "classic r {r}");
                check_arc(&w, start, c, start, rotation, Classic);

                let mut arc = ArcInterp::new(start, c, start, rotation, Diagonal).unwrap();
                let w = trace(&mut arc, start, c, Diagonal);
                let analytic = 4.0 * SQRT_2 * r as f64;
                assert!((w.len() as f64 - analytic).abs() <= 4.0, "diagonal r {r}: {} vs {analytic}", w.len());
                assert_eq!(w.last(), start);
                check_arc(&w, start, c, start, rotation, Diagonal);
            }
        }
    }
}

#[test]
fn arcs_across_quadrants_end_on_their_end_points() {
    // (3, 4) → (4, −3) counter-clockwise sweeps 270° through three boundaries.
    let cases = [
        ((3, 4), (4, -3), Ccw),
        ((3, 4), (4, -3), Cw),
        ((-5, 0), (5, 0), Ccw),
        ((0, 13), (-12, -5), Cw),
        ((7, -1), (-1, 7), Ccw),
        ((7, -1), (-1, 7), Cw),
    ];
    for ((sx, sy), (ex, ey), rotation) in cases {
        for method in [Classic, Diagonal] {
            let (start, end) = (Point::new(sx, sy), Point::new(ex, ey));
            let mut arc = ArcInterp::new(start, Point::ORIGIN, end, rotation, method).unwrap();
            let w = trace(&mut arc, start, Point::ORIGIN, method);
            check_arc(&w, start, Point::ORIGIN, end, rotation, method);
            assert_eq!(w.tail_len(), 0, "end on the circle is on the path");
        }
    }
}

#[test]
fn tiny_radii_and_every_tolerated_end_terminate_exactly() {
    // Every start with |s| <= 4 and every end within the tolerance, both methods and
    // directions: the trace ends on the end and stays short.
    for sx in -4..=4 {
        for sy in -4..=4 {
            let s = Point::new(sx, sy);
            if s == Point::ORIGIN || r2(s, Point::ORIGIN) > 16 {
                continue;
            }
            for ex in -7..=7 {
                for ey in -7..=7 {
                    let e = Point::new(ex, ey);
                    for rotation in [Ccw, Cw] {
                        for method in [Classic, Diagonal] {
                            match ArcInterp::new(s, Point::ORIGIN, e, rotation, method) {
                                Ok(mut arc) => {
                                    let w = walk(&mut arc, s, method == Classic, ArcInterp::tail_steps, 100);
                                    assert_eq!(w.last(), e, "{s:?}→{e:?} {rotation:?} {method:?}");
                                    if off_circle(e, Point::ORIGIN, s) == 0.0 {
                                        check_arc(&w, s, Point::ORIGIN, e, rotation, method);
                                    }
                                }
                                Err(err) => {
                                    assert_eq!(err, ArcError::EndOffCurve);
                                    assert!(e == Point::ORIGIN || off_circle(e, Point::ORIGIN, s) > 2.0);
                                }
                            }
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn a_radius_of_one_goes_around_the_centre_not_through_it() {
    let s = Point::new(1, 0);
    let mut arc = ArcInterp::new(s, Point::ORIGIN, s, Ccw, Classic).unwrap();
    let w = trace(&mut arc, s, Point::ORIGIN, Classic);
    assert_eq!(w.len(), 8);
    assert!(!w.points.contains(&Point::ORIGIN));
    let mut arc = ArcInterp::new(s, Point::ORIGIN, Point::new(0, 1), Ccw, Classic).unwrap();
    assert_eq!(trace(&mut arc, s, Point::ORIGIN, Classic).len(), 2);
}

#[test]
fn bad_arcs_are_refused() {
    let p = Point::new(10, 0);
    assert_eq!(ArcInterp::new(p, p, p, Ccw, Classic).err(), Some(ArcError::ZeroRadius));
    assert_eq!(ArcInterp::new(p, Point::ORIGIN, Point::new(0, 13), Ccw, Classic).err(), Some(ArcError::EndOffCurve));
    assert!(ArcInterp::new(p, Point::ORIGIN, Point::new(0, 12), Ccw, Classic).is_ok());
    assert_eq!(ArcInterp::new(p, Point::ORIGIN, Point::ORIGIN, Ccw, Classic).err(), Some(ArcError::EndOffCurve));
    let far = Point::new(MAX_RADIUS_STEPS + 1, 0);
    assert_eq!(ArcInterp::new(far, Point::ORIGIN, far, Ccw, Classic).err(), Some(ArcError::TooLarge));
    let corner = Point::new(i32::MIN, i32::MAX);
    assert_eq!(
        ArcInterp::new(corner, Point::new(i32::MAX, i32::MIN), corner, Cw, Diagonal).err(),
        Some(ArcError::TooLarge)
    );
}

#[test]
fn the_tangent_is_perpendicular_to_the_radius_in_the_direction_of_travel() {
    let s = Point::new(30, 0);
    let arc = ArcInterp::new(s, Point::ORIGIN, s, Ccw, Classic).unwrap();
    let t = arc.tangent();
    assert!(t.x.abs() < 1e-6 && (t.y - 1.0).abs() < 1e-6, "{t:?}");
    let arc = ArcInterp::new(s, Point::ORIGIN, s, Cw, Classic).unwrap();
    let t = arc.tangent();
    assert!(t.x.abs() < 1e-6 && (t.y + 1.0).abs() < 1e-6, "{t:?}");
    // Along whole circles: unit length, perpendicular to the radius, and every step goes
    // forward along it.
    for rotation in [Ccw, Cw] {
        for method in [Classic, Diagonal] {
            let c = Point::new(7, -3);
            let s = Point::new(7 + 37, -3 + 11);
            let mut arc = ArcInterp::new(s, c, s, rotation, method).unwrap();
            let mut p = s;
            loop {
                let t = arc.tangent();
                let (rx, ry) = ((p.x - c.x) as f32, (p.y - c.y) as f32);
                assert!(((t.x * t.x + t.y * t.y) - 1.0).abs() < 1e-5);
                assert!((t.x * rx + t.y * ry).abs() / (rx * rx + ry * ry).sqrt() < 1e-5, "not perpendicular at {p:?}");
                let turn = rx * t.y - ry * t.x;
                assert!(if rotation == Ccw { turn > 0.0 } else { turn < 0.0 }, "wrong way at {p:?}");
                let Some(step) = arc.next_step().unwrap() else { break };
                assert!(t.x * step.x as f32 + t.y * step.y as f32 >= 0.0, "step {step:?} against the tangent at {p:?}");
                p = p.stepped(step);
            }
        }
    }
}

#[test]
fn the_largest_circles_do_not_overflow() {
    // Radius 100_000 around the origin, and a circle through opposite corners of the
    // ±100_000 machine (radius 282_843); a quarter at the radius limit.
    let cases = [
        (Point::new(100_000, 0), Point::ORIGIN, Point::new(100_000, 0), Ccw),
        (Point::new(100_000, 100_000), Point::new(-100_000, -100_000), Point::new(100_000, 100_000), Cw),
        (Point::new(MAX_RADIUS_STEPS, 0), Point::ORIGIN, Point::new(0, MAX_RADIUS_STEPS), Ccw),
        (Point::new(-100_000, 100_000), Point::new(100_000, -100_000), Point::new(-100_000, -300_000), Ccw),
    ];
    for (start, center, end, rotation) in cases {
        for method in [Classic, Diagonal] {
            let mut arc = ArcInterp::new(start, center, end, rotation, method).unwrap();
            let w = trace(&mut arc, start, center, method);
            check_arc(&w, start, center, end, rotation, method);
        }
    }
    // The full circle of radius 100_000 from an axis: exactly 8R classic steps, 4·√2·R ± 4
    // diagonal ones; the quarter at the limit exactly 2R classic steps.
    let s = Point::new(100_000, 0);
    let n =
        |method| trace(&mut ArcInterp::new(s, Point::ORIGIN, s, Ccw, method).unwrap(), s, Point::ORIGIN, method).len();
    assert_eq!(n(Classic), 800_000);
    assert!((n(Diagonal) as f64 - 400_000.0 * SQRT_2).abs() <= 4.0);
    let (s, e) = (Point::new(0, -MAX_RADIUS_STEPS), Point::new(MAX_RADIUS_STEPS, 0));
    let mut arc = ArcInterp::new(s, Point::ORIGIN, e, Ccw, Classic).unwrap();
    assert_eq!(trace(&mut arc, s, Point::ORIGIN, Classic).len(), 2 * MAX_RADIUS_STEPS as usize);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

    /// Random arcs with lattice ends rounded from random angles (so generally off the circle).
    #[test]
    fn random_arcs_stay_on_the_circle_and_end_exactly(
        cx in -100_000i32..100_000, cy in -100_000i32..100_000,
        sx in -300i32..300, sy in -300i32..300,
        end_angle in 0.0f64..TAU, ccw: bool, classic: bool,
    ) {
        prop_assume!((sx, sy) != (0, 0));
        let (c, method, rotation) = (Point::new(cx, cy), if classic { Classic } else { Diagonal }, if ccw { Ccw } else { Cw });
        let start = Point::new(cx + sx, cy + sy);
        let r = libm::sqrt((sx * sx + sy * sy) as f64);
        let end = Point::new(cx + libm::round(r * libm::cos(end_angle)) as i32, cy + libm::round(r * libm::sin(end_angle)) as i32);
        let mut arc = ArcInterp::new(start, c, end, rotation, method).unwrap();
        let w = trace(&mut arc, start, c, method);
        check_arc(&w, start, c, end, rotation, method);
    }

    /// An arc to any point of a full circle's path is that path's prefix, with no finish.
    #[test]
    fn arcs_to_points_of_the_path_follow_the_full_circle(
        sx in -200i32..200, sy in -200i32..200, pick in 0.0f64..1.0, ccw: bool, classic: bool,
    ) {
        prop_assume!((sx, sy) != (0, 0));
        let (method, rotation) = (if classic { Classic } else { Diagonal }, if ccw { Ccw } else { Cw });
        let start = Point::new(sx, sy);
        let mut full = ArcInterp::new(start, Point::ORIGIN, start, rotation, method).unwrap();
        let circle = trace(&mut full, start, Point::ORIGIN, method);
        prop_assert_eq!(circle.last(), start);
        prop_assert_eq!(circle.tail_len(), 0);
        let k = 1 + ((circle.len() - 2) as f64 * pick) as usize;
        let end = circle.points[k];
        prop_assume!(cross(offset(start, Point::ORIGIN), offset(end, Point::ORIGIN)) != 0);
        let mut arc = ArcInterp::new(start, Point::ORIGIN, end, rotation, method).unwrap();
        let w = trace(&mut arc, start, Point::ORIGIN, method);
        prop_assert_eq!(&w.points[..], &circle.points[..=k]);
    }

    /// Garbage in never panics and never hangs.
    #[test]
    fn any_input_is_refused_or_drawn(
        s in any::<(i32, i32)>(), c in any::<(i32, i32)>(), e in any::<(i32, i32)>(),
        ccw: bool, classic: bool,
    ) {
        let (method, rotation) = (if classic { Classic } else { Diagonal }, if ccw { Ccw } else { Cw });
        let (s, c, e) = (Point::new(s.0, s.1), Point::new(c.0, c.1), Point::new(e.0, e.1));
        if let Ok(mut arc) = ArcInterp::new(s, c, e, rotation, method) {
            // Within tolerance only by chance; tiny circles are walked.
            if r2(s, c) < 10_000 {
                trace(&mut arc, s, c, method);
            }
        }
    }
}

#[test]
fn isqrt_matches_the_integer_square_root_over_every_squared_radius() {
    let max = MAX_RADIUS_STEPS as u64;
    let limit = 2 * max * max;
    // Perfect squares and their neighbours, across the whole range, and the limit itself.
    let mut r = 0u64;
    while r * r <= limit {
        for n in [r * r, (r * r).saturating_sub(1), r * r + 1, (r + 1) * (r + 1) - 1] {
            if n <= limit {
                assert_eq!(super::isqrt(n), n.isqrt(), "isqrt({n})");
            }
        }
        r += 1 + r / 64;
    }
    assert_eq!(super::isqrt(limit), limit.isqrt());
    for n in 0..10_000u64 {
        assert_eq!(super::isqrt(n), n.isqrt(), "isqrt({n})");
    }
}

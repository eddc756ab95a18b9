//! Axis-aligned ellipses and elliptic arcs by point-by-point comparison (逐点比较法).
//!
//! The ellipse with semi-axis `a` along X and `b` along Y is the zero set of
//! `F = b²x² + a²y² − a²b²` around its centre. It is traced by the same rules as circles (see
//! [`crate::interp::conic`]): `classic` steps one axis at a time, inward when `F >= 0` and
//! outward otherwise (error <= 1 step, a full ellipse started on an axis takes `4(a + b)`
//! steps); `diagonal` picks between the inward, outward and diagonal moves by a midpoint test
//! (error <= 0.5 step, about `4·√(a² + b²)` steps for a full ellipse). `F` is kept in `i128`:
//! `a²b²` reaches 10²⁴ at [`MAX_RADIUS_STEPS`]. Tips narrower than a step are climbed and
//! come back along the axis instead of being cut off (see [`crate::interp::conic`]).
//!
//! Start and end points are lattice points and so lie slightly off the ideal ellipse; both may
//! be up to [`ARC_END_TOLERANCE_STEPS`] away (measured as the true Euclidean distance, see
//! [`distance_to_ellipse`]). The trace ends exactly on the end point.

use crate::geom::{Point, Rotation, Step};
use crate::interp::arc::{ARC_END_TOLERANCE_STEPS, ArcError, MAX_RADIUS_STEPS, offset, point_at, round};
use crate::interp::conic::{Plan, Tracer};
use crate::interp::{CurveError, Interpolator, Method, Tangent};

#[cfg(test)]
mod tests;

/// Bisection rounds of [`distance_to_ellipse`]; enough to exhaust `f64` precision.
const DISTANCE_ITERATIONS: u32 = 200;

/// An ellipse or elliptic arc; see the module documentation.
#[derive(Clone, Debug)]
pub struct EllipseInterp {
    tracer: Tracer<i128>,
    center: Point,
    end: Point,
    rotation: Rotation,
}

impl EllipseInterp {
    /// An elliptic arc around `center` with semi-axes `a` (along X) and `b` (along Y), from
    /// `start` to `end` in absolute steps.
    ///
    /// `start` and `end` may each lie up to [`ARC_END_TOLERANCE_STEPS`] off the ellipse; the
    /// trace still ends exactly on `end`. `end == start`, or an end on the ray from the centre
    /// through the start, means the full ellipse (one turn).
    pub fn new(
        start: Point,
        center: Point,
        a: i32,
        b: i32,
        end: Point,
        rotation: Rotation,
        method: Method,
    ) -> Result<Self, ArcError> {
        if a <= 0 || b <= 0 {
            return Err(ArcError::ZeroRadius);
        }
        if a > MAX_RADIUS_STEPS || b > MAX_RADIUS_STEPS {
            return Err(ArcError::TooLarge);
        }
        let s = offset(start, center);
        let e = offset(end, center);
        if s == (0, 0) {
            return Err(ArcError::ZeroRadius);
        }
        let tol = ARC_END_TOLERANCE_STEPS as f64;
        let (af, bf) = (a as f64, b as f64);
        if distance_to_ellipse(af, bf, s.0 as f64, s.1 as f64) > tol {
            return Err(ArcError::StartOffCurve);
        }
        if e == (0, 0) || distance_to_ellipse(af, bf, e.0 as f64, e.1 as f64) > tol {
            return Err(ArcError::EndOffCurve);
        }
        let plan = Plan::ToEnd { near: nearest_on_ellipse(af, bf, e.0 as f64, e.1 as f64) };
        Ok(Self::build(s, e, a, b, center, end, rotation, method, plan))
    }

    /// An elliptic arc that starts at the pen point `start`, which lies at parametric angle
    /// `start_angle_rad` (the point `center + (a·cos t, b·sin t)`); the centre is rounded to the
    /// lattice, so `start` is within 0.71 step of the ellipse.
    ///
    /// A positive `sweep_rad` turns counter-clockwise, a negative one clockwise; a sweep of at
    /// least 2π either way draws the full ellipse (one turn). The end is the lattice point
    /// nearest to the ideal end at parametric angle `start_angle + sweep` ([`end`](Self::end)
    /// tells it). The number of quadrants swept comes from the angles, not from the rounded
    /// points, so rounding never turns a short arc into a full turn or back: an arc shorter
    /// than half a turn whose end rounds onto the start takes no steps.
    pub fn from_angles(
        start: Point,
        a: i32,
        b: i32,
        start_angle_rad: f32,
        sweep_rad: f32,
        method: Method,
    ) -> Result<Self, ArcError> {
        if !start_angle_rad.is_finite() || !sweep_rad.is_finite() {
            return Err(ArcError::NotFinite);
        }
        if a <= 0 || b <= 0 {
            return Err(ArcError::ZeroRadius);
        }
        if a > MAX_RADIUS_STEPS || b > MAX_RADIUS_STEPS {
            return Err(ArcError::TooLarge);
        }
        let (t, sweep, af, bf) = (start_angle_rad as f64, sweep_rad as f64, a as f64, b as f64);
        let s = (round(af * libm::cos(t)), round(bf * libm::sin(t)));
        if s == (0, 0) {
            return Err(ArcError::ZeroRadius);
        }
        let center = point_at(start, (-s.0, -s.1))?;
        let rotation = if sweep < 0.0 { Rotation::Clockwise } else { Rotation::CounterClockwise };
        let (e, plan) = if libm::fabs(sweep) >= core::f64::consts::TAU {
            (s, Plan::ToEnd { near: (s.0 as f64, s.1 as f64) })
        } else {
            // The ideal arc, between the requested parametric angles; the lattice start and
            // end are its ends rounded.
            let from = (af * libm::cos(t), bf * libm::sin(t));
            let end_param = t + sweep;
            let to = (af * libm::cos(end_param), bf * libm::sin(end_param));
            let e = (round(to.0), round(to.1));
            (e, Plan::between(from, to, sweep, e == s))
        };
        if e == (0, 0) {
            // Cannot happen with semi-axes of a step or more (one of |a·cos|, |b·sin| is at
            // least 0.71); refused rather than traced should it ever.
            return Err(ArcError::EndOffCurve);
        }
        let end = point_at(center, e)?;
        Ok(Self::build(s, e, a, b, center, end, rotation, method, plan))
    }

    #[allow(clippy::too_many_arguments)]
    fn build(
        s: (i64, i64),
        e: (i64, i64),
        a: i32,
        b: i32,
        center: Point,
        end: Point,
        rotation: Rotation,
        method: Method,
        plan: Plan,
    ) -> Self {
        let (a2, b2) = (a as i64 * a as i64, b as i64 * b as i64);
        let c = a2 as i128 * b2 as i128;
        let tracer = Tracer::new(s, e, plan, (b2, a2), c, (a as i64, b as i64), rotation, method);
        EllipseInterp { tracer, center, end, rotation }
    }

    /// The centre, in absolute steps.
    pub fn center(&self) -> Point {
        self.center
    }

    /// The point where the trace ends, in absolute steps.
    pub fn end(&self) -> Point {
        self.end
    }

    /// The direction of travel.
    pub fn rotation(&self) -> Rotation {
        self.rotation
    }
}

impl Interpolator for EllipseInterp {
    fn next_step(&mut self) -> Result<Option<Step>, CurveError> {
        Ok(self.tracer.next())
    }

    fn tangent(&self) -> Tangent {
        self.tracer.tangent()
    }
}

/// Euclidean distance from `(x, y)` (relative to the centre) to the ellipse with semi-axes
/// `a` along X and `b` along Y (both > 0).
pub fn distance_to_ellipse(a: f64, b: f64, x: f64, y: f64) -> f64 {
    let (px, py) = nearest_on_ellipse(a, b, x, y);
    libm::hypot(px - x, py - y)
}

/// The point of the ellipse with semi-axes `a` along X and `b` along Y (both > 0) nearest to
/// `(x, y)` (relative to the centre); in the same closed quadrant (a zero coordinate counts as
/// positive where the nearest point leaves the axis).
///
/// The nearest point `p` satisfies `p = (a²x/(t + a²), b²y/(t + b²))` for the root `t` of a
/// monotone function, found by bisection (D. Eberly, "Distance from a Point to an Ellipse").
pub fn nearest_on_ellipse(a: f64, b: f64, x: f64, y: f64) -> (f64, f64) {
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

//! Axis-aligned ellipses and elliptic arcs: their setup (centre, semi-axes, how far the start
//! and end lie from the curve, where the trace ends) and the nearest point of an ellipse. The
//! stepping is the conic tracer's ([`crate::motion::interp::conic`]).
//!
//! The ellipse with semi-axis `a` along X and `b` along Y is the zero set of
//! `F = b²x² + a²y² − a²b²` around its centre. It is traced by the same rules as circles:
//! `classic` steps one axis at a time, inward when `F >= 0` and outward otherwise (error <= 1
//! step, a full ellipse started on an axis takes `4(a + b)` steps); `diagonal` picks between
//! the inward, outward and diagonal moves by a midpoint test (error <= 0.5 step, about
//! `4·√(a² + b²)` steps for a full ellipse). Tips narrower than a step are climbed and come
//! back along the axis instead of being cut off. `F` grows with the cube of the ellipse's size,
//! hence [`MAX_ELLIPSE_AXIS_STEPS`], which keeps every value of a trace inside `i64`.
//!
//! Start and end points are lattice points and so lie slightly off the ideal ellipse; both may
//! be up to [`ARC_END_TOLERANCE_STEPS`] away (measured as the true Euclidean distance, see
//! [`foot`]). The trace ends exactly on the end point.
//!
//! Setup is `f32` and integer arithmetic only. The nearest point is found without the
//! cancellation that `f32` would suffer near the curve (where `F` is a small difference of
//! numbers up to 2⁷²): `F` itself is computed exactly in integers and the equation for the
//! nearest point is written in terms of it, so the offset to the curve comes out to `f32`'s
//! relative precision (about 10⁻⁶ step) for any size of ellipse.

use crate::geom::{Point, Rotation, Step};
use crate::math;
use crate::motion::interp::arc::{ARC_END_TOLERANCE_STEPS, ArcError, narrow, offset};
use crate::motion::interp::conic::{GATE_SCALE, Tracer};
use crate::motion::interp::interpolator::{CurveError, Filled, Interpolator, Tangent};
use crate::motion::method::Method;

#[cfg(test)]
mod tests;

/// Largest semi-axis of an ellipse, in steps: 2¹⁸ = 262_144, 1.3 m at 200 steps/mm, more than
/// the machine's diagonal. `F` and its changes grow with the cube of the ellipse's size: at this
/// limit every value a trace computes stays below 2⁶¹ (see [`crate::motion::interp::conic`]); twice the
/// limit would take them to the edge of `i64`. Circles of any radius up to
/// [`MAX_RADIUS_STEPS`](crate::motion::interp::arc::MAX_RADIUS_STEPS) are arcs, not ellipses.
pub const MAX_ELLIPSE_AXIS_STEPS: i32 = 1 << 18;

/// Most Newton steps of [`foot`]'s root search. Points near the curve take two to four; only
/// points far inside a flat ellipse, near its long axis, take more.
const ROOT_ITERATIONS_MAX: u32 = 64;

/// `|F|` of a point within twice the semi-axes, as `f32`, up to which `F` is computed exactly:
/// the `f32` estimate is then within 2⁵⁴ of `F`, so `|F| < 2⁶²` and its `i64` value, computed
/// modulo 2⁶⁴, is exact. Farther from the curve the estimate is used (it has no cancellation
/// there).
const EXACT_RESIDUAL_MAX: f32 = 2_305_843_009_213_693_952.0; // 2⁶¹

/// An ellipse or elliptic arc; see the module documentation.
#[derive(Clone, Debug)]
pub struct EllipseInterp {
    tracer: Tracer,
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
        if a > MAX_ELLIPSE_AXIS_STEPS || b > MAX_ELLIPSE_AXIS_STEPS {
            return Err(ArcError::TooLarge);
        }
        let s = offset(start, center);
        let e = offset(end, center);
        if s == (0, 0) {
            return Err(ArcError::ZeroRadius);
        }
        if foot_within_tolerance(a, b, s).is_none() {
            return Err(ArcError::StartOffCurve);
        }
        let Some(d) = foot_within_tolerance(a, b, e).filter(|_| e != (0, 0)) else {
            return Err(ArcError::EndOffCurve);
        };
        let scale = GATE_SCALE as f32;
        let near =
            (e.0 * GATE_SCALE + math::round(d.0 * scale) as i64, e.1 * GATE_SCALE + math::round(d.1 * scale) as i64);
        let (a2, b2) = (a as i64 * a as i64, b as i64 * b as i64);
        // a²b² modulo 2⁶⁴; the tracer only ever needs F near the curve, which fits.
        let c = a2.wrapping_mul(b2);
        let tracer = Tracer::new(narrow(s), narrow(e), near, (b2, a2), c, (a, b), rotation, method);
        Ok(EllipseInterp { tracer })
    }

    /// The tracer, for tests that step it by the rules alone.
    #[cfg(test)]
    pub(crate) fn tracer(&self) -> &Tracer {
        &self.tracer
    }
}

impl Interpolator for EllipseInterp {
    fn next_step(&mut self) -> Result<Option<Step>, CurveError> {
        Ok(self.tracer.next_step())
    }

    fn tangent(&self) -> Tangent {
        self.tracer.tangent()
    }

    fn fill(&mut self, out: &mut [Step]) -> Filled {
        self.tracer.fill(out)
    }
}

/// [`foot`] of `p`, if `p` lies within [`ARC_END_TOLERANCE_STEPS`] of the ellipse.
fn foot_within_tolerance(a: i32, b: i32, p: (i64, i64)) -> Option<(f32, f32)> {
    let tol = ARC_END_TOLERANCE_STEPS as i64;
    // The ellipse lies within |x| <= a, |y| <= b.
    if p.0.abs() > a as i64 + tol || p.1.abs() > b as i64 + tol {
        return None;
    }
    let d = foot(a, b, p);
    if math::hypot(d.0, d.1) <= ARC_END_TOLERANCE_STEPS as f32 { Some(d) } else { None }
}

/// From lattice point `p` (relative to the centre) to the point of the ellipse with semi-axes
/// `a` along X and `b` along Y (both > 0) nearest to it: `nearest − p`. The nearest point lies
/// in the same closed quadrant as `p` (a zero coordinate counts as positive where the nearest
/// point leaves the axis).
///
/// The nearest point is `(x/(1 + λb²), y/(1 + λa²))` for the root `λ` of a monotone function
/// (D. Eberly, "Distance from a Point to an Ellipse", with `s = λ·a²` for `a >= b`), found by
/// Newton's method. Written as `F(p)/(a²b²)` less terms that vanish at `λ = 0`, the function has
/// no cancellation near the curve. To `f32`'s relative precision for points within twice the
/// semi-axes; a few `f32` roundings of the coordinates beyond.
pub fn foot(a: i32, b: i32, p: (i64, i64)) -> (f32, f32) {
    // Work in the first quadrant with the major axis first.
    let swap = a < b;
    let (e0, e1) = if swap { (b as i64, a as i64) } else { (a as i64, b as i64) };
    let (y0, y1) = if swap { (p.1.abs(), p.0.abs()) } else { (p.0.abs(), p.1.abs()) };
    let (d0, d1) = if y1 > 0 {
        if y0 > 0 {
            foot_off_axes(e0, e1, y0, y1)
        } else {
            // On the minor axis: the minor vertex.
            (0.0, (e1 - y1) as f32)
        }
    } else {
        // On the major axis: off it toward (e0·ξ, e1·√(1 − ξ²)) when inside the evolute,
        // else the major vertex.
        let (numer, denom) = (e0 * y0, e0 * e0 - e1 * e1);
        if numer < denom {
            let xi = numer as f32 / denom as f32;
            let one_less_xi = (denom - numer) as f32 / denom as f32;
            (y0 as f32 * (e1 * e1) as f32 / denom as f32, e1 as f32 * math::sqrt(one_less_xi * (1.0 + xi)))
        } else {
            ((e0 - y0) as f32, 0.0)
        }
    };
    let (dx, dy) = if swap { (d1, d0) } else { (d0, d1) };
    (if p.0 < 0 { -dx } else { dx }, if p.1 < 0 { -dy } else { dy })
}

/// [`foot`] of `(y0, y1)`, both positive, for the ellipse with semi-axes `e0 >= e1` along them.
fn foot_off_axes(e0: i64, e1: i64, y0: i64, y1: i64) -> (f32, f32) {
    let (e0f, e1f, y0f, y1f) = (e0 as f32, e1 as f32, y0 as f32, y1 as f32);
    let (z0, z1) = (y0f / e0f, y1f / e1f);
    let r0 = (e0f / e1f) * (e0f / e1f);
    // z0² + z1² − 1, z0² − 1 and z1² − 1, each from exact integers.
    let sums = Sums {
        both: residual(e0, e1, y0, y1) / ((e0f * e1f) * (e0f * e1f)),
        first: (y0 - e0) as f32 * (y0 + e0) as f32 / (e0f * e0f),
        second: (y1 - e1) as f32 * (y1 + e1) as f32 / (e1f * e1f),
    };
    let s = root(r0, z0, z1, &sums, e0 as f32 * (y0 - e0) as f32 / (e1f * e1f));
    let u0 = s / r0;
    (-y0f * u0 / (1.0 + u0), -y1f * s / (1.0 + s))
}

/// `F = e1²·y0² + e0²·y1² − e0²e1²` as `f32`: computed exactly in integers near the curve
/// (see [`EXACT_RESIDUAL_MAX`]), estimated in `f32` farther out.
fn residual(e0: i64, e1: i64, y0: i64, y1: i64) -> f32 {
    let (e0s, e1s) = (e0 * e0, e1 * e1);
    let (y0f, y1f) = (y0 as f32, y1 as f32);
    let estimate = e1s as f32 * (y0f * y0f) + e0s as f32 * (y1f * y1f) - e0s as f32 * e1s as f32;
    if y0 <= 2 * e0 && y1 <= 2 * e1 && estimate.abs() <= EXACT_RESIDUAL_MAX {
        let f = e1s.wrapping_mul(y0 * y0).wrapping_add(e0s.wrapping_mul(y1 * y1)).wrapping_sub(e0s.wrapping_mul(e1s));
        f as f32
    } else {
        estimate
    }
}

/// The constant parts of [`root`]'s function: `z0² + z1² − 1`, `z0² − 1`, `z1² − 1`.
struct Sums {
    both: f32,
    first: f32,
    second: f32,
}

/// Below this `u`, `φ(u) = 1 − 1/(1 + u)²` is smaller than `1/(1 + u)²` (`√2 − 1`).
const PHI_SMALLER_BELOW: f32 = core::f32::consts::SQRT_2 - 1.0;

/// The root `s > −1` of `G(s) = z0²·w0² + z1²·w1² − 1` with `w0 = 1/(1 + s/r0)`,
/// `w1 = 1/(1 + s)` (`z1 > 0`, `r0 >= 1`): Eberly's function. Near `s = 0` its terms nearly
/// cancel, so each term is written in the smaller of its two forms, `z²·w²` or
/// `z² − z²·φ(u)` with `φ(u) = 1 − w² = u·(2 + u)·w²`, and the `z²` of the second forms are
/// summed with the −1 beforehand, exactly ([`Sums`]). Every piece is then no larger than `G`'s
/// own scale and `f32` rounding moves the root by a relative `10⁻⁷`.
///
/// `G` falls and is convex on `(−1, ∞)`, so Newton's method from a point left of the root
/// climbs to it without overshooting. The root lies right of `r0·(z0 − 1)` (`bound0`, passed in
/// from exact integers) and of `z1 − 1` (each term of `G` is at most 1 at the root), and right of
/// 0 when `G(0) >= 0`; when `G(0) < 0` the Newton step from 0 lands left of it (convexity).
// Written `!(value > 0.0)` on purpose: a NaN must stop the search.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn root(r0: f32, z0: f32, z1: f32, sums: &Sums, bound0: f32) -> f32 {
    let (a0, a1) = (z0 * z0, z1 * z1);
    let eval = |s: f32| {
        let u = s / r0;
        let (w0, w1) = (1.0 / (1.0 + u), 1.0 / (1.0 + s));
        let (t0, phi0) =
            if u < PHI_SMALLER_BELOW { (-a0 * u * (2.0 + u) * w0 * w0, true) } else { (a0 * w0 * w0, false) };
        let (t1, phi1) =
            if s < PHI_SMALLER_BELOW { (-a1 * s * (2.0 + s) * w1 * w1, true) } else { (a1 * w1 * w1, false) };
        let k = match (phi0, phi1) {
            (true, true) => sums.both,
            (true, false) => sums.first,
            (false, true) => sums.second,
            (false, false) => -1.0,
        };
        let slope = -2.0 * (a0 * w0 * w0 * w0 / r0 + a1 * w1 * w1 * w1);
        (k + t0 + t1, slope)
    };
    let g = sums.both;
    let from_zero = if g >= 0.0 { 0.0 } else { g / (2.0 * (a0 / r0 + a1)) };
    let mut s = math::max(math::max(from_zero, bound0), sums.second / (z1 + 1.0));
    for _ in 0..ROOT_ITERATIONS_MAX {
        let (value, slope) = eval(s);
        if !(value > 0.0) {
            break;
        }
        let next = s - value / slope;
        if !(next > s) {
            break;
        }
        s = next;
    }
    s
}

//! Circular arcs and full circles: their setup (centre, radius, end point, which way round) and
//! the limits and errors shared with [`crate::interp::ellipse`]. The stepping is the conic
//! tracer's ([`crate::interp::conic`]), with `F = x² + y² − R²`.
//!
//! Setup is `f32` and integer arithmetic only. The radius check compares squared lengths, which
//! are exact integers: `| |e| − R | = |e² − R²| / (|e| + R)`, the difference exact and the sum
//! to `f32` precision, so the decision at [`ARC_END_TOLERANCE_STEPS`] is right to about 10⁻⁶
//! step at any radius. Arcs given by angles take their points from `f32` sines and cosines:
//! `r·cos θ` is within about `r·2⁻²³` of the ideal (0.1 step at [`MAX_RADIUS_STEPS`], 10⁻⁵ step
//! at the radii of the machine's menu) before it is rounded to the lattice.

use crate::geom::{Point, Rotation, Step};
use crate::interp::conic::{GATE_SCALE, Plan, Tracer};
use crate::interp::{CurveError, Filled, Interpolator, Method, Tangent};
use crate::math;

#[cfg(test)]
mod tests;

/// How far an end point (and an ellipse's start point) may lie from the curve, in steps.
/// Integer end points of real arcs are generally off the curve by up to ~0.71 step; farther
/// than this is refused with [`ArcError::EndOffCurve`].
pub const ARC_END_TOLERANCE_STEPS: u32 = 2;

/// Largest offset of a circle's start from its centre on either axis, and largest radius of an
/// arc given by angles, in steps. Five times the machine's ±100_000-step travel, so that the
/// huge radii of G2/G3 arcs stay possible; every value a circle's trace computes stays below
/// 2³⁰ (see [`crate::interp::conic`]).
pub const MAX_RADIUS_STEPS: i32 = 1_000_000;

/// `|e² − R²|` above which an end cannot lie within [`ARC_END_TOLERANCE_STEPS`] of the circle:
/// `|e| + R <= 3·√2·MAX_RADIUS_STEPS < 2²²·1.02`, so an end within 2 steps has `|e² − R²| <=
/// 2·(|e| + R) < 2²⁴`. Below it, the difference converts to `f32` exactly.
const END_SQUARES_DIFFERENCE_MAX: i64 = 1 << 24;

/// Why an arc or an ellipse could not be set up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum ArcError {
    /// The start point is the centre, or a radius or semi-axis is not positive.
    ZeroRadius,
    /// The start point is more than [`ARC_END_TOLERANCE_STEPS`] from the ellipse.
    StartOffCurve,
    /// The end point is more than [`ARC_END_TOLERANCE_STEPS`] from the curve, or is its centre.
    EndOffCurve,
    /// A radius, semi-axis or point offset exceeds [`MAX_RADIUS_STEPS`] (for ellipses
    /// [`MAX_ELLIPSE_AXIS_STEPS`](crate::interp::ellipse::MAX_ELLIPSE_AXIS_STEPS)), or a computed
    /// point falls outside the `i32` step range.
    TooLarge,
    /// An angle is NaN or infinite.
    NotFinite,
}

/// A circular arc or full circle; see the module documentation.
#[derive(Clone, Debug)]
pub struct ArcInterp {
    tracer: Tracer,
    center: Point,
    end: Point,
    rotation: Rotation,
}

impl ArcInterp {
    /// An arc from `start` around `center` to `end`, in absolute steps.
    ///
    /// The radius is `|start − center|`. `end` may lie up to [`ARC_END_TOLERANCE_STEPS`] off the
    /// circle; the arc still ends exactly on it. `end == start`, or an end on the ray from the
    /// centre through the start, means one full turn.
    pub fn new(start: Point, center: Point, end: Point, rotation: Rotation, method: Method) -> Result<Self, ArcError> {
        let s = offset(start, center);
        let e = offset(end, center);
        if s == (0, 0) {
            return Err(ArcError::ZeroRadius);
        }
        let max = MAX_RADIUS_STEPS as i64;
        if s.0.abs() > max || s.1.abs() > max {
            return Err(ArcError::TooLarge);
        }
        // Beyond twice the limit an end cannot be within tolerance; checked before squaring.
        if e == (0, 0) || e.0.abs() > 2 * max || e.1.abs() > 2 * max {
            return Err(ArcError::EndOffCurve);
        }
        let r2 = s.0 * s.0 + s.1 * s.1;
        let e2 = e.0 * e.0 + e.1 * e.1;
        let diff = e2 - r2;
        if diff.abs() > END_SQUARES_DIFFERENCE_MAX {
            return Err(ArcError::EndOffCurve);
        }
        let off = (diff.abs() as i32) as f32 / (math::sqrt(e2 as f32) + math::sqrt(r2 as f32));
        if off > ARC_END_TOLERANCE_STEPS as f32 {
            return Err(ArcError::EndOffCurve);
        }
        // The nearest point of the circle lies on the end's own ray, as does the gate.
        let plan = Plan::ToEnd { near: (e.0 * GATE_SCALE, e.1 * GATE_SCALE) };
        Ok(Self::build(narrow(s), narrow(e), r2, center, end, rotation, method, plan))
    }

    /// An arc that starts at the pen point `start`, which lies at `start_angle_rad` on a circle
    /// of `radius` steps; the centre is `start − radius·(cos, sin)`, rounded to the lattice
    /// (so the actual radius, `|start − center|`, is within 0.71 step of `radius`, plus the
    /// `f32` error of the cosine: 0.1 step at [`MAX_RADIUS_STEPS`]).
    ///
    /// A positive `sweep_rad` turns counter-clockwise, a negative one clockwise; a sweep of at
    /// least 2π either way draws the full circle (one turn). The end is the lattice point
    /// nearest to the ideal end ([`end`](Self::end) tells it). The number of quadrants swept
    /// comes from the angles, not from the rounded points, so rounding never turns a short arc
    /// into a full turn or back: an arc shorter than half a turn whose end rounds onto the
    /// start takes no steps.
    pub fn from_angles(
        start: Point,
        radius: i32,
        start_angle_rad: f32,
        sweep_rad: f32,
        method: Method,
    ) -> Result<Self, ArcError> {
        if !start_angle_rad.is_finite() || !sweep_rad.is_finite() {
            return Err(ArcError::NotFinite);
        }
        if radius <= 0 {
            return Err(ArcError::ZeroRadius);
        }
        if radius > MAX_RADIUS_STEPS {
            return Err(ArcError::TooLarge);
        }
        let (sin, cos) = math::sin_cos(start_angle_rad);
        let r = radius as f32;
        let s = (round(r * cos), round(r * sin));
        if s == (0, 0) {
            return Err(ArcError::ZeroRadius);
        }
        let center = point_at(start, (-s.0, -s.1))?;
        let (sx, sy) = (s.0 as i64, s.1 as i64);
        let r2 = sx * sx + sy * sy;
        let rotation = if sweep_rad < 0.0 { Rotation::Clockwise } else { Rotation::CounterClockwise };
        let from = (s.0 as f32, s.1 as f32);
        let (e, plan) = if sweep_rad.abs() >= core::f32::consts::TAU {
            (s, Plan::ToEnd { near: (sx * GATE_SCALE, sy * GATE_SCALE) })
        } else {
            let r_actual = math::sqrt(r2 as f32);
            let end_angle = math::atan2(from.1, from.0) + sweep_rad;
            let (sin, cos) = math::sin_cos(end_angle);
            let to = (r_actual * cos, r_actual * sin);
            let e = (round(to.0), round(to.1));
            (e, Plan::between(from, to, sweep_rad, e == s))
        };
        let end = point_at(center, e)?;
        Ok(Self::build(s, e, r2, center, end, rotation, method, plan))
    }

    #[allow(clippy::too_many_arguments)]
    fn build(
        s: (i32, i32),
        e: (i32, i32),
        r2: i64,
        center: Point,
        end: Point,
        rotation: Rotation,
        method: Method,
        plan: Plan,
    ) -> Self {
        // Ceiling of the radius, for the step budget.
        let r = r2.unsigned_abs().isqrt() as i32 + 1;
        let tracer = Tracer::new(s, e, plan, (1, 1), r2, (r, r), rotation, method);
        ArcInterp { tracer, center, end, rotation }
    }

    /// The centre, in absolute steps.
    pub fn center(&self) -> Point {
        self.center
    }

    /// The point where the arc ends, in absolute steps.
    pub fn end(&self) -> Point {
        self.end
    }

    /// The direction of travel.
    pub fn rotation(&self) -> Rotation {
        self.rotation
    }

    /// The tracer, for tests that step it by the rules alone.
    #[cfg(test)]
    pub(crate) fn tracer(&self) -> &Tracer {
        &self.tracer
    }
}

impl Interpolator for ArcInterp {
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

/// `p − origin` in `i64` (cannot overflow).
pub(crate) fn offset(p: Point, origin: Point) -> (i64, i64) {
    (p.x as i64 - origin.x as i64, p.y as i64 - origin.y as i64)
}

/// An offset the caller has bounded (by the radius limits) as `i32`.
pub(crate) fn narrow(d: (i64, i64)) -> (i32, i32) {
    (d.0 as i32, d.1 as i32)
}

/// `origin + (dx, dy)`, or [`ArcError::TooLarge`] outside the `i32` range.
pub(crate) fn point_at(origin: Point, d: (i32, i32)) -> Result<Point, ArcError> {
    let x = i32::try_from(origin.x as i64 + d.0 as i64).map_err(|_| ArcError::TooLarge)?;
    let y = i32::try_from(origin.y as i64 + d.1 as i64).map_err(|_| ArcError::TooLarge)?;
    Ok(Point::new(x, y))
}

/// Nearest integer, halfway cases away from zero (saturating; callers bound their inputs).
pub(crate) fn round(v: f32) -> i32 {
    math::round(v) as i32
}

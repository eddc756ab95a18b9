//! Circular arcs and full circles: their setup (centre, radius, end point, which way round) and
//! the limits and errors shared with [`crate::motion::interp::ellipse`]. The stepping is the conic
//! tracer's ([`crate::motion::interp::conic`]), with `F = x² + y² − R²`.
//!
//! Setup is `f32` and integer arithmetic only. The radius check compares squared lengths, which
//! are exact integers: `| |e| − R | = |e² − R²| / (|e| + R)`, the difference exact and the sum
//! to `f32` precision, so the decision at [`ARC_END_TOLERANCE_STEPS`] is right to about 10⁻⁶
//! step at any radius.

use crate::geom::{Point, Rotation, Step};
use crate::math;
use crate::motion::interp::conic::{GATE_SCALE, Tracer};
use crate::motion::interp::interpolator::{CurveError, Filled, Interpolator, Tangent};
use crate::motion::interp::setup::CurveSetupError;
use crate::motion::method::Method;

#[cfg(test)]
mod tests;

/// How far an end point (and an ellipse's start point) may lie from the curve, in steps.
/// Integer end points of real arcs are generally off the curve by up to ~0.71 step; farther
/// than this is refused with [`ArcError::EndOffCurve`].
pub const ARC_END_TOLERANCE_STEPS: u32 = 2;

/// Largest offset of a circle's start from its centre on either axis, in steps. Five times the machine's ±100_000-step travel, so that the
/// huge radii of G2/G3 arcs stay possible; every value a circle's trace computes stays below
/// 2³⁰ (see [`crate::motion::interp::conic`]).
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
    /// [`MAX_ELLIPSE_AXIS_STEPS`](crate::motion::interp::ellipse::MAX_ELLIPSE_AXIS_STEPS)).
    TooLarge,
}

impl From<ArcError> for CurveSetupError {
    fn from(e: ArcError) -> Self {
        match e {
            ArcError::TooLarge => CurveSetupError::OutOfRange,
            ArcError::ZeroRadius | ArcError::StartOffCurve | ArcError::EndOffCurve => CurveSetupError::BadParameter,
        }
    }
}

/// A circular arc or full circle; see the module documentation.
#[derive(Clone, Debug)]
pub struct ArcInterp {
    tracer: Tracer,
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
        let near = (e.0 * GATE_SCALE, e.1 * GATE_SCALE);
        // Ceiling of the radius, for the step budget.
        let r = isqrt(r2.unsigned_abs()) as i32 + 1;
        let tracer = Tracer::new(narrow(s), narrow(e), near, (1, 1), r2, (r, r), rotation, method);
        Ok(ArcInterp { tracer })
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

/// ⌊√n⌋, exactly as `u64::isqrt`, for `n` up to 2·[`MAX_RADIUS_STEPS`]² (a squared radius):
/// the FPU's square root, then corrected by whole steps. `u64::isqrt` links 540 B of code.
fn isqrt(n: u64) -> u64 {
    let mut r = u64::from(math::sqrt(n as f32) as u32);
    while r * r > n {
        r -= 1;
    }
    while (r + 1) * (r + 1) <= n {
        r += 1;
    }
    r
}

/// `p − origin` in `i64` (cannot overflow).
pub(crate) fn offset(p: Point, origin: Point) -> (i64, i64) {
    (p.x as i64 - origin.x as i64, p.y as i64 - origin.y as i64)
}

/// An offset the caller has bounded (by the radius limits) as `i32`.
pub(crate) fn narrow(d: (i64, i64)) -> (i32, i32) {
    (d.0 as i32, d.1 as i32)
}

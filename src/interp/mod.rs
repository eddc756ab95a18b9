//! Point-by-point (逐点比较法) interpolators: each curve becomes a stream of single steps.
//!
//! Every interpolator works in integer steps relative to its start point and yields [`Step`]s
//! to lattice neighbours. Two methods exist ([`Method`]): `classic`, the seed's one-axis-per-step
//! comparison (error <= 1 step), and `diagonal`, which may move both axes at once (error <= 0.5
//! step, fewer steps). Interpolators never read a clock and never allocate.

pub mod line;

pub use line::LineInterp;

use crate::geom::Step;

/// How an interpolator chooses its steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Method {
    /// One axis per step, the seed's point-by-point comparison; error <= 1 step.
    Classic,
    /// Both axes may step together; error <= 0.5 step, fewer and longer steps.
    #[default]
    Diagonal,
}

/// Why a curve ended before its end point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum CurveError {
    /// The function left its domain (sqrt of a negative, ln of zero, ...).
    Domain,
    /// Division by zero.
    DivisionByZero,
    /// A value too large for the machine's range.
    Overflow,
    /// The curve jumps by more than the allowed distance between two points.
    Jump,
}

/// A unit vector in step space: the direction of travel of the ideal curve.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Tangent {
    pub x: f32,
    pub y: f32,
}

impl Tangent {
    /// The unit vector along `(x, y)`; `(1, 0)` for a zero vector.
    pub fn along(x: f32, y: f32) -> Self {
        let len = libm::sqrtf(x * x + y * y);
        if len > 0.0 && len.is_finite() {
            Tangent { x: x / len, y: y / len }
        } else {
            Tangent { x: 1.0, y: 0.0 }
        }
    }
}

/// What every interpolator offers the motion planner.
pub trait Interpolator {
    /// The next step, `Ok(None)` once the end point is reached. After `None` or an error the
    /// interpolator keeps returning `Ok(None)`.
    fn next_step(&mut self) -> Result<Option<Step>, CurveError>;

    /// The unit tangent of the ideal curve at the current point, in the direction of travel.
    fn tangent(&self) -> Tangent;
}

//! Why a curve could not be set up: [`CurveSetupError`], shared by every interpolator that
//! checks its parameters before the first step (explicit curves, arcs, ellipses).
//!
//! Owns nothing else: the errors a curve meets on the way are [`CurveError`].

use crate::motion::interp::interpolator::CurveError;

/// Why a curve could not be set up; nothing moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum CurveSetupError {
    /// A parameter is not a finite number, a steps/mm is not positive or a jump limit is negative.
    BadParameter,
    /// The curve would reach further than
    /// [`MAX_CURVE_OFFSET_STEPS`](crate::motion::interp::explicit::MAX_CURVE_OFFSET_STEPS) from its start.
    OutOfRange,
    /// The curve cannot be evaluated at its start point.
    Start(CurveError),
}

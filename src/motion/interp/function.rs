//! The function curve y = f(x) of an [`Expr`] given in millimetres, drawn from the pen:
//! [`FunctionInterp`] evaluates the expression once per X step (a *column*) and leaves the
//! stepping, its bounds and its limits (jump, travel, overflow) to
//! [`ExplicitCurve`](crate::motion::interp::explicit).
//!
//! # Columns
//!
//! The X range becomes `n = round((x1 - x0)·steps_per_mm[0])` columns, rounded as the G-code
//! parser rounds it (half away from zero, from the same `f32` product), so both count the same
//! columns. Column `k` is at `x0 + (x1 - x0)·(k/n)` millimetres, computed from the integer `k`
//! every time, never by adding up a step: its error is a few roundings relative to `|x1 - x0|`
//! and one relative to `|x|`, within `2⁻²³·(|x1 - x0| + |x|)`, the same at the last column as at
//! the first (0.02 µm on a 100 mm range, 0.005 step at 200 steps/mm). The ends are exactly `x0`
//! and `x1`.
//!
//! # Values
//!
//! The expression evaluates in `f32` ([`Expr::eval`]); its value in millimetres, minus f(x0), is
//! scaled to steps by the Y steps/mm: the subtraction comes first, so a curve far from zero
//! (`1000 + sin(x)`) loses nothing to cancellation beyond the error of the values themselves
//! (a few units in the last place of |f|: 2⁻²³·1000 mm is 0.01 step at 80 steps/mm). An
//! evaluation error (domain, division by zero, overflow) ends the curve at the column before;
//! at x0 it is a setup error and nothing moves.
//!
//! # Precision
//!
//! Both errors above grow with the numbers, not with the steps: far enough from zero, `f32`
//! cannot tell one step from the next (at x = 10,000,000 mm its numbers are 1 mm apart, 100
//! steps at 100 steps/mm, and `(x-10000000)*4` comes out as 4 mm stairs). [`f32_error_steps`]
//! bounds how far they can move a column's point from the curve, in steps on each axis: x's
//! error moves it along X (the point `(x, f(x))` computed is on the curve, drawn at the ideal x),
//! f's along Y. A curve whose bound is over [`F32_ERROR_MAX_STEPS`] on either axis is refused
//! before anything moves (the drawing builder asks).

use crate::geom::{Point, Step};
use crate::math;
use crate::motion::expr::{EvalError, Expr};
use crate::motion::interp::explicit::{CurveFn, ExplicitCurve, MAX_CURVE_OFFSET_STEPS};
use crate::motion::interp::interpolator::{CurveError, Filled, Interpolator, Tangent};
use crate::motion::interp::setup::CurveSetupError;
use crate::motion::method::Method;

#[cfg(test)]
mod tests;

/// The most single precision may move a column's point from the curve on either axis, in
/// steps: with the √2/2 step the path keeps from its chords, it stays within a step of the
/// curve.
pub const F32_ERROR_MAX_STEPS: f32 = 0.25;

/// A column's x is within this much of its ideal, relative to `|x1 - x0| + max(|x0|, |x1|)`
/// (2⁻²³: see the module documentation).
const X_RELATIVE_ERROR: f32 = 1.0 / 8_388_608.0;

/// f's values carry a few units in their last place of error: within 2⁻²¹ of |f| (see
/// [`crate::motion::interp::explicit`]'s Arithmetic).
const VALUE_RELATIVE_ERROR: f32 = 1.0 / 2_097_152.0;

/// How far single precision may move a column's point from the curve of f over x from `x0_mm`
/// to `x1_mm`, in steps along X and along Y, for values of f up to `largest_value_mm` in size,
/// at `steps_per_mm` (X, Y). See the module documentation; compare with
/// [`F32_ERROR_MAX_STEPS`]. Not finite for inputs that are not.
pub fn f32_error_steps(x0_mm: f32, x1_mm: f32, largest_value_mm: f32, steps_per_mm: [f32; 2]) -> [f32; 2] {
    let x_size_mm = (x1_mm - x0_mm).abs() + math::max(x0_mm.abs(), x1_mm.abs());
    [x_size_mm * X_RELATIVE_ERROR * steps_per_mm[0], largest_value_mm.abs() * VALUE_RELATIVE_ERROR * steps_per_mm[1]]
}

impl From<EvalError> for CurveError {
    fn from(e: EvalError) -> Self {
        match e {
            EvalError::SqrtOfNegative
            | EvalError::LogOfNonPositive
            | EvalError::ArcOutOfRange
            | EvalError::PowerOfNegative => CurveError::Domain,
            EvalError::TanPole | EvalError::DivisionByZero => CurveError::DivisionByZero,
            EvalError::Overflow => CurveError::Overflow,
        }
    }
}

/// y = f(x) of an [`Expr`] in millimetres, sampled at the columns of its X range.
#[derive(Clone, Debug)]
struct ExprFn {
    expr: Expr,
    x0_mm: f32,
    x1_mm: f32,
    /// `x1 - x0`.
    span_mm: f32,
    columns: i32,
    /// `columns` as an `f32` (exactly: at most [`MAX_CURVE_OFFSET_STEPS`]).
    columns_f32: f32,
    y_steps_per_mm: f32,
}

impl ExprFn {
    /// Column `k` of `n` is at `x0 + (x1 - x0)·(k/n)`: the ends exactly x0 and x1, and no error
    /// that grows along the range (see the module documentation).
    #[inline]
    fn x_mm(&self, column: i32) -> f32 {
        if column <= 0 {
            self.x0_mm
        } else if column >= self.columns {
            self.x1_mm
        } else {
            self.x0_mm + self.span_mm * (column as f32 / self.columns_f32)
        }
    }
}

impl CurveFn for ExprFn {
    #[inline]
    fn y(&self, column: i32) -> Result<f32, CurveError> {
        Ok(self.expr.eval(self.x_mm(column))?)
    }

    fn y_steps_per_unit(&self) -> f32 {
        self.y_steps_per_mm
    }

    /// At `x0 + (x1 - x0)·((k + fraction)/n)`, as a column is, between the columns; kept within
    /// the range, which the last chord's rounding can pass by a unit in the last place past
    /// 131,072 columns (`(k + fraction)/n` rounds to 1 there, and `x0 + (x1 - x0)` need not be
    /// x1): out of `sqrt(x1 - x)`'s domain, say.
    fn y_between(&self, column: i32, fraction: f32) -> Option<Result<f32, CurveError>> {
        let x = self.x0_mm + self.span_mm * ((column as f32 + fraction) / self.columns_f32);
        let (low, high) = (math::min(self.x0_mm, self.x1_mm), math::max(self.x0_mm, self.x1_mm));
        Some(self.expr.eval(math::max(math::min(x, high), low)).map_err(CurveError::from))
    }
}

/// The curve y = f(x) for x from `x0_mm` to `x1_mm`, drawn from the pen: see the module
/// documentation for its columns and values, and `crate::motion::interp::explicit` for how it steps
/// and where it stops.
#[derive(Clone, Debug)]
pub struct FunctionInterp {
    curve: ExplicitCurve<ExprFn>,
}

impl FunctionInterp {
    /// The curve of `expr` (x and y in millimetres) for x from `x0_mm` to `x1_mm` (`x1 < x0`
    /// runs toward -x), converted with `steps_per_mm` (X, Y) and translated so that it starts at
    /// the pen: the path is `(xs - xs0, ys(x) - ys(x0))` in steps. The range becomes
    /// `round((x1 - x0)·steps_per_mm[0])` columns. A rise or fall of more than `max_jump_steps`
    /// between neighbouring columns ends the curve with [`CurveError::Jump`] (the caller derives
    /// it from the `max_jump_mm` setting with
    /// [`jump_limit_steps`](crate::motion::interp::explicit::jump_limit_steps)).
    ///
    /// f(x0) is evaluated here: a domain error there is [`CurveSetupError::Start`] and nothing
    /// moves.
    pub fn new(
        expr: Expr,
        x0_mm: f32,
        x1_mm: f32,
        steps_per_mm: [f32; 2],
        max_jump_steps: i32,
        method: Method,
    ) -> Result<Self, CurveSetupError> {
        let [x_spm, y_spm] = steps_per_mm;
        let positive = |v: f32| v.is_finite() && v > 0.0;
        if !(x0_mm.is_finite() && x1_mm.is_finite() && positive(x_spm) && positive(y_spm)) {
            return Err(CurveSetupError::BadParameter);
        }
        // Finite inputs: the length is a number, at worst infinite.
        let length = (x1_mm - x0_mm) * x_spm;
        if length.abs() > MAX_CURVE_OFFSET_STEPS as f32 {
            return Err(CurveSetupError::OutOfRange);
        }
        let length_steps = math::round(length) as i32;
        let columns = length_steps.abs();
        let g = ExprFn {
            expr,
            x0_mm,
            x1_mm,
            span_mm: x1_mm - x0_mm,
            columns,
            columns_f32: columns as f32,
            y_steps_per_mm: y_spm,
        };
        Ok(FunctionInterp { curve: ExplicitCurve::new(g, length_steps, max_jump_steps, method)? })
    }

    /// The same curve, checked between its columns as it is walked: see
    /// [`ExplicitCurve::check_between_columns`].
    pub fn check_between_columns(self) -> Self {
        FunctionInterp { curve: self.curve.check_between_columns() }
    }

    /// Where the steps handed out so far have taken the pen, relative to the start.
    pub fn position(&self) -> Point {
        self.curve.position()
    }

    /// Where the curve ends if nothing stops it on the way, relative to the start: the last
    /// column, at f(x1), exactly where the steps end; an error means f cannot be evaluated at
    /// x1. Costs one evaluation of f.
    pub fn nominal_end(&self) -> Result<Point, CurveError> {
        self.curve.nominal_end()
    }

    #[cfg(test)]
    fn curve_fn(&self) -> &ExprFn {
        self.curve.curve_fn()
    }
}

impl Interpolator for FunctionInterp {
    fn next_step(&mut self) -> Result<Option<Step>, CurveError> {
        self.curve.next_step()
    }

    fn tangent(&self) -> Tangent {
        self.curve.tangent()
    }

    fn fill(&mut self, out: &mut [Step]) -> Filled {
        self.curve.fill(out)
    }
}

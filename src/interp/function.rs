//! The function curve y = f(x) of an [`Expr`] given in millimetres, drawn from the pen:
//! [`FunctionInterp`] evaluates the expression at each X step (a *column*) and leaves the
//! stepping, its bounds and its limits (jump, travel, overflow) to
//! [`ExplicitCurve`](crate::interp::explicit).

use crate::expr::{EvalError, Expr};
use crate::geom::{Point, Step};
use crate::interp::explicit::{CurveFn, ExplicitCurve, MAX_CURVE_OFFSET_STEPS, RowRange, nearest_step};
use crate::interp::{CurveError, CurveSetupError, Interpolator, Method, Tangent};

#[cfg(test)]
mod tests;

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
    x0_mm: f64,
    x1_mm: f64,
    columns: i32,
    y_steps_per_mm: f64,
}

impl ExprFn {
    /// Column `k` of `n` is at `x0 + (x1 - x0)·k/n`: the ends are exactly x0 and x1, the X scale
    /// off by less than half a step over the whole range.
    fn x_mm(&self, column: i32) -> f64 {
        if column == 0 || self.columns == 0 {
            self.x0_mm
        } else if column >= self.columns {
            self.x1_mm
        } else {
            self.x0_mm + (self.x1_mm - self.x0_mm) * (f64::from(column) / f64::from(self.columns))
        }
    }
}

impl CurveFn for ExprFn {
    fn y_steps(&self, column: i32) -> Result<f64, CurveError> {
        // Expressions evaluate in f32; the curve still steps in f64 around them.
        Ok(f64::from(self.expr.eval(self.x_mm(column) as f32)?) * self.y_steps_per_mm)
    }
}

/// The curve y = f(x) for x from `x0_mm` to `x1_mm`, drawn from the pen: see the module
/// documentation for how it steps and where it stops.
#[derive(Clone, Debug)]
pub struct FunctionInterp {
    curve: ExplicitCurve<ExprFn>,
}

impl FunctionInterp {
    /// The curve of `expr` (x and y in millimetres) for x from `x0_mm` to `x1_mm` (`x1 < x0`
    /// runs toward -x), converted with `steps_per_mm` (X, Y) and translated so that it starts at
    /// the pen: the path is `(xs - xs0, ys(x) - ys(x0))` in steps. The range becomes
    /// `round(|x1 - x0|·steps_per_mm[0])` columns. A rise or fall of more than `max_jump_steps`
    /// between neighbouring columns ends the curve with [`CurveError::Jump`] (the caller derives
    /// it from the `max_jump_mm` setting with [`jump_limit_steps`](crate::interp::explicit::jump_limit_steps)), a column outside `rows`
    /// with [`CurveError::Travel`] (the caller derives it from the travel limits with
    /// [`RowRange::within_travel`]).
    ///
    /// f(x0) is evaluated here: a domain error there is [`CurveSetupError::Start`] and nothing
    /// moves.
    pub fn new(
        expr: Expr,
        x0_mm: f64,
        x1_mm: f64,
        steps_per_mm: [f64; 2],
        max_jump_steps: i32,
        rows: RowRange,
        method: Method,
    ) -> Result<Self, CurveSetupError> {
        let [x_spm, y_spm] = steps_per_mm;
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !(x0_mm.is_finite() && x1_mm.is_finite() && positive(x_spm) && positive(y_spm)) {
            return Err(CurveSetupError::BadParameter);
        }
        // Finite inputs: the length is a number, at worst infinite.
        let length = (x1_mm - x0_mm) * x_spm;
        if libm::fabs(length) > f64::from(MAX_CURVE_OFFSET_STEPS) {
            return Err(CurveSetupError::OutOfRange);
        }
        let length_steps = nearest_step(length);
        let g = ExprFn { expr, x0_mm, x1_mm, columns: length_steps.abs(), y_steps_per_mm: y_spm };
        Ok(FunctionInterp { curve: ExplicitCurve::new(g, length_steps, max_jump_steps, rows, method)? })
    }

    /// Where the steps handed out so far have taken the pen, relative to the start.
    pub fn position(&self) -> Point {
        self.curve.position()
    }

    /// Where the curve ends if nothing stops it on the way, relative to the start; an error
    /// means f cannot be evaluated at x1. Costs one evaluation of f.
    pub fn nominal_end(&self) -> Result<Point, CurveError> {
        self.curve.nominal_end()
    }
}

impl Interpolator for FunctionInterp {
    fn next_step(&mut self) -> Result<Option<Step>, CurveError> {
        self.curve.next_step()
    }

    fn tangent(&self) -> Tangent {
        self.curve.tangent()
    }
}

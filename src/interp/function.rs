//! Explicit curves y = g(x), stepped column by column, and the function curve y = f(x) of an
//! [`Expr`] given in millimetres.
//!
//! # The shared core: [`ExplicitCurve`]
//!
//! Every explicit curve (the sine curve of `crate::interp::sine` and [`FunctionInterp`]) is
//! stepped by [`ExplicitCurve`], which sees the curve only through [`CurveFn`]: the ideal y, in
//! steps, at each whole-step *column* 0, 1, ..., n along the direction of travel. The path is
//! translated to start at the pen: it follows `h(k) = g(k) - g(0)`.
//!
//! Between two columns the ideal curve is taken as its chord, the segment from `(k, h(k))` to
//! `(k + 1, h(k + 1))`; the curve as drawn is the polyline through the column values (for a
//! smooth g it differs from g by at most `max|g''| / 8` between columns).
//!
//! * The chain. Every column `k` is entered at its rounded value `r(k) = round(h(k))` (nearest
//!   step, ties toward +y). A flat chord (|slope| <= 1) is one step, straight or diagonal, to
//!   `(k + 1, r(k + 1))`. A steep chord is walked row by row from `r(k)` to `r(k + 1)`, and in each
//!   row the pen stands in the column nearer to where the chord crosses that row, so X advances
//!   in the middle of a steep rise, not at its end.
//! * `Diagonal` takes the chain as it is: both axes may move together. Every lattice point
//!   visited lies within 0.5 step (Euclidean distance) of the chord it belongs to;
//!   `Σ max(1, |r(k+1) - r(k)|)` steps in all.
//! * `Classic` moves one axis per step, in the manner of the point-by-point comparison: where
//!   the chain moves diagonally it compares the two corners of that move and passes through the
//!   one nearer to the chord. Every lattice point visited lies within √2/2 ≈ 0.71 step of its
//!   chord (both ends of the move are within 0.5 of it, so the chord crosses the move's other
//!   diagonal within 0.5 of its middle); `n + Σ |r(k+1) - r(k)|` steps in all, none wasted.
//! * The end point is exactly `(n, round(h(n)))`, and every chord takes at most
//!   `1 + |r(k+1) - r(k)|` steps, so the curve always terminates.
//!
//! Each column value is computed just before its chord is stepped. If it cannot be computed
//! (the function's domain error, [`CurveError::Overflow`] beyond [`MAX_CURVE_OFFSET_STEPS`]),
//! the chord rises or falls by more than the curve's `max_jump_steps`
//! ([`CurveError::Jump`]), or its end row lies outside the curve's [`RowRange`]
//! ([`CurveError::Travel`]), the curve ends with that error *before* any step of the chord,
//! the pen standing at `(k, r(k))`; afterwards `next_step` returns `Ok(None)`. Since the
//! planner's look-ahead runs a clone of the curve ahead of the pen, it meets the error as early
//! as any end and brings the pen to a stop there.
//!
//! * A jump is an error, never a travel: the machine has no pen lift, so crossing a pole would
//!   draw a line the function does not contain.
//! * The row range is the machine's travel seen from the start (`Curve::for_job` derives it with
//!   [`RowRange::within_travel`]). Every step of a chord lies between the rows of its two
//!   columns, so a curve that starts inside the travel never takes a step outside it, and one
//!   that leaves the travel part way stops at the last column inside. This check is exact, at
//!   every column; the G-code parser only samples a function to refuse most such curves before
//!   anything moves.
//!
//! [`Interpolator::tangent`] is the direction of the current chord, `(1, h(k+1) - h(k))`
//! normalised and pointing in the direction of travel (the derivative by finite difference).

use crate::expr::{EvalError, Expr};
use crate::geom::{Point, Step};
use crate::interp::{CurveError, Interpolator, Method, Tangent};

/// Furthest an explicit curve may reach from its start on either axis, in steps: five times the
/// machine's full travel (±500 mm at 200 steps/mm is 200_000 steps corner to corner), so a curve
/// that fits the machine is never refused and all step arithmetic stays far from `i32`'s limits.
pub const MAX_CURVE_OFFSET_STEPS: i32 = 1_000_000;

/// Why a curve could not be set up; nothing moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum CurveSetupError {
    /// A parameter is not a finite number, a steps/mm is not positive or a jump limit is negative.
    BadParameter,
    /// The curve would reach further than [`MAX_CURVE_OFFSET_STEPS`] from its start.
    OutOfRange,
    /// The curve cannot be evaluated at its start point.
    Start(CurveError),
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

/// The rows an explicit curve may reach, relative to its start, both ends included: the
/// machine's travel on Y as seen from the start. A column whose row lies outside ends the curve
/// with [`CurveError::Travel`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct RowRange {
    pub min: i32,
    pub max: i32,
}

impl RowRange {
    /// Every row: no travel limit.
    pub const ANY: RowRange = RowRange { min: i32::MIN, max: i32::MAX };

    /// The rows `r` with `|start_y + r| <= limit_steps`, for a curve that starts at the absolute
    /// row `start_y` on a machine whose travel is ±`limit_steps` (a negative limit allows no
    /// row at all).
    pub fn within_travel(start_y: i32, limit_steps: i32) -> RowRange {
        let (start, limit) = (i64::from(start_y), i64::from(limit_steps));
        let clamp = |v: i64| v.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32;
        RowRange { min: clamp(-limit - start), max: clamp(limit - start) }
    }

    pub fn contains(self, row: i32) -> bool {
        self.min <= row && row <= self.max
    }
}

/// The jump limit of an explicit curve, in rows: the `max_jump_mm` setting (`$204`) at
/// `y_steps_per_mm`, rounded down, and at least one row, or any slope at all would be a jump.
pub fn jump_limit_steps(max_jump_mm: f32, y_steps_per_mm: f32) -> i32 {
    (max_jump_mm * y_steps_per_mm).max(1.0) as i32
}

/// An explicit curve as [`ExplicitCurve`] sees it.
pub trait CurveFn {
    /// The ideal y, in steps, at `column` (0 at the start, counted in the direction of travel,
    /// up to the curve's length). Only differences from column 0 matter.
    fn y_steps(&self, column: i32) -> Result<f64, CurveError>;
}

impl<F: Fn(i32) -> Result<f64, CurveError>> CurveFn for F {
    fn y_steps(&self, column: i32) -> Result<f64, CurveError> {
        self(column)
    }
}

/// The nearest whole step to `h`, ties toward +y (monotonic, so that neighbouring columns whose
/// values differ by at most one step round at most one step apart).
pub(crate) fn nearest_step(h: f64) -> i32 {
    libm::floor(h + 0.5) as i32
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    Running,
    /// Ends with this error at the next call.
    Failed(CurveError),
    Done,
}

/// Steps along an explicit curve y = g(x); see the module documentation.
#[derive(Clone, Debug)]
pub struct ExplicitCurve<G> {
    g: G,
    method: Method,
    /// Direction of travel on X: +1 or -1.
    dir: i8,
    /// Number of columns to travel (|length|).
    columns: i32,
    max_jump_steps: i32,
    /// Rows every column must lie in.
    rows: RowRange,
    /// g(0): the curve is translated by it so that it starts at the pen.
    origin: f64,
    /// The current chord runs from column `seg` to `seg + 1`...
    seg: i32,
    /// ...from `h0` to `h1` (steps relative to the start)...
    h0: f64,
    h1: f64,
    /// ...and ends at row `r1 = round(h1)`.
    r1: i32,
    /// The chain's current lattice point: column (counted along the travel) and row.
    col: i32,
    y: i32,
    /// `Classic`: the second half of a diagonal chain move.
    pending: Option<Step>,
    /// Where the steps handed out so far have taken the pen, relative to the start.
    at: Point,
    phase: Phase,
    tangent: Tangent,
}

impl<G: CurveFn> ExplicitCurve<G> {
    /// A curve over `length_steps` columns (negative: toward -x), refusing jumps of more than
    /// `max_jump_steps` rows between neighbouring columns (`i32::MAX`: no limit) and columns
    /// outside `rows` ([`RowRange::ANY`]: no limit; the start, row 0, is not checked). Evaluates
    /// g at the start; an error there is [`CurveSetupError::Start`] and nothing moves.
    pub fn new(
        g: G,
        length_steps: i32,
        max_jump_steps: i32,
        rows: RowRange,
        method: Method,
    ) -> Result<Self, CurveSetupError> {
        if max_jump_steps < 0 {
            return Err(CurveSetupError::BadParameter);
        }
        if length_steps.unsigned_abs() > MAX_CURVE_OFFSET_STEPS as u32 {
            return Err(CurveSetupError::OutOfRange);
        }
        let origin = g.y_steps(0).map_err(CurveSetupError::Start)?;
        if !origin.is_finite() {
            return Err(CurveSetupError::Start(CurveError::Overflow));
        }
        let dir = if length_steps < 0 { -1 } else { 1 };
        let mut curve = ExplicitCurve {
            g,
            method,
            dir,
            columns: length_steps.abs(),
            max_jump_steps,
            rows,
            origin,
            seg: 0,
            h0: 0.0,
            h1: 0.0,
            r1: 0,
            col: 0,
            y: 0,
            pending: None,
            at: Point::ORIGIN,
            phase: Phase::Running,
            tangent: Tangent::along(f32::from(dir), 0.0),
        };
        if curve.columns == 0 {
            curve.phase = Phase::Done;
        } else if let Err(e) = curve.load(0) {
            curve.phase = Phase::Failed(e);
        }
        Ok(curve)
    }

    /// Where the steps handed out so far have taken the pen, relative to the start.
    pub fn position(&self) -> Point {
        self.at
    }

    /// Where the whole curve ends, relative to the start, `(±n, round(h(n)))`, found from its
    /// last column alone; an error there means the curve cannot reach its end.
    pub fn nominal_end(&self) -> Result<Point, CurveError> {
        Ok(Point::new(i32::from(self.dir) * self.columns, nearest_step(self.offset(self.columns)?)))
    }

    /// The ideal curve at `column`, relative to the start, in steps.
    fn offset(&self, column: i32) -> Result<f64, CurveError> {
        let h = self.g.y_steps(column)? - self.origin;
        if h.is_finite() && libm::fabs(h) <= f64::from(MAX_CURVE_OFFSET_STEPS) {
            Ok(h)
        } else {
            Err(CurveError::Overflow)
        }
    }

    /// Makes the chord from column `seg` (where the chain stands, at row `r(seg)`) to `seg + 1`
    /// current, or tells why it cannot be drawn.
    fn load(&mut self, seg: i32) -> Result<(), CurveError> {
        let h1 = self.offset(seg + 1)?;
        let r1 = nearest_step(h1);
        if (r1 - self.y).abs() > self.max_jump_steps {
            return Err(CurveError::Jump);
        }
        if !self.rows.contains(r1) {
            return Err(CurveError::Travel);
        }
        self.seg = seg;
        self.h0 = self.h1;
        self.h1 = h1;
        self.r1 = r1;
        self.tangent = Tangent::along(f32::from(self.dir), (h1 - self.h0) as f32);
        Ok(())
    }

    /// The chain's next move along the current chord: (columns 0 or 1, rows -1, 0 or +1).
    fn chain_move(&self) -> (i32, i32) {
        let toward = (self.r1 - self.y).signum();
        if self.col > self.seg {
            // In the chord's last column: the remaining rows.
            return (0, toward);
        }
        let slope = self.h1 - self.h0;
        if libm::fabs(slope) <= 1.0 || toward == 0 {
            // Flat: rounded values of neighbouring columns are at most one row apart.
            return (1, toward);
        }
        // Steep: in the next row, stand in the column nearer to the chord's crossing.
        let row = self.y + toward;
        let crossed_half = row == self.r1 || (f64::from(row) - self.h0) / slope >= 0.5;
        (i32::from(crossed_half), toward)
    }

    /// Squared distance from the lattice point `(col, y)` to the current chord.
    fn chord_distance2(&self, col: i32, y: i32) -> f64 {
        let (px, py) = (f64::from(col - self.seg), f64::from(y) - self.h0);
        let slope = self.h1 - self.h0;
        let t = ((px + py * slope) / (1.0 + slope * slope)).clamp(0.0, 1.0);
        let (ex, ey) = (px - t, py - t * slope);
        ex * ex + ey * ey
    }

    fn emit(&mut self, step: Step) -> Result<Option<Step>, CurveError> {
        self.at = self.at.stepped(step);
        Ok(Some(step))
    }
}

impl<G: CurveFn> Interpolator for ExplicitCurve<G> {
    fn next_step(&mut self) -> Result<Option<Step>, CurveError> {
        if let Some(step) = self.pending.take() {
            return self.emit(step);
        }
        match self.phase {
            Phase::Running => {}
            Phase::Done => return Ok(None),
            Phase::Failed(e) => {
                self.phase = Phase::Done;
                return Err(e);
            }
        }
        let (dc, dy) = self.chain_move();
        let (sx, sy) = (if dc != 0 { self.dir } else { 0 }, dy as i8);
        let step = if self.method == Method::Classic && sx != 0 && sy != 0 {
            // Through the corner nearer to the chord.
            let x_first = self.chord_distance2(self.col + 1, self.y) <= self.chord_distance2(self.col, self.y + dy);
            let (first, second) =
                if x_first { (Step::new(sx, 0), Step::new(0, sy)) } else { (Step::new(0, sy), Step::new(sx, 0)) };
            self.pending = Some(second);
            first
        } else {
            Step::new(sx, sy)
        };
        self.col += dc;
        self.y += dy;
        if self.col > self.seg && self.y == self.r1 {
            let next = self.seg + 1;
            if next == self.columns {
                self.phase = Phase::Done;
            } else if let Err(e) = self.load(next) {
                self.phase = Phase::Failed(e);
            }
        }
        self.emit(step)
    }

    fn tangent(&self) -> Tangent {
        self.tangent
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
    /// it from the `max_jump_mm` setting with [`jump_limit_steps`]), a column outside `rows`
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

/// Checks shared by the tests of every explicit curve.
#[cfg(test)]
pub(crate) mod test_support {
    extern crate std;
    use crate::geom::Point;
    use crate::interp::{CurveError, Interpolator, Method};
    use std::vec::Vec;

    /// Deviation bound of `Diagonal` from the chord polyline, in steps.
    pub const DIAGONAL_MAX_DEVIATION_STEPS: f64 = 0.5;
    /// Deviation bound of `Classic` from the chord polyline, in steps (√2/2).
    pub const CLASSIC_MAX_DEVIATION_STEPS: f64 = core::f64::consts::FRAC_1_SQRT_2;
    /// Floating-point slack on every bound, in steps.
    pub const FLOAT_SLACK_STEPS: f64 = 1e-6;

    pub fn max_deviation_for(method: Method) -> f64 {
        match method {
            Method::Classic => CLASSIC_MAX_DEVIATION_STEPS,
            Method::Diagonal => DIAGONAL_MAX_DEVIATION_STEPS,
        }
    }

    /// The lattice points an interpolator visits, from the start, and how it ended.
    pub struct Walk {
        pub path: Vec<Point>,
        pub end: Result<(), CurveError>,
    }

    impl Walk {
        pub fn last(&self) -> Point {
            self.path.last().copied().unwrap_or(Point::ORIGIN)
        }

        pub fn steps(&self) -> usize {
            self.path.len() - 1
        }
    }

    /// Runs `interp` to its end, checking every step (a neighbour; one axis for `Classic`), that
    /// it ends within `max_steps` and that it stays ended.
    pub fn walk(interp: &mut impl Interpolator, method: Method, max_steps: usize) -> Walk {
        let mut p = Point::ORIGIN;
        let mut path = Vec::from([p]);
        let end = loop {
            match interp.next_step() {
                Ok(Some(s)) => {
                    assert!(s.is_neighbour(), "{s:?} after {p:?} is not a step to a neighbour");
                    assert!(method != Method::Classic || !s.is_diagonal(), "classic moved both axes after {p:?}");
                    p = p.stepped(s);
                    path.push(p);
                    assert!(path.len() <= max_steps + 1, "more than {max_steps} steps");
                }
                Ok(None) => break Ok(()),
                Err(e) => break Err(e),
            }
        };
        for _ in 0..2 {
            assert_eq!(interp.next_step(), Ok(None), "a finished curve moved again");
        }
        Walk { path, end }
    }

    fn segment_distance(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let t = (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
        let (ex, ey) = (p.0 - a.0 - t * dx, p.1 - a.1 - t * dy);
        (ex * ex + ey * ey).sqrt()
    }

    /// Largest distance from a path point to the polyline through `(dir·k, h[k])` (measured to
    /// the chords on either side of the point's column), checking that no point leaves the
    /// columns `0..h.len()`.
    pub fn max_deviation(path: &[Point], dir: i32, h: &[f64]) -> f64 {
        let mut worst = 0.0f64;
        for p in path {
            let k = p.x * dir;
            assert!(k >= 0 && (k as usize) < h.len(), "{p:?} is outside the curve's columns");
            let k = k as usize;
            let at = |c: usize| ((dir * c as i32) as f64, h[c]);
            let pt = (p.x as f64, p.y as f64);
            let mut d = if h.len() == 1 { segment_distance(pt, at(0), (at(0).0 + 1.0, h[0])) } else { f64::INFINITY };
            if k > 0 {
                d = d.min(segment_distance(pt, at(k - 1), at(k)));
            }
            if k + 1 < h.len() {
                d = d.min(segment_distance(pt, at(k), at(k + 1)));
            }
            worst = worst.max(d);
        }
        worst
    }

    /// Checks that the path stands, in every column `k` of `h`, at a row within half a step of
    /// `h[k]`.
    pub fn assert_meets_every_column(path: &[Point], dir: i32, h: &[f64]) {
        let mut met = std::vec![false; h.len()];
        for p in path {
            let k = (p.x * dir) as usize;
            if k < h.len() && (p.y as f64 - h[k]).abs() <= 0.5 + FLOAT_SLACK_STEPS {
                met[k] = true;
            }
        }
        if let Some(k) = met.iter().position(|m| !m) {
            panic!("column {k} (ideal {}) is not met", h[k]);
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::test_support::*;
    use super::*;
    use crate::expr::parse;
    use proptest::prelude::*;
    use std::vec::Vec;

    const METHODS: [Method; 2] = [Method::Classic, Method::Diagonal];
    const ANY: RowRange = RowRange::ANY;

    /// Curve values at columns 0..=n: a random walk mixing flat, steep and exactly-half rises,
    /// from an arbitrary origin.
    fn sampled_curve() -> impl Strategy<Value = Vec<f64>> {
        let rise = prop_oneof![-1.2f64..1.2, -60.0f64..60.0, (-40i32..40).prop_map(|k| k as f64 + 0.5), Just(0.0),];
        (proptest::collection::vec(rise, 0..80), -5_000.0f64..5_000.0).prop_map(|(rises, origin)| {
            let mut g = Vec::from([origin]);
            for r in rises {
                g.push(g[g.len() - 1] + r);
            }
            g
        })
    }

    /// The core over samples `g` (absolute values), failing with `fail` at column `fail_at`.
    fn sampled(g: &[f64], fail_at: Option<(usize, CurveError)>) -> impl Fn(i32) -> Result<f64, CurveError> + '_ {
        move |c| match fail_at {
            Some((at, e)) if at == c as usize => Err(e),
            _ => Ok(g[c as usize]),
        }
    }

    fn relative(g: &[f64]) -> Vec<f64> {
        g.iter().map(|v| v - g[0]).collect()
    }

    fn rounded(h: &[f64]) -> Vec<i32> {
        h.iter().map(|&v| libm::floor(v + 0.5) as i32).collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        #[test]
        fn explicit_curves_meet_every_column_stay_close_and_end_exactly(g in sampled_curve(), backwards: bool) {
            let n = g.len() as i32 - 1;
            let dir = if backwards { -1 } else { 1 };
            let h = relative(&g);
            let r = rounded(&h);
            let rises: Vec<i32> = r.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
            for method in METHODS {
                let mut curve = ExplicitCurve::new(sampled(&g, None), dir * n, i32::MAX, ANY, method).unwrap();
                let w = walk(&mut curve, method, 100_000);
                prop_assert_eq!(w.end, Ok(()));
                prop_assert_eq!(w.last(), Point::new(dir * n, r[n as usize]));
                prop_assert_eq!(curve.position(), w.last());
                assert_meets_every_column(&w.path, dir, &h);
                let dev = max_deviation(&w.path, dir, &h);
                prop_assert!(dev <= max_deviation_for(method) + FLOAT_SLACK_STEPS, "{:?} deviates {}", method, dev);
                let expected_steps: i32 = match method {
                    Method::Classic => n + rises.iter().sum::<i32>(),
                    Method::Diagonal => rises.iter().map(|&d| d.max(1)).sum(),
                };
                prop_assert_eq!(w.steps(), expected_steps as usize);
            }
        }

        #[test]
        fn a_jump_ends_the_curve_before_any_of_its_steps(g in sampled_curve(), max_jump in 0i32..30, backwards: bool) {
            let n = g.len() as i32 - 1;
            let dir = if backwards { -1 } else { 1 };
            let r = rounded(&relative(&g));
            let first_jump = r.windows(2).position(|w| (w[1] - w[0]).abs() > max_jump);
            for method in METHODS {
                let mut curve = ExplicitCurve::new(sampled(&g, None), dir * n, max_jump, ANY, method).unwrap();
                let w = walk(&mut curve, method, 100_000);
                match first_jump {
                    None => prop_assert_eq!(w.last(), Point::new(dir * n, r[n as usize])),
                    Some(k) => {
                        prop_assert_eq!(w.end, Err(CurveError::Jump));
                        prop_assert_eq!(w.last(), Point::new(dir * k as i32, r[k]));
                        prop_assert!(w.path.iter().all(|p| p.x * dir <= k as i32), "stepped into the jump");
                    }
                }
            }
        }

        #[test]
        fn a_failing_column_ends_the_curve_at_the_column_before(g in sampled_curve(), at in 0usize..80, which in 0usize..3) {
            let n = g.len() - 1;
            let at = at % (n + 1);
            let err = [CurveError::Domain, CurveError::DivisionByZero, CurveError::Overflow][which];
            let r = rounded(&relative(&g));
            for method in METHODS {
                match ExplicitCurve::new(sampled(&g, Some((at, err))), n as i32, i32::MAX, ANY, method) {
                    Err(e) => prop_assert_eq!((e, at), (CurveSetupError::Start(err), 0)),
                    Ok(mut curve) => {
                        let w = walk(&mut curve, method, 100_000);
                        prop_assert_eq!(w.end, Err(err));
                        prop_assert_eq!(w.last(), Point::new(at as i32 - 1, r[at - 1]));
                        prop_assert!(w.path.iter().all(|p| (p.x as usize) < at));
                    }
                }
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// No step ever leaves the rows: the curve ends, with the first error met (a jump is
        /// reported before the travel), at the last column before the first column that jumps
        /// or lies outside them.
        #[test]
        fn a_column_outside_the_rows_ends_the_curve_at_the_last_column_inside(
            g in sampled_curve(),
            below in 0i32..300,
            above in 0i32..300,
            max_jump in prop_oneof![Just(i32::MAX), 0i32..30],
            backwards: bool,
        ) {
            let n = g.len() as i32 - 1;
            let dir = if backwards { -1 } else { 1 };
            let r = rounded(&relative(&g));
            let rows = RowRange { min: -below, max: above };
            let jumps = |k: usize| (r[k] - r[k - 1]).abs() > max_jump;
            let first = (1..r.len()).find(|&k| jumps(k) || !rows.contains(r[k]));
            for method in METHODS {
                let mut curve = ExplicitCurve::new(sampled(&g, None), dir * n, max_jump, rows, method).unwrap();
                let w = walk(&mut curve, method, 100_000);
                prop_assert!(w.path.iter().all(|p| rows.contains(p.y)), "a step outside {:?}", rows);
                match first {
                    None => prop_assert_eq!((w.end, w.last()), (Ok(()), Point::new(dir * n, r[n as usize]))),
                    Some(k) => {
                        let error = if jumps(k) { CurveError::Jump } else { CurveError::Travel };
                        prop_assert_eq!(w.end, Err(error));
                        prop_assert_eq!(w.last(), Point::new(dir * (k as i32 - 1), r[k - 1]));
                        prop_assert!(w.path.iter().all(|p| p.x * dir < k as i32), "stepped toward column {}", k);
                    }
                }
            }
        }
    }

    #[test]
    fn the_row_range_is_the_travel_seen_from_the_start() {
        assert_eq!(RowRange::within_travel(0, 20_000), RowRange { min: -20_000, max: 20_000 });
        assert_eq!(RowRange::within_travel(5_000, 20_000), RowRange { min: -25_000, max: 15_000 });
        assert_eq!(RowRange::within_travel(-20_000, 20_000), RowRange { min: 0, max: 40_000 });
        // Beyond i32: clamped, never wrapped.
        assert_eq!(RowRange::within_travel(i32::MIN, i32::MAX), RowRange { min: 1, max: i32::MAX });
        // A start outside the travel: only the rows back inside.
        assert_eq!(RowRange::within_travel(20_005, 20_000), RowRange { min: -40_005, max: -5 });
        assert!(!RowRange::within_travel(0, -1).contains(0));
        assert!(RowRange::ANY.contains(i32::MIN) && RowRange::ANY.contains(i32::MAX));
        // The jump limit: `$204` in rows, at least one.
        assert_eq!(jump_limit_steps(5.0, 100.0), 500);
        assert_eq!(jump_limit_steps(0.001, 100.0), 1);
        assert_eq!(jump_limit_steps(0.0, 100.0), 1);
    }

    #[test]
    fn a_steep_rise_advances_x_halfway_up() {
        // One column rising four rows: the chord (0,0)-(1,4) crosses the middle at row 2.
        let g = [0.0, 4.0];
        let mut diagonal = ExplicitCurve::new(sampled(&g, None), 1, i32::MAX, ANY, Method::Diagonal).unwrap();
        let w = walk(&mut diagonal, Method::Diagonal, 10);
        let pts = |v: &[(i32, i32)]| v.iter().map(|&(x, y)| Point::new(x, y)).collect::<Vec<_>>();
        assert_eq!(w.path, pts(&[(0, 0), (0, 1), (1, 2), (1, 3), (1, 4)]));
        // Classic goes through the corner nearer to the chord: up two, across, up two.
        let mut classic = ExplicitCurve::new(sampled(&g, None), 1, i32::MAX, ANY, Method::Classic).unwrap();
        let w = walk(&mut classic, Method::Classic, 10);
        assert_eq!(w.path, pts(&[(0, 0), (0, 1), (0, 2), (1, 2), (1, 3), (1, 4)]));
    }

    #[test]
    fn values_beyond_the_machine_overflow_and_bad_parameters_are_refused() {
        let g = [0.0, 10.0, 2e6];
        for method in METHODS {
            let mut curve = ExplicitCurve::new(sampled(&g, None), 2, i32::MAX, ANY, method).unwrap();
            let w = walk(&mut curve, method, 100);
            assert_eq!((w.end, w.last()), (Err(CurveError::Overflow), Point::new(1, 10)));
            let f = |_| Ok(0.0);
            assert_eq!(ExplicitCurve::new(f, 10, -1, ANY, method).err(), Some(CurveSetupError::BadParameter));
            assert_eq!(
                ExplicitCurve::new(f, MAX_CURVE_OFFSET_STEPS + 1, 0, ANY, method).err(),
                Some(CurveSetupError::OutOfRange)
            );
            assert_eq!(ExplicitCurve::new(f, i32::MIN, 0, ANY, method).err(), Some(CurveSetupError::OutOfRange));
            let nan = |_| Ok(f64::NAN);
            assert_eq!(
                ExplicitCurve::new(nan, 10, 0, ANY, method).err(),
                Some(CurveSetupError::Start(CurveError::Overflow))
            );
        }
    }

    // ---- FunctionInterp ----

    /// Runs `src` over [x0, x1] mm at `spm` steps/mm; returns the walk and the ideal values
    /// (steps, relative) at its columns computed by `f`.
    fn draw(
        src: &str,
        x0: f64,
        x1: f64,
        spm: f64,
        max_jump: i32,
        method: Method,
        f: impl Fn(f64) -> f64,
    ) -> (Walk, Vec<f64>, i32) {
        let mut interp = FunctionInterp::new(parse(src).unwrap(), x0, x1, [spm, spm], max_jump, ANY, method).unwrap();
        let n = ((x1 - x0) * spm).round() as i32;
        let dir = if n < 0 { -1 } else { 1 };
        let h: Vec<f64> = (0..=n.abs())
            .map(|k| {
                let x = x0 + (x1 - x0) * k as f64 / n.abs() as f64;
                (f(x) - f(x0)) * spm
            })
            .collect();
        let w = walk(&mut interp, method, 1_000_000);
        assert_eq!(interp.position(), w.last());
        (w, h, dir)
    }

    #[test]
    fn a_parabola_dips_to_its_vertex_and_returns() {
        for method in METHODS {
            // x²/10 on [-10, 10] mm at 20 steps/mm: from (-10, 10) mm down to (0, 0) and up again.
            let (w, h, dir) = draw("x^2/10", -10.0, 10.0, 20.0, 100, method, |x| x * x / 10.0);
            assert_eq!(w.end, Ok(()));
            assert_eq!(w.last(), Point::new(400, 0));
            let lowest = w.path.iter().map(|p| p.y).min();
            assert_eq!(lowest, Some(-200));
            assert!(w.path.contains(&Point::new(200, -200)));
            assert!(max_deviation(&w.path, dir, &h) <= max_deviation_for(method) + FLOAT_SLACK_STEPS);
            assert_meets_every_column(&w.path, dir, &h);
        }
    }

    #[test]
    fn x1_below_x0_draws_toward_minus_x() {
        for method in METHODS {
            let (w, h, dir) = draw("x^2/10", 10.0, -10.0, 20.0, 100, method, |x| x * x / 10.0);
            assert_eq!(dir, -1);
            assert_eq!(w.last(), Point::new(-400, 0));
            assert!(w.path.iter().all(|p| p.x <= 0));
            assert!(w.path.contains(&Point::new(-200, -200)));
            assert!(max_deviation(&w.path, dir, &h) <= max_deviation_for(method) + FLOAT_SLACK_STEPS);
        }
    }

    #[test]
    fn a_square_root_is_followed_up_its_vertical_start() {
        for method in METHODS {
            // sqrt(x) on [0, 4] mm at 10 steps/mm: 40 columns, ends 20 steps up; the first column
            // alone rises 3.16 steps.
            let (w, h, dir) = draw("sqrt(x)", 0.0, 4.0, 10.0, 100, method, libm::sqrt);
            assert_eq!(w.last(), Point::new(40, 20));
            assert!(w.path.contains(&Point::new(1, 3)));
            assert!(w.path.iter().take_while(|p| p.x == 0).count() >= 2, "no climb in the first column");
            assert!(max_deviation(&w.path, dir, &h) <= max_deviation_for(method) + FLOAT_SLACK_STEPS);
            assert_meets_every_column(&w.path, dir, &h);
        }
    }

    #[test]
    fn one_over_x_stops_before_zero() {
        for method in METHODS {
            // Generous jump limit: the curve reaches x = -0.1 mm and fails on the division at 0.
            let mut interp =
                FunctionInterp::new(parse("1/x").unwrap(), -1.0, 1.0, [10.0, 10.0], 1000, ANY, method).unwrap();
            let w = walk(&mut interp, method, 10_000);
            assert_eq!(w.end, Err(CurveError::DivisionByZero));
            // x = -0.1 mm: 1/x - 1/x0 = -10 + 1 = -9 mm.
            assert_eq!(w.last(), Point::new(9, -90));
            assert!(w.path.iter().all(|p| p.x <= 9));
            // A tighter limit stops it earlier, at the first rise of more than 30 steps.
            let mut interp =
                FunctionInterp::new(parse("1/x").unwrap(), -1.0, 1.0, [10.0, 10.0], 30, ANY, method).unwrap();
            let w = walk(&mut interp, method, 10_000);
            assert_eq!(w.end, Err(CurveError::Jump));
            // -1/0.3 → -1/0.2 falls 16.7 steps; -1/0.2 → -1/0.1 falls 50.
            assert_eq!(w.last(), Point::new(8, -40));
            assert!(w.path.iter().all(|p| p.x <= 8));
        }
    }

    #[test]
    fn tan_stops_at_its_pole_as_a_jump() {
        for method in METHODS {
            // tan(x) on [1, 2] mm at 100 steps/mm: x = 1.57 gives 1255.8 mm, x = 1.58 gives
            // -108.6 mm; a 1000-step jump limit stops it before the pole.
            let mut interp =
                FunctionInterp::new(parse("tan(x)").unwrap(), 1.0, 2.0, [100.0, 100.0], 1000, ANY, method).unwrap();
            let w = walk(&mut interp, method, 1_000_000);
            assert_eq!(w.end, Err(CurveError::Jump));
            let last = w.last();
            assert!(last.x < 57, "reached column {} past tan's steepest", last.x);
            assert!(w.path.iter().all(|p| (1.0 + p.x as f64 / 100.0) < core::f64::consts::FRAC_PI_2));
            let ideal = (libm::tan(1.0 + last.x as f64 / 100.0) - libm::tan(1.0)) * 100.0;
            assert!((last.y as f64 - ideal).abs() <= 0.5 + FLOAT_SLACK_STEPS);
            // Without a jump limit a pole between two columns goes unseen: over [0, π] at one
            // step/mm the columns are 0, π/3, 2π/3 and π, drawn as their polyline. Hence the limit.
            let mut interp = FunctionInterp::new(
                parse("tan(x)").unwrap(),
                0.0,
                core::f64::consts::PI,
                [1.0, 1.0],
                i32::MAX,
                ANY,
                method,
            )
            .unwrap();
            assert_eq!(walk(&mut interp, method, 100_000).end, Ok(()));
            // Started exactly at π/2, the pole is an error and nothing moves.
            let at_pole = FunctionInterp::new(
                parse("tan(x)").unwrap(),
                core::f64::consts::FRAC_PI_2,
                3.0,
                [1.0, 1.0],
                10,
                ANY,
                method,
            );
            assert_eq!(at_pole.err(), Some(CurveSetupError::Start(CurveError::DivisionByZero)));
        }
    }

    #[test]
    fn a_square_root_leaving_its_domain_ends_at_the_edge() {
        for method in METHODS {
            // sqrt(-1-x) is defined for x <= -1: from x = -3 mm it climbs down to x = -1 mm
            // (column 20 at 10 steps/mm) and fails at the next column.
            let mut interp =
                FunctionInterp::new(parse("sqrt(-1-x)").unwrap(), -3.0, 0.0, [10.0, 10.0], 1000, ANY, method).unwrap();
            let w = walk(&mut interp, method, 10_000);
            assert_eq!(w.end, Err(CurveError::Domain));
            assert_eq!(w.last(), Point::new(20, (-libm::sqrt(2.0) * 10.0).round() as i32));
            assert!(w.path.iter().all(|p| p.x <= 20));
            // Started outside the domain, it does not start at all.
            let outside = FunctionInterp::new(parse("sqrt(-1-x)").unwrap(), 0.0, 1.0, [10.0, 10.0], 1000, ANY, method);
            assert_eq!(outside.err(), Some(CurveSetupError::Start(CurveError::Domain)));
        }
    }

    #[test]
    fn a_function_leaving_the_travel_part_way_stops_at_the_last_column_inside() {
        // y = 250·sin²(πx/2) mm on [0, 4] mm at 100 steps/mm, the pen at row 1_000 of a ±20_000-row
        // travel: rows above 19_000 (relative) are outside. The first hump (up to 25_000 rows)
        // passes them, at most 393 rows per column, within the 500-row jump limit.
        let (spm, start_y, limit) = (100.0, 1_000, 20_000);
        let rows = RowRange::within_travel(start_y, limit);
        let row = |k: i32| {
            let s = libm::sin(core::f64::consts::PI * (k as f64 / spm) / 2.0);
            nearest_step(250.0 * s * s * spm)
        };
        let first_out = (0..=400).find(|&k| row(k) > 19_000).unwrap();
        let last_in = first_out - 1;
        for method in METHODS {
            let e = parse("250*sin(pi*x/2)^2").unwrap();
            let mut interp = FunctionInterp::new(e, 0.0, 4.0, [spm, spm], 500, rows, method).unwrap();
            assert_eq!(interp.nominal_end(), Ok(Point::new(400, 0)), "its end is inside");
            let w = walk(&mut interp, method, 1_000_000);
            assert_eq!(w.end, Err(CurveError::Travel));
            assert_eq!(w.last(), Point::new(last_in, row(last_in)));
            assert!(w.path.iter().all(|p| p.x <= last_in), "stepped toward column {first_out}");
            assert!(w.path.iter().all(|p| (start_y + p.y).abs() <= limit), "a step outside the travel");
            // Without the limit it draws both humps to its end.
            let e = parse("250*sin(pi*x/2)^2").unwrap();
            let mut free = FunctionInterp::new(e, 0.0, 4.0, [spm, spm], 500, ANY, method).unwrap();
            assert_eq!(walk(&mut free, method, 1_000_000).end, Ok(()));
        }
    }

    #[test]
    fn a_realistic_expression_is_drawn_end_to_end() {
        let src = "2.5*sin(2*pi*x/40) * exp(-x/100) + 0.1*x";
        let f = |x: f64| 2.5 * libm::sin(2.0 * core::f64::consts::PI * x / 40.0) * libm::exp(-x / 100.0) + 0.1 * x;
        for method in METHODS {
            let (w, h, dir) = draw(src, 0.0, 100.0, 80.0, 400, method, f);
            assert_eq!(w.end, Ok(()));
            assert_eq!(w.last(), Point::new(8000, ((f(100.0) - f(0.0)) * 80.0).round() as i32));
            assert!(max_deviation(&w.path, dir, &h) <= max_deviation_for(method) + FLOAT_SLACK_STEPS);
            assert_meets_every_column(&w.path, dir, &h);
        }
    }

    #[test]
    fn steps_per_mm_differ_per_axis() {
        // y = x/2 on [0, 10] mm at 40 X steps/mm and 100 Y steps/mm: 400 columns, 500 rows.
        let mut interp =
            FunctionInterp::new(parse("x/2").unwrap(), 0.0, 10.0, [40.0, 100.0], 10, ANY, Method::Diagonal).unwrap();
        let w = walk(&mut interp, Method::Diagonal, 10_000);
        assert_eq!(w.last(), Point::new(400, 500));
        assert_eq!(w.steps(), 500);
    }

    #[test]
    fn the_tangent_follows_the_curve_in_the_direction_of_travel() {
        let e = parse("x^2/10").unwrap();
        // At x = -10 mm the slope is 2x/10 = -2.
        let mut fwd = FunctionInterp::new(e.clone(), -10.0, 10.0, [20.0, 20.0], 100, ANY, Method::Diagonal).unwrap();
        let t = fwd.tangent();
        let want = (1.0 / 5f32.sqrt(), -2.0 / 5f32.sqrt());
        assert!((t.x - want.0).abs() < 0.01 && (t.y - want.1).abs() < 0.01, "{t:?}");
        // At the vertex it is level.
        while fwd.position().x < 200 {
            fwd.next_step().unwrap();
        }
        assert!(fwd.tangent().x > 0.999, "{:?}", fwd.tangent());
        // Drawn from x = 10 mm toward -x, the curve falls to the left.
        let back = FunctionInterp::new(e, 10.0, -10.0, [20.0, 20.0], 100, ANY, Method::Classic).unwrap();
        let t = back.tangent();
        assert!((t.x + want.0).abs() < 0.01 && (t.y - want.1).abs() < 0.01, "{t:?}");
    }

    #[test]
    fn bad_parameters_are_refused_and_an_empty_range_takes_no_step() {
        let e = parse("x").unwrap();
        let new = |x0: f64, x1: f64, spm: [f64; 2], jump: i32| {
            FunctionInterp::new(e.clone(), x0, x1, spm, jump, ANY, Method::Diagonal).err()
        };
        assert_eq!(new(f64::NAN, 1.0, [10.0, 10.0], 10), Some(CurveSetupError::BadParameter));
        assert_eq!(new(0.0, f64::INFINITY, [10.0, 10.0], 10), Some(CurveSetupError::BadParameter));
        assert_eq!(new(0.0, 1.0, [0.0, 10.0], 10), Some(CurveSetupError::BadParameter));
        assert_eq!(new(0.0, 1.0, [10.0, -1.0], 10), Some(CurveSetupError::BadParameter));
        assert_eq!(new(0.0, 1.0, [10.0, 10.0], -1), Some(CurveSetupError::BadParameter));
        assert_eq!(new(-1e6, 1e6, [10.0, 10.0], 10), Some(CurveSetupError::OutOfRange));
        let mut empty = FunctionInterp::new(e, 3.0, 3.0, [10.0, 10.0], 10, ANY, Method::Classic).unwrap();
        assert_eq!(empty.next_step(), Ok(None));
    }
}

//! Explicit curves y = g(x), stepped column by column: [`ExplicitCurve`], the stepping shared by
//! the sine curve (`crate::interp::sine`) and the function curve (`crate::interp::function`),
//! with the limits every explicit curve is held to ([`RowRange`], [`jump_limit_steps`],
//! [`MAX_CURVE_OFFSET_STEPS`]).
//!
//! [`ExplicitCurve`] sees the curve only through [`CurveFn`]: the ideal y, in steps, at each
//! whole-step *column* 0, 1, ..., n along the direction of travel. The path is translated to
//! start at the pen: it follows `h(k) = g(k) - g(0)`.
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

use crate::geom::{Point, Step};
use crate::interp::{CurveError, CurveSetupError, Interpolator, Method, Tangent};

#[cfg(test)]
pub(crate) mod test_support;
#[cfg(test)]
mod tests;

/// Furthest an explicit curve may reach from its start on either axis, in steps: five times the
/// machine's full travel (±500 mm at 200 steps/mm is 200_000 steps corner to corner), so a curve
/// that fits the machine is never refused and all step arithmetic stays far from `i32`'s limits.
pub const MAX_CURVE_OFFSET_STEPS: i32 = 1_000_000;
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

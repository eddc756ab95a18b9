//! Explicit curves y = g(x), stepped column by column: [`ExplicitCurve`], the stepping shared by
//! the sine curve (`crate::motion::interp::sine`) and the function curve (`crate::motion::interp::function`),
//! with the limits every explicit curve is held to ([`jump_limit_steps`],
//! [`MAX_CURVE_OFFSET_STEPS`]).
//!
//! [`ExplicitCurve`] sees the curve only through [`CurveFn`]: the ideal y at each whole-step
//! *column* 0, 1, ..., n along the direction of travel, in the curve's own unit, and how many
//! steps that unit is. The path is translated to start at the pen: it follows
//! `h(k) = (g(k) - g(0))·steps_per_unit`, in steps.
//!
//! Between two columns the ideal curve is taken as its chord, the segment from `(k, h(k))` to
//! `(k + 1, h(k + 1))`; the curve as drawn is the polyline through the column values (for a
//! smooth g it differs from g by at most `max|g''| / 8` between columns).
//!
//! * The chain. Every column `k` is entered at its rounded value `r(k) = round(h(k))` (nearest
//!   step, ties toward +y). A chord whose rows differ by at most one is one step, straight or
//!   diagonal, to `(k + 1, r(k + 1))`. A steeper chord is walked row by row from `r(k)` to
//!   `r(k + 1)`, and in each row the pen stands in the column nearer to where the chord crosses
//!   that row, so X advances in the middle of a steep rise, not at its end: at the first row at
//!   or past the chord's middle value `(h(k) + h(k + 1)) / 2`.
//! * `Diagonal` takes the chain as it is: both axes may move together. Every lattice point
//!   visited lies within 0.5 step (Euclidean distance) of the chord it belongs to;
//!   `Σ max(1, |r(k+1) - r(k)|)` steps in all.
//! * `Classic` moves one axis per step, in the manner of the point-by-point comparison: where
//!   the chain moves diagonally it compares the two corners of that move and passes through the
//!   one nearer to the chord's line (ties: X first). Every lattice point visited lies within
//!   √2/2 ≈ 0.71 step of its chord (both ends of the move are within 0.5 of it, so the chord
//!   crosses the move's other diagonal within 0.5 of its middle, and the corner nearer to the
//!   line is the one nearer to that crossing); `n + Σ |r(k+1) - r(k)|` steps in all, none
//!   wasted.
//! * The end point is exactly `(n, round(h(n)))`, and every chord takes at most
//!   `1 + |r(k+1) - r(k)|` steps, so the curve always terminates.
//!
//! Each column value is computed just before its chord is stepped. If it cannot be computed
//! (the function's domain error, [`CurveError::Overflow`] beyond [`MAX_CURVE_OFFSET_STEPS`]),
//! or the chord rises or falls by more than the curve's `max_jump_steps`
//! ([`CurveError::Jump`]), the curve ends with that error *before* any step of the chord,
//! the pen standing at `(k, r(k))`; afterwards `next_step` returns `Ok(None)`. Since the
//! planner's look-ahead runs a clone of the curve ahead of the pen, it meets the error as early
//! as any end and brings the pen to a stop there.
//!
//! A jump is an error, never a travel: the machine has no pen lift, so crossing a pole would
//! draw a line the function does not contain. The machine's travel is not this module's: the
//! drawing builder refuses a curve whose lattice path leaves it, and the guard of
//! [`crate::motion::interp::Curve`] stops one at the edge.
//!
//! The drawing builder's copy of a curve is also checked between its columns
//! ([`ExplicitCurve::check_between_columns`], see [`between`]): one more evaluation of g per
//! column, at a point inside the chord, and the curve ends with [`CurveError::Aliased`] one
//! column after a chord that strays there further than its columns show (at the end, for the
//! last chord), or with g's own error where g cannot be evaluated there. The steps are the
//! same either way; the curve the motion steps is not checked.
//!
//! [`Interpolator::tangent`] is the direction of the current chord, `(1, h(k+1) - h(k))`
//! normalised and pointing in the direction of travel (the derivative by finite difference). It
//! changes only where the pen reaches a column, so that is the only place a curve can kink
//! ([`KINK_CHORD`]).
//!
//! # Batches
//!
//! Once a chord's two rows are known its steps are fixed: some steps along Y, the one move that
//! advances X (two steps for `Classic` where it is diagonal), the rest along Y. Loading a chord
//! works that pattern out once; [`Interpolator::fill`] then writes it straight into the buffer
//! (a chord of one step, the most common, without even that), and does per-chord work
//! (evaluate g, round, check the limits, choose the classic corner, test for a kink) only where
//! a column is reached, with the chain's state in locals. `next_step` is `fill` with a
//! buffer of one, so both hand out the same steps by construction. A kink can only fall where a
//! chord starts, and only where the slope changes by more than [`KINK_CHORD`] (the angle
//! between two directions is at most the difference of their slopes), so only there are the
//! two unit tangents compared.
//!
//! # Arithmetic
//!
//! Columns and rows are integers; values are `f32`, whose 24-bit significand is what limits
//! their precision. The care taken:
//!
//! * Cancellation in `g(k) - g(0)`: g is subtracted in its own unit, before the scale to steps,
//!   so a curve far from zero (`1000 + sin(x)` mm) loses nothing to the subtraction itself:
//!   two `f32` within a factor of two of each other subtract exactly. What remains is the error
//!   g's values carry in themselves, a few units in the last place of |g| (an `f32`'s ulp is
//!   2⁻²³ of it), then one rounding of h relative to |h|. A curve's rows are therefore exact to
//!   about `2⁻²¹·(max|g| in steps)`: 0.005 step for a curve reaching 10_000 steps from zero,
//!   0.05 step at the machine's full ±100_000 (f32 numbers there are 1/128 step apart). The
//!   sine and function modules state what their g adds.
//! * Rounding to rows is exact: `floor` by conversion to an integer, then a comparison with
//!   the integer plus one half (both exact below 2²³), so `(n, round(h(n)))` is exact for the
//!   value computed, and ties go toward +y.
//! * The chain's own decisions (the middle of a steep chord, the classic corner) use the chord's
//!   two values; each costs at most one more rounding of a value of the size of h. So every
//!   bound above holds for the computed values within `2⁻²³·max|h|`, for the ideal ones within
//!   the values' own error besides.
//! * Offsets are checked against [`MAX_CURVE_OFFSET_STEPS`] (below 2²⁰) before any rounding to
//!   an integer, so all of the above stays in the exact range, and all step arithmetic is `i32`.

use crate::geom::{Point, Step};
use crate::math;
use crate::motion::interp::explicit::between::{BetweenColumns, sample_fraction};
use crate::motion::interp::interpolator::{CurveError, Filled, Interpolator, KINK_CHORD, Tangent};
use crate::motion::interp::setup::CurveSetupError;
use crate::motion::method::Method;

pub mod between;
#[cfg(test)]
pub(crate) mod test_support;
#[cfg(test)]
mod tests;

/// Furthest an explicit curve may reach from its start on either axis, in steps: five times the
/// machine's full travel (±500 mm at 200 steps/mm is 200_000 steps corner to corner), so a curve
/// that fits the machine is never refused and all step arithmetic stays far from `i32`'s limits.
pub const MAX_CURVE_OFFSET_STEPS: i32 = 1_000_000;

/// [`MAX_CURVE_OFFSET_STEPS`] as an `f32` (exactly: it is below 2²⁴).
const MAX_CURVE_OFFSET_STEPS_F32: f32 = MAX_CURVE_OFFSET_STEPS as f32;

/// The jump limit of an explicit curve, in rows: the `max_jump_mm` setting (`$204`) at
/// `y_steps_per_mm`, rounded down, and at least one row, or any slope at all would be a jump.
pub fn jump_limit_steps(max_jump_mm: f32, y_steps_per_mm: f32) -> i32 {
    math::max(max_jump_mm * y_steps_per_mm, 1.0) as i32
}

/// An explicit curve as [`ExplicitCurve`] sees it.
pub trait CurveFn {
    /// The ideal y at `column` (0 at the start, counted in the direction of travel, up to the
    /// curve's length), in the curve's own unit. Only differences from column 0 matter.
    fn y(&self, column: i32) -> Result<f32, CurveError>;

    /// Steps per unit of [`CurveFn::y`]; any finite number (negative mirrors the curve).
    fn y_steps_per_unit(&self) -> f32 {
        1.0
    }

    /// The ideal y a `fraction` (between 0 and 1) of the way from `column` to the next one, for
    /// the check between columns ([`between`]); `None` for a curve that is not checked there.
    fn y_between(&self, _column: i32, _fraction: f32) -> Option<Result<f32, CurveError>> {
        None
    }
}

impl<F: Fn(i32) -> Result<f32, CurveError>> CurveFn for F {
    fn y(&self, column: i32) -> Result<f32, CurveError> {
        self(column)
    }
}

/// The largest integer not above `v`, for |v| < 2²³ (exact there).
#[inline]
fn floor_steps(v: f32) -> i32 {
    // Toward zero, then one down where that went up.
    let t = v as i32;
    if t as f32 > v { t - 1 } else { t }
}

/// The nearest whole step to `h`, ties toward +y (monotonic, so that neighbouring columns whose
/// values differ by at most one step round at most one step apart). Exact for |h| < 2²²: the
/// comparison is with `floor(h) + 0.5`, which is an `f32` there.
#[inline]
pub(crate) fn nearest_step(h: f32) -> i32 {
    let f = floor_steps(h);
    f + i32::from(h >= f as f32 + 0.5)
}

/// The unit tangent `(dir, slope)` normalised.
#[inline]
fn unit(dir: i8, slope: f32) -> Tangent {
    let inv = 1.0 / math::sqrt(1.0 + slope * slope);
    Tangent { x: f32::from(dir) * inv, y: slope * inv }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    Running,
    /// Ends with this error where the next step would be.
    Failed(CurveError),
    Done,
}

/// The steps of the current chord: `total` steps, each `vertical` except the step at
/// `middle_at` (`middle`, the one that advances X or its first half) and the one after it
/// (`after_middle`: the second half of a classic diagonal move, otherwise `vertical`).
#[derive(Clone, Copy, Debug)]
struct Chord {
    vertical: Step,
    middle: Step,
    after_middle: Step,
    middle_at: usize,
    total: usize,
    /// Steps handed out so far.
    done: usize,
}

impl Chord {
    /// No steps: before the first chord is loaded.
    const EMPTY: Chord =
        Chord { vertical: Step::NONE, middle: Step::NONE, after_middle: Step::NONE, middle_at: 0, total: 0, done: 0 };

    /// Writes the chord's steps `from..from + out.len()` into `out`.
    #[inline]
    fn write(&self, from: usize, out: &mut [Step]) {
        out.fill(self.vertical);
        // Where the middle falls in `out` (wrapping: before it, the step after the middle can
        // still be its first slot).
        let at = self.middle_at.wrapping_sub(from);
        if let Some(slot) = out.get_mut(at) {
            *slot = self.middle;
        }
        if let Some(slot) = out.get_mut(at.wrapping_add(1)) {
            *slot = self.after_middle;
        }
    }

    fn step(&self, j: usize) -> Step {
        if j == self.middle_at {
            self.middle
        } else if j == self.middle_at + 1 {
            self.after_middle
        } else {
            self.vertical
        }
    }
}

/// Steps along an explicit curve y = g(x); see the module documentation.
#[derive(Clone, Debug)]
pub struct ExplicitCurve<G> {
    g: G,
    walk: Walk,
}

/// Where the walk along an explicit curve stands. Its stepping is compiled for each kind of
/// curve (a sine, a function), so that g is called directly at each column, not through a
/// pointer; what runs once per curve takes g as a `&dyn CurveFn`.
#[derive(Clone, Debug)]
struct Walk {
    method: Method,
    /// Direction of travel on X: +1 or -1.
    dir: i8,
    /// Number of columns to travel (|length|).
    columns: i32,
    max_jump_steps: i32,
    /// The check between columns, where the walk makes it (the drawing builder's copy).
    between: Option<BetweenColumns>,
    /// g(0), in g's unit: the curve is translated by it so that it starts at the pen.
    origin: f32,
    /// Steps per unit of g.
    steps_per_unit: f32,
    /// The current chord runs from column `seg` (row `r0`) to `seg + 1` (value `h1`, row `r1`)...
    seg: i32,
    r0: i32,
    h1: f32,
    r1: i32,
    /// ...rising `h1 - h0` rows per column...
    slope: f32,
    /// ...in these steps (once all are handed out, the chords after it may have been written
    /// straight into a batch, each all at once: `seg`, `r0`, `r1` are then the last one's).
    chord: Chord,
    phase: Phase,
}

impl<G: CurveFn> ExplicitCurve<G> {
    /// A curve over `length_steps` columns (negative: toward -x), refusing jumps of more than
    /// `max_jump_steps` rows between neighbouring columns (`i32::MAX`: no limit). Evaluates
    /// g at the start; an error there is [`CurveSetupError::Start`] and nothing moves.
    pub fn new(g: G, length_steps: i32, max_jump_steps: i32, method: Method) -> Result<Self, CurveSetupError> {
        let walk = Walk::new(&g, length_steps, max_jump_steps, method)?;
        Ok(ExplicitCurve { g, walk })
    }

    /// The same curve, checked between its columns as it is walked (see [`between`]): the
    /// drawing builder walks such a copy, so a curve that changes faster than its steps sample
    /// it ends with [`CurveError::Aliased`]. Costs one more evaluation of g per column.
    pub fn check_between_columns(mut self) -> Self {
        self.walk.between = Some(BetweenColumns::default());
        // The first chord was loaded unchecked: load it again.
        if self.walk.columns > 0 {
            self.walk.phase = match self.walk.start(&self.g) {
                Ok(()) => Phase::Running,
                Err(e) => Phase::Failed(e),
            };
        }
        self
    }

    /// The curve's g.
    #[cfg(test)]
    pub(crate) fn curve_fn(&self) -> &G {
        &self.g
    }

    /// Where the steps handed out so far have taken the pen, relative to the start.
    pub fn position(&self) -> Point {
        self.walk.position()
    }

    /// Where the whole curve ends, relative to the start, `(±n, round(h(n)))`, found from its
    /// last column alone (exactly as the steps reach it); an error there means the curve cannot
    /// reach its end.
    pub fn nominal_end(&self) -> Result<Point, CurveError> {
        self.walk.nominal_end(&self.g)
    }

    /// The value the curve steps by at `column`, relative to the start, in steps.
    #[cfg(test)]
    pub(crate) fn offset_steps(&self, column: i32) -> Result<f32, CurveError> {
        self.walk.offset(&self.g, column)
    }
}

impl Walk {
    fn new(g: &dyn CurveFn, length_steps: i32, max_jump_steps: i32, method: Method) -> Result<Self, CurveSetupError> {
        let steps_per_unit = g.y_steps_per_unit();
        if max_jump_steps < 0 || !steps_per_unit.is_finite() {
            return Err(CurveSetupError::BadParameter);
        }
        if length_steps.unsigned_abs() > MAX_CURVE_OFFSET_STEPS as u32 {
            return Err(CurveSetupError::OutOfRange);
        }
        let origin = g.y(0).map_err(CurveSetupError::Start)?;
        if !origin.is_finite() {
            return Err(CurveSetupError::Start(CurveError::Overflow));
        }
        let dir = if length_steps < 0 { -1 } else { 1 };
        let mut curve = Walk {
            method,
            dir,
            columns: length_steps.abs(),
            max_jump_steps,
            between: None,
            origin,
            steps_per_unit,
            // Before column 0: the pen stands at the end of no chord.
            seg: -1,
            r0: 0,
            h1: 0.0,
            r1: 0,
            slope: 0.0,
            chord: Chord::EMPTY,
            phase: Phase::Running,
        };
        if curve.columns == 0 {
            curve.phase = Phase::Done;
        } else if let Err(e) = curve.start(g) {
            curve.phase = Phase::Failed(e);
        }
        Ok(curve)
    }

    fn position(&self) -> Point {
        let c = &self.chord;
        if c.done == c.total {
            // The current chord is all handed out (or none is left): the pen is on its end.
            return Point::new(i32::from(self.dir) * (self.seg + 1), self.r1);
        }
        let start = Point::new(i32::from(self.dir) * self.seg, self.r0);
        (0..c.done).fold(start, |p, j| p.stepped(c.step(j)))
    }

    fn nominal_end<G: CurveFn + ?Sized>(&self, g: &G) -> Result<Point, CurveError> {
        Ok(Point::new(i32::from(self.dir) * self.columns, nearest_step(self.offset(g, self.columns)?)))
    }

    /// The ideal curve at `column`, relative to the start, in steps.
    #[inline]
    fn offset<G: CurveFn + ?Sized>(&self, g: &G, column: i32) -> Result<f32, CurveError> {
        let h = (g.y(column)? - self.origin) * self.steps_per_unit;
        // False for NaN as well.
        if h.abs() <= MAX_CURVE_OFFSET_STEPS_F32 { Ok(h) } else { Err(CurveError::Overflow) }
    }

    /// The value and row of `column`, checked against the limits for a chord that starts at
    /// row `r0`, or why that chord cannot be drawn.
    #[inline(always)]
    fn column<G: CurveFn + ?Sized>(&self, g: &G, column: i32, r0: i32) -> Result<(f32, i32), CurveError> {
        let h = self.offset(g, column)?;
        let r = nearest_step(h);
        if (r - r0).abs() > self.max_jump_steps { Err(CurveError::Jump) } else { Ok((h, r)) }
    }

    /// The steps of a chord from value `h0` (row `r0`) to value `h1` (row `r1`), one column on.
    #[inline(always)]
    fn chord(&self, h0: f32, r0: i32, h1: f32, r1: i32) -> Chord {
        let rise = r1 - r0;
        let s = Step::sign(rise);
        let rows = rise.unsigned_abs() as usize;
        // X advances at the first row at or past the chord's middle value (never before the
        // first row, at the last at the latest).
        let middle_at = if rows <= 1 {
            0
        } else {
            let mid = h0 + 0.5 * (h1 - h0);
            let first = if rise > 0 { -floor_steps(-mid) - r0 } else { r0 - floor_steps(mid) };
            first.clamp(1, rise.abs()) as usize - 1
        };
        let (vertical, x) = (Step::new(0, s), Step::new(self.dir, 0));
        let (middle, after_middle, total) = if self.method == Method::Classic && s != 0 {
            // Through the corner nearer to the chord's line: from the move's start `(0, y)`, X
            // first passes `(1, y)`, at |y - h1|·c from it, Y first `(0, y + s)`, at
            // |y + s - h0|·c (c = 1/√(1 + slope²), the same for both).
            let y = (r0 + i32::from(s) * middle_at as i32) as f32;
            if (y - h1).abs() <= (y + f32::from(s) - h0).abs() {
                (x, vertical, rows + 1)
            } else {
                (vertical, x, rows + 1)
            }
        } else {
            (Step::new(self.dir, s), vertical, rows.max(1))
        };
        Chord { vertical, middle, after_middle, middle_at, total, done: 0 }
    }

    /// Checks the chord from column `chord` (value `h0`) to the next (value `h1`) between its
    /// columns (see [`between`]), when the walk does; an error where the curve cannot be
    /// evaluated there or a chord strays further than its columns show.
    #[inline(never)]
    fn check_between<G: CurveFn + ?Sized>(&mut self, g: &G, chord: i32, h0: f32, h1: f32) -> Result<(), CurveError> {
        let Some(mut check) = self.between else { return Ok(()) };
        let fraction = sample_fraction(chord);
        let Some(y) = g.y_between(chord, fraction) else {
            // The curve does not say: nothing to check.
            self.between = None;
            return Ok(());
        };
        let at = (y? - self.origin) * self.steps_per_unit;
        let judged = check.chord(h0, h1, at);
        self.between = Some(check);
        judged
    }

    /// Judges the last chord between its columns, when the walk checks there.
    fn check_between_end(&self) -> Result<(), CurveError> {
        self.between.map_or(Ok(()), |check| check.end())
    }

    /// Makes the chord from column 0 to column 1 current, or tells why it cannot be drawn.
    fn start(&mut self, g: &dyn CurveFn) -> Result<(), CurveError> {
        let (h1, r1) = self.column(g, 1, 0)?;
        self.check_between(g, 0, 0.0, h1)?;
        self.chord = self.chord(0.0, 0, h1, r1);
        self.seg = 0;
        self.h1 = h1;
        self.r1 = r1;
        self.slope = h1;
        Ok(())
    }
}

impl<G: CurveFn> Interpolator for ExplicitCurve<G> {
    fn next_step(&mut self) -> Result<Option<Step>, CurveError> {
        let mut one = [Step::NONE];
        let filled = self.fill(&mut one);
        if filled.steps == 1 {
            return Ok(Some(one[0]));
        }
        match filled.end {
            Some(Err(e)) => Err(e),
            _ => Ok(None),
        }
    }

    fn tangent(&self) -> Tangent {
        unit(self.walk.dir, self.walk.slope)
    }

    fn fill(&mut self, out: &mut [Step]) -> Filled {
        self.walk.fill(&self.g, out)
    }
}

impl Walk {
    fn fill<G: CurveFn>(&mut self, g: &G, out: &mut [Step]) -> Filled {
        let mut i = 0;
        loop {
            // An error is handed out only where there is room for a step: where `next_step`
            // would hand it out.
            if i == out.len() {
                return if self.phase == Phase::Done { Filled::ended(i, Ok(())) } else { Filled::more(i) };
            }
            match self.phase {
                Phase::Running => {}
                Phase::Done => return Filled::ended(i, Ok(())),
                Phase::Failed(e) => {
                    self.phase = Phase::Done;
                    return Filled::ended(i, Err(e));
                }
            }
            // The rest of the current chord.
            let c = &mut self.chord;
            let take = (c.total - c.done).min(out.len() - i);
            c.write(c.done, &mut out[i..i + take]);
            c.done += take;
            i += take;
            if c.done < c.total {
                return Filled::more(i);
            }
            // Column by column while the chords fit, the chain's state in locals: the pen is on
            // column `seg + 1`, row `r1`, where the next chord starts.
            let (mut seg, mut r0, mut h1, mut r1, mut slope) = (self.seg, self.r0, self.h1, self.r1, self.slope);
            let ended = loop {
                if seg + 1 == self.columns {
                    break match self.check_between_end() {
                        Ok(()) => Phase::Done,
                        Err(e) => Phase::Failed(e),
                    };
                }
                let (h, r) = match self.column(g, seg + 2, r1) {
                    Ok(v) => v,
                    Err(e) => break Phase::Failed(e),
                };
                if self.between.is_some()
                    && let Err(e) = self.check_between(g, seg + 1, h1, h)
                {
                    break Phase::Failed(e);
                }
                let (h0, before) = (h1, slope);
                (seg, r0, h1, r1, slope) = (seg + 1, r1, h, r, h - h1);
                // Unit tangents whose slopes differ by at most the kink chord differ by less
                // (the angle between them is at most the difference of slopes), so only past it
                // can the curve kink.
                if (slope - before).abs() > KINK_CHORD {
                    let before = unit(self.dir, before);
                    if before.kinks_to(unit(self.dir, slope)) {
                        (self.seg, self.r0, self.h1, self.r1, self.slope) = (seg, r0, h1, r1, slope);
                        self.chord = self.chord(h0, r0, h1, r1);
                        return Filled::kink(i, before);
                    }
                }
                // Most chords are one step.
                let rise = r1 - r0;
                if i < out.len() && (rise == 0 || (rise.abs() == 1 && self.method == Method::Diagonal)) {
                    out[i] = Step::new(self.dir, Step::sign(rise));
                    i += 1;
                    continue;
                }
                let mut chord = self.chord(h0, r0, h1, r1);
                let room = out.len() - i;
                if chord.total > room {
                    chord.write(0, &mut out[i..]);
                    chord.done = room;
                    (self.seg, self.r0, self.h1, self.r1, self.slope) = (seg, r0, h1, r1, slope);
                    self.chord = chord;
                    return Filled::more(out.len());
                }
                chord.write(0, &mut out[i..i + chord.total]);
                i += chord.total;
            };
            // Every chord so far is handed out: `chord` may be an earlier one, all done.
            (self.seg, self.r0, self.h1, self.r1, self.slope) = (seg, r0, h1, r1, slope);
            self.phase = ended;
        }
    }
}

//! What an explicit curve does between its columns: [`BetweenColumns`], the check the drawing
//! builder's walk makes that the column values show the curve, so that a curve which changes
//! faster than the X steps sample it (`sin(x*628.3)` at 100 steps/mm: a wave of 0.01 mm, one
//! step) is refused instead of drawn as whatever its columns happen to give (nearly flat).
//!
//! The walk evaluates the curve once more per chord, at a point a [`sample_fraction`] of the way
//! from column `k` to `k + 1`, and measures how far the curve is there outside the rows the
//! chord spans, from its row at `k` to its row at `k + 1`: the chord's *stray*. The pen covers
//! those rows in the chord's two columns, so a curve inside them is within a step of the path
//! (a curve that only rises or only falls between two columns, a staircase's riser, never
//! strays); only a crest or a trough between the columns does, or a wave. A chord is refused
//! when its stray is more than [`STRAY_MAX_STEPS`] *and* the columns around it do not show a
//! bend that large: the change of rise from the chord before to the chord after it (the second
//! difference, in rows per column) is under [`STRAY_SHOWN_RATIO`] times the stray.
//!
//! * A smooth curve strays from its chords by at most `max|h''|/8` rows, while the rises around
//!   a chord change by about `2·|h''|`, sixteen times that. Gaussians, cubics, `sin(x/20)·x/10`
//!   pass however large they are, and a kink (`abs`) passes too: the rise turns around it by at
//!   least four times its stray.
//! * A sine of `n` steps per wave cuts its crests by `A·(1 - cos(π/n))` rows, and the rises
//!   around a crest change by `2A·(cos(π/n) - cos(3π/n))`: at `n = 8`, `$S`'s fewest, fourteen
//!   times the stray. Sampled anywhere in its chords, a sine of three steps per wave or more
//!   bends at least 4.6 times its stray, whatever its amplitude and phase. Those draw, as `$S`
//!   draws them at eight or more.
//! * A wave of 2.25 steps or fewer, which the columns miss or see as a slower one, leaves them
//!   bending little from chord to chord, while the curve between them strays by up to its
//!   whole height: somewhere the bend is under 2.4 times the stray (none at all for a whole
//!   number of waves a step, or two steps a wave), and it is refused there, as soon as it
//!   strays more than a step. Between 2.25 and 3 steps a wave it depends on the amplitude.
//! * A staircase (`floor`) does not stray at all.
//!
//! The sample point moves from chord to chord along the golden-ratio sequence, so no wave can
//! hide between the sample points of every chord, as one with a whole number of waves per step
//! would between the same fraction of every chord.
//!
//! Each chord is judged once the chord after it is known, so a refusal comes one column after
//! the chord that strays; the last is judged at the end. Only the builder's copy of a curve
//! makes the check ([`crate::motion::interp::Curve::check_between_columns`]), at one more evaluation
//! of the curve per column; the curve the motion steps does not.

#[cfg(test)]
mod tests;

use crate::math;
use crate::motion::interp::interpolator::CurveError;

/// How far the curve may stray beyond the rows of a chord between its two columns whatever the
/// columns show, in steps: the drawn path stays within about a step of the curve there.
pub const STRAY_MAX_STEPS: f32 = 1.0;

/// How many times a chord's stray the columns around it must bend (their change of rise, rows
/// per column) to show it, beyond [`STRAY_MAX_STEPS`]. A smooth curve bends sixteen times its
/// stray, a kink four, a sine of three steps per wave or more at least 4.6, a wave of 2.25
/// steps or fewer under 2.4 somewhere along it.
pub const STRAY_SHOWN_RATIO: f32 = 3.0;

/// The golden ratio's fractional part, 0.618..., in 32-bit fixed point: the step of the
/// sequence of sample fractions.
const GOLDEN_FRACTION_FIXED: u32 = 0x9E37_79B9;

/// Where chord `chord` (from column `chord` to `chord + 1`) is sampled: a fraction of the way,
/// in [1/256, 255/256], the golden-ratio sequence `frac((chord + 1)·0.618...)`.
#[inline]
pub fn sample_fraction(chord: i32) -> f32 {
    let fixed = (chord as u32).wrapping_add(1).wrapping_mul(GOLDEN_FRACTION_FIXED);
    // 8 bits: exact in f32, and never at a column itself.
    let eighth_bits = (fixed >> 24).clamp(1, 255);
    eighth_bits as f32 * (1.0 / 256.0)
}

/// A chord seen, waiting for the rise of the chord after it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Seen {
    /// Rows the chord rises over its column.
    rise: f32,
    /// How far the curve at the sample point is outside the chord's rows, in rows (negative
    /// inside them).
    stray: f32,
}

/// The check between columns; see the module documentation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BetweenColumns {
    /// The rise of the chord before `pending`, if there is one.
    rise_before: Option<f32>,
    /// The last chord seen, not yet judged.
    pending: Option<Seen>,
}

impl BetweenColumns {
    /// The next chord, from value `h0` to `h1` (rows, one column apart), where the curve is `at`
    /// at its sample point: judges the chord before it, now that its neighbours are known.
    /// [`CurveError::Aliased`] when that one strays further than its columns show.
    pub fn chord(&mut self, h0: f32, h1: f32, at: f32) -> Result<(), CurveError> {
        let rise = h1 - h0;
        let (low, high) = if rise < 0.0 { (h1, h0) } else { (h0, h1) };
        // NaN stays NaN, and is refused.
        let seen = Seen { rise, stray: math::max(low - at, at - high) };
        let judged = self.judge(Some(rise));
        self.rise_before = self.pending.map(|p| p.rise);
        self.pending = Some(seen);
        judged
    }

    /// Judges the last chord, which has no chord after it.
    pub fn end(&self) -> Result<(), CurveError> {
        self.judge(None)
    }

    /// Judges the pending chord, `rise_after` the rise of the chord after it.
    fn judge(&self, rise_after: Option<f32>) -> Result<(), CurveError> {
        let Some(Seen { rise, stray }) = self.pending else { return Ok(()) };
        // A missing neighbour counts as the chord's own rise: at an end the bend is judged from
        // one side.
        let bend = rise_after.unwrap_or(rise) - self.rise_before.unwrap_or(rise);
        let within = stray <= STRAY_MAX_STEPS;
        let shown = stray * STRAY_SHOWN_RATIO <= bend.abs();
        // NaN is neither.
        if within || shown { Ok(()) } else { Err(CurveError::Aliased) }
    }
}

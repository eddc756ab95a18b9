//! The sine curve y = A·sin(ω·x + φ) in steps, drawn from the pen, and the checks the inputs
//! make on a sine before they queue it ([`sin_range`], [`fits_jump_limit`]).
//!
//! x runs over whole steps from 0 to the curve's length (a negative length runs toward -x) and
//! the curve is translated so that it starts at the pen: the path is `(x, f(x) - f(0))`, ending
//! exactly at `(length, round(f(length) - f(0)))`. The stepping itself — chords between
//! columns, classic and diagonal rules, deviation bounds, tangent — is the explicit-curve core
//! of `crate::motion::interp::explicit` ([`ExplicitCurve`]); this module only supplies the function.
//!
//! A sine is continuous, but it is sampled once per X step: where |A·ω| (the steepest slope,
//! in rows per column) is large, neighbouring columns lie far apart and the chord between them
//! is a stroke the curve does not contain. It is therefore held to the same rules as a
//! function: a rise or fall of more than `max_jump_steps` rows between neighbouring columns
//! ends it with [`CurveError::Jump`] before any step toward that column. Otherwise, once set up,
//! it never fails.
//!
//! # Phase
//!
//! The angle at column k, `φ + ω·x` with `x = ±k`, reaches thousands of radians on a long
//! curve, where an `f32` angle is only good to a few 1e-4 rad. It is therefore kept as a
//! fraction of a turn in 64-bit fixed point (2⁻⁶⁴ turn): φ and ω are converted once, exactly
//! from their `f32` values (the mantissa times 2⁶⁴/2π to 64 bits), and the angle of column k
//! is `φ + k·ω` in wrapping integer arithmetic, which is exact modulo one turn. Its error is
//! that of the two conversions, under 2⁻⁶³ turn each per unit of the column index: under
//! 1e-12 rad at a million columns, so the same at the curve's end as at its start.
//!
//! The angle is then reduced, exactly, to the nearest quarter turn and an offset within an
//! eighth of a turn, and the offset, rounded to 2⁻³³ turn (4e-10 rad), becomes an `f32` angle
//! of at most π/4 for `math::sin` or `math::cos`. Each value sin(θ) is so within 1.5e-7 of the
//! true one wherever the column lies (the `f32` angle's rounding, 5e-8 rad, and the
//! polynomial's, within 1.6 ulp). With the subtraction of sin(φ) (exact or one rounding) and
//! the scale by A (one rounding relative to h), every column's value h(k) is within
//! `|A|·2⁻²¹` (4.8e-7·|A|) of `A·(sin(θ_k) - sin(φ))`: 0.05 step at A = 100_000.

use crate::geom::{Point, Step};
use crate::math;
use crate::motion::interp::explicit::{CurveFn, ExplicitCurve, MAX_CURVE_OFFSET_STEPS, jump_limit_steps};
use crate::motion::interp::interpolator::{CurveError, Filled, Interpolator, Tangent};
use crate::motion::interp::setup::CurveSetupError;
use crate::motion::method::Method;

#[cfg(test)]
mod tests;

/// Largest amplitude, in steps: the curve then spans at most [`MAX_CURVE_OFFSET_STEPS`] from its
/// start.
pub const MAX_SINE_AMPLITUDE_STEPS: f32 = MAX_CURVE_OFFSET_STEPS as f32 / 2.0;

/// Bound on the error of a column's value, per step of amplitude (2⁻²¹; see the module
/// documentation), doubled for a rise between two columns.
pub const SINE_RISE_ERROR_PER_AMPLITUDE_STEP: f32 = 2.0 / 2_097_152.0;

/// 2⁶⁴/2π, truncated: one radian in 2⁻⁶⁴ turn.
const TURN_Q64_PER_RAD: u64 = 0x28BE_60DB_9391_054A;

/// A quarter turn in 2⁻⁶⁴ turn is `1 << QUARTER_TURN_SHIFT`.
const QUARTER_TURN_SHIFT: u32 = 62;

/// The reduced offset is kept in 2⁻³³ turn: 2⁻⁶⁴ turn shifted right by this.
const REDUCED_ANGLE_SHIFT: u32 = 31;

/// Radians per 2⁻³³ turn (2π/2³³, exact as an `f32` up to the rounding of π).
const RAD_PER_REDUCED_UNIT: f32 = core::f32::consts::TAU / 8_589_934_592.0;

/// `rad` radians as a fraction of a turn, in 2⁻⁶⁴ turn, modulo one turn; `rad` must be finite.
/// The mantissa of `rad` (24 bits) times [`TURN_Q64_PER_RAD`] is formed exactly (88 bits, as a
/// high 64 and a low 32) and shifted by the exponent; the result is within `|rad| + 1` units of
/// 2⁻⁶⁴ turn of the exact value modulo one turn.
fn turns_q64(rad: f32) -> u64 {
    let bits = rad.to_bits();
    let biased = (bits >> 23) & 0xFF;
    let fraction = bits & 0x7F_FFFF;
    // |rad| = mantissa·2^exp.
    let (mantissa, exp) = if biased == 0 { (fraction, -149) } else { (fraction | 0x80_0000, biased as i32 - 150) };
    let m = u64::from(mantissa);
    let low = m * (TURN_Q64_PER_RAD & 0xFFFF_FFFF);
    let high = m * (TURN_Q64_PER_RAD >> 32) + (low >> 32);
    let low = low & 0xFFFF_FFFF;
    // (high·2³² + low)·2^exp modulo 2⁶⁴: the two parts' bits do not overlap.
    let turns = if exp >= 0 {
        let e = exp as u32;
        high.checked_shl(32 + e).unwrap_or(0) | low.checked_shl(e).unwrap_or(0)
    } else {
        let s = exp.unsigned_abs();
        if s >= 32 { high.checked_shr(s - 32).unwrap_or(0) } else { (high << (32 - s)) | (low >> s) }
    };
    if bits >> 31 != 0 { turns.wrapping_neg() } else { turns }
}

/// sin(2π·t/2⁶⁴): reduced exactly to the nearest quarter turn, the offset (at most an eighth of
/// a turn) to an `f32` angle of at most π/4.
#[inline]
fn sin_turns(t: u64) -> f32 {
    let quadrant = t.wrapping_add(1 << (QUARTER_TURN_SHIFT - 1)) >> QUARTER_TURN_SHIFT;
    // In [-2⁶¹, 2⁶¹): then rounded to 2⁻³³ turn, at most 2³⁰ in magnitude.
    let offset = t.wrapping_sub(quadrant << QUARTER_TURN_SHIFT) as i64;
    let units = (offset + (1 << (REDUCED_ANGLE_SHIFT - 1))) >> REDUCED_ANGLE_SHIFT;
    let r = units as i32 as f32 * RAD_PER_REDUCED_UNIT;
    let v = if quadrant & 1 == 0 { math::sin(r) } else { math::cos(r) };
    if quadrant & 2 == 0 { v } else { -v }
}

/// sin(ω·x + φ) at the columns of a run, x = ±column: A is the curve's scale.
#[derive(Clone, Copy, Debug)]
struct SineFn {
    amplitude_steps: f32,
    /// φ in 2⁻⁶⁴ turn.
    phase_turns: u64,
    /// ω times the direction of travel: the angle from one column to the next, in 2⁻⁶⁴ turn.
    turns_per_column: u64,
}

impl SineFn {
    /// The angle at `column`, exactly (modulo one turn).
    #[inline]
    fn turns(&self, column: i32) -> u64 {
        self.phase_turns.wrapping_add(self.turns_per_column.wrapping_mul(u64::from(column.unsigned_abs())))
    }
}

impl CurveFn for SineFn {
    #[inline]
    fn y(&self, column: i32) -> Result<f32, CurveError> {
        Ok(sin_turns(self.turns(column)))
    }

    fn y_steps_per_unit(&self) -> f32 {
        self.amplitude_steps
    }
}

/// Interpolates y = A·sin(ω·x + φ); see the module documentation.
#[derive(Clone, Debug)]
pub struct SineInterp {
    curve: ExplicitCurve<SineFn>,
    end: Point,
}

impl SineInterp {
    /// The sine of amplitude `amplitude_steps`, angular frequency `omega_rad_per_step` and phase
    /// `phase_rad` for x from 0 to `length_steps` (0: no step). Every parameter must be finite,
    /// and so must ω times the length ([`CurveSetupError::BadParameter`]); |A| up to
    /// [`MAX_SINE_AMPLITUDE_STEPS`] and |length| up to [`MAX_CURVE_OFFSET_STEPS`]
    /// ([`CurveSetupError::OutOfRange`]).
    ///
    /// A rise or fall of more than `max_jump_steps` rows between neighbouring columns
    /// (`i32::MAX`: no limit; a negative limit is [`CurveSetupError::BadParameter`]) ends the
    /// curve with [`CurveError::Jump`]; the caller derives the limit from the settings with
    /// [`jump_limit_steps`]. With
    /// [`fits_jump_limit`] no jump can occur: the sine rises by at most |A·ω| per column, the
    /// values by at most |A|·[`SINE_RISE_ERROR_PER_AMPLITUDE_STEP`] more, and the rounded rows
    /// of two values at most an integer `J` apart are at most `J` apart.
    pub fn new(
        amplitude_steps: f32,
        omega_rad_per_step: f32,
        phase_rad: f32,
        length_steps: i32,
        max_jump_steps: i32,
        method: Method,
    ) -> Result<Self, CurveSetupError> {
        let span_rad = omega_rad_per_step * length_steps as f32;
        if !(amplitude_steps.is_finite()
            && omega_rad_per_step.is_finite()
            && phase_rad.is_finite()
            && span_rad.is_finite())
        {
            return Err(CurveSetupError::BadParameter);
        }
        if amplitude_steps.abs() > MAX_SINE_AMPLITUDE_STEPS {
            return Err(CurveSetupError::OutOfRange);
        }
        let per_step = turns_q64(omega_rad_per_step);
        let f = SineFn {
            amplitude_steps,
            phase_turns: turns_q64(phase_rad),
            turns_per_column: if length_steps < 0 { per_step.wrapping_neg() } else { per_step },
        };
        let curve = ExplicitCurve::new(f, length_steps, max_jump_steps, method)?;
        // |h| <= 2·|A| <= MAX_CURVE_OFFSET_STEPS: the end is always within reach.
        let end = curve.nominal_end().map_err(|_| CurveSetupError::OutOfRange)?;
        Ok(SineInterp { curve, end })
    }

    /// Where the curve ends, relative to its start: `(length, round(f(length) - f(0)))`, ties
    /// rounded toward +y; exactly where the steps end.
    pub fn end(&self) -> Point {
        self.end
    }

    /// Where the steps handed out so far have taken the pen, relative to the start.
    pub fn position(&self) -> Point {
        self.curve.position()
    }
}

impl Interpolator for SineInterp {
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

/// The least and greatest sin(t) for t between `t0` and `t1` (either order).
pub fn sin_range(t0: f32, t1: f32) -> (f32, f32) {
    use core::f32::consts::{FRAC_PI_2, TAU};
    let (lo, hi) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
    if hi - lo >= TAU {
        return (-1.0, 1.0);
    }
    let (a, b) = (math::sin(lo), math::sin(hi));
    let (mut min, mut max) = (math::min(a, b), math::max(a, b));
    if FRAC_PI_2 + math::ceil((lo - FRAC_PI_2) / TAU) * TAU <= hi {
        max = 1.0;
    }
    if -FRAC_PI_2 + math::ceil((lo + FRAC_PI_2) / TAU) * TAU <= hi {
        min = -1.0;
    }
    (min, max)
}

/// True when the sine y = A·sin(ω·x + φ) rises or falls by no more than the jump limit between
/// two neighbouring X steps anywhere, as its interpolator computes it (the steepest slope
/// |A·ω|, and |A|·[`SINE_RISE_ERROR_PER_AMPLITUDE_STEP`] for the values' rounding), so that its
/// interpolator never stops at a jump. Both inputs that draw sines (the host link and the
/// keypad) refuse one that does not fit before anything moves.
pub fn fits_jump_limit(amplitude_steps: f32, omega_rad_per_step: f32, settings: &crate::settings::Settings) -> bool {
    let max_jump_steps = jump_limit_steps(settings.max_jump_mm, settings.steps_per_mm[1]);
    let steepest =
        (amplitude_steps * omega_rad_per_step).abs() + amplitude_steps.abs() * SINE_RISE_ERROR_PER_AMPLITUDE_STEP;
    steepest <= max_jump_steps as f32
}

//! The sine curve y = A·sin(ω·x + φ) in steps, drawn from the pen.
//!
//! x runs over whole steps from 0 to the curve's length (a negative length runs toward -x) and
//! the curve is translated so that it starts at the pen: the path is `(x, f(x) - f(0))`, ending
//! exactly at `(length, round(f(length) - f(0)))`. The stepping itself — chords between
//! columns, classic and diagonal rules, deviation bounds, tangent — is the explicit-curve core
//! of `crate::interp::explicit` ([`ExplicitCurve`]); this module only supplies the function.
//!
//! A sine is continuous, but it is sampled once per X step: where |A·ω| (the steepest slope,
//! in rows per column) is large, neighbouring columns lie far apart and the chord between them
//! is a stroke the curve does not contain. It is therefore held to the same rules as a
//! function: a rise or fall of more than `max_jump_steps` rows between neighbouring columns
//! ends it with [`CurveError::Jump`], and a column outside its [`RowRange`] (the machine's
//! travel) with [`CurveError::Travel`], both before any step toward that column. Otherwise, once
//! set up, it never fails.

use crate::geom::{Point, Step};
use crate::interp::explicit::{CurveFn, ExplicitCurve, MAX_CURVE_OFFSET_STEPS, RowRange, nearest_step};
use crate::interp::{CurveError, CurveSetupError, Interpolator, Method, Tangent};

#[cfg(test)]
mod tests;

/// Largest amplitude, in steps: the curve then spans at most [`MAX_CURVE_OFFSET_STEPS`] from its
/// start.
pub const MAX_SINE_AMPLITUDE_STEPS: f64 = MAX_CURVE_OFFSET_STEPS as f64 / 2.0;

/// f(x) = A·sin(ω·x + φ) at the columns of a run in direction `dir`.
#[derive(Clone, Copy, Debug)]
struct SineFn {
    amplitude_steps: f64,
    omega_rad_per_step: f64,
    phase_rad: f64,
    /// +1 or -1: column k is at x = dir·k.
    dir: f64,
}

impl SineFn {
    fn at(&self, x: f64) -> f64 {
        self.amplitude_steps * libm::sin(self.omega_rad_per_step * x + self.phase_rad)
    }
}

impl CurveFn for SineFn {
    fn y_steps(&self, column: i32) -> Result<f64, CurveError> {
        Ok(self.at(self.dir * f64::from(column)))
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
    /// `phase_rad` for x from 0 to `length_steps` (0: no step). Every parameter must be finite
    /// ([`CurveSetupError::BadParameter`]); |A| up to [`MAX_SINE_AMPLITUDE_STEPS`] and |length|
    /// up to [`MAX_CURVE_OFFSET_STEPS`] ([`CurveSetupError::OutOfRange`]).
    ///
    /// A rise or fall of more than `max_jump_steps` rows between neighbouring columns
    /// (`i32::MAX`: no limit; a negative limit is [`CurveSetupError::BadParameter`]) ends the
    /// curve with [`CurveError::Jump`], a column outside `rows` ([`RowRange::ANY`]: no limit)
    /// with [`CurveError::Travel`]; the caller derives them from the settings with
    /// `crate::interp::explicit::jump_limit_steps` and [`RowRange::within_travel`]. With
    /// `|A·ω| <= max_jump_steps` no jump can occur: the sine rises by at most |A·ω| per column,
    /// and the rounded rows of two values at most an integer `J` apart are at most `J` apart.
    pub fn new(
        amplitude_steps: f64,
        omega_rad_per_step: f64,
        phase_rad: f64,
        length_steps: i32,
        max_jump_steps: i32,
        rows: RowRange,
        method: Method,
    ) -> Result<Self, CurveSetupError> {
        let span_rad = omega_rad_per_step * f64::from(length_steps);
        if !(amplitude_steps.is_finite()
            && omega_rad_per_step.is_finite()
            && phase_rad.is_finite()
            && span_rad.is_finite())
        {
            return Err(CurveSetupError::BadParameter);
        }
        if libm::fabs(amplitude_steps) > MAX_SINE_AMPLITUDE_STEPS {
            return Err(CurveSetupError::OutOfRange);
        }
        let f =
            SineFn { amplitude_steps, omega_rad_per_step, phase_rad, dir: if length_steps < 0 { -1.0 } else { 1.0 } };
        let end = Point::new(length_steps, nearest_step(f.at(f64::from(length_steps)) - f.at(0.0)));
        let curve = ExplicitCurve::new(f, length_steps, max_jump_steps, rows, method)?;
        Ok(SineInterp { curve, end })
    }

    /// Where the curve ends, relative to its start: `(length, round(f(length) - f(0)))`, ties
    /// rounded toward +y.
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
}

/// The least and greatest sin(t) for t between `t0` and `t1` (either order).
pub fn sin_range(t0: f32, t1: f32) -> (f32, f32) {
    use core::f32::consts::{FRAC_PI_2, TAU};
    let (lo, hi) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
    if hi - lo >= TAU {
        return (-1.0, 1.0);
    }
    let (a, b) = (libm::sinf(lo), libm::sinf(hi));
    let (mut min, mut max) = (a.min(b), a.max(b));
    if FRAC_PI_2 + libm::ceilf((lo - FRAC_PI_2) / TAU) * TAU <= hi {
        max = 1.0;
    }
    if -FRAC_PI_2 + libm::ceilf((lo + FRAC_PI_2) / TAU) * TAU <= hi {
        min = -1.0;
    }
    (min, max)
}

/// True when the sine y = A·sin(ω·x + φ) rises or falls by no more than the jump limit between
/// two neighbouring X steps anywhere (its steepest slope is |A·ω|), so its interpolator never
/// stops at a jump. Both inputs that draw sines (the host link and the keypad) refuse one that
/// does not fit before anything moves.
pub fn fits_jump_limit(amplitude_steps: f32, omega_rad_per_step: f32, settings: &crate::settings::Settings) -> bool {
    let max_jump_steps = crate::interp::explicit::jump_limit_steps(settings.max_jump_mm, settings.steps_per_mm[1]);
    let steepest = libm::fabs(f64::from(amplitude_steps) * f64::from(omega_rad_per_step));
    steepest <= f64::from(max_jump_steps)
}

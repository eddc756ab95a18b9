//! The sine curve y = A·sin(ω·x + φ) in steps, drawn from the pen.
//!
//! x runs over whole steps from 0 to the curve's length (a negative length runs toward -x) and
//! the curve is translated so that it starts at the pen: the path is `(x, f(x) - f(0))`, ending
//! exactly at `(length, round(f(length) - f(0)))`. The stepping itself — chords between
//! columns, classic and diagonal rules, deviation bounds, tangent — is the explicit-curve core
//! of `crate::interp::function` ([`ExplicitCurve`]); this module only supplies the function.
//!
//! A sine is continuous, but it is sampled once per X step: where |A·ω| (the steepest slope,
//! in rows per column) is large, neighbouring columns lie far apart and the chord between them
//! is a stroke the curve does not contain. It is therefore held to the same rules as a
//! function: a rise or fall of more than `max_jump_steps` rows between neighbouring columns
//! ends it with [`CurveError::Jump`], and a column outside its [`RowRange`] (the machine's
//! travel) with [`CurveError::Travel`], both before any step toward that column. Otherwise, once
//! set up, it never fails.

use crate::geom::{Point, Step};
use crate::interp::function::{
    CurveFn, CurveSetupError, ExplicitCurve, MAX_CURVE_OFFSET_STEPS, RowRange, nearest_step,
};
use crate::interp::{CurveError, Interpolator, Method, Tangent};

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
    /// `crate::interp::function::jump_limit_steps` and [`RowRange::within_travel`]. With
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
    let max_jump_steps = crate::interp::function::jump_limit_steps(settings.max_jump_mm, settings.steps_per_mm[1]);
    let steepest = libm::fabs(f64::from(amplitude_steps) * f64::from(omega_rad_per_step));
    steepest <= f64::from(max_jump_steps)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::interp::function::test_support::*;
    use core::f64::consts::{FRAC_PI_2, PI};
    use proptest::prelude::*;
    use std::vec::Vec;

    const METHODS: [Method; 2] = [Method::Classic, Method::Diagonal];

    /// f(x) - f(0) at the columns 0..=|length|, in the direction of travel.
    fn ideal(a: f64, omega: f64, phase: f64, length: i32) -> Vec<f64> {
        let dir = if length < 0 { -1.0 } else { 1.0 };
        let f = |x: f64| a * libm::sin(omega * x + phase);
        (0..=length.abs()).map(|k| f(dir * k as f64) - f(0.0)).collect()
    }

    /// Draws the sine with both methods and checks everything a user would see: neighbour
    /// steps, the deviation bound, every column met, the exact end and the number of steps.
    fn check_sine(a: f64, omega: f64, phase: f64, length: i32) -> Result<(), TestCaseError> {
        let h = ideal(a, omega, phase, length);
        let dir = if length < 0 { -1 } else { 1 };
        let n = length.abs();
        let rows: Vec<i32> = h.iter().map(|&v| libm::floor(v + 0.5) as i32).collect();
        let rises: Vec<i32> = rows.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
        // |A·ω| rows bounds the rise from one column to the next, so this jump limit never stops it.
        let max_jump = libm::ceil(libm::fabs(a * omega)) as i32;
        for method in METHODS {
            let mut sine = SineInterp::new(a, omega, phase, length, max_jump, RowRange::ANY, method).unwrap();
            let end = sine.end();
            let expected_steps: i32 = match method {
                Method::Classic => n + rises.iter().sum::<i32>(),
                Method::Diagonal => rises.iter().map(|&d| d.max(1)).sum(),
            };
            let w = walk(&mut sine, method, expected_steps as usize);
            prop_assert_eq!(w.end, Ok(()));
            prop_assert_eq!(w.last(), end);
            prop_assert_eq!(end.x, length);
            prop_assert!(
                (end.y as f64 - h[n as usize]).abs() <= 0.5 + FLOAT_SLACK_STEPS,
                "{:?} vs {}",
                end,
                h[n as usize]
            );
            prop_assert_eq!(w.steps(), expected_steps as usize);
            let dev = max_deviation(&w.path, dir, &h);
            prop_assert!(dev <= max_deviation_for(method) + FLOAT_SLACK_STEPS, "{:?} deviates {}", method, dev);
            assert_meets_every_column(&w.path, dir, &h);
        }
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(128))]

        /// Gentle to very steep (up to 750 steps per column), either direction, any phase.
        #[test]
        fn short_sines_of_any_steepness(a in -500.0f64..500.0, omega in -1.5f64..1.5, phase in -7.0f64..7.0, length in -400i32..400) {
            check_sine(a, omega, phase, length)?;
        }

        /// Long, smooth curves of a few periods.
        #[test]
        fn long_smooth_sines(a in -5_000.0f64..5_000.0, omega in -0.02f64..0.02, phase in -7.0f64..7.0, length in -5_000i32..5_000) {
            check_sine(a, omega, phase, length)?;
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(8))]

        /// The machine's full range: ±100_000 steps long, amplitude up to 100_000 steps, up to
        /// two periods (so that a case stays under a million steps).
        #[test]
        fn machine_sized_sines_do_not_overflow(
            a in -100_000.0f64..100_000.0,
            periods in 0.0f64..2.0,
            phase in -PI..PI,
            length in 90_000i32..=100_000,
            backwards: bool,
        ) {
            let omega = 2.0 * PI * periods / length as f64;
            check_sine(a, omega, phase, if backwards { -length } else { length })?;
        }
    }

    #[test]
    fn one_period_peaks_and_troughs_where_the_sine_does() {
        for method in METHODS {
            // A = 10, one period over 40 steps.
            let mut sine = SineInterp::new(10.0, 2.0 * PI / 40.0, 0.0, 40, i32::MAX, RowRange::ANY, method).unwrap();
            let w = walk(&mut sine, method, 200);
            assert_eq!(w.last(), Point::new(40, 0));
            assert_eq!(w.path.iter().map(|p| p.y).max(), Some(10));
            assert_eq!(w.path.iter().map(|p| p.y).min(), Some(-10));
            assert!(w.path.contains(&Point::new(10, 10)) && w.path.contains(&Point::new(30, -10)));
            // Drawn toward -x it first falls: sin(-ωk) < 0.
            let mut back = SineInterp::new(10.0, 2.0 * PI / 40.0, 0.0, -40, i32::MAX, RowRange::ANY, method).unwrap();
            let w = walk(&mut back, method, 200);
            assert_eq!(w.last(), Point::new(-40, 0));
            assert!(w.path.contains(&Point::new(-10, -10)) && w.path.contains(&Point::new(-30, 10)));
        }
    }

    #[test]
    fn a_sine_steeper_than_the_jump_limit_stops_before_its_first_steep_chord() {
        for method in METHODS {
            // A = 1000 rows, ω = 1 rad/step: the first column is already 841 rows up.
            let mut sine = SineInterp::new(1000.0, 1.0, 0.0, 100, 500, RowRange::ANY, method).unwrap();
            let w = walk(&mut sine, method, 10);
            assert_eq!((w.end, w.steps()), (Err(CurveError::Jump), 0));
            // A = 100 rows, ω = 0.05 rad/step from the crest (phase 90°): level at first, steepest
            // (|A·ω| = 5 rows per column) a quarter period later. A limit of 4 stops it on the way
            // down, at the column before the first rise of 5...
            let (a, omega, phase) = (100.0, 0.05, FRAC_PI_2);
            let rows: Vec<i32> = ideal(a, omega, phase, 200).iter().map(|&v| nearest_step(v)).collect();
            let first = rows.windows(2).position(|w| (w[1] - w[0]).abs() > 4).unwrap();
            let mut sine = SineInterp::new(a, omega, phase, 200, 4, RowRange::ANY, method).unwrap();
            let w = walk(&mut sine, method, 10_000);
            assert_eq!(w.end, Err(CurveError::Jump));
            assert_eq!(w.last(), Point::new(first as i32, rows[first]));
            assert!(w.path.iter().all(|p| p.x <= first as i32));
            // ...and a limit of |A·ω| lets it through.
            let mut sine = SineInterp::new(a, omega, phase, 200, 5, RowRange::ANY, method).unwrap();
            assert_eq!(walk(&mut sine, method, 10_000).end, Ok(()));
            assert_eq!(
                SineInterp::new(a, omega, phase, 200, -1, RowRange::ANY, method).err(),
                Some(CurveSetupError::BadParameter)
            );
        }
    }

    #[test]
    fn a_sine_leaving_the_travel_stops_at_the_last_column_inside() {
        // A = 100 rows, half a period over 200 columns, from a pen at row 50 of a ±120-row
        // travel: rows -170..=70 relative. The crest, 100 rows up, is outside.
        let (start_y, limit) = (50, 120);
        let rows = RowRange::within_travel(start_y, limit);
        let h: Vec<i32> = ideal(100.0, PI / 200.0, 0.0, 200).iter().map(|&v| nearest_step(v)).collect();
        let first_out = h.iter().position(|&r| r > 70).unwrap();
        for method in METHODS {
            let mut sine = SineInterp::new(100.0, PI / 200.0, 0.0, 200, i32::MAX, rows, method).unwrap();
            assert_eq!(sine.end(), Point::new(200, 0), "its end is inside");
            let w = walk(&mut sine, method, 10_000);
            assert_eq!(w.end, Err(CurveError::Travel));
            assert_eq!(w.last(), Point::new(first_out as i32 - 1, h[first_out - 1]));
            assert!(w.path.iter().all(|p| (start_y + p.y).abs() <= limit), "a step outside the travel");
        }
    }

    #[test]
    fn the_curve_starts_at_the_pen_whatever_the_phase() {
        // cos-shaped: f(0) = 5, so the path starts at 0 and falls to -10 at half a period.
        let mut sine =
            SineInterp::new(5.0, PI / 20.0, FRAC_PI_2, 40, i32::MAX, RowRange::ANY, Method::Diagonal).unwrap();
        let w = walk(&mut sine, Method::Diagonal, 200);
        assert_eq!(w.path[0], Point::ORIGIN);
        assert!(w.path.contains(&Point::new(20, -10)));
        assert_eq!(w.last(), Point::new(40, 0));
        assert!(w.path.iter().all(|p| p.y <= 0));
    }

    #[test]
    fn the_tangent_points_along_the_travel() {
        // A·ω = 1: at the start the curve rises at 45°.
        let sine = SineInterp::new(10.0, 0.1, 0.0, 100, i32::MAX, RowRange::ANY, Method::Diagonal).unwrap();
        let t = sine.tangent();
        let s = core::f32::consts::FRAC_1_SQRT_2;
        assert!((t.x - s).abs() < 0.01 && (t.y - s).abs() < 0.01, "{t:?}");
        // Toward -x it falls to the left.
        let sine = SineInterp::new(10.0, 0.1, 0.0, -100, i32::MAX, RowRange::ANY, Method::Classic).unwrap();
        let t = sine.tangent();
        assert!((t.x + s).abs() < 0.01 && (t.y + s).abs() < 0.01, "{t:?}");
        // At the crest (x = π/2/ω ≈ 15.7) it is level.
        let mut sine = SineInterp::new(10.0, 0.1, 0.0, 100, i32::MAX, RowRange::ANY, Method::Diagonal).unwrap();
        while sine.position().x < 15 {
            sine.next_step().unwrap();
        }
        assert!(sine.tangent().x > 0.99, "{:?}", sine.tangent());
    }

    #[test]
    fn bad_parameters_are_refused_and_length_zero_takes_no_step() {
        let new = |a: f64, w: f64, p: f64, l: i32| {
            SineInterp::new(a, w, p, l, i32::MAX, RowRange::ANY, Method::Diagonal).err()
        };
        assert_eq!(new(f64::NAN, 0.1, 0.0, 10), Some(CurveSetupError::BadParameter));
        assert_eq!(new(1.0, f64::INFINITY, 0.0, 10), Some(CurveSetupError::BadParameter));
        assert_eq!(new(1.0, 0.1, f64::NEG_INFINITY, 10), Some(CurveSetupError::BadParameter));
        assert_eq!(new(1.0, 1e308, 0.0, 10), Some(CurveSetupError::BadParameter));
        assert_eq!(new(MAX_SINE_AMPLITUDE_STEPS * 1.01, 0.1, 0.0, 10), Some(CurveSetupError::OutOfRange));
        assert_eq!(new(1.0, 0.1, 0.0, -MAX_CURVE_OFFSET_STEPS - 1), Some(CurveSetupError::OutOfRange));
        for method in METHODS {
            let mut sine = SineInterp::new(100.0, 0.3, 1.0, 0, i32::MAX, RowRange::ANY, method).unwrap();
            assert_eq!(sine.end(), Point::ORIGIN);
            assert_eq!(sine.next_step(), Ok(None));
        }
    }
}

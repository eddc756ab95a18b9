//! The sine curve y = A·sin(ω·x + φ) in steps, drawn from the pen.
//!
//! x runs over whole steps from 0 to the curve's length (a negative length runs toward -x) and
//! the curve is translated so that it starts at the pen: the path is `(x, f(x) - f(0))`, ending
//! exactly at `(length, round(f(length) - f(0)))`. The stepping itself — chords between
//! columns, classic and diagonal rules, deviation bounds, tangent — is the explicit-curve core
//! of `crate::interp::function` ([`ExplicitCurve`]); this module only supplies the function.
//! A sine is continuous, so it has no jump limit and, once set up, never fails.

use crate::geom::{Point, Step};
use crate::interp::function::{CurveFn, CurveSetupError, ExplicitCurve, MAX_CURVE_OFFSET_STEPS, nearest_step};
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
    pub fn new(
        amplitude_steps: f64,
        omega_rad_per_step: f64,
        phase_rad: f64,
        length_steps: i32,
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
        // Continuous: no jump limit.
        let curve = ExplicitCurve::new(f, length_steps, i32::MAX, method)?;
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
        for method in METHODS {
            let mut sine = SineInterp::new(a, omega, phase, length, method).unwrap();
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
            let mut sine = SineInterp::new(10.0, 2.0 * PI / 40.0, 0.0, 40, method).unwrap();
            let w = walk(&mut sine, method, 200);
            assert_eq!(w.last(), Point::new(40, 0));
            assert_eq!(w.path.iter().map(|p| p.y).max(), Some(10));
            assert_eq!(w.path.iter().map(|p| p.y).min(), Some(-10));
            assert!(w.path.contains(&Point::new(10, 10)) && w.path.contains(&Point::new(30, -10)));
            // Drawn toward -x it first falls: sin(-ωk) < 0.
            let mut back = SineInterp::new(10.0, 2.0 * PI / 40.0, 0.0, -40, method).unwrap();
            let w = walk(&mut back, method, 200);
            assert_eq!(w.last(), Point::new(-40, 0));
            assert!(w.path.contains(&Point::new(-10, -10)) && w.path.contains(&Point::new(-30, 10)));
        }
    }

    #[test]
    fn the_curve_starts_at_the_pen_whatever_the_phase() {
        // cos-shaped: f(0) = 5, so the path starts at 0 and falls to -10 at half a period.
        let mut sine = SineInterp::new(5.0, PI / 20.0, FRAC_PI_2, 40, Method::Diagonal).unwrap();
        let w = walk(&mut sine, Method::Diagonal, 200);
        assert_eq!(w.path[0], Point::ORIGIN);
        assert!(w.path.contains(&Point::new(20, -10)));
        assert_eq!(w.last(), Point::new(40, 0));
        assert!(w.path.iter().all(|p| p.y <= 0));
    }

    #[test]
    fn the_tangent_points_along_the_travel() {
        // A·ω = 1: at the start the curve rises at 45°.
        let sine = SineInterp::new(10.0, 0.1, 0.0, 100, Method::Diagonal).unwrap();
        let t = sine.tangent();
        let s = core::f32::consts::FRAC_1_SQRT_2;
        assert!((t.x - s).abs() < 0.01 && (t.y - s).abs() < 0.01, "{t:?}");
        // Toward -x it falls to the left.
        let sine = SineInterp::new(10.0, 0.1, 0.0, -100, Method::Classic).unwrap();
        let t = sine.tangent();
        assert!((t.x + s).abs() < 0.01 && (t.y + s).abs() < 0.01, "{t:?}");
        // At the crest (x = π/2/ω ≈ 15.7) it is level.
        let mut sine = SineInterp::new(10.0, 0.1, 0.0, 100, Method::Diagonal).unwrap();
        while sine.position().x < 15 {
            sine.next_step().unwrap();
        }
        assert!(sine.tangent().x > 0.99, "{:?}", sine.tangent());
    }

    #[test]
    fn bad_parameters_are_refused_and_length_zero_takes_no_step() {
        let new = |a: f64, w: f64, p: f64, l: i32| SineInterp::new(a, w, p, l, Method::Diagonal).err();
        assert_eq!(new(f64::NAN, 0.1, 0.0, 10), Some(CurveSetupError::BadParameter));
        assert_eq!(new(1.0, f64::INFINITY, 0.0, 10), Some(CurveSetupError::BadParameter));
        assert_eq!(new(1.0, 0.1, f64::NEG_INFINITY, 10), Some(CurveSetupError::BadParameter));
        assert_eq!(new(1.0, 1e308, 0.0, 10), Some(CurveSetupError::BadParameter));
        assert_eq!(new(MAX_SINE_AMPLITUDE_STEPS * 1.01, 0.1, 0.0, 10), Some(CurveSetupError::OutOfRange));
        assert_eq!(new(1.0, 0.1, 0.0, -MAX_CURVE_OFFSET_STEPS - 1), Some(CurveSetupError::OutOfRange));
        for method in METHODS {
            let mut sine = SineInterp::new(100.0, 0.3, 1.0, 0, method).unwrap();
            assert_eq!(sine.end(), Point::ORIGIN);
            assert_eq!(sine.next_step(), Ok(None));
        }
    }
}

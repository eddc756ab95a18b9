//! The curves the keypad draws besides lines, as typed (millimetres and degrees), and their
//! extents so the menu can refuse a curve that would leave the travel area.
//!
//! Every keypad curve starts at the pen: the menu hands the pen position and these parameters
//! on, and the motion side turns them into a [`crate::job::Shape`]. Geometry, relative to the
//! start point, with X to the right and Y up:
//!
//! - Circle/arc: the pen is on the circle at angle `start_deg` seen from the centre, so the
//!   centre is at `-r·(cos start, sin start)`. The arc turns `sweep_deg` (positive = counter-
//!   clockwise); ±360 is a full circle.
//! - Ellipse: axes along X (`a`) and Y (`b`); points are `(a·cos t, b·sin t)` from the centre with
//!   `t` the parametric (eccentric) angle; `start_deg` and `sweep_deg` are values of `t`.
//! - Sine: `y = A·sin(2π·x/P + φ) − A·sin φ` for `x` from 0 to `length` (negative = towards −X).
//! - Function: `y = f(x)` for `x` from `x0` to `x1`, moved so that `(x0, f(x0))` is the pen.
//!
//! This module owns no state and reads no settings.

use core::f32::consts::TAU;

use crate::expr::ParseError;
use crate::geom::{Axis, Point, Rotation};
use crate::interp::sine::sin_range;
use crate::job::{Feed, Job, Shape};
use crate::settings::Settings;

/// The box a curve covers, relative to its start point, in millimetres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extent {
    pub x_min_mm: f32,
    pub x_max_mm: f32,
    pub y_min_mm: f32,
    pub y_max_mm: f32,
}

impl Extent {
    /// The box around the given points.
    fn around(points: impl Iterator<Item = (f32, f32)>) -> Extent {
        let mut e = Extent { x_min_mm: f32::MAX, x_max_mm: f32::MIN, y_min_mm: f32::MAX, y_max_mm: f32::MIN };
        for (x, y) in points {
            e.x_min_mm = e.x_min_mm.min(x);
            e.x_max_mm = e.x_max_mm.max(x);
            e.y_min_mm = e.y_min_mm.min(y);
            e.y_max_mm = e.y_max_mm.max(y);
        }
        e
    }
}

/// A circular arc or full circle; see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct CircleParams {
    pub radius_mm: f32,
    pub start_deg: f32,
    /// In [-360, 360], never 0; ±360 is a full circle; positive is counter-clockwise.
    pub sweep_deg: f32,
}

impl CircleParams {
    /// The same arc as an ellipse with equal axes.
    pub const fn as_ellipse(&self) -> EllipseParams {
        EllipseParams {
            a_mm: self.radius_mm,
            b_mm: self.radius_mm,
            start_deg: self.start_deg,
            sweep_deg: self.sweep_deg,
        }
    }
}

/// An elliptic arc or full ellipse with axes along X and Y; see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct EllipseParams {
    /// Semi-axis along X.
    pub a_mm: f32,
    /// Semi-axis along Y.
    pub b_mm: f32,
    pub start_deg: f32,
    /// In [-360, 360], never 0; ±360 is a full ellipse; positive is counter-clockwise.
    pub sweep_deg: f32,
}

impl EllipseParams {
    /// The point at parametric angle `t_deg`, relative to the centre.
    pub fn point_mm(&self, t_deg: f32) -> (f32, f32) {
        let (s, c) = sin_cos_deg(t_deg);
        (self.a_mm * c, self.b_mm * s)
    }

    /// The centre, relative to the start point (the pen).
    pub fn center_offset_mm(&self) -> (f32, f32) {
        let (x, y) = self.point_mm(self.start_deg);
        (-x, -y)
    }

    /// The end point, relative to the start point.
    pub fn end_offset_mm(&self) -> (f32, f32) {
        let (x0, y0) = self.point_mm(self.start_deg);
        let (x1, y1) = self.point_mm(self.start_deg + self.sweep_deg);
        (x1 - x0, y1 - y0)
    }

    /// The direction of travel.
    pub fn rotation(&self) -> Rotation {
        if self.sweep_deg < 0.0 { Rotation::Clockwise } else { Rotation::CounterClockwise }
    }

    /// True when the arc closes on itself.
    pub fn is_full(&self) -> bool {
        self.sweep_deg.abs() >= 360.0
    }

    /// The box the arc covers, relative to the start point.
    pub fn extent(&self) -> Extent {
        let lo = self.start_deg.min(self.start_deg + self.sweep_deg);
        let hi = self.start_deg.max(self.start_deg + self.sweep_deg);
        let (x0, y0) = self.point_mm(self.start_deg);
        // Extremes of x and y lie at the ends and at every multiple of 90 degrees in between.
        let quarters =
            (crate::math::ceil(lo / 90.0) as i32..=crate::math::floor(hi / 90.0) as i32).map(|k| k as f32 * 90.0);
        let angles = [lo, hi].into_iter().chain(quarters);
        Extent::around(angles.map(|t| {
            let (x, y) = self.point_mm(t);
            (x - x0, y - y0)
        }))
    }
}

/// A sine wave along X; see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct SineParams {
    pub amplitude_mm: f32,
    /// Length of one wave along X; the angular frequency is `2π / period` rad/mm.
    pub period_mm: f32,
    pub phase_deg: f32,
    /// Length along X, never 0; negative draws towards −X.
    pub length_mm: f32,
}

impl SineParams {
    /// Angular frequency, rad/mm.
    pub fn omega_rad_per_mm(&self) -> f32 {
        TAU / self.period_mm
    }

    /// The curve's y at `x_mm`, relative to the start point.
    pub fn y_at(&self, x_mm: f32) -> f32 {
        let phase = self.phase_deg.to_radians();
        self.amplitude_mm * (crate::math::sin(self.omega_rad_per_mm() * x_mm + phase) - crate::math::sin(phase))
    }

    /// The box the curve covers, relative to the start point.
    pub fn extent(&self) -> Extent {
        let phase = self.phase_deg.to_radians();
        let (x_min, x_max) = (self.length_mm.min(0.0), self.length_mm.max(0.0));
        let w = self.omega_rad_per_mm();
        let (s_min, s_max) = sin_range(w * x_min + phase, w * x_max + phase);
        let (y_a, y_b) = (self.amplitude_mm * s_min, self.amplitude_mm * s_max);
        let offset = self.amplitude_mm * crate::math::sin(phase);
        Extent { x_min_mm: x_min, x_max_mm: x_max, y_min_mm: y_a.min(y_b) - offset, y_max_mm: y_a.max(y_b) - offset }
    }
}

/// The functions y = f(x) the keypad offers (x and y in mm). The host link takes any expression;
/// the keypad cannot type letters, so it picks one of these.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum FunctionPreset {
    /// `x^2/20`
    Parabola,
    /// `10*sin(x/5)`
    Wave,
    /// `5*sqrt(x)`, defined for x >= 0.
    Root,
    /// `x^3/400`
    Cubic,
    /// `20*exp(-x^2/200)`
    Bell,
}

impl FunctionPreset {
    /// Every preset, in the order the keypad numbers them (1-based).
    pub const ALL: [FunctionPreset; 5] = [
        FunctionPreset::Parabola,
        FunctionPreset::Wave,
        FunctionPreset::Root,
        FunctionPreset::Cubic,
        FunctionPreset::Bell,
    ];

    /// The expression, in the host link's expression language.
    pub const fn expression(self) -> &'static str {
        match self {
            FunctionPreset::Parabola => "x^2/20",
            FunctionPreset::Wave => "10*sin(x/5)",
            FunctionPreset::Root => "5*sqrt(x)",
            FunctionPreset::Cubic => "x^3/400",
            FunctionPreset::Bell => "20*exp(-x^2/200)",
        }
    }

    /// Position in [`FunctionPreset::ALL`].
    pub fn index(self) -> usize {
        FunctionPreset::ALL.iter().position(|&p| p == self).unwrap_or(0)
    }

    /// f(x) in mm; `None` outside the function's domain.
    pub fn eval(self, x: f32) -> Option<f32> {
        match self {
            FunctionPreset::Parabola => Some(x * x / 20.0),
            FunctionPreset::Wave => Some(10.0 * crate::math::sin(x / 5.0)),
            FunctionPreset::Root => (x >= 0.0).then(|| 5.0 * crate::math::sqrt(x)),
            FunctionPreset::Cubic => Some(x * x * x / 400.0),
            FunctionPreset::Bell => Some(20.0 * crate::math::exp(-x * x / 200.0)),
        }
    }

    /// The least and greatest f(x) on [lo, hi]; `None` when part of it is outside the domain.
    fn range(self, lo: f32, hi: f32) -> Option<(f32, f32)> {
        let (f_lo, f_hi) = (self.eval(lo)?, self.eval(hi)?);
        let (mut min, mut max) = (f_lo.min(f_hi), f_lo.max(f_hi));
        match self {
            // Single extremum at x = 0.
            FunctionPreset::Parabola | FunctionPreset::Bell if lo <= 0.0 && hi >= 0.0 => {
                let f0 = self.eval(0.0)?;
                min = min.min(f0);
                max = max.max(f0);
            }
            FunctionPreset::Wave => {
                let (s_min, s_max) = sin_range(lo / 5.0, hi / 5.0);
                min = 10.0 * s_min;
                max = 10.0 * s_max;
            }
            // Monotonic (Root only where defined, which `eval` checked at both ends).
            _ => {}
        }
        Some((min, max))
    }
}

/// y = f(x) from x0 to x1; see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct FunctionParams {
    pub preset: FunctionPreset,
    pub x0_mm: f32,
    /// Never equal to `x0_mm`; below it draws towards −X.
    pub x1_mm: f32,
}

impl FunctionParams {
    /// The box the curve covers, relative to the start point; `None` when the function is
    /// undefined somewhere between x0 and x1.
    pub fn extent(&self) -> Option<Extent> {
        let (lo, hi) = (self.x0_mm.min(self.x1_mm), self.x0_mm.max(self.x1_mm));
        let (y_min, y_max) = self.preset.range(lo, hi)?;
        let y0 = self.preset.eval(self.x0_mm)?;
        Some(Extent {
            x_min_mm: lo - self.x0_mm,
            x_max_mm: hi - self.x0_mm,
            y_min_mm: y_min - y0,
            y_max_mm: y_max - y0,
        })
    }
}

/// A keypad curve, typed and checked.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum CurveParams {
    Circle(CircleParams),
    Ellipse(EllipseParams),
    Sine(SineParams),
    Function(FunctionParams),
}

impl CurveParams {
    /// The box the curve covers, relative to its start point; `None` for a function undefined
    /// on part of its interval.
    pub fn extent(&self) -> Option<Extent> {
        match self {
            CurveParams::Circle(c) => Some(c.as_ellipse().extent()),
            CurveParams::Ellipse(e) => Some(e.extent()),
            CurveParams::Sine(s) => Some(s.extent()),
            CurveParams::Function(f) => f.extent(),
        }
    }
}

/// A curve to draw from `start`, the pen position when it was confirmed (in steps, absolute).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct CurveJob {
    pub start: Point,
    pub curve: CurveParams,
    pub feed: Feed,
}

impl CurveJob {
    /// The job in machine units (steps). A circle becomes an `Arc` when both axes have the same
    /// steps/mm and an `Ellipse` in steps otherwise, as the host link's commands do.
    pub fn to_job(&self, settings: &Settings) -> Result<Job, ParseError> {
        let at = |(x, y): (f32, f32)| {
            Point::new(self.start.x + settings.mm_to_steps(Axis::X, x), self.start.y + settings.mm_to_steps(Axis::Y, y))
        };
        let elliptic = |e: &EllipseParams| {
            let center = at(e.center_offset_mm());
            let to = if e.is_full() { self.start } else { at(e.end_offset_mm()) };
            let (a_steps, b_steps) = (settings.mm_to_steps(Axis::X, e.a_mm), settings.mm_to_steps(Axis::Y, e.b_mm));
            let rotation = e.rotation();
            if a_steps == b_steps {
                Shape::Arc { center, to, rotation }
            } else {
                Shape::Ellipse { center, a_steps, b_steps, to, rotation }
            }
        };
        let shape = match &self.curve {
            CurveParams::Circle(c) => elliptic(&c.as_ellipse()),
            CurveParams::Ellipse(e) => elliptic(e),
            CurveParams::Sine(s) => Shape::Sine {
                amplitude_steps: s.amplitude_mm * settings.steps_per_mm(Axis::Y),
                omega_rad_per_step: s.omega_rad_per_mm() / settings.steps_per_mm(Axis::X),
                phase_rad: s.phase_deg.to_radians(),
                length_steps: settings.mm_to_steps(Axis::X, s.length_mm),
            },
            CurveParams::Function(f) => {
                Shape::Function { expr: crate::expr::parse(f.preset.expression())?, x0_mm: f.x0_mm, x1_mm: f.x1_mm }
            }
        };
        Ok(Job::draw(shape, self.feed))
    }
}

/// sin and cos of an angle in degrees, exact at multiples of 90.
fn sin_cos_deg(deg: f32) -> (f32, f32) {
    let quarter = deg / 90.0;
    if quarter == crate::math::round(quarter) {
        match (quarter as i32).rem_euclid(4) {
            0 => (0.0, 1.0),
            1 => (1.0, 0.0),
            2 => (0.0, -1.0),
            _ => (-1.0, 0.0),
        }
    } else {
        crate::math::sin_cos(deg.to_radians())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() < 1e-3
    }

    fn assert_extent(e: Extent, x: (f32, f32), y: (f32, f32)) {
        assert!(
            close(e.x_min_mm, x.0) && close(e.x_max_mm, x.1) && close(e.y_min_mm, y.0) && close(e.y_max_mm, y.1),
            "{e:?} != x {x:?} y {y:?}"
        );
    }

    #[test]
    fn full_circle_from_angle_zero_lies_left_of_the_pen() {
        let c = CircleParams { radius_mm: 10.0, start_deg: 0.0, sweep_deg: 360.0 };
        assert_eq!(c.as_ellipse().center_offset_mm(), (-10.0, 0.0));
        assert_eq!(c.as_ellipse().end_offset_mm(), (0.0, 0.0));
        assert!(c.as_ellipse().is_full());
        assert_extent(c.as_ellipse().extent(), (-20.0, 0.0), (-10.0, 10.0));
    }

    #[test]
    fn quarter_arcs_cover_only_their_quarter() {
        // From the top of the circle, a quarter turn clockwise ends at its right.
        let e = EllipseParams { a_mm: 10.0, b_mm: 10.0, start_deg: 90.0, sweep_deg: -90.0 };
        assert_eq!(e.rotation(), Rotation::Clockwise);
        assert_eq!(e.end_offset_mm(), (10.0, -10.0));
        assert_extent(e.extent(), (0.0, 10.0), (-10.0, 0.0));
        // Ellipse, 45° to 135° counter-clockwise: passes the top (t = 90°).
        let e = EllipseParams { a_mm: 20.0, b_mm: 10.0, start_deg: 45.0, sweep_deg: 90.0 };
        let s = core::f32::consts::FRAC_1_SQRT_2;
        assert_extent(e.extent(), (-40.0 * s, 0.0), (0.0, 10.0 - 10.0 * s));
    }

    #[test]
    fn sine_extent_follows_amplitude_phase_and_length() {
        let s = SineParams { amplitude_mm: 5.0, period_mm: 20.0, phase_deg: 0.0, length_mm: 40.0 };
        assert!(close(s.y_at(5.0), 5.0));
        assert_extent(s.extent(), (0.0, 40.0), (-5.0, 5.0));
        // A quarter wave from phase 0: rises to the crest and no further.
        let s = SineParams { length_mm: 5.0, ..s };
        assert_extent(s.extent(), (0.0, 5.0), (0.0, 5.0));
        // Phase 90° starts at the crest: the curve only goes down, to -2A.
        let s = SineParams { phase_deg: 90.0, length_mm: 10.0, ..s };
        assert_extent(s.extent(), (0.0, 10.0), (-10.0, 0.0));
        // Backwards along X.
        let s = SineParams { phase_deg: 0.0, length_mm: -5.0, ..s };
        assert_extent(s.extent(), (-5.0, 0.0), (-5.0, 0.0));
    }

    #[test]
    fn function_extents_and_domains() {
        let p = FunctionParams { preset: FunctionPreset::Parabola, x0_mm: -20.0, x1_mm: 10.0 };
        // From (-20, 20) down to the vertex (0, 0) and up to (10, 5).
        assert_extent(p.extent().unwrap(), (0.0, 30.0), (-20.0, 0.0));
        let w = FunctionParams { preset: FunctionPreset::Wave, x0_mm: 0.0, x1_mm: 10.0 };
        assert_extent(w.extent().unwrap(), (0.0, 10.0), (0.0, 10.0));
        let r = FunctionParams { preset: FunctionPreset::Root, x0_mm: 100.0, x1_mm: 0.0 };
        assert_extent(r.extent().unwrap(), (-100.0, 0.0), (-50.0, 0.0));
        assert_eq!(FunctionParams { x1_mm: -1.0, ..r }.extent(), None, "sqrt of a negative");
        let b = FunctionParams { preset: FunctionPreset::Bell, x0_mm: -30.0, x1_mm: 30.0 };
        let y0 = 20.0 * crate::math::exp(-4.5);
        assert_extent(b.extent().unwrap(), (0.0, 60.0), (0.0, 20.0 - y0));
        for p in FunctionPreset::ALL {
            assert_eq!(FunctionPreset::ALL[p.index()], p);
        }
    }

    #[test]
    fn every_preset_computes_the_function_its_expression_draws() {
        for preset in FunctionPreset::ALL {
            let expr = crate::expr::parse(preset.expression()).unwrap();
            for k in -40..=40 {
                let x = k as f32 * 0.75;
                match (preset.eval(x), expr.eval(x)) {
                    (Some(a), Ok(b)) => assert!((a - b).abs() < 1e-3 * (1.0 + b.abs()), "{preset:?} at {x}"),
                    (None, Err(_)) => {}
                    other => panic!("{preset:?} at {x}: {other:?}"),
                }
            }
        }
    }
}

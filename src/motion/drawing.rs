//! The one builder of drawings: turns a request (a line, an arc or circle, an ellipse, a sine or
//! a function, in millimetres and degrees relative to the pen) into a checked [`Drawing`], for
//! both front ends. The G-code parser and the keypad menu only translate their syntax into a
//! [`Request`]; everything that decides whether and how it is drawn lives here.
//!
//! A drawing holds the built curve, ready for the planner, its start and its exact end on the
//! step lattice, and the box its lattice path covers. Both come from the curve itself: the
//! builder walks a copy of the curve once, step by step, before anything moves (a straight line
//! excepted, whose path its ends give). The walk of a long curve takes a large share of a second
//! on the board, so the front ends walk it a slice at a time with [`Builder`], the other tasks
//! running between slices; [`build`] walks it in one go. So:
//!
//! - the next drawing starts where this one really ends, not where millimetre arithmetic says;
//! - nothing is queued that would leave the travel (`$130`, `$131`): the box is exact;
//! - a function that fails part way (undefined, or jumping more than `$204`) is refused with the
//!   x where it fails, instead of stopping the pen part way;
//! - a request finer than the lattice can draw (an ellipse axis under a step, a sine with fewer
//!   than [`SINE_MIN_STEPS_PER_WAVE`] steps per wave, a path that strays from its ideal box, a
//!   function that strays between its X steps further than they show, see
//!   [`crate::motion::interp::explicit::between`]) is refused rather than drawn as something else;
//! - a function too far from zero for single precision to place its points within
//!   [`F32_ERROR_MAX_STEPS`] of the curve is refused.
//!
//! Geometry, relative to the pen, X to the right and Y up:
//!
//! - Ellipse (and circle, with equal semi-axes): axes along X (`a`) and Y (`b`); points are
//!   `(a·cos t, b·sin t)` from the centre with `t` the parametric angle. The pen is the point at
//!   `start_deg`, so the centre is at `−(a·cos start, b·sin start)`. The arc turns `sweep_deg`
//!   (positive: counter-clockwise); ±360 is the whole ellipse. Angles at multiples of 90° are
//!   exact.
//! - Sine: `y = A·(sin(ω·u + φ) − sin φ)` for `u` from 0 to `length` (negative: towards −X).
//! - Function: `y = f(x)` for `x` from `x0` to `x1`, moved so that `(x0, f(x0))` is the pen.
//! - Line: straight to a lattice point: the target in millimetres rounded to the nearest step
//!   ([`line_target`]), as GRBL rounds its targets.
//!
//! A sine or function shorter than one step along X draws nothing.

mod builder;

pub use builder::{BUILD_SLICE_STEPS, Builder, Slice, build, from_shape};

use crate::geom::{Axis, Point, Rotation};
use crate::motion::expr::Expr;
use crate::motion::interp::function::{F32_ERROR_MAX_STEPS, f32_error_steps};
use crate::motion::interp::sine::{fits_jump_limit, sin_range};
use crate::motion::interp::{Curve, CurveError, CurveSetupError, Shape, ShapeKind};
use crate::settings::Settings;

/// Largest radius or semi-axis of an arc or ellipse, mm.
pub const CURVE_RADIUS_MAX_MM: f32 = 5_000.0;

/// Fewest X steps per wave a sine may have: below it the lattice cannot show the wave.
pub const SINE_MIN_STEPS_PER_WAVE: f32 = 8.0;

/// How far a lattice path may reach beyond its ideal curve's box, steps: the interpolator's
/// error (at most one step) plus the rounding of the centre and of the semi-axes.
pub const LATTICE_SLACK_STEPS: f32 = 2.0;

/// An elliptic (or circular) arc, or the whole ellipse; see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct EllipseParams {
    /// Semi-axis along X, mm.
    pub a_mm: f32,
    /// Semi-axis along Y, mm.
    pub b_mm: f32,
    pub start_deg: f32,
    /// In [−360, 360], never 0; ±360 is the whole ellipse; positive is counter-clockwise.
    pub sweep_deg: f32,
}

impl EllipseParams {
    /// A circle of radius `r_mm`, or an arc of it.
    pub const fn circle(r_mm: f32, start_deg: f32, sweep_deg: f32) -> EllipseParams {
        EllipseParams { a_mm: r_mm, b_mm: r_mm, start_deg, sweep_deg }
    }

    /// The point at parametric angle `t_deg`, relative to the centre, mm.
    pub fn point_mm(&self, t_deg: f32) -> [f32; 2] {
        let (s, c) = sin_cos_deg(t_deg);
        [self.a_mm * c, self.b_mm * s]
    }

    /// The centre, relative to the pen, mm.
    pub fn center_offset_mm(&self) -> [f32; 2] {
        let [x, y] = self.point_mm(self.start_deg);
        [-x, -y]
    }

    /// The end point, relative to the pen, mm.
    pub fn end_offset_mm(&self) -> [f32; 2] {
        let [x0, y0] = self.point_mm(self.start_deg);
        let [x1, y1] = self.point_mm(self.start_deg + self.sweep_deg);
        [x1 - x0, y1 - y0]
    }

    /// True when the arc closes on itself.
    pub fn is_full(&self) -> bool {
        self.sweep_deg.abs() >= 360.0
    }

    /// The box the ideal arc covers, relative to the pen, mm: its ends and every multiple of 90°
    /// in between.
    pub fn extent(&self) -> Extent {
        let lo = self.start_deg.min(self.start_deg + self.sweep_deg);
        let hi = self.start_deg.max(self.start_deg + self.sweep_deg);
        let [x0, y0] = self.point_mm(self.start_deg);
        let first = crate::math::ceil(lo / 90.0) as i32;
        // A sweep of at most a full turn passes at most five such angles.
        let last = (crate::math::floor(hi / 90.0) as i32).min(first.saturating_add(4));
        let quarters = (first..=last).map(|k| k as f32 * 90.0);
        Extent::around([lo, hi].into_iter().chain(quarters).map(|t| {
            let [x, y] = self.point_mm(t);
            [x - x0, y - y0]
        }))
    }
}

/// A sine wave along X; see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct SineParams {
    pub amplitude_mm: f32,
    pub omega_rad_per_mm: f32,
    pub phase_deg: f32,
    /// Length along X; negative draws towards −X.
    pub length_mm: f32,
}

impl SineParams {
    /// The box the ideal curve covers, relative to the pen, mm.
    pub fn extent(&self) -> Extent {
        let phase = self.phase_deg.to_radians();
        let (x_min, x_max) = (self.length_mm.min(0.0), self.length_mm.max(0.0));
        let w = self.omega_rad_per_mm;
        let (s_min, s_max) = sin_range(w * x_min + phase, w * x_max + phase);
        let (y_a, y_b) = (self.amplitude_mm * s_min, self.amplitude_mm * s_max);
        let offset = self.amplitude_mm * crate::math::sin(phase);
        Extent { min_mm: [x_min, y_a.min(y_b) - offset], max_mm: [x_max, y_a.max(y_b) - offset] }
    }
}

/// The box an ideal curve covers, relative to the pen, mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extent {
    pub min_mm: [f32; 2],
    pub max_mm: [f32; 2],
}

impl Extent {
    fn around(points: impl Iterator<Item = [f32; 2]>) -> Extent {
        let mut e = Extent { min_mm: [f32::MAX; 2], max_mm: [f32::MIN; 2] };
        for p in points {
            for (i, v) in p.into_iter().enumerate() {
                e.min_mm[i] = e.min_mm[i].min(v);
                e.max_mm[i] = e.max_mm[i].max(v);
            }
        }
        e
    }
}

/// What to draw, relative to the pen.
// No heap: a function carries its expression by value, so it is the largest.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Request {
    /// A straight line to the lattice point `to` (absolute).
    Straight {
        to: Point,
    },
    Ellipse(EllipseParams),
    Sine(SineParams),
    /// y = f(x) for x from `x0_mm` to `x1_mm`.
    Function {
        expr: Expr,
        x0_mm: f32,
        x1_mm: f32,
    },
}

/// Why a request is not drawn; nothing moves.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum DrawError {
    /// A parameter is not a finite number or is out of its range.
    BadParameter,
    /// Part of the drawing lies outside the travel (`$130`, `$131`).
    Travel,
    /// The curve cannot be set up from the pen (see [`CurveSetupError`]).
    Setup(CurveSetupError),
    /// A sine rises more between two X steps than the max function jump (`$204`) allows.
    TooSteep,
    /// Finer than the step lattice can draw.
    TooFine,
    /// A function too far from zero for single precision to place its points within
    /// [`F32_ERROR_MAX_STEPS`] of its curve.
    Imprecise,
    /// The function fails part way, after `x_mm` (undefined there, or jumping).
    Fails { x_mm: f32, error: CurveError },
}

impl From<CurveSetupError> for DrawError {
    fn from(e: CurveSetupError) -> Self {
        DrawError::Setup(e)
    }
}

/// The box a lattice path covers, absolute steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Bounds {
    pub min: Point,
    pub max: Point,
}

impl Bounds {
    /// The box of the one point `p`.
    pub fn at(p: Point) -> Bounds {
        Bounds { min: p, max: p }
    }

    /// Grows the box to take `p`.
    pub fn add(&mut self, p: Point) {
        self.min = Point::new(self.min.x.min(p.x), self.min.y.min(p.y));
        self.max = Point::new(self.max.x.max(p.x), self.max.y.max(p.y));
    }

    /// True when every point is inside the travel area of `settings`.
    pub fn within_travel(&self, settings: &Settings) -> bool {
        let [lx, ly] = settings.travel_steps();
        self.min.x >= -lx && self.max.x <= lx && self.min.y >= -ly && self.max.y <= ly
    }
}

/// A checked drawing: its curve, ready for the planner, where it starts and really ends, and
/// the box its lattice path covers.
#[derive(Clone, Debug)]
pub struct Drawing {
    curve: Curve,
    shape: Shape,
    start: Point,
    end: Point,
    bounds: Bounds,
    steps: u64,
}

impl Drawing {
    /// The curve, for the planner.
    pub fn into_curve(self) -> Curve {
        self.curve
    }

    pub fn kind(&self) -> ShapeKind {
        self.shape.kind()
    }

    /// The shape in steps, as the interpolator was set up.
    pub fn shape(&self) -> &Shape {
        &self.shape
    }

    pub fn start(&self) -> Point {
        self.start
    }

    /// The last lattice point of the curve: where the pen is once it is drawn.
    pub fn end(&self) -> Point {
        self.end
    }

    pub fn bounds(&self) -> Bounds {
        self.bounds
    }

    /// Steps the interpolator hands out from start to end.
    pub fn steps(&self) -> u64 {
        self.steps
    }
}

#[cfg(target_os = "none")]
impl defmt::Format for Drawing {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(
            f,
            "{} from ({}, {}) to ({}, {})",
            self.kind(),
            self.start.x,
            self.start.y,
            self.end.x,
            self.end.y
        )
    }
}

/// The lattice point a line from the pen at `start` to `target_mm` (absolute, machine mm) ends
/// at; `None` for a target no lattice point is near (not finite, or beyond twice the travel).
/// Both front ends round their line targets here, so a keypad line and the same G-code line
/// end on the same step.
pub fn line_target(target_mm: [f32; 2], settings: &Settings) -> Option<Point> {
    let near = target_mm.iter().zip(settings.max_travel_mm).all(|(v, limit)| v.abs() <= 2.0 * limit);
    near.then(|| Point::new(settings.mm_to_steps(Axis::X, target_mm[0]), settings.mm_to_steps(Axis::Y, target_mm[1])))
}

/// Two drawings are the same when they draw the same shape to the same end (and so from the
/// same start, with the same settings: the curve is set up from those).
impl PartialEq for Drawing {
    fn eq(&self, other: &Self) -> bool {
        self.shape == other.shape && self.start == other.start && self.end == other.end
    }
}

/// The ideal curve's box in absolute steps (fractional).
#[derive(Clone, Copy, Debug)]
struct IdealBox {
    min: [f32; 2],
    max: [f32; 2],
}

impl IdealBox {
    fn from_extent(start: Point, e: &Extent, settings: &Settings) -> IdealBox {
        let spm = settings.steps_per_mm;
        let at = [start.x as f32, start.y as f32];
        IdealBox {
            min: [at[0] + e.min_mm[0] * spm[0], at[1] + e.min_mm[1] * spm[1]],
            max: [at[0] + e.max_mm[0] * spm[0], at[1] + e.max_mm[1] * spm[1]],
        }
    }

    /// True when the box lies within ±`limit` steps and `slack`. NaN is outside.
    fn within(&self, limit: [i32; 2], slack: f32) -> bool {
        (0..2).all(|i| {
            let l = limit[i] as f32 + slack;
            self.min[i] >= -l && self.max[i] <= l
        })
    }

    /// True when the lattice path's box `bounds` lies within this box and its slack.
    fn follows(&self, bounds: &Bounds) -> bool {
        let (min, max) = ([bounds.min.x, bounds.min.y], [bounds.max.x, bounds.max.y]);
        (0..2).all(|i| {
            min[i] as f32 >= self.min[i] - LATTICE_SLACK_STEPS && max[i] as f32 <= self.max[i] + LATTICE_SLACK_STEPS
        })
    }
}

/// The shape in steps from the pen at `start`, and the ideal box where it is known; `None` when
/// the request is shorter than a step.
fn shape(request: &Request, start: Point, settings: &Settings) -> Result<Option<(Shape, Option<IdealBox>)>, DrawError> {
    let spm = settings.steps_per_mm;
    let at = |[x, y]: [f32; 2]| {
        Point::new(start.x + settings.mm_to_steps(Axis::X, x), start.y + settings.mm_to_steps(Axis::Y, y))
    };
    Ok(match request {
        Request::Straight { to } => {
            if *to == start {
                return Ok(None);
            }
            let min = [start.x.min(to.x) as f32, start.y.min(to.y) as f32];
            let max = [start.x.max(to.x) as f32, start.y.max(to.y) as f32];
            Some((Shape::Straight { to: *to }, Some(IdealBox { min, max })))
        }
        Request::Ellipse(e) => {
            let finite = e.a_mm.is_finite() && e.b_mm.is_finite() && e.start_deg.is_finite();
            let sized = e.a_mm > 0.0 && e.b_mm > 0.0 && e.a_mm <= CURVE_RADIUS_MAX_MM && e.b_mm <= CURVE_RADIUS_MAX_MM;
            if !(finite && sized && e.sweep_deg.abs() <= 360.0 && e.sweep_deg != 0.0) {
                return Err(DrawError::BadParameter);
            }
            let ideal = IdealBox::from_extent(start, &e.extent(), settings);
            let (a_steps, b_steps) = (crate::math::round(e.a_mm * spm[0]), crate::math::round(e.b_mm * spm[1]));
            if a_steps < 1.0 || b_steps < 1.0 {
                return Err(DrawError::TooFine);
            }
            let center = at(e.center_offset_mm());
            let to = if e.is_full() { start } else { at(e.end_offset_mm()) };
            if to == start && !e.is_full() && e.sweep_deg.abs() < 180.0 {
                // Shorter than a step.
                return Ok(None);
            }
            let rotation = if e.sweep_deg < 0.0 { Rotation::Clockwise } else { Rotation::CounterClockwise };
            let shape = if a_steps == b_steps {
                Shape::Arc { center, to, rotation }
            } else {
                Shape::Ellipse { center, a_steps: a_steps as i32, b_steps: b_steps as i32, to, rotation }
            };
            Some((shape, Some(ideal)))
        }
        Request::Sine(s) => {
            let phase_rad = s.phase_deg.to_radians();
            let finite = s.amplitude_mm.is_finite() && s.omega_rad_per_mm.is_finite() && phase_rad.is_finite();
            if !(finite && s.length_mm.is_finite() && s.amplitude_mm.abs() <= CURVE_RADIUS_MAX_MM) {
                return Err(DrawError::BadParameter);
            }
            let ideal = IdealBox::from_extent(start, &s.extent(), settings);
            // Shorter than one step: nothing to draw.
            if s.length_mm.abs() * spm[0] < 1.0 {
                return Ok(None);
            }
            let length_steps = settings.mm_to_steps(Axis::X, s.length_mm);
            let amplitude_steps = s.amplitude_mm * spm[1];
            let omega_rad_per_step = s.omega_rad_per_mm / spm[0];
            if omega_rad_per_step.abs() * SINE_MIN_STEPS_PER_WAVE > core::f32::consts::TAU {
                return Err(DrawError::TooFine);
            }
            if !fits_jump_limit(amplitude_steps, omega_rad_per_step, settings) {
                return Err(DrawError::TooSteep);
            }
            Some((Shape::Sine { amplitude_steps, omega_rad_per_step, phase_rad, length_steps }, Some(ideal)))
        }
        Request::Function { expr, x0_mm, x1_mm } => {
            if !(x0_mm.is_finite() && x1_mm.is_finite()) {
                return Err(DrawError::BadParameter);
            }
            // Shorter than one step: nothing to draw.
            if (x1_mm - x0_mm).abs() * spm[0] < 1.0 {
                return Ok(None);
            }
            // A span past the step range saturates (and is far outside the travel).
            let dx = settings.mm_to_steps(Axis::X, x1_mm - x0_mm);
            let x = [start.x as f32, start.x.saturating_add(dx) as f32];
            let ideal_x = IdealBox { min: [x[0].min(x[1]), start.y as f32], max: [x[0].max(x[1]), start.y as f32] };
            if !ideal_x.within(settings.travel_steps(), LATTICE_SLACK_STEPS) {
                return Err(DrawError::Travel);
            }
            if !precise_enough(expr, *x0_mm, *x1_mm, settings) {
                return Err(DrawError::Imprecise);
            }
            Some((Shape::Function { expr: expr.clone(), x0_mm: *x0_mm, x1_mm: *x1_mm }, None))
        }
    })
}

/// True when single precision places every column's point of `expr` over x from `x0_mm` to
/// `x1_mm` within [`F32_ERROR_MAX_STEPS`] of its curve. Its values are f(x0) give or take the
/// machine's Y travel (`$131`) either way: a path that goes further does not draw. An f not
/// defined at x0 passes: the curve's setup says why it is not drawn.
fn precise_enough(expr: &Expr, x0_mm: f32, x1_mm: f32, settings: &Settings) -> bool {
    let Ok(start_mm) = expr.eval(x0_mm) else { return true };
    let largest_mm = start_mm.abs() + 2.0 * settings.max_travel_mm[1];
    // False for NaN as well.
    f32_error_steps(x0_mm, x1_mm, largest_mm, settings.steps_per_mm).iter().all(|e| *e <= F32_ERROR_MAX_STEPS)
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
mod tests;

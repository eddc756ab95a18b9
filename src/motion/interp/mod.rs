//! Point-by-point (逐点比较法) interpolators: each curve becomes a stream of single steps.
//!
//! Every interpolator works in integer steps relative to its start point and yields [`Step`]s
//! to lattice neighbours. Two methods exist ([`Method`]): `classic`, the original controller's one-axis-per-step
//! comparison (error <= 1 step), and `diagonal`, which may move both axes at once (error <= 0.5
//! step, fewer steps). Interpolators never read a clock and never allocate.

pub mod arc;
pub(crate) mod conic;
pub mod ellipse;
pub mod explicit;
pub mod function;
pub mod interpolator;
pub mod setup;
pub mod sine;
pub mod straight;

pub use crate::motion::method::Method;
pub use arc::{ArcError, ArcInterp};
pub use ellipse::EllipseInterp;
pub use explicit::jump_limit_steps;
pub use function::FunctionInterp;
pub use interpolator::{CurveError, Filled, Interpolator, KINK_CHORD, Tangent};
pub use setup::CurveSetupError;
pub use sine::SineInterp;
pub use straight::StraightInterp;

use crate::geom::{Point, Rotation, Step};
use crate::motion::expr::Expr;
use crate::settings::Settings;

/// The path of one drawing in steps, as the interpolators take it. Curves that start "at the
/// pen" (sine, function) are translated so their first point is the start point.
// No heap: a function carries its expression by value, so it is the largest.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Shape {
    /// Straight line to `to`.
    Straight { to: Point },
    /// Circular arc around `center` to `to`; `to` equal to the start point is a full circle.
    Arc { center: Point, to: Point, rotation: Rotation },
    /// Elliptic arc with semi-axes `a_steps` (along X) and `b_steps` (along Y) around `center`
    /// to `to`; `to` equal to the start point is the full ellipse.
    Ellipse { center: Point, a_steps: i32, b_steps: i32, to: Point, rotation: Rotation },
    /// y = A·sin(ω·x + φ) − A·sin φ, for x from 0 to `length_steps` (negative: towards −X).
    Sine { amplitude_steps: f32, omega_rad_per_step: f32, phase_rad: f32, length_steps: i32 },
    /// y = f(x) with x and y in millimetres, for x from `x0_mm` to `x1_mm`, translated so that
    /// (x0, f(x0)) is the start point.
    Function { expr: Expr, x0_mm: f32, x1_mm: f32 },
}

/// What a [`Shape`] is, without its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum ShapeKind {
    Straight,
    Arc,
    Ellipse,
    Sine,
    Function,
}

impl ShapeKind {
    pub const ALL: [ShapeKind; 5] =
        [ShapeKind::Straight, ShapeKind::Arc, ShapeKind::Ellipse, ShapeKind::Sine, ShapeKind::Function];

    /// Its name in the cost model's tables (`cost/f407.txt`).
    pub const fn name(self) -> &'static str {
        match self {
            ShapeKind::Straight => "line",
            ShapeKind::Arc => "arc",
            ShapeKind::Ellipse => "ellipse",
            ShapeKind::Sine => "sine",
            ShapeKind::Function => "function",
        }
    }
}

impl Shape {
    pub fn kind(&self) -> ShapeKind {
        match self {
            Shape::Straight { .. } => ShapeKind::Straight,
            Shape::Arc { .. } => ShapeKind::Arc,
            Shape::Ellipse { .. } => ShapeKind::Ellipse,
            Shape::Sine { .. } => ShapeKind::Sine,
            Shape::Function { .. } => ShapeKind::Function,
        }
    }
}

/// Any curve the machine draws, from a known start point: what the planner queues.
///
/// It keeps the pen inside the travel whatever its interpolator does: every step is checked
/// against the travel limits where it is generated, and the first step that would leave them
/// ends the curve with [`CurveError::Travel`] at the last point inside (the planner brakes to
/// it). The drawing builder refuses such curves before they move; this guard is there for a
/// defect upstream.
#[derive(Clone, Debug)]
pub struct Curve {
    kind: CurveKind,
    /// The pen after the steps handed out so far, absolute.
    at: Point,
    /// Travel limits, ± steps on each axis.
    limit: [i32; 2],
    /// The curve ended (or was stopped by the guard): no more steps.
    ended: bool,
}

// No heap: a function curve carries its expression by value, so it is the largest.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
enum CurveKind {
    Straight(StraightInterp),
    Arc(ArcInterp),
    Ellipse(EllipseInterp),
    Sine(SineInterp),
    Function(FunctionInterp),
}

impl Curve {
    /// The curve `shape` draws when the pen starts at `start`. A shape that cannot be drawn from
    /// there (a bad parameter, a function undefined at its first point) is an error.
    pub fn new(shape: &Shape, start: Point, settings: &Settings) -> Result<Curve, CurveSetupError> {
        let method = settings.method;
        let max_jump_steps = jump_limit_steps(settings.max_jump_mm, settings.steps_per_mm[1]);
        let kind = match shape {
            Shape::Straight { to } => {
                let d = to.offset_from(start);
                CurveKind::Straight(StraightInterp::new(d.x, d.y, method))
            }
            Shape::Sine { amplitude_steps, omega_rad_per_step, phase_rad, length_steps } => {
                CurveKind::Sine(SineInterp::new(
                    *amplitude_steps,
                    *omega_rad_per_step,
                    *phase_rad,
                    *length_steps,
                    max_jump_steps,
                    method,
                )?)
            }
            Shape::Function { expr, x0_mm, x1_mm } => CurveKind::Function(FunctionInterp::new(
                expr.clone(),
                *x0_mm,
                *x1_mm,
                settings.steps_per_mm,
                max_jump_steps,
                method,
            )?),
            Shape::Arc { center, to, rotation } => {
                CurveKind::Arc(ArcInterp::new(start, *center, *to, *rotation, method)?)
            }
            Shape::Ellipse { center, a_steps, b_steps, to, rotation } => {
                CurveKind::Ellipse(EllipseInterp::new(start, *center, *a_steps, *b_steps, *to, *rotation, method)?)
            }
        };
        let limit = settings.travel_steps();
        Ok(Curve { kind, at: start, limit, ended: false })
    }

    /// The same curve, checked as it is walked between the columns where a function is
    /// evaluated (see [`explicit::between`]): the drawing builder walks such a copy, so a
    /// function that changes faster than its X steps sample it ends with
    /// [`CurveError::Aliased`] before anything moves. Other curves are the same as before.
    pub fn check_between_columns(mut self) -> Curve {
        if let CurveKind::Function(f) = self.kind {
            self.kind = CurveKind::Function(f.check_between_columns());
        }
        self
    }

    /// The same curve, guarded by the travel `limit` (± steps on each axis) instead of the one
    /// of the settings it was set up with: the motion task guards every curve by the travel of
    /// the settings it runs under, should they have changed since the curve was built.
    pub fn keep_within(mut self, limit: [i32; 2]) -> Curve {
        self.limit = limit;
        self
    }

    /// Steps the pen is away from the nearest edge of the travel (negative outside).
    fn margin_steps(&self) -> i32 {
        (self.limit[0] - self.at.x.abs()).min(self.limit[1] - self.at.y.abs())
    }

    /// True when `p` is inside the travel.
    fn inside(&self, p: Point) -> bool {
        p.x.unsigned_abs() <= self.limit[0] as u32 && p.y.unsigned_abs() <= self.limit[1] as u32
    }
}

impl Interpolator for Curve {
    fn next_step(&mut self) -> Result<Option<Step>, CurveError> {
        if self.ended {
            return Ok(None);
        }
        let step = match &mut self.kind {
            CurveKind::Straight(c) => c.next_step(),
            CurveKind::Arc(c) => c.next_step(),
            CurveKind::Ellipse(c) => c.next_step(),
            CurveKind::Sine(c) => c.next_step(),
            CurveKind::Function(c) => c.next_step(),
        };
        match step {
            Ok(Some(s)) if !self.inside(self.at.stepped(s)) => {
                self.ended = true;
                Err(CurveError::Travel)
            }
            Ok(Some(s)) => {
                self.at = self.at.stepped(s);
                Ok(Some(s))
            }
            other => {
                self.ended = true;
                other
            }
        }
    }

    fn tangent(&self) -> Tangent {
        match &self.kind {
            CurveKind::Straight(c) => c.tangent(),
            CurveKind::Arc(c) => c.tangent(),
            CurveKind::Ellipse(c) => c.tangent(),
            CurveKind::Sine(c) => c.tangent(),
            CurveKind::Function(c) => c.tangent(),
        }
    }

    fn straight_steps_left(&self) -> Option<u64> {
        match &self.kind {
            CurveKind::Straight(c) if !self.ended => c.straight_steps_left(),
            _ => None,
        }
    }

    fn fill(&mut self, out: &mut [Step]) -> Filled {
        if self.ended {
            return Filled::ended(0, Ok(()));
        }
        // The guard costs a sum per step: a curve moves each axis by at most one step per step,
        // so as many steps as the pen is away from the nearest edge cannot leave the travel and
        // are taken in one fill. At the edge, steps are taken and checked one by one.
        let mut done = 0;
        loop {
            let margin = self.margin_steps();
            let take = (out.len() - done).min(margin.max(1) as usize);
            let part = &mut out[done..done + take];
            let filled = match &mut self.kind {
                CurveKind::Straight(c) => c.fill(part),
                CurveKind::Arc(c) => c.fill(part),
                CurveKind::Ellipse(c) => c.fill(part),
                CurveKind::Sine(c) => c.fill(part),
                CurveKind::Function(c) => c.fill(part),
            };
            let (mut dx, mut dy) = (0i32, 0i32);
            for step in &part[..filled.steps] {
                dx += i32::from(step.x);
                dy += i32::from(step.y);
            }
            let next = Point::new(self.at.x + dx, self.at.y + dy);
            if margin < 1 && !self.inside(next) {
                // The one step just taken would leave: it is not handed out.
                self.ended = true;
                return Filled::ended(done, Err(CurveError::Travel));
            }
            self.at = next;
            done += filled.steps;
            if filled.end.is_some() || filled.kink.is_some() {
                self.ended = filled.end.is_some();
                return Filled { steps: done, ..filled };
            }
            if done == out.len() {
                return Filled::more(done);
            }
        }
    }
}

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
pub mod line;
pub mod setup;
pub mod sine;

pub use crate::method::Method;
pub use arc::{ArcError, ArcInterp};
pub use ellipse::EllipseInterp;
pub use explicit::{RowRange, jump_limit_steps};
pub use function::FunctionInterp;
pub use line::LineInterp;
pub use setup::CurveSetupError;
pub use sine::SineInterp;

use crate::geom::{Point, Step};
use crate::job::{Job, Shape};
use crate::settings::Settings;

/// Why a curve ended before its end point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum CurveError {
    /// The function left its domain (sqrt of a negative, ln of zero, ...).
    Domain,
    /// Division by zero.
    DivisionByZero,
    /// A value too large for the machine's range.
    Overflow,
    /// The curve jumps by more than the allowed distance between two points.
    Jump,
    /// The curve would leave the machine's travel area (`$130`, `$131`): it ends at the last
    /// point inside, before any step toward the first point outside.
    Travel,
}

/// A unit vector in step space: the direction of travel of the ideal curve.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Tangent {
    pub x: f32,
    pub y: f32,
}

impl Tangent {
    /// The unit vector along `(x, y)`; `(1, 0)` for a zero vector.
    pub fn along(x: f32, y: f32) -> Self {
        let len = crate::math::sqrt(x * x + y * y);
        if len > 0.0 && len.is_finite() { Tangent { x: x / len, y: y / len } } else { Tangent { x: 1.0, y: 0.0 } }
    }
}

/// A change of direction between two steps larger than this chord between their unit tangents
/// (≈ 5.7°) is a kink: no smooth curve turns so much in one step unless its radius is under
/// about ten steps. The planner passes a kink by the junction rule, as a joint between two
/// segments; [`Interpolator::fill`] stops at every kink so that the planner sees it.
pub const KINK_CHORD: f32 = 0.1;

/// What [`Interpolator::fill`] did: how many steps it wrote, and why it stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Filled {
    /// Steps written, from the start of the buffer.
    pub steps: usize,
    /// `None`: the buffer is full, or the curve kinks (see `kink`), and goes on. `Some(Ok(()))`:
    /// the curve reached its end point after these steps; `Some(Err(e))`: it failed there (see
    /// [`Interpolator::next_step`]).
    pub end: Option<Result<(), CurveError>>,
    /// The last step written reached a kink (see [`KINK_CHORD`]): the unit tangent before that
    /// step. [`Interpolator::tangent`] now gives the direction after the kink.
    pub kink: Option<Tangent>,
}

impl Filled {
    /// `steps` written and the buffer full: the curve goes on.
    pub const fn more(steps: usize) -> Filled {
        Filled { steps, end: None, kink: None }
    }

    /// `steps` written, then the curve ended (`Ok`) or failed.
    pub const fn ended(steps: usize, end: Result<(), CurveError>) -> Filled {
        Filled { steps, end: Some(end), kink: None }
    }

    /// `steps` written, the last reaching a kink from direction `before`.
    pub const fn kink(steps: usize, before: Tangent) -> Filled {
        Filled { steps, end: None, kink: Some(before) }
    }
}

impl Tangent {
    /// True when the direction jumps from `self` to `next` by more than [`KINK_CHORD`].
    pub fn kinks_to(self, next: Tangent) -> bool {
        let (dx, dy) = (next.x - self.x, next.y - self.y);
        dx * dx + dy * dy > KINK_CHORD * KINK_CHORD
    }
}

/// What every interpolator offers the motion planner.
pub trait Interpolator {
    /// The next step, `Ok(None)` once the end point is reached. After `None` or an error the
    /// interpolator keeps returning `Ok(None)`.
    fn next_step(&mut self) -> Result<Option<Step>, CurveError>;

    /// The unit tangent of the ideal curve at the current point, in the direction of travel.
    fn tangent(&self) -> Tangent;

    /// `Some(n)` when the rest of the curve is `n` steps along one straight line (its tangent
    /// never changes again): the planner then takes its steps in long chunks, and plans its
    /// braking from the curve's end rather than from what it has stepped so far.
    fn straight_steps_left(&self) -> Option<u64> {
        None
    }

    /// Writes the next steps into `out`, exactly those `next_step` would hand out one by one,
    /// until `out` is full, the curve ends or fails, or a step reaches a kink: a point where the
    /// tangent jumps from the one before the step by more than [`KINK_CHORD`]. The planner takes
    /// steps this way: a curve steps in a tight loop, without a call per step, and every kink
    /// falls at the end of a fill. This default compares the tangent at every step; a curve
    /// that cannot kink, or knows where it does, does better.
    fn fill(&mut self, out: &mut [Step]) -> Filled {
        let mut before = self.tangent();
        for (i, slot) in out.iter_mut().enumerate() {
            match self.next_step() {
                Ok(Some(step)) => *slot = step,
                Ok(None) => return Filled::ended(i, Ok(())),
                Err(e) => return Filled::ended(i, Err(e)),
            }
            let now = self.tangent();
            if before.kinks_to(now) {
                return Filled::kink(i + 1, before);
            }
            before = now;
        }
        Filled::more(out.len())
    }
}

impl From<ArcError> for CurveSetupError {
    fn from(e: ArcError) -> Self {
        match e {
            ArcError::TooLarge => CurveSetupError::OutOfRange,
            ArcError::ZeroRadius | ArcError::StartOffCurve | ArcError::EndOffCurve | ArcError::NotFinite => {
                CurveSetupError::BadParameter
            }
        }
    }
}

/// Any curve the machine draws, starting at a known point: what the planner queues.
#[derive(Clone, Debug)]
pub struct Curve {
    kind: CurveKind,
    end: Point,
}

// No heap: a function curve carries its expression by value, so it is the largest.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
enum CurveKind {
    Line(LineInterp),
    Arc(ArcInterp),
    Ellipse(EllipseInterp),
    Sine(SineInterp),
    Function(FunctionInterp),
}

impl Curve {
    /// The curve a job draws when the pen starts at `start`. A job that cannot be drawn from
    /// there (a bad parameter, a function undefined at its first point) is an error and nothing
    /// moves.
    pub fn for_job(job: &Job, start: Point, settings: &Settings) -> Result<Curve, CurveSetupError> {
        let method = settings.method;
        Ok(match &job.shape {
            Shape::Line { to } => {
                let d = to.offset_from(start);
                Curve { kind: CurveKind::Line(LineInterp::new(d.x, d.y, method)), end: *to }
            }
            Shape::Sine { amplitude_steps, omega_rad_per_step, phase_rad, length_steps } => {
                // The same limits as a function's: no stroke between columns longer than `$204`,
                // no row outside the travel.
                let travel_steps = settings.mm_to_steps(crate::geom::Axis::Y, settings.max_travel_mm[1]);
                let sine = SineInterp::new(
                    *amplitude_steps,
                    *omega_rad_per_step,
                    *phase_rad,
                    *length_steps,
                    jump_limit_steps(settings.max_jump_mm, settings.steps_per_mm[1]),
                    RowRange::within_travel(start.y, travel_steps),
                    method,
                )?;
                let d = sine.end();
                Curve { kind: CurveKind::Sine(sine), end: Point::new(start.x + d.x, start.y + d.y) }
            }
            Shape::Function { expr, x0_mm, x1_mm } => {
                // The parser checks X exactly (it is linear) and Y only on samples; the
                // interpolator holds every column to the travel.
                let travel_steps = settings.mm_to_steps(crate::geom::Axis::Y, settings.max_travel_mm[1]);
                let f = FunctionInterp::new(
                    expr.clone(),
                    *x0_mm,
                    *x1_mm,
                    settings.steps_per_mm,
                    jump_limit_steps(settings.max_jump_mm, settings.steps_per_mm[1]),
                    RowRange::within_travel(start.y, travel_steps),
                    method,
                )?;
                // Where it ends if nothing stops it; a curve that stops early (a domain error,
                // a jump or the travel limit part way) ends the program there, and the motion
                // drops whatever was planned from this end.
                let d = f.nominal_end().unwrap_or(Point::ORIGIN);
                Curve { kind: CurveKind::Function(f), end: Point::new(start.x + d.x, start.y + d.y) }
            }
            Shape::Arc { center, to, rotation } => {
                let arc = ArcInterp::new(start, *center, *to, *rotation, method)?;
                Curve { kind: CurveKind::Arc(arc), end: *to }
            }
            Shape::Ellipse { center, a_steps, b_steps, to, rotation } => {
                let ellipse = EllipseInterp::new(start, *center, *a_steps, *b_steps, *to, *rotation, method)?;
                Curve { kind: CurveKind::Ellipse(ellipse), end: *to }
            }
        })
    }

    /// Where the pen is once the whole curve is drawn.
    pub fn end(&self) -> Point {
        self.end
    }
}

impl Interpolator for Curve {
    fn next_step(&mut self) -> Result<Option<Step>, CurveError> {
        match &mut self.kind {
            CurveKind::Line(c) => c.next_step(),
            CurveKind::Arc(c) => c.next_step(),
            CurveKind::Ellipse(c) => c.next_step(),
            CurveKind::Sine(c) => c.next_step(),
            CurveKind::Function(c) => c.next_step(),
        }
    }

    fn tangent(&self) -> Tangent {
        match &self.kind {
            CurveKind::Line(c) => c.tangent(),
            CurveKind::Arc(c) => c.tangent(),
            CurveKind::Ellipse(c) => c.tangent(),
            CurveKind::Sine(c) => c.tangent(),
            CurveKind::Function(c) => c.tangent(),
        }
    }

    fn straight_steps_left(&self) -> Option<u64> {
        match &self.kind {
            CurveKind::Line(c) => c.straight_steps_left(),
            _ => None,
        }
    }

    fn fill(&mut self, out: &mut [Step]) -> Filled {
        match &mut self.kind {
            CurveKind::Line(c) => c.fill(out),
            CurveKind::Arc(c) => c.fill(out),
            CurveKind::Ellipse(c) => c.fill(out),
            CurveKind::Sine(c) => c.fill(out),
            CurveKind::Function(c) => c.fill(out),
        }
    }
}

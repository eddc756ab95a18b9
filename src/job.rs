//! What the machine is asked to do: drawing jobs and run-time controls.
//!
//! Both inputs (serial protocol and keypad menu) produce the same [`Job`]s, in machine units
//! (steps), so everything the keypad can draw the host can draw too. A job starts where the pen
//! is when the job begins; positions in it are absolute.

use crate::expr::Expr;
use crate::geom::{Axis, Point, Rotation, Step};
use crate::settings::Settings;

/// Feed of a jog from the keypad.
pub const JOG_FEED_MM_PER_MIN: f32 = 1_200.0;

/// How fast a job moves.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Feed {
    /// As fast as the axes allow (G0).
    Rapid,
    /// Tangential speed along the path.
    MmPerMin(f32),
}

/// The path of one job, in steps. Curves that start "at the pen" (sine, function) are
/// translated so their first point is wherever the pen is when the job begins.
// No heap: a function carries its expression by value, so it is the largest.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Shape {
    /// Straight line to `to`.
    Line { to: Point },
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
    Line,
    Arc,
    Ellipse,
    Sine,
    Function,
}

impl ShapeKind {
    pub const ALL: [ShapeKind; 5] =
        [ShapeKind::Line, ShapeKind::Arc, ShapeKind::Ellipse, ShapeKind::Sine, ShapeKind::Function];
}

impl Shape {
    pub fn kind(&self) -> ShapeKind {
        match self {
            Shape::Line { .. } => ShapeKind::Line,
            Shape::Arc { .. } => ShapeKind::Arc,
            Shape::Ellipse { .. } => ShapeKind::Ellipse,
            Shape::Sine { .. } => ShapeKind::Sine,
            Shape::Function { .. } => ShapeKind::Function,
        }
    }
}

/// Whether a job draws or jogs. A jog is reported as such and only a jog cancel stops it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum JobKind {
    Draw,
    Jog,
}

/// One job for the motion task.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Job {
    pub shape: Shape,
    pub feed: Feed,
    pub kind: JobKind,
    /// Aborts the machine had counted when the job was planned (`Machine::aborts`): a job
    /// planned before an abort was planned from a point the pen never reached, and the motion
    /// task drops it.
    pub aborts_before: u32,
}

/// Run-time commands that act on the motion in progress. Requests that arrive before the motion
/// task takes them are merged by [`Control::then`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Control {
    /// Decelerate to a stop on the path, keeping the rest of the job.
    Hold,
    /// Continue a held job on the same path.
    Resume,
    /// Decelerate to a stop and drop the rest of the job and every queued one.
    Abort,
}

impl Control {
    /// The request left pending when `next` arrives while `self` is still waiting to be taken:
    /// an abort stays an abort (nothing cancels it), otherwise the newer request wins.
    pub const fn then(self, next: Control) -> Control {
        match self {
            Control::Abort => Control::Abort,
            _ => next,
        }
    }
}

impl Job {
    /// A drawing job.
    pub const fn draw(shape: Shape, feed: Feed) -> Job {
        Job { shape, feed, kind: JobKind::Draw, aborts_before: 0 }
    }

    /// A jog: a straight move to `to`.
    pub const fn jog_to(to: Point, feed: Feed) -> Job {
        Job { shape: Shape::Line { to }, feed, kind: JobKind::Jog, aborts_before: 0 }
    }

    /// The same job, planned after `aborts` aborts.
    pub const fn planned_after(mut self, aborts: u32) -> Job {
        self.aborts_before = aborts;
        self
    }

    /// A jog from `from` in `direction` (one of the 8), as far as the travel limits allow along a
    /// straight 0°, 45° or 90° line; releasing the key aborts it, which decelerates to a stop.
    pub fn jog(direction: Step, from: Point, settings: &Settings) -> Job {
        let room = |axis: Axis| -> i32 {
            let limit = settings.mm_to_steps(axis, settings.max_travel_mm[axis.index()]);
            let at = match axis {
                Axis::X => from.x,
                Axis::Y => from.y,
            };
            match direction.on(axis) {
                1 => (limit - at).max(0),
                -1 => (at + limit).max(0),
                _ => i32::MAX,
            }
        };
        let distance = room(Axis::X).min(room(Axis::Y));
        let distance = if distance == i32::MAX { 0 } else { distance };
        let to = Point::new(from.x + direction.x as i32 * distance, from.y + direction.y as i32 * distance);
        Job::jog_to(to, Feed::MmPerMin(JOG_FEED_MM_PER_MIN))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_abort_is_never_overwritten_by_a_later_request() {
        assert_eq!(Control::Abort.then(Control::Hold), Control::Abort);
        assert_eq!(Control::Abort.then(Control::Resume), Control::Abort);
        assert_eq!(Control::Hold.then(Control::Abort), Control::Abort);
        assert_eq!(Control::Hold.then(Control::Resume), Control::Resume);
        assert_eq!(Control::Resume.then(Control::Hold), Control::Hold);
    }

    #[test]
    fn a_diagonal_jog_stays_at_45_degrees_and_inside_the_travel() {
        let s = Settings::default(); // ±200 mm at 100 steps/mm
        let job = Job::jog(Step::new(1, -1), Point::new(19_000, 5_000), &s);
        assert_eq!(job.shape, Shape::Line { to: Point::new(20_000, 4_000) });
        let job = Job::jog(Step::XN, Point::new(19_000, 5_000), &s);
        assert_eq!(job.shape, Shape::Line { to: Point::new(-20_000, 5_000) });
    }
}

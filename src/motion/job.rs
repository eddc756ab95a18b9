//! What the machine is asked to do: jobs (a built [`Drawing`] with its feed) and run-time
//! controls.
//!
//! Both inputs (serial protocol and keypad menu) build their drawings with the one builder
//! ([`crate::motion::drawing`]), so everything the keypad can draw the host can draw too, step for step.

use crate::geom::{Axis, Point, Step};
use crate::machine_io::pen::{self, Pen};
use crate::motion::drawing::{self, DrawError, Drawing, Request};
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

/// Whether a job draws, jogs or homes. A jog is reported as such and only a jog cancel stops
/// it. A homing move goes where the travel does not reach: it is planned like a drawing, but
/// neither built nor guarded against the travel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum JobKind {
    Draw,
    Jog,
    Home,
}

/// One job for the motion task: a drawing, checked and built, and how fast to draw it.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Job {
    pub drawing: Drawing,
    pub feed: Feed,
    pub kind: JobKind,
    /// Where the pen must be for this job (`None`: it stays where it is). The motion task moves
    /// it at rest, before the job, and waits for it to settle.
    pub pen: Option<Pen>,
    /// The pen goes up once the machine comes to rest after this job (a keypad drawing).
    pub raise_after: bool,
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
    pub const fn draw(drawing: Drawing, feed: Feed) -> Job {
        Job { drawing, feed, kind: JobKind::Draw, pen: None, raise_after: false }
    }

    /// A jog: a straight move from `from` to `to`; `None` when it goes nowhere.
    pub fn jog_to(from: Point, to: Point, feed: Feed, settings: &Settings) -> Result<Option<Job>, DrawError> {
        let drawing = drawing::build(&Request::Straight { to }, from, settings)?;
        Ok(drawing.map(|drawing| Job { drawing, feed, kind: JobKind::Jog, pen: None, raise_after: false }))
    }

    /// A move of the homing cycle: a straight line from `from` to `to` at `feed_mm_per_min`,
    /// wherever the pen and the travel are (the position is unknown until homed). `None` when
    /// it goes nowhere, or beyond what any plotter reaches.
    pub fn homing_move(from: Point, to: Point, feed_mm_per_min: f32, settings: &Settings) -> Option<Job> {
        let unchecked = Settings { soft_limits: false, ..*settings };
        let drawing = drawing::build(&Request::Straight { to }, from, &unchecked).ok()??;
        // Homing never draws: with a pen lift, the pen is up.
        let pen = pen::for_homing(settings);
        Some(Job { drawing, feed: Feed::MmPerMin(feed_mm_per_min), kind: JobKind::Home, pen, raise_after: false })
    }

    /// A jog from `from` in `direction` (one of the 8), as far as the travel limits allow along a
    /// straight 0°, 45° or 90° line; releasing the key aborts it, which decelerates to a stop.
    /// `None` when the pen is at the edge already.
    pub fn jog(direction: Step, from: Point, settings: &Settings) -> Option<Job> {
        let limit = settings.travel_steps();
        let room = |axis: Axis| -> i32 {
            let at = match axis {
                Axis::X => from.x,
                Axis::Y => from.y,
            };
            let l = limit[axis.index()];
            match direction.on(axis) {
                1 => (l - at).max(0),
                -1 => (at + l).max(0),
                _ => i32::MAX,
            }
        };
        let distance = room(Axis::X).min(room(Axis::Y));
        let distance = if distance == i32::MAX { 0 } else { distance };
        let to = Point::new(from.x + direction.x as i32 * distance, from.y + direction.y as i32 * distance);
        Job::jog_to(from, to, Feed::MmPerMin(JOG_FEED_MM_PER_MIN), settings).ok().flatten()
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
        let job = Job::jog(Step::new(1, -1), Point::new(19_000, 5_000), &s).unwrap();
        assert_eq!(job.drawing.end(), Point::new(20_000, 4_000));
        let job = Job::jog(Step::XN, Point::new(19_000, 5_000), &s).unwrap();
        assert_eq!(job.drawing.end(), Point::new(-20_000, 5_000));
        assert!(Job::jog(Step::XP, Point::new(20_000, 0), &s).is_none(), "at the edge already");
    }
}

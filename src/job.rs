//! What the machine is asked to do: drawing jobs and run-time controls.
//!
//! Both inputs (serial protocol and keypad menu) produce the same [`Job`]s, in machine units
//! (steps), so everything the keypad can draw the host can draw too. A job starts where the pen
//! is when the job begins; positions in it are absolute.

use crate::geom::{Point, Rotation};

/// How fast a job moves.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Feed {
    /// As fast as the axes allow (G0).
    Rapid,
    /// Tangential speed along the path.
    MmPerMin(f32),
}

/// The path of one job.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Shape {
    /// Straight line to `to`.
    Line { to: Point },
}

/// One drawing job.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Job {
    pub shape: Shape,
    pub feed: Feed,
}

/// Run-time commands that act on the motion in progress.
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

//! What the machine reports about itself: run state and position, as the LCD, the status
//! reports and the menu see it.

use crate::geom::Point;

/// The machine's run state, named as GRBL reports it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum RunState {
    #[default]
    Idle,
    /// Drawing a job.
    Run,
    /// Stopped on the path by a hold; a resume continues.
    Hold,
    /// Moving under a jog command (keypad or `$J=`).
    Jog,
    /// A driver alarm or limit switch stopped the machine.
    Alarm,
}

/// A snapshot of the machine for displays and reports.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Status {
    pub state: RunState,
    /// Pulses emitted so far, per axis: the position, always.
    pub position: Point,
    /// Jobs waiting behind the one in progress.
    pub queued_jobs: u8,
}

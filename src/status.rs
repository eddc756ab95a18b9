//! What the machine reports about itself: run state and position, as the LCD, the status
//! reports and the menu see it.

use crate::geom::Point;
use crate::machine_io::homing::HomingFail;
use crate::machine_io::inputs::Trip;
use crate::motion::interp::CurveError;
use crate::motion::overrides::Overrides;

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
    /// A fault stopped the machine (see [`MotionFault`]); motion is refused until `$X`.
    Alarm,
    /// The host link's check mode (`$C`): lines are parsed and every drawing built and checked,
    /// but nothing moves.
    Check,
    /// A homing cycle (`$H`) runs.
    Home,
    /// `$SLP`: the servos are off (SON low) and every line is refused until a reset, after which
    /// the machine is in alarm: the axes were free, the pen may have been moved.
    Sleep,
}

impl RunState {
    /// True while the machine moves or holds a job: drawing, held, jogging or homing.
    pub const fn moving(self) -> bool {
        matches!(self, RunState::Run | RunState::Hold | RunState::Jog | RunState::Home)
    }
}

/// Why the last job stopped early, shown on the LCD and reported to the host.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum MotionFault {
    /// The curve ended part way: the travel guard stopped it at the edge (see
    /// [`crate::motion::interp::Curve`]).
    Curve(CurveError),
    /// An input stopped the machine at once: a limit switch, a driver alarm, the emergency stop.
    Tripped(Trip),
    /// A homing cycle failed.
    Homing(HomingFail),
    /// The card was removed, or could not be read, while a file of it was plotted: the plot
    /// stopped on its path and the pen went up.
    CardLost,
}

/// A snapshot of the machine for displays and reports.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Status {
    pub state: RunState,
    /// The machine position, steps: the pulses emitted so far, from machine zero.
    pub position: Point,
    /// The position may be wrong (see `Machine::position_lost`): the LCD shows it inverted.
    pub position_lost: bool,
    /// Jobs waiting behind the one in progress.
    pub queued_jobs: u8,
    /// Why the last job stopped early, until the next one starts.
    pub fault: Option<MotionFault>,
    /// The hold came from the safety door (GRBL's 0x84): reported as `Door`, resumed by `~`.
    pub door: bool,
    /// Times the pulses had to wait for the motion task since power-on (step-queue underruns):
    /// where the machine could not keep up with the speeds it planned.
    pub underruns: u32,
    /// Times the step timer's interrupt came a whole period late since power-on: each stopped
    /// the machine in an alarm (the position stays the pulses emitted).
    pub missed_updates: u32,
    /// The feed, rapid and spindle overrides in force.
    pub overrides: Overrides,
    /// Steps emitted since power-on (wrapping): how far the motion has come.
    pub emitted_steps: u32,
    /// Something is queued, planned or moving, held or not.
    pub work_left: bool,
}

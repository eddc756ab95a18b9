//! The motion supervisor: what the motion task does about what happened to the motion. Pure
//! logic; the motion task ([`crate::tasks::motion`]) waits, calls it, and carries out what it
//! says on the machine, the planner and the step queue.
//!
//! It owns these rules:
//! - the motion's state: `Run` while a drawing or a homing move is queued, `Jog` for a jog,
//!   `Hold` once a hold stands, `Idle` at rest (an alarm is a latch over it, raised here for a
//!   curve or a trip, and kept by the machine until `$X`: [`crate::machine`]);
//! - the pen at rest: a job that needs the pen elsewhere is held back until the motion before it
//!   has been emitted, then the pen goes there; a keypad drawing lifts the pen where a program's
//!   end leaves it once it rests, unless a job is queued behind it (the pen rules themselves are
//!   [`crate::machine_io::pen`]'s);
//! - a curve failing part way raises the alarm for it and aborts what was planned;
//! - a trip raises the alarm for it, unless it is the limit switch a homing approach looks for;
//! - when pulses may start from rest (servos ready, pen settled), when the step queue rests (the
//!   pulse engine stops after what it holds), and what the task waits for after each fill.

use crate::machine_io::inputs::Trip;
use crate::machine_io::pen::{self, Pen};
use crate::motion::interp::CurveError;
use crate::motion::job::{Job, JobKind};
use crate::motion::planner::PlannerState;
use crate::settings::Settings;
use crate::status::{MotionFault, RunState};

/// Why a fill of the step queue stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FillEnd {
    /// The queue holds as much as it may.
    QueueFull,
    /// This poll queued its share and the queue has room still: the task yields and goes on.
    PollDone,
    /// The planner has nothing more now.
    PlanEmpty,
    /// The curve failed part way.
    CurveFailed(CurveError),
}

/// What the supervisor needs to know of a job the motion task takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct JobOrder {
    pub kind: JobKind,
    /// Where the job needs the pen (`None`: wherever it is).
    pub pen: Option<Pen>,
    /// The pen goes up once the machine rests after the job (a keypad drawing).
    pub raise_after: bool,
}

impl JobOrder {
    pub fn of(job: &Job) -> JobOrder {
        JobOrder { kind: job.kind, pen: job.pen, raise_after: job.raise_after }
    }
}

/// What becomes of a job taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Take {
    /// The job needs the pen elsewhere and the motion before it has not come to rest: it waits,
    /// and is taken again once the motion rests.
    Hold,
    /// Plan the job, first sending the pen to `pen` (at rest) if it is `Some`.
    Plan { pen: Option<Pen> },
}

/// What to do once a fill of the step queue ended, before anything else.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Filled {
    /// The run state to publish.
    pub publish: Option<RunState>,
    /// Raise the alarm for this fault (motion is refused until `$X`), drop any job held back,
    /// and abort everything planned and queued.
    pub alarm: Option<MotionFault>,
}

/// What the task waits for after a fill.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Next {
    /// The poll queued its share and the queue has room: yield and go on.
    Yield,
    /// Enough motion is queued: wait until half of it has been emitted, or for a control.
    UntilEmitted,
    /// Everything planned is queued: wait until it has been emitted, then ask
    /// [`Supervisor::at_rest`].
    Rest,
    /// A hold stands: publish `Hold` and wait for a control, or a job while the planner has room.
    Held,
    /// The planner has nothing to emit while it still moves (braking for a hold or an abort):
    /// look again shortly.
    Retry,
}

/// What follows a fill, once its [`Filled`] was carried out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Then {
    /// Mark a rest after the steps queued: the pulse engine stops once it has emitted them.
    pub rest: bool,
    /// Report whether anything is planned or held back (`None`: as reported).
    pub plan_empty: Option<bool>,
    pub next: Next,
}

/// What to do once everything planned has been emitted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AtRest {
    /// A job was held back for this rest: take it now.
    TakeHeld,
    /// Send the pen to `pen` if `Some`, publish `publish`, and wait for work.
    Wait { pen: Option<Pen>, publish: RunState },
}

/// What a trip does once the pulses have stopped and everything planned was dropped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tripped {
    /// The limit switch a homing approach looks for: the homing cycle takes it from there.
    FoundSwitch,
    /// Raise the alarm for this fault; motion is refused until `$X`.
    Alarm(MotionFault),
}

/// What pulses starting from rest wait for, as the machine reports it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StartReady {
    /// A trip halted the machine: it starts nothing, so nothing is to be waited for.
    pub halted: bool,
    /// The servo drivers hold their axes (SON on for `$209`).
    pub servos_ready: bool,
    /// The pen is where it was last sent, and has had its settle time (`$212`).
    pub pen_settled: bool,
}

impl StartReady {
    /// True when pulses may start from rest: the servos hold their axes and the pen has settled
    /// (or the machine is halted).
    pub fn ready(self) -> bool {
        self.halted || (self.servos_ready && self.pen_settled)
    }
}

/// The decisions of the motion task, and what they remember: the kind of motion taken last and
/// whether the pen is to go up at the next rest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Supervisor {
    /// Reported while steps are queued: `Jog` while the last job taken was a jog (jogs start
    /// only at rest or behind other jogs), else `Run`.
    moving: RunState,
    /// The last job taken was a keypad drawing: the pen goes up at rest.
    raise_at_rest: bool,
}

impl Default for Supervisor {
    fn default() -> Self {
        Supervisor::new()
    }
}

impl Supervisor {
    pub const fn new() -> Supervisor {
        Supervisor { moving: RunState::Run, raise_at_rest: false }
    }

    /// `job` is taken, the pen being at `pen`; `at_rest` when nothing is planned and no pulse is
    /// queued or being emitted. The pen moves only at rest.
    pub fn take(&mut self, job: JobOrder, pen: Pen, at_rest: bool) -> Take {
        let pen = job.pen.filter(|&p| p != pen);
        if pen.is_some() && !at_rest {
            return Take::Hold;
        }
        self.moving = match job.kind {
            JobKind::Draw | JobKind::Home => RunState::Run,
            JobKind::Jog => RunState::Jog,
        };
        self.raise_at_rest = job.raise_after;
        Take::Plan { pen }
    }

    /// A fill ended at `end`; `queued` when it queued steps.
    pub fn filled(&self, end: FillEnd, queued: bool) -> Filled {
        let publish = queued.then_some(self.moving);
        match end {
            // A curve stopped part way (the travel guard at the edge, or a curve failing where
            // the builder's trace did not): a defect upstream, since the builder refuses both.
            // Stop there, drop what was planned after it (it was planned from a point the pen
            // never reached, and its lines were answered `ok`) and raise an alarm at once, as
            // GRBL does.
            FillEnd::CurveFailed(e) => Filled { publish, alarm: Some(MotionFault::Curve(e)) },
            _ => Filled { publish, alarm: None },
        }
    }

    /// What follows a fill that ended at `end`, once its [`Filled`] was carried out: the
    /// planner now in `planner` (`planner_idle`: nothing left in it), a job `held` back or not,
    /// the steps queued so far `resting` already or not.
    pub fn then(&self, end: FillEnd, planner: PlannerState, planner_idle: bool, held: bool, resting: bool) -> Then {
        let stands = matches!(planner, PlannerState::Idle | PlannerState::Held);
        let (plan_empty, next) = match end {
            FillEnd::PollDone => (None, Next::Yield),
            FillEnd::QueueFull => (None, Next::UntilEmitted),
            FillEnd::PlanEmpty | FillEnd::CurveFailed(_) => (
                Some(planner_idle && !held),
                match planner {
                    PlannerState::Idle => Next::Rest,
                    PlannerState::Held => Next::Held,
                    PlannerState::Running | PlannerState::Holding | PlannerState::Aborting => Next::Retry,
                },
            ),
        };
        // The motion comes to rest after the steps queued: at its end, or held.
        let rest = plan_empty.is_some() && stands && !resting;
        Then { rest, plan_empty, next }
    }

    /// Everything planned has been emitted: a job `held` back or not, `queued_jobs` waiting.
    pub fn at_rest(&mut self, held: bool, queued_jobs: usize, settings: &Settings) -> AtRest {
        if held {
            return AtRest::TakeHeld;
        }
        let raise = core::mem::take(&mut self.raise_at_rest) && queued_jobs == 0;
        AtRest::Wait { pen: raise.then(|| pen::at_program_end(settings)).flatten(), publish: RunState::Idle }
    }

    /// `trip` stopped the machine; `homing_switch` when it is the switch a homing approach
    /// looks for.
    pub fn tripped(&self, trip: Trip, homing_switch: bool) -> Tripped {
        if homing_switch { Tripped::FoundSwitch } else { Tripped::Alarm(MotionFault::Tripped(trip)) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Axis;

    const DRAW: JobOrder = JobOrder { kind: JobKind::Draw, pen: None, raise_after: false };
    const PEN_DOWN: JobOrder = JobOrder { pen: Some(Pen::Down), ..DRAW };
    const KEYPAD: JobOrder = JobOrder { pen: Some(Pen::Down), raise_after: true, ..DRAW };
    const JOG: JobOrder = JobOrder { kind: JobKind::Jog, ..DRAW };
    const HOME: JobOrder = JobOrder { kind: JobKind::Home, pen: Some(Pen::Up), ..DRAW };

    fn pen_lift() -> Settings {
        Settings { pen_lift: 1, ..Settings::default() }
    }

    /// The motion's state published once a fill queued steps.
    fn moving(s: &Supervisor) -> Option<RunState> {
        s.filled(FillEnd::QueueFull, true).publish
    }

    #[test]
    fn a_job_needing_the_pen_down_behind_a_moving_job_waits_for_the_rest_then_the_pen_goes_down() {
        let mut s = Supervisor::new();
        assert_eq!(s.take(DRAW, Pen::Up, true), Take::Plan { pen: None });
        assert_eq!(s.take(PEN_DOWN, Pen::Up, false), Take::Hold, "the motion before it still runs");
        // The drawing's last steps are queued: the plan is not empty while a job waits.
        let then = s.then(FillEnd::PlanEmpty, PlannerState::Idle, true, true, false);
        assert_eq!(then, Then { rest: true, plan_empty: Some(false), next: Next::Rest });
        assert_eq!(s.at_rest(true, 0, &pen_lift()), AtRest::TakeHeld);
        assert_eq!(s.take(PEN_DOWN, Pen::Up, true), Take::Plan { pen: Some(Pen::Down) });
    }

    #[test]
    fn a_job_wanting_the_pen_where_it_is_follows_without_a_stop() {
        let mut s = Supervisor::new();
        assert_eq!(s.take(PEN_DOWN, Pen::Down, false), Take::Plan { pen: None });
        assert_eq!(s.take(DRAW, Pen::Up, false), Take::Plan { pen: None }, "no pen order: wherever it is");
    }

    #[test]
    fn a_jog_reports_jog_and_a_drawing_or_homing_move_run() {
        let mut s = Supervisor::new();
        assert_eq!(moving(&s), Some(RunState::Run), "before any job");
        s.take(JOG, Pen::Up, true);
        assert_eq!(moving(&s), Some(RunState::Jog));
        s.take(HOME, Pen::Up, true);
        assert_eq!(moving(&s), Some(RunState::Run));
        s.take(DRAW, Pen::Up, true);
        assert_eq!(moving(&s), Some(RunState::Run));
        assert_eq!(s.filled(FillEnd::PlanEmpty, false).publish, None, "nothing queued: as it was");
    }

    #[test]
    fn a_keypad_drawing_raises_the_pen_at_rest_unless_a_job_is_queued_behind_it() {
        let mut s = Supervisor::new();
        assert_eq!(s.take(KEYPAD, Pen::Up, true), Take::Plan { pen: Some(Pen::Down) });
        let rest = s.at_rest(false, 0, &pen_lift());
        assert_eq!(rest, AtRest::Wait { pen: Some(Pen::Up), publish: RunState::Idle });
        let again = s.at_rest(false, 0, &pen_lift());
        assert_eq!(again, AtRest::Wait { pen: None, publish: RunState::Idle }, "once");

        s.take(KEYPAD, Pen::Up, true);
        let rest = s.at_rest(false, 1, &pen_lift());
        assert_eq!(rest, AtRest::Wait { pen: None, publish: RunState::Idle }, "a job behind it");

        s.take(KEYPAD, Pen::Up, true);
        s.take(DRAW, Pen::Down, false);
        let rest = s.at_rest(false, 0, &pen_lift());
        assert_eq!(rest, AtRest::Wait { pen: None, publish: RunState::Idle }, "a host job followed it");

        s.take(KEYPAD, Pen::Up, true);
        let rest = s.at_rest(false, 0, &Settings::default());
        assert_eq!(rest, AtRest::Wait { pen: None, publish: RunState::Idle }, "no pen lift");
    }

    #[test]
    fn a_curve_failing_part_way_raises_the_curve_alarm_and_aborts() {
        let mut s = Supervisor::new();
        s.take(DRAW, Pen::Up, true);
        let failed = FillEnd::CurveFailed(CurveError::Travel);
        let filled = s.filled(failed, true);
        let alarm = Some(MotionFault::Curve(CurveError::Travel));
        assert_eq!(filled, Filled { publish: Some(RunState::Run), alarm }, "the motion brakes under the alarm");
        // Braking after the abort: no rest yet, the task looks again.
        let then = s.then(failed, PlannerState::Aborting, false, false, false);
        assert_eq!(then, Then { rest: false, plan_empty: Some(false), next: Next::Retry });
        let stopped = s.then(failed, PlannerState::Idle, true, false, false);
        assert_eq!(stopped, Then { rest: true, plan_empty: Some(true), next: Next::Rest });
        assert_eq!(s.filled(FillEnd::PlanEmpty, true).alarm, None, "a curve that ends raises nothing");
    }

    #[test]
    fn a_trip_raises_its_alarm_unless_homing_looks_for_that_switch() {
        let s = Supervisor::new();
        let limit = Trip::Limit { axis: Axis::X, max: false };
        assert_eq!(s.tripped(limit, true), Tripped::FoundSwitch);
        assert_eq!(s.tripped(limit, false), Tripped::Alarm(MotionFault::Tripped(limit)));
        assert_eq!(s.tripped(Trip::EStop, false), Tripped::Alarm(MotionFault::Tripped(Trip::EStop)));
    }

    #[test]
    fn a_hold_reports_hold_once_the_motion_stands_and_the_queue_rests_there() {
        let s = Supervisor::new();
        let braking = s.then(FillEnd::PlanEmpty, PlannerState::Holding, false, false, false);
        assert_eq!(braking, Then { rest: false, plan_empty: Some(false), next: Next::Retry });
        let held = s.then(FillEnd::PlanEmpty, PlannerState::Held, false, false, false);
        assert_eq!(held, Then { rest: true, plan_empty: Some(false), next: Next::Held });
        let again = s.then(FillEnd::PlanEmpty, PlannerState::Held, false, false, true);
        assert!(!again.rest, "a rest is marked once");
    }

    #[test]
    fn pulses_start_from_rest_only_once_the_servos_hold_and_the_pen_has_settled() {
        let ready = StartReady { halted: false, servos_ready: true, pen_settled: true };
        assert!(ready.ready());
        assert!(!StartReady { servos_ready: false, ..ready }.ready(), "servos just switched on");
        assert!(!StartReady { pen_settled: false, ..ready }.ready(), "pen still moving");
        let halted = StartReady { halted: true, servos_ready: false, pen_settled: false };
        assert!(halted.ready(), "a halted machine starts nothing: no wait");
    }

    #[test]
    fn the_queue_rests_only_once_the_planner_has_nothing_more() {
        let s = Supervisor::new();
        for end in [FillEnd::QueueFull, FillEnd::PollDone] {
            let then = s.then(end, PlannerState::Idle, true, false, false);
            assert!(!then.rest && then.plan_empty.is_none(), "{end:?}: more may come");
        }
        assert_eq!(s.then(FillEnd::QueueFull, PlannerState::Running, false, false, false).next, Next::UntilEmitted);
        assert_eq!(s.then(FillEnd::PollDone, PlannerState::Running, false, false, false).next, Next::Yield);
        let running = s.then(FillEnd::PlanEmpty, PlannerState::Running, false, false, false);
        assert_eq!(running, Then { rest: false, plan_empty: Some(false), next: Next::Retry });
    }
}

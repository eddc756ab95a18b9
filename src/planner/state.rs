//! The planner's state: the [`Planner`] struct and the request it runs under. The look-ahead is
//! the scan's ([`Lookahead`]); the rest is the step generator's and the controls'. Its methods
//! live with the part they belong to: the queue and its controls in [`crate::planner`], the step
//! generator in `stepgen`.

use crate::interp::Interpolator;
use crate::planner::limits::Limits;
use crate::planner::lookahead::Lookahead;
use crate::planner::run::Run;
use crate::planner::scaling::Factors;

/// What the user last asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Request {
    Run,
    Hold,
    Abort,
}

/// The speed profile and look-ahead queue; see the [planner's documentation](crate::planner).
///
/// `C` is the interpolator type of the motion task (an enum over the curve kinds); `N` the
/// look-ahead depth in segments ([`PLANNER_SEGMENTS`](crate::planner::PLANNER_SEGMENTS)).
pub struct Planner<C: Interpolator, const N: usize> {
    pub(super) limits: Limits,
    /// The feed and rapid overrides in force.
    pub(super) factors: Factors,
    /// Limits to apply once the planner is idle.
    pub(super) pending_limits: Option<Limits>,
    /// The segments queued, the steps scanned from them and their blocks: the scan's.
    pub(super) ahead: Lookahead<C, N>,
    pub(super) request: Request,
    /// Speed of the last step while moving, mm/s; `None` at rest.
    pub(super) speed: Option<f32>,
    /// The run being emitted.
    pub(super) run: Run,
    /// Fraction of a tick carried to the next step, in units of 2⁻³² tick.
    pub(super) carry: u32,
    /// How far the scan has to catch up with the motion, and how fast it does.
    pub(super) pace: ScanPace,
}

/// How fast the scan keeps ahead of the motion (see `Planner::keep_scanning`).
#[derive(Clone, Copy, Debug)]
pub(super) struct ScanPace {
    /// Steps emitted since the scan last ran: it scans `rate` times that many, and a chunk more.
    pub emitted: usize,
    /// 2 while the scan's front may cap the motion, 1 once it cannot.
    pub rate: usize,
    /// Steps emitted since `rate` was last worked out.
    pub since_check: usize,
}

impl ScanPace {
    /// At rest: the look-ahead grows from nothing.
    pub const START: ScanPace = ScanPace { emitted: 0, rate: 2, since_check: 0 };
}

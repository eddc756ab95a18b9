//! Motion planner: turns the steps of queued curves into timed [`StepCmd`]s — start rate,
//! acceleration, tangential feed, per-axis limits, curvature, look-ahead across segments, hold
//! and abort.
//!
//! It owns the speed profile and nothing else: it reads no clock (time exists only as the
//! intervals it computes), never touches pins, never allocates, and never panics. The motion
//! task [`push`](Planner::push)es one interpolator per job (a segment) and the pulse task
//! receives what [`next_cmd`](Planner::next_cmd) returns.
//!
//! # Speed along the ideal curve
//!
//! Each step advances along the ideal curve by `δ = 1/(|tx| + |ty|)` step units for
//! [`Method::Classic`] (one axis per step) and `δ = 1/max(|tx|, |ty|)` for [`Method::Diagonal`]
//! (the major axis steps every time), with `t` the unit tangent in step space before the step.
//! In millimetres that is `δ_mm = δ·√((tx/spm_x)² + (ty/spm_y)²)`, and the step lasts
//! `δ_mm / v`. So the tangential speed is the feed in every direction for both methods.
//!
//! # Dry run and blocks
//!
//! A clone of each segment's interpolator runs ahead of the real one (the scan):
//! [`SCAN_STEPS_PER_PUSH`] steps on push, then [`SCAN_STEPS_PER_CMD`] per emitted step, so no
//! call does unbounded work while pulses are flowing and the scan outruns the motion. The scan
//! measures each step (its length and direction) and cuts the path into blocks of steps that
//! share one speed and acceleration cap (up to [`PLANNER_BLOCKS`] of them): a straight line is
//! one block; a curve gets a new block where its direction or curvature needs lower caps than
//! the block's (a block then takes caps [`BLOCK_MARGIN`] below its first step's, so a smooth
//! curve is cut every few percent of change) or allows much higher ones. Whatever is not
//! scanned yet is treated as a stop at the scan's front. The scan also finds a segment's exit
//! tangent and a curve error: the plan stops at the error point, and `next_cmd` returns
//! `Some(Err(e))` exactly when the real interpolator reaches it; the next segment starts from
//! rest. Interpolators must be deterministic: a clone yields the same steps and tangents.
//!
//! # Limits of a step
//!
//! * Speed: the feed (`Rapid`: unbounded), capped so that each axis' share `v·|u_axis|` (u =
//!   unit direction in mm) stays within its max rate — the axis' mean rate over the step
//!   pattern — and so that every step lasts at least one period of the max pulse rate: no
//!   interval between two pulses, of one axis or of both, is shorter than `1/max_pulse_rate`
//!   (intervals are also floored at that period in ticks). On a curve, the centripetal
//!   acceleration `v²·κ` stays within [`CENTRIPETAL_SHARE`] of the slower axis' acceleration,
//!   with the curvature `κ` measured over [`CURVATURE_BASELINE_STEPS`] steps; where the tangent
//!   jumps inside a curve (a kink), the junction rule below applies as between segments.
//! * Tangential acceleration: what each axis has left, `a·|u_axis| + v²κ·|n_axis| ≤ accel_axis`
//!   with `n` the normal; on a straight line `a = min over axes of accel_axis / |u_axis|`.
//!
//! # Profile
//!
//! Every step `k` has one speed `w_k` (its length over its interval). From rest the first step
//! runs at the start rate (or the cap, if lower); then `w_k² ≤ w_{k−1}² + 2·a·δ_k`, `w_k ≤ cap`,
//! and `w_k² ≤ v_exit² + 2·a·R_k` where `R_k` is the distance left in the block after step `k`
//! and `v_exit` the speed allowed at its end. Motion ends only where the plan ends with
//! `v_exit` = start rate, so the last step is never faster than the start rate. Intervals are
//! rounded to whole ticks and the remainder is carried to the next step, so long runs have no
//! rounding drift. After rest, the first interval is one step's time at the start rate (the pulse
//! task may fire it at once when it has idled longer than that).
//!
//! # Junctions (look-ahead)
//!
//! Queued segments join without stopping where the turn allows. With `u_exit` the unit
//! direction (mm) after the last step of a segment and `u_entry` the one before the first step of
//! the next, `θ = π − φ` where `φ` is the turn between them (θ = π straight on, 0 for a
//! reversal), GRBL's junction deviation rule gives
//! `v_junction = √(a · junction_deviation · sin(θ/2) / (1 − sin(θ/2)))` with `a` the smaller of
//! the two segments' accelerations; straight on it is unbounded, for a reversal zero. The
//! junction speed is then limited to the next segment's cap and raised to at least the start
//! rate (a servo takes a jump up to its start rate, as when it starts). A backward pass over the
//! blocks, from a stop at the end of the last one (and at every curve error and at the scan's
//! front), gives each block `v_exit = min(junction, cap_next, √(v_exit,next² + 2·a_next·L_next))`;
//! the forward pass is done step by step by the acceleration rule above.
//!
//! # Hold and abort
//!
//! A hold decelerates at the block's acceleration on the path, down to the start rate, and
//! stops there; `next_cmd` then returns `None` until [`resume`](Planner::resume), which continues
//! the same path from the start rate. An abort stops the same way, then drops the rest of the
//! current segment and every queued one. Every emitted step is a step of the path, so the
//! position (the sum of emitted steps) stays exact.

mod limits;
mod ring;
mod scan;
#[cfg(test)]
mod tests;

pub use limits::{
    CENTRIPETAL_SHARE, CURVATURE_BASELINE_STEPS, Limits, LimitsError, MIN_FEED_MM_PER_MIN, plot_time_lower_bound,
};

use crate::geom::{Step, StepCmd, TICK_HZ};
use crate::interp::{CurveError, Interpolator, Method};
use crate::job::Feed;
use limits::{BendTracker, Caps, MIN_SPEED_MM_PER_S, UnitDir};
use ring::Ring;
use scan::{Block, Track, to_nm};

/// Look-ahead depth of the motion task's planner, in segments. At the default limits 16
/// segments of a 2,000-segment polyline circle of 100 mm diameter (0.16 mm each) are enough
/// braking distance to cruise at about 3,000 mm/min.
pub const PLANNER_SEGMENTS: usize = 16;

/// Blocks of steps with one cap each (see the module documentation), for all queued segments.
/// A line takes one; a curve one per few percent of change of its caps. When they run out the
/// scan waits, and the motion brakes for the scan's front.
pub const PLANNER_BLOCKS: usize = 64;

/// Steps of the queue scanned by [`Planner::push`]: a short line is planned in full at once.
pub const SCAN_STEPS_PER_PUSH: u32 = 32;

/// Steps scanned per emitted step. More than one, so the scan outruns the motion; small, so a
/// `next_cmd` call costs a few interpolator steps at most.
pub const SCAN_STEPS_PER_CMD: u32 = 4;

/// Caps of a curve's later blocks sit this far (relative) below those of their first step.
pub const BLOCK_MARGIN: f32 = 0.02;

/// The planner holds as many segments as it can ([`Planner::is_full`]); try again after the next
/// [`Planner::next_cmd`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct PlannerFull;

/// What the planner is doing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum PlannerState {
    /// Nothing queued, at rest.
    Idle,
    /// Moving, or about to move on the next `next_cmd`.
    Running,
    /// Decelerating for a hold.
    Holding,
    /// Stopped by a hold (also when a hold came while idle); `resume` continues.
    Held,
    /// Decelerating for an abort; afterwards idle with nothing queued.
    Aborting,
}

/// What the user last asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Request {
    Run,
    Hold,
    Abort,
}

/// The speed profile and look-ahead queue; see the module documentation.
///
/// `C` is the interpolator type of the motion task (an enum over the curve kinds); `N` the
/// look-ahead depth in segments ([`PLANNER_SEGMENTS`]).
pub struct Planner<C: Interpolator + Clone, const N: usize> {
    limits: Limits,
    /// Limits to apply once the planner is idle.
    pending: Option<Limits>,
    tracks: Ring<Track<C>, N>,
    blocks: Ring<Block, PLANNER_BLOCKS>,
    /// Recent directions of the segment being scanned (one at a time, in order).
    bend: BendTracker,
    request: Request,
    /// Speed of the last emitted step while moving, mm/s; `None` at rest.
    speed: Option<f32>,
    /// Fraction of a tick owed to the next interval.
    carry_ticks: f32,
}

impl<C: Interpolator + Clone, const N: usize> Planner<C, N> {
    /// An idle planner.
    pub fn new(limits: Limits) -> Self {
        Planner {
            limits,
            pending: None,
            tracks: Ring::new(),
            blocks: Ring::new(),
            bend: BendTracker::new(),
            request: Request::Run,
            speed: None,
            carry_ticks: 0.0,
        }
    }

    /// The limits in force.
    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// Replaces the limits. They take effect at once when the planner is idle, otherwise as soon
    /// as it becomes idle: queued segments, and those pushed until then, keep the limits they were
    /// planned with (steps/mm changing under a moving plan would make no sense).
    pub fn set_limits(&mut self, limits: Limits) {
        self.pending = Some(limits);
        self.apply_pending_if_idle();
    }

    /// True when [`push`](Self::push) would refuse: the queue is full, or an abort is braking.
    pub fn is_full(&self) -> bool {
        self.tracks.is_full() || self.request == Request::Abort
    }

    /// True when nothing is left to emit and the machine is at rest.
    pub fn is_idle(&self) -> bool {
        self.tracks.is_empty() && self.speed.is_none()
    }

    /// What the planner is doing.
    pub fn state(&self) -> PlannerState {
        match self.request {
            Request::Abort => PlannerState::Aborting,
            Request::Hold if self.speed.is_some() => PlannerState::Holding,
            Request::Hold => PlannerState::Held,
            Request::Run if self.is_idle() => PlannerState::Idle,
            Request::Run => PlannerState::Running,
        }
    }

    /// Queues a curve to be drawn at `feed` with `method`, which must be the interpolator's own
    /// method (it decides the distance per step). A curve without a single step is accepted and
    /// dropped. Feeds: see [`Limits::requested_speed_mm_per_s`].
    pub fn push(&mut self, curve: C, feed: Feed, method: Method) -> Result<(), PlannerFull> {
        self.apply_pending_if_idle();
        if self.is_full() {
            return Err(PlannerFull);
        }
        let track = Track {
            scout: curve.clone(),
            curve,
            method,
            requested_mm_per_s: self.limits.requested_speed_mm_per_s(feed),
            scanning: true,
            scout_dir_mm: None,
            last_scanned: Step::NONE,
            blocks: 0,
        };
        if self.tracks.push_back(track).is_err() {
            return Err(PlannerFull);
        }
        self.scan(SCAN_STEPS_PER_PUSH);
        self.drop_finished_fronts();
        Ok(())
    }

    /// The next step command: `None` when there is nothing to emit now (queue empty, or stopped
    /// by a hold), `Some(Err(e))` where a curve fails (the machine is then at rest; the next call
    /// goes on with the next segment).
    pub fn next_cmd(&mut self) -> Option<Result<StepCmd, CurveError>> {
        self.apply_pending_if_idle();
        if self.request == Request::Hold && self.speed.is_none() {
            return None;
        }
        self.scan(SCAN_STEPS_PER_CMD);
        // Every pass returns, drops a finished block or segment, or scans one step where the
        // motion has caught up with the scan; the bound only guards against the unforeseen.
        for _ in 0..(N + PLANNER_BLOCKS + 8) {
            self.drop_finished_fronts();
            let Some(track) = self.tracks.front() else {
                self.rest();
                return None;
            };
            let front_block = if track.blocks > 0 { self.blocks.front().copied() } else { None };
            let Some(block) = front_block else {
                // The segment has no scanned step left: scan on (at rest or at the start rate).
                self.scan_front();
                continue;
            };
            if let Some(e) = block.error {
                self.drop_front_track();
                self.rest();
                return Some(Err(e));
            }
            if block.done_steps >= block.steps {
                self.scan_front();
                continue;
            }
            let start = self.limits.start_speed_mm_per_s.min(block.caps.speed_mm_per_s);
            if self.request != Request::Run && self.speed.is_none_or(|w| w <= start) {
                self.rest();
                return None;
            }
            if let Some(cmd) = self.emit(start) {
                return Some(cmd);
            }
        }
        None
    }

    /// Decelerates to a stop on the path; `next_cmd` returns `None` once stopped. While idle it
    /// keeps pushed segments from starting until [`resume`](Self::resume).
    pub fn hold(&mut self) {
        if self.request == Request::Run {
            self.request = Request::Hold;
        }
    }

    /// Ends a hold: continues the same path, from the start rate if it had stopped.
    pub fn resume(&mut self) {
        if self.request == Request::Hold {
            self.request = Request::Run;
        }
    }

    /// Decelerates to a stop on the path, then drops the rest of the current segment and every
    /// queued one. At rest this happens at once.
    pub fn abort(&mut self) {
        self.request = Request::Abort;
        if self.speed.is_none() {
            self.rest();
        }
    }

    /// Takes the front segment's next step and times it; `start` is the front block's speed from
    /// rest. `None`: no step after all (the caller goes on).
    fn emit(&mut self, start: f32) -> Option<Result<StepCmd, CurveError>> {
        let limits = self.limits;
        let (prev, braking) = (self.speed, self.request != Request::Run);
        let track = self.tracks.front_mut()?;
        let tangent = track.curve.tangent();
        let step = match track.curve.next_step() {
            Ok(Some(step)) => step,
            other => {
                // Only an interpolator that differs from its clone gets here.
                self.drop_front_track();
                self.rest();
                return other.err().map(Err);
            }
        };
        let g = limits.step_geometry(track.method, UnitDir::from_tangent(tangent, step.x, step.y));
        let step_nm = to_nm(g.step_mm);
        let block = self.blocks.front_mut()?;
        let Caps { speed_mm_per_s: cap, accel_mm_per_s2: a } = block.caps;
        let mut w = match prev {
            None => start,
            Some(p) => libm::sqrtf(p * p + 2.0 * a * g.step_mm),
        }
        .min(cap)
        .min(block.brake_limit(block.done_nm.saturating_add(step_nm)));
        if let (true, Some(p)) = (braking, prev) {
            w = w.min(libm::sqrtf((p * p - 2.0 * a * g.step_mm).max(0.0)).max(start));
        }
        // `max` also replaces a NaN, which valid limits never produce.
        w = w.max(MIN_SPEED_MM_PER_S);
        block.done_nm = block.done_nm.saturating_add(step_nm);
        block.done_steps += 1;
        let block_done = block.done_steps >= block.steps && !block.open;

        // Rounded to the nearest tick; the remainder (at most half a tick) goes to the next step.
        let exact = g.step_mm / w * TICK_HZ as f32 + self.carry_ticks;
        let interval_ticks = (libm::roundf(exact) as u32).max(limits.min_interval_ticks);
        self.carry_ticks = (exact - interval_ticks as f32).clamp(-1.0, 1.0);
        self.speed = Some(w);
        if block_done {
            self.pop_front_block();
        }
        self.drop_finished_fronts();
        if self.tracks.is_empty() || (braking && w <= start) {
            self.rest();
        }
        Some(Ok(StepCmd { step, interval_ticks }))
    }

    /// The machine is at rest: finishes an abort, applies pending limits.
    fn rest(&mut self) {
        self.speed = None;
        self.carry_ticks = 0.0;
        if self.request == Request::Abort {
            self.tracks.clear();
            self.blocks.clear();
            self.request = Request::Run;
        }
        self.apply_pending_if_idle();
    }

    fn apply_pending_if_idle(&mut self) {
        if self.is_idle()
            && let Some(limits) = self.pending.take()
        {
            self.limits = limits;
        }
    }

    /// Drops front segments that have nothing left to scan or to emit.
    fn drop_finished_fronts(&mut self) {
        while let Some(track) = self.tracks.front() {
            if track.blocks > 0 || track.scanning {
                return;
            }
            self.tracks.pop_front();
        }
    }

    fn pop_front_block(&mut self) {
        if self.blocks.pop_front().is_some()
            && let Some(track) = self.tracks.front_mut()
        {
            track.blocks = track.blocks.saturating_sub(1);
        }
    }

    /// Drops the front segment and its blocks.
    fn drop_front_track(&mut self) {
        if let Some(track) = self.tracks.pop_front() {
            for _ in 0..track.blocks {
                self.blocks.pop_front();
            }
        }
    }
}

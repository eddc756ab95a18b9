//! Motion planner: turns the steps of queued curves into timed
//! [`StepCmd`]s — start rate, acceleration, tangential feed, per-axis
//! limits, curvature, look-ahead across segments, hold and abort.
//!
//! It owns the speed profile and nothing else: it reads no clock (time exists only as the
//! intervals it computes), never touches pins, never allocates, and never panics. The motion
//! task [`push`](Planner::push)es one interpolator per job (a segment) and hands what
//! [`next_cmd`](Planner::next_cmd) returns to the pulse engine.
//!
//! The work is split as in GRBL (`planner.c` / `stepper.c`): the look-ahead ([`lookahead`],
//! filled and planned by its scan) decides speed caps and exit speeds per *block* of steps, with
//! floating point once per chunk of steps; the step generator ([`stepgen`]) takes them from the
//! look-ahead's front through a narrow interface, as GRBL's stepper takes its blocks, and runs
//! the steps out a *run* at a time, cruising steps with an integer addition each, ramps with the
//! acceleration rule worked out once per run.
//!
//! # Speed along the ideal curve
//!
//! Each step advances along the ideal curve by `δ = 1/(|tx| + |ty|)` step units for
//! [`Method::Classic`] (one axis per step) and `δ = 1/max(|tx|, |ty|)` for [`Method::Diagonal`]
//! (the major axis steps every time), with `t` the unit tangent in step space. In millimetres
//! that is `δ_mm = δ·√((tx/spm_x)² + (ty/spm_y)²)`, and a step lasts `δ_mm / v`. So the
//! tangential speed is the feed in every direction for both methods.
//!
//! # Scan: steps, chunks and blocks
//!
//! Every pushed curve is stepped exactly once, ahead of the motion, into a ring of steps
//! ([`STEP_RING_LEN`]: the look-ahead horizon). The scan takes steps in chunks of
//! [`CHUNK_STEPS`] ([`STRAIGHT_CHUNK_STEPS`] on a straight line) and reads the curve's tangent
//! only at chunk ends (a chunk over which it does not change at all, a straight run, just
//! extends the one before): from the tangents before and after a chunk it works out,
//! once, the distance its steps advance along the ideal curve (`δ_mm`, the same for all its
//! steps), their direction, the curve's bend over the chunk, and the speed and acceleration caps
//! of those steps (below). Chunks with the same caps form a *block*: a straight line is one
//! block; a curve gets a new block where its caps fall below the block's (a block then takes
//! caps [`BLOCK_MARGIN`] below its first chunk's, so a smooth curve is cut every few percent of
//! change) or allow much more. Whatever is not scanned yet is treated as a stop at the scan's
//! front, but for the rest of a straight line: its length is known
//! ([`Interpolator::straight_steps_left`]), so its block brakes for the line's end and a long
//! line reaches its speed whatever the horizon. The step generator keeps the scan ahead as it
//! emits, a few hundred steps at a time ([`SCAN_STEPS_PER_CALL`]): twice as fast as it emits
//! while the scan's front is nearer than braking from the highest cap scanned needs
//! ([`LEAD_SHARE`]), as fast once it is not, so a curve's evaluations double only while the
//! look-ahead grows. The scan also finds a segment's exit direction
//! and a curve error: the plan stops at the error point, and `next_cmd` returns `Some(Err(e))`
//! exactly when the motion reaches it; the next segment starts from rest.
//!
//! A kink (the tangent jumps by more than [`KINK_CHORD`](crate::motion::interp::KINK_CHORD) within one
//! step) ends a fill ([`Interpolator::fill`]); the step after it is a chunk and a block of its
//! own, capped by the junction rule below, so a kink is passed exactly where it is.
//!
//! # Limits of a step
//!
//! * Speed: the feed (`Rapid`: unbounded), capped so that each axis' share `v·|u_axis|` (u =
//!   unit direction in mm) stays within its max rate — the axis' mean rate over the step
//!   pattern — and so that every step lasts at least one period of the max pulse rate: no
//!   interval between two pulses, of one axis or of both, is shorter than `1/max_pulse_rate`
//!   (intervals are also floored at that period in ticks). On a curve, the centripetal
//!   acceleration `v²·κ` stays within [`CENTRIPETAL_SHARE`] of the slower axis' acceleration,
//!   with `κ` the turn over a chunk divided by its length; at a kink, the junction rule applies
//!   as between segments.
//! * Tangential acceleration: what each axis has left, `a·|u_axis| + v²κ·|n_axis| ≤ accel_axis`
//!   with `n` the normal; on a straight line `a = min over axes of accel_axis / |u_axis|`.
//!
//! # Profile: runs
//!
//! Every step `k` has one speed `w_k` (its `δ_mm` over its interval). From rest the first step
//! runs at the start rate (or the cap, if lower); then `w_k² ≤ w_{k−1}² + 2·a·δ`, `w_k ≤ cap`,
//! and `w_k² ≤ v_exit² + 2·a·R_k` where `R_k` is the distance left in the block after step `k`
//! and `v_exit` the speed allowed at its end. The step generator runs the steps of one chunk of
//! one block at a time. While the speed is below the cap, or braking, a *ramp* run applies this
//! rule to every step, its figures (`2·a·δ`, the cap, the exit) worked out once for the run. At
//! the cap a *cruise* run takes every step at the cap, as far as the way is clear of braking:
//! each step's interval is the same number of whole ticks and a 32-bit fraction carried over,
//! so long runs have no rounding drift. Above the cap (an override lowered it under the moving
//! pen) a ramp brakes down to it, `w_k² ≥ w_{k−1}² − 2·a·δ`, as a hold does to the start rate.
//! Motion ends only where the plan ends with `v_exit` =
//! start rate, so the last step is never faster than the start rate. After rest the first
//! interval is one step's time at the start rate (the pulse task may fire it at once when it
//! has idled longer than that).
//!
//! # Junctions (look-ahead)
//!
//! Queued segments join without stopping where the turn allows. With `u_exit` the unit
//! direction (mm) at the end of a segment and `u_entry` the one at the start of the next,
//! `θ = π − φ` where `φ` is the turn between them (θ = π straight on, 0 for a reversal), GRBL's
//! junction deviation rule gives `v_junction = √(a · junction_deviation · sin(θ/2) / (1 −
//! sin(θ/2)))` with `a` the smaller of the two segments' accelerations; straight on it is
//! unbounded, for a reversal zero. The junction speed is then limited to the next segment's cap
//! and raised to at least the start rate (a servo takes a jump up to its start rate, as when it
//! starts). A backward pass over the blocks, from a stop at the end of the last one (and at
//! every curve error and at the scan's front), gives each block `v_exit = min(junction,
//! cap_next, √(v_exit,next² + 2·a_next·L_next))`; the runs are the forward pass.
//!
//! # Overrides
//!
//! GRBL's feed and rapid overrides ([`Planner::set_overrides`]) act on the motion already
//! queued: each block keeps what the machine allows it apart from the feed asked for and which
//! override scales it (see `scaling`), so a change gives every queued block its new cap, never
//! beyond the machine's, and the backward pass runs again (see `overriding` for how the speed
//! then changes within the acceleration limits). Jogs ([`Planner::push_jog`]) take none.
//!
//! # Hold and abort
//!
//! A hold decelerates at the block's acceleration on the path, down to the start rate, and
//! stops there; `next_cmd` then returns `None` until [`resume`](Planner::resume), which continues
//! the same path from the start rate. An abort stops the same way, then drops the rest of the
//! current segment and every queued one. Every emitted step is a step of the path, so the
//! position (the sum of emitted steps) stays exact.

mod block;
mod limits;
mod lookahead;
mod ring;
mod scaling;
mod segment;
mod sizes;
mod stepgen;
#[cfg(test)]
mod tests;

pub use limits::{CENTRIPETAL_SHARE, Limits, LimitsError, MIN_FEED_MM_PER_MIN, plot_time_lower_bound};
pub use lookahead::BLOCK_MARGIN;
pub use sizes::{
    CHUNK_RING_LEN, CHUNK_STEPS, LEAD_SHARE, PLANNER_BLOCKS, PLANNER_SEGMENTS, SCAN_EVERY_STEPS, SCAN_STEPS_PER_CALL,
    SCAN_STEPS_PER_PUSH, STEP_RING_LEN, STRAIGHT_CHUNK_STEPS,
};
pub use stepgen::Emitted;

use crate::geom::StepCmd;
use crate::motion::interp::{CurveError, Interpolator, Method};
use crate::motion::job::Feed;
use crate::motion::overrides::Overrides;
use lookahead::Lookahead;
use scaling::{Factors, Scale};
use segment::Segment;
use stepgen::{Request, StepGen};

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

/// The speed profile and look-ahead queue; see the [planner's documentation](crate::motion::planner).
///
/// `C` is the interpolator type of the motion task (an enum over the curve kinds); `N` the
/// look-ahead depth in segments ([`PLANNER_SEGMENTS`]). It is two parts handing over through
/// narrow interfaces, as GRBL's planner and stepper: the look-ahead, which the scan fills and
/// plans, and the step generator, which takes its front.
pub struct Planner<C: Interpolator, const N: usize> {
    limits: Limits,
    /// The feed and rapid overrides in force.
    factors: Factors,
    /// Limits to apply once the planner is idle.
    pending_limits: Option<Limits>,
    /// The segments queued, the steps scanned from them and their blocks: the scan's.
    ahead: Lookahead<C, N>,
    /// The motion: the step generator's.
    steps: StepGen,
}

impl<C: Interpolator, const N: usize> Planner<C, N> {
    /// An idle planner, built in `slot` where it lies: it is 50 KB, too much to build on a
    /// small stack and move (see [`new`](Self::new)). The board builds its planner so, in
    /// static storage.
    pub fn init(slot: &mut core::mem::MaybeUninit<Self>, limits: Limits) -> &mut Self {
        use core::ptr::addr_of_mut;
        let p = slot.as_mut_ptr();
        // SAFETY: every field of `*p` is written once below, in place (the rings a slot at a
        // time), before the slot is taken as initialised; `every_field` lists them all, so that
        // a new field cannot be left out unnoticed.
        unsafe {
            addr_of_mut!((*p).limits).write(limits);
            addr_of_mut!((*p).factors).write(Factors::NONE);
            addr_of_mut!((*p).pending_limits).write(None);
            Lookahead::init_in_place(addr_of_mut!((*p).ahead));
            addr_of_mut!((*p).steps).write(StepGen::START);
            slot.assume_init_mut()
        }
    }

    /// Every field of the planner: this pattern stops compiling when one is added, a reminder
    /// that [`init`](Self::init) must write it too.
    #[allow(dead_code)]
    fn every_field(self) {
        let Planner { limits: _, factors: _, pending_limits: _, ahead: _, steps: _ } = self;
    }

    /// An idle planner, built as a value (on the host, or in a test).
    pub fn new(limits: Limits) -> Self {
        Planner { limits, factors: Factors::NONE, pending_limits: None, ahead: Lookahead::new(), steps: StepGen::START }
    }

    /// The limits in force.
    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// Replaces the limits. They take effect at once when the planner is idle, otherwise as soon
    /// as it becomes idle: queued segments, and those pushed until then, keep the limits they were
    /// planned with (steps/mm changing under a moving plan would make no sense).
    pub fn set_limits(&mut self, limits: Limits) {
        self.pending_limits = Some(limits);
        self.apply_pending_if_idle();
    }

    /// True when [`push`](Self::push) would refuse: the planner holds `N` segments, or an abort
    /// is braking.
    pub fn is_full(&self) -> bool {
        self.ahead.held() >= N || self.steps.request() == Request::Abort
    }

    /// Segments [`push`](Self::push) would still take.
    pub fn free_segments(&self) -> usize {
        if self.steps.request() == Request::Abort { 0 } else { N.saturating_sub(self.ahead.held()) }
    }

    /// True when nothing is left to emit and the machine is at rest.
    pub fn is_idle(&self) -> bool {
        self.ahead.held() == 0 && self.steps.speed().is_none()
    }

    /// What the planner is doing.
    pub fn state(&self) -> PlannerState {
        match self.steps.request() {
            Request::Abort => PlannerState::Aborting,
            Request::Hold if self.steps.speed().is_some() => PlannerState::Holding,
            Request::Hold => PlannerState::Held,
            Request::Run if self.is_idle() => PlannerState::Idle,
            Request::Run => PlannerState::Running,
        }
    }

    /// Queues a curve to be drawn at `feed` with `method`, which must be the interpolator's own
    /// method (it decides the distance per step). A curve without a single step is accepted and
    /// dropped. Feeds: see [`Limits::requested_speed_mm_per_s`]; the feed override scales a feed,
    /// the rapid override a rapid (see [`Self::set_overrides`]).
    pub fn push(&mut self, curve: C, feed: Feed, method: Method) -> Result<(), PlannerFull> {
        let scale = match feed {
            Feed::Rapid => Scale::Rapid,
            Feed::MmPerMin(_) => Scale::Feed,
        };
        self.push_scaled(curve, feed, method, scale)
    }

    /// Queues a jog, as [`Self::push`] does a drawing, at its own feed whatever the overrides.
    pub fn push_jog(&mut self, curve: C, feed: Feed, method: Method) -> Result<(), PlannerFull> {
        self.push_scaled(curve, feed, method, Scale::Fixed)
    }

    fn push_scaled(&mut self, curve: C, feed: Feed, method: Method, scale: Scale) -> Result<(), PlannerFull> {
        self.apply_pending_if_idle();
        if self.is_full() {
            return Err(PlannerFull);
        }
        let requested_mm_per_s = self.limits.requested_speed_mm_per_s(feed);
        let segment = Segment { curve, method, requested_mm_per_s, scale };
        if self.ahead.push(segment).is_err() {
            return Err(PlannerFull);
        }
        self.ahead.scan(&self.limits, self.factors, SCAN_STEPS_PER_PUSH);
        Ok(())
    }

    /// Decelerates to a stop on the path; `next_cmd` returns `None` once stopped. While idle it
    /// keeps pushed segments from starting until [`resume`](Self::resume).
    pub fn hold(&mut self) {
        self.steps.hold();
    }

    /// Ends a hold: continues the same path, from the start rate if it had stopped.
    pub fn resume(&mut self) {
        self.steps.resume();
    }

    /// Decelerates to a stop on the path, then drops the rest of the current segment and every
    /// queued one. At rest this happens at once.
    pub fn abort(&mut self) {
        self.steps.abort(&mut self.ahead);
        self.apply_pending_if_idle();
    }

    /// Drops everything at once, without braking: the pulses were cut by a trip, and the machine
    /// stands where they stopped.
    pub fn drop_all(&mut self) {
        self.steps.drop_all(&mut self.ahead);
        self.apply_pending_if_idle();
    }

    /// Applies the feed and rapid overrides (GRBL's, percent) to the queued segments and to
    /// those pushed from now on; see [`crate::motion::overrides`] and the look-ahead's `overriding`. The
    /// next run of steps the step generator starts runs at the new speeds; the steps it
    /// returned already keep theirs.
    pub fn set_overrides(&mut self, overrides: Overrides) {
        let factors = Factors::from_overrides(overrides);
        if factors == self.factors {
            return;
        }
        self.factors = factors;
        // Book the steps emitted so far, so that the front block's progress is the motion's.
        self.steps.book_emitted(&mut self.ahead, &self.limits);
        self.ahead.apply_factors(&self.limits, factors, self.steps.speed());
    }

    /// The next step command: `None` when there is nothing to emit now (queue empty, or stopped
    /// by a hold), `Some(Err(e))` where a curve fails (the machine is then at rest; the next call
    /// goes on with the next segment).
    pub fn next_cmd(&mut self) -> Option<Result<StepCmd, CurveError>> {
        let mut cmd = [StepCmd::NONE];
        let emitted = self.fill(&mut cmd, u32::MAX);
        match emitted.end {
            _ if emitted.steps == 1 => Some(Ok(cmd[0])),
            Some(Err(e)) => Some(Err(e)),
            _ => None,
        }
    }

    /// Writes the next step commands into `out`, until it is full, their intervals add up to
    /// `ticks_room` or more, or there is nothing more to emit now: the motion task fills the
    /// step queue this way, one run at a time in a tight loop. Out of line: the motion task and
    /// a program's check share it (its loop is the cost, not the call, once per batch).
    #[inline(never)]
    pub fn fill(&mut self, out: &mut [StepCmd], ticks_room: u32) -> Emitted {
        let emitted = self.steps.fill(&mut self.ahead, &self.limits, self.factors, out, ticks_room);
        self.apply_pending_if_idle();
        emitted
    }

    fn apply_pending_if_idle(&mut self) {
        if self.is_idle()
            && let Some(limits) = self.pending_limits.take()
        {
            self.limits = limits;
        }
    }
}

//! The step generator: runs the scanned steps out as timed [`StepCmd`]s, a *run* of steps at a
//! time within one chunk of one block. A cruise run keeps one speed and times each step by an
//! integer addition; a ramp run (accelerating or braking) applies the acceleration rule step by
//! step, its block's and chunk's figures worked out once for the run, so each of its steps
//! costs one square root and one division on the FPU.
//!
//! It owns the motion's side of the planner ([`StepGen`]): the request it runs under (run,
//! hold, abort), the speed reached, the run being emitted and the scan's pace. It takes the
//! look-ahead's front only through the look-ahead's narrow interface (`front_block`,
//! `front_chunk`, `front_steps`, `drop_steps`, `book`, `finish_block`), as GRBL's stepper takes
//! its planner's blocks.

use crate::geom::{Point, StepCmd, TICK_HZ};
use crate::math;
use crate::motion::interp::{CurveError, Interpolator};
use crate::motion::planner::block::{Ahead, Chunk, NM_PER_MM};
use crate::motion::planner::limits::{Limits, MIN_SPEED_MM_PER_S};
use crate::motion::planner::lookahead::Lookahead;
use crate::motion::planner::scaling::Factors;
use crate::motion::planner::sizes::{CHUNK_STEPS, LEAD_SHARE, PLANNER_BLOCKS, SCAN_EVERY_STEPS, SCAN_STEPS_PER_CALL};

/// 2³², the scale of a step's fraction of a tick.
const TICK_FRACTION_SCALE: f32 = 4_294_967_296.0;

/// Most steps in a ramp run. Its figures are those of its block when it starts; the scan, and a
/// block still growing at the scan's front, move on only between runs.
const RAMP_RUN_MAX_STEPS: u32 = 32;

/// A speed up to this factor above its block's cap counts as at the cap (float noise); beyond
/// it, the motion is above the cap because an override lowered it, and brakes down to it.
const OVER_CAP: f32 = 1.0 + 1.0e-4;

/// Half a tick in units of 2⁻³² tick: the carry from rest, so that the ticks of a run are its
/// exact times rounded to the nearest tick.
const HALF_TICK: u32 = 1 << 31;

/// What [`Planner::fill`](crate::motion::planner::Planner::fill) wrote, and why it stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emitted {
    /// Step commands written, from the start of the buffer.
    pub steps: usize,
    /// The sum of their intervals, ticks.
    pub ticks: u32,
    /// Where they take the pen, relative to where it was before them.
    pub moved: Point,
    /// How far each of them advances along the ideal curve, mm (over its interval, the pen's
    /// speed along its path): `step_mm` from the step `step_mm_from` on, `step_mm_before` before
    /// it (the steps of the run before, where the batch spans two). 0 when none was written.
    pub step_mm: f32,
    pub step_mm_from: usize,
    pub step_mm_before: f32,
    /// `None`: the buffer is full or the ticks asked for are written. `Some(Ok(()))`: nothing
    /// more to emit now (the queue is empty, or a hold has stopped the motion).
    /// `Some(Err(e))`: a curve fails after these steps (the machine is then at rest; the next
    /// call goes on with the next segment).
    pub end: Option<Result<(), CurveError>>,
}

/// What the user last asked for: the step generator runs the motion under it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Request {
    Run,
    Hold,
    Abort,
}

/// The step generator's state: the request the motion runs under, its speed, the run being
/// emitted and how far the scan has to catch up. It takes the look-ahead's front through the
/// look-ahead's narrow interface, as GRBL's stepper takes its planner's blocks.
pub(super) struct StepGen {
    request: Request,
    /// Speed of the last step while moving, mm/s; `None` at rest.
    speed: Option<f32>,
    /// The run being emitted.
    run: Run,
    /// Fraction of a tick carried to the next step, in units of 2⁻³² tick.
    carry: u32,
    /// How far the scan has to catch up with the motion, and how fast it does.
    pace: ScanPace,
}

/// How fast the scan keeps ahead of the motion (see `StepGen::keep_scanning`).
#[derive(Clone, Copy, Debug)]
struct ScanPace {
    /// Steps emitted since the scan last ran: it scans `rate` times that many, and a chunk more.
    emitted: usize,
    /// 2 while the scan's front may cap the motion, 1 once it cannot.
    rate: usize,
    /// Steps emitted since `rate` was last worked out.
    since_check: usize,
}

impl ScanPace {
    /// At rest: the look-ahead grows from nothing.
    const START: ScanPace = ScanPace { emitted: 0, rate: 2, since_check: 0 };
}

/// Steps of one chunk of one block, timed one way.
#[derive(Clone, Copy, Debug)]
struct Run {
    /// Steps in the run, and how many of them are still to emit.
    steps: u32,
    left: u32,
    pace: Pace,
    /// How far each of its steps advances along the ideal curve, mm (its chunk's `δ_mm`).
    step_mm: f32,
}

#[derive(Clone, Copy, Debug)]
enum Pace {
    /// Every step takes `ticks` and `frac` / 2³² ticks, the fractions carried over.
    Cruise { ticks: u32, frac: u32 },
    /// Each step at the speed the acceleration rule allows.
    Ramp(Ramp),
}

/// The figures of the acceleration rule for the steps of one chunk of one block.
#[derive(Clone, Copy, Debug)]
struct Ramp {
    /// A step at speed `w` takes `ticks_mm / w` ticks (its length in mm times the tick rate).
    ticks_mm: f32,
    /// `2·a·δ`: what one step adds to (or takes from) `v²`.
    gain: f32,
    /// `2·a`, for the distance left to brake.
    two_a: f32,
    cap2: f32,
    exit2: f32,
    /// `v²` from rest, and where braking ends: the start rate for a hold or an abort, the cap
    /// when braking down to a lower cap (an override lowered it; the motion is not at rest then).
    start2: f32,
    /// The step's length, nm, and the distance left in the block before the run, nm.
    step_nm: u32,
    left_nm: u32,
    /// A hold or an abort, or a speed above the cap: decelerate to `start2`.
    braking: bool,
    min_ticks: u32,
}

impl Run {
    const EMPTY: Run = Run { steps: 0, left: 0, pace: Pace::Cruise { ticks: 0, frac: 0 }, step_mm: 0.0 };

    /// Ends the run after the steps emitted so far: the next step is planned afresh.
    fn cut(&mut self) {
        self.steps -= self.left;
        self.left = 0;
    }
}

/// What planning the next run found.
enum RunStart {
    Ready,
    Empty,
    Failed(CurveError),
}

/// `exact_ticks` as whole ticks and a fraction in 2⁻³² ticks, no shorter than `min_ticks`.
fn split_ticks(exact_ticks: f32, min_ticks: u32) -> (u32, u32) {
    let ticks = exact_ticks as u32;
    if ticks < min_ticks {
        return (min_ticks, 0);
    }
    (ticks, ((exact_ticks - ticks as f32) * TICK_FRACTION_SCALE) as u32)
}

impl StepGen {
    /// At rest, running what is queued.
    pub const START: StepGen =
        StepGen { request: Request::Run, speed: None, run: Run::EMPTY, carry: 0, pace: ScanPace::START };

    /// What the motion runs under.
    pub fn request(&self) -> Request {
        self.request
    }

    /// The speed of the last step while moving, mm/s; `None` at rest.
    pub fn speed(&self) -> Option<f32> {
        self.speed
    }

    /// A hold: brakes to a stop on the path from the next step on.
    pub fn hold(&mut self) {
        if self.request == Request::Run {
            self.request = Request::Hold;
            self.run.cut();
        }
    }

    /// Ends a hold: goes on along the same path.
    pub fn resume(&mut self) {
        if self.request == Request::Hold {
            self.request = Request::Run;
            self.run.cut();
        }
    }

    /// An abort: brakes to a stop on the path, then `ahead` is emptied. At rest at once.
    pub fn abort<C: Interpolator, const N: usize>(&mut self, ahead: &mut Lookahead<C, N>) {
        self.request = Request::Abort;
        self.run.cut();
        if self.speed.is_none() {
            self.rest(ahead);
        }
    }

    /// Empties `ahead` at once, without braking: the pulses were cut already.
    pub fn drop_all<C: Interpolator, const N: usize>(&mut self, ahead: &mut Lookahead<C, N>) {
        self.request = Request::Abort;
        self.rest(ahead);
    }

    /// Ends the run after the steps emitted so far and books them in `ahead`, so that its front
    /// block's progress is the motion's.
    pub fn book_emitted<C: Interpolator, const N: usize>(&mut self, ahead: &mut Lookahead<C, N>, limits: &Limits) {
        self.run.cut();
        self.retire_run(ahead, limits);
    }

    /// The machine is at rest: an abort is finished (`ahead` emptied).
    fn rest<C: Interpolator, const N: usize>(&mut self, ahead: &mut Lookahead<C, N>) {
        self.speed = None;
        self.run = Run::EMPTY;
        if self.request == Request::Abort {
            ahead.clear();
            self.request = Request::Run;
        }
    }
}

impl StepGen {
    /// Writes the next step commands into `out`, until it is full, their intervals add up to
    /// `ticks_room` or more, or there is nothing more to emit now: the motion task fills the
    /// step queue this way, one run at a time in a tight loop.
    pub fn fill<C: Interpolator, const N: usize>(
        &mut self,
        ahead: &mut Lookahead<C, N>,
        limits: &Limits,
        factors: Factors,
        out: &mut [StepCmd],
        ticks_room: u32,
    ) -> Emitted {
        if self.pace.emitted >= SCAN_EVERY_STEPS {
            self.keep_scanning(ahead, limits, factors);
        }
        let (mut written, mut ticks, mut dx, mut dy) = (0usize, 0u32, 0i32, 0i32);
        let (mut step_mm, mut step_mm_from, mut step_mm_before) = (0.0, 0, 0.0);
        let end = loop {
            if written >= out.len() || ticks >= ticks_room {
                break None;
            }
            if self.run.left == 0 {
                match self.next_run(ahead, limits, factors) {
                    RunStart::Ready => {}
                    RunStart::Empty => break Some(Ok(())),
                    RunStart::Failed(e) => break Some(Err(e)),
                }
            }
            let room = out.len() - written;
            let steps = ahead.front_steps((self.run.left as usize).min(room));
            let mut carry = self.carry;
            let mut taken = 0;
            // A ramp that reaches the cap goes on as a cruise; braking ends at `start2`.
            let mut ends_early = false;
            match &mut self.run.pace {
                Pace::Cruise { ticks: whole, frac } => {
                    for (slot, &step) in out[written..].iter_mut().zip(steps) {
                        let (c, over) = carry.overflowing_add(*frac);
                        carry = c;
                        let interval_ticks = *whole + u32::from(over);
                        *slot = StepCmd::new(step, interval_ticks);
                        ticks = ticks.wrapping_add(interval_ticks);
                        dx += i32::from(step.x);
                        dy += i32::from(step.y);
                        taken += 1;
                        if ticks >= ticks_room {
                            break;
                        }
                    }
                }
                Pace::Ramp(ramp) => {
                    // The run's figures in locals, so that they stay in registers through the
                    // loop; the distance left is written back after it.
                    let r = *ramp;
                    let mut left_nm = r.left_nm;
                    let mut v2 = self.speed.map_or(-1.0, |w| w * w);
                    for (slot, &step) in out[written..].iter_mut().zip(steps) {
                        // The rule step by step: from rest the start rate; then what the
                        // acceleration adds, within the cap and the braking distance left, and
                        // for a hold or an abort what braking allows.
                        let mut w2 = if v2 < 0.0 { r.start2 } else { v2 + r.gain };
                        w2 = math::min(w2, r.cap2);
                        left_nm = left_nm.saturating_sub(r.step_nm);
                        w2 = math::min(w2, r.exit2 + r.two_a * (left_nm as f32 / NM_PER_MM));
                        if r.braking && v2 >= 0.0 {
                            w2 = math::min(w2, math::max(v2 - r.gain, r.start2));
                        }
                        // `max` also replaces a NaN, which valid limits never produce.
                        w2 = math::max(w2, MIN_SPEED_MM_PER_S * MIN_SPEED_MM_PER_S);
                        let (whole, frac) = split_ticks(r.ticks_mm / math::sqrt(w2), r.min_ticks);
                        let (c, over) = carry.overflowing_add(frac);
                        carry = c;
                        let interval_ticks = whole + u32::from(over);
                        *slot = StepCmd::new(step, interval_ticks);
                        ticks = ticks.wrapping_add(interval_ticks);
                        dx += i32::from(step.x);
                        dy += i32::from(step.y);
                        taken += 1;
                        let reached_cap = w2 >= r.cap2;
                        let stopped = r.braking && w2 <= r.start2;
                        v2 = w2;
                        if stopped || (reached_cap && !r.braking) {
                            ends_early = true;
                            break;
                        }
                        if ticks >= ticks_room {
                            break;
                        }
                    }
                    ramp.left_nm = left_nm;
                    if v2 >= 0.0 {
                        self.speed = Some(math::sqrt(v2));
                    }
                }
            }
            if taken == 0 {
                // A run is never longer than the steps scanned; only a bug gets here.
                self.run.cut();
                continue;
            }
            self.carry = carry;
            if written == 0 {
                (step_mm, step_mm_before) = (self.run.step_mm, self.run.step_mm);
            } else if self.run.step_mm != step_mm {
                (step_mm_before, step_mm_from, step_mm) = (step_mm, written, self.run.step_mm);
            }
            ahead.drop_steps(taken);
            self.pace.emitted += taken;
            self.run.left -= taken as u32;
            if ends_early {
                self.run.cut();
            }
            written += taken;
            if self.run.left == 0 {
                self.retire_run(ahead, limits);
            }
        };
        Emitted { steps: written, ticks, moved: Point::new(dx, dy), step_mm, step_mm_from, step_mm_before, end }
    }

    /// Keeps the scan ahead: twice what was emitted since it last ran, and a chunk more, while
    /// the scan's front may still cap the motion (`Lookahead::lead_short`); once it cannot, as much
    /// as was emitted, and a chunk more. At most [`SCAN_STEPS_PER_CALL`] at once; what is left
    /// waits for the next call. The steps are counted as they are emitted, not as their run ends:
    /// a cruise along a long line is one run, and its steps scanned again all at once at its end
    /// would be milliseconds of the F407's in one call.
    ///
    /// Scanning twice the steps emitted doubles a curve's evaluations while the look-ahead
    /// grows: at a function's top rate the processor has no room for that, so the look-ahead
    /// grows only as far as braking from the caps scanned needs.
    fn keep_scanning<C: Interpolator, const N: usize>(
        &mut self,
        ahead: &mut Lookahead<C, N>,
        limits: &Limits,
        factors: Factors,
    ) {
        if ahead.steps_free() < CHUNK_STEPS {
            return;
        }
        self.pace.since_check += self.pace.emitted;
        if self.pace.since_check >= SCAN_EVERY_STEPS || self.speed.is_none() {
            // Worked out now and then: it reads every block.
            self.pace.since_check = 0;
            self.pace.rate = if ahead.lead_short(LEAD_SHARE) { 2 } else { 1 };
        }
        let ScanPace { emitted, rate, .. } = self.pace;
        let budget = (rate * emitted + CHUNK_STEPS).min(SCAN_STEPS_PER_CALL);
        ahead.scan(limits, factors, budget);
        self.pace.emitted = emitted.saturating_sub(budget / rate);
    }

    /// Plans the next run.
    #[inline(never)]
    fn next_run<C: Interpolator, const N: usize>(
        &mut self,
        ahead: &mut Lookahead<C, N>,
        limits: &Limits,
        factors: Factors,
    ) -> RunStart {
        self.run.cut();
        self.retire_run(ahead, limits);
        if self.request == Request::Hold && self.speed.is_none() {
            return RunStart::Empty;
        }
        self.keep_scanning(ahead, limits, factors);
        // Every pass returns, drops a finished block, or scans where the motion has caught up
        // with the scan; the bound only guards against the unforeseen.
        for _ in 0..(N + PLANNER_BLOCKS + 8) {
            let Some(block) = ahead.front_block() else {
                // Nothing scanned: scan on (at rest or at the start rate), unless nothing is left.
                if ahead.scan_chunk(limits, factors).is_some() {
                    ahead.replan(limits);
                    continue;
                }
                self.rest(ahead);
                return RunStart::Empty;
            };
            if let Some(e) = block.error {
                ahead.finish_block();
                self.rest(ahead);
                return RunStart::Failed(e);
            }
            if block.done_steps >= block.steps {
                if block.open {
                    // The motion has caught up with the scan (the plan brought it to the start
                    // rate there).
                    if ahead.scan_chunk(limits, factors).is_some() {
                        ahead.replan(limits);
                        continue;
                    }
                    self.rest(ahead);
                    return RunStart::Empty;
                }
                ahead.finish_block();
                continue;
            }
            let start = math::min(limits.start_speed_mm_per_s, block.caps.speed_mm_per_s);
            if self.request != Request::Run && self.speed.is_none_or(|w| w <= start) {
                self.rest(ahead);
                return RunStart::Empty;
            }
            let ahead_of_block = block.ahead();
            let Some(chunk) = ahead.front_chunk() else {
                // Every scanned step is in a chunk; only a bug gets here.
                self.rest(ahead);
                return RunStart::Empty;
            };
            self.plan_run(limits, &ahead_of_block, &chunk, start);
            return RunStart::Ready;
        }
        RunStart::Empty
    }

    /// The next run, in the front block (what lies `ahead` in it) and `chunk` (the front one),
    /// with `start` the speed from rest:
    /// a cruise as far as the way is clear of braking when the speed is at the cap, a ramp
    /// otherwise; see the planner's module documentation. Above the cap (an override lowered
    /// it), the ramp brakes down to it at the acceleration limit, as a hold does to the start
    /// rate; from the start rate or slower, the speed may drop to the cap at once, as it starts
    /// and stops.
    fn plan_run(&mut self, limits: &Limits, ahead: &Ahead, chunk: &Chunk, start: f32) {
        let step_mm = chunk.step_mm;
        let a = ahead.caps.accel_mm_per_s2;
        let cap = ahead.caps.speed_mm_per_s;
        let exit = ahead.exit_mm_per_s;
        let available = chunk.left.min(ahead.steps);
        let hold = self.request != Request::Run;
        let jump = limits.start_speed_mm_per_s;
        let over = self.speed.filter(|&p| p > cap * OVER_CAP && p > jump);
        let min_ticks = limits.min_interval_ticks;
        if self.speed.is_none() {
            self.carry = HALF_TICK;
        }
        if let (false, None, Some(p)) = (hold, over, self.speed)
            && p >= cap
        {
            // Cruising: as far as the way is clear of braking to the block's exit.
            // Counted in whole nanometres, as the distance left is: a braking distance shorter
            // than the rounding of the steps' lengths still leaves the last step to a ramp.
            let clear_nm = ahead.left_nm as f32 - (cap * cap - exit * exit) * (NM_PER_MM / 2.0) / a;
            let n = (clear_nm as u32 / chunk.step_nm.max(1)).min(available);
            if n > 0 {
                let (ticks, frac) = split_ticks(step_mm / cap * TICK_HZ as f32, min_ticks);
                self.speed = Some(cap);
                self.run = Run { steps: n, left: n, pace: Pace::Cruise { ticks, frac }, step_mm };
                return;
            }
        }
        let top = over.unwrap_or(cap);
        // Braking from above the cap ends at the cap (or the start rate, from which the speed may
        // drop to the cap at once).
        let floor = if over.is_some() && !hold { math::max(cap, jump) } else { start };
        let ramp = Ramp {
            ticks_mm: step_mm * TICK_HZ as f32,
            gain: 2.0 * a * step_mm,
            two_a: 2.0 * a,
            cap2: top * top,
            exit2: exit * exit,
            start2: floor * floor,
            step_nm: chunk.step_nm,
            left_nm: ahead.left_nm,
            braking: hold || over.is_some(),
            min_ticks,
        };
        let n = available.min(RAMP_RUN_MAX_STEPS);
        self.run = Run { steps: n, left: n, pace: Pace::Ramp(ramp), step_mm };
    }

    /// Books the steps emitted in the run just ended against its chunk and block; rests when
    /// the plan is done, or a hold or an abort has braked to the start rate.
    #[inline(never)]
    fn retire_run<C: Interpolator, const N: usize>(&mut self, ahead: &mut Lookahead<C, N>, limits: &Limits) {
        let emitted = self.run.steps;
        self.run = Run::EMPTY;
        if emitted == 0 {
            return;
        }
        let Some(cap_mm_per_s) = ahead.book(emitted) else { return };
        let start = math::min(limits.start_speed_mm_per_s, cap_mm_per_s);
        let stopped = self.request != Request::Run && self.speed.is_some_and(|w| w <= start);
        if ahead.held() == 0 || stopped {
            self.rest(ahead);
        }
    }
}

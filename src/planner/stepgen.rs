//! The step generator: runs the scanned steps out as timed [`StepCmd`]s. It decides one speed
//! per slice of steps (floating point, once per slice); each step of a slice then costs a
//! ring read and an integer addition.

use crate::geom::{Point, StepCmd, TICK_HZ};
use crate::interp::{CurveError, Interpolator};
use crate::math;
use crate::planner::limits::MIN_SPEED_MM_PER_S;
use crate::planner::scan::{Block, Chunk};
use crate::planner::{CHUNK_STEPS, Planner, Request, SLICE_MAX_STEPS, SLICE_SPEED_GAIN};

/// 2³², the scale of a slice's fraction of a tick.
const TICK_FRACTION_SCALE: f32 = 4_294_967_296.0;

/// Half a tick in units of 2⁻³² tick: the carry from rest, so that the ticks of a run are its
/// exact times rounded to the nearest tick.
const HALF_TICK: u32 = 1 << 31;

/// Steps of one speed: each takes `ticks` and `frac` / 2³² ticks, the fractions carried over.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Slice {
    /// Steps in the slice, and how many of them are still to emit.
    steps: u32,
    pub left: u32,
    ticks: u32,
    frac: u32,
}

impl Slice {
    pub const EMPTY: Slice = Slice { steps: 0, left: 0, ticks: 0, frac: 0 };

    /// Ends the slice after the steps emitted so far: the next step gets a speed of its own.
    pub fn cut(&mut self) {
        self.steps -= self.left;
        self.left = 0;
    }
}

/// What [`Planner::fill`] wrote, and why it stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Emitted {
    /// Step commands written, from the start of the buffer.
    pub steps: usize,
    /// The sum of their intervals, ticks.
    pub ticks: u32,
    /// Where they take the pen, relative to where it was before them.
    pub moved: Point,
    /// `None`: the buffer is full or the ticks asked for are written. `Some(Ok(()))`: nothing
    /// more to emit now (the queue is empty, or a hold has stopped the motion).
    /// `Some(Err(e))`: a curve fails after these steps (the machine is then at rest; the next
    /// call goes on with the next segment).
    pub end: Option<Result<(), CurveError>>,
}

/// What planning the next slice found.
enum SliceStart {
    Ready,
    Empty,
    Failed(CurveError),
}

impl<C: Interpolator, const N: usize> Planner<C, N> {
    /// The next step command: `None` when there is nothing to emit now (queue empty, or stopped
    /// by a hold), `Some(Err(e))` where a curve fails (the machine is then at rest; the next call
    /// goes on with the next segment).
    pub fn next_cmd(&mut self) -> Option<Result<StepCmd, CurveError>> {
        let mut cmd = [StepCmd { step: crate::geom::Step::NONE, interval_ticks: 0 }];
        let emitted = self.fill(&mut cmd, u32::MAX);
        match emitted.end {
            _ if emitted.steps == 1 => Some(Ok(cmd[0])),
            Some(Err(e)) => Some(Err(e)),
            _ => None,
        }
    }

    /// Writes the next step commands into `out`, until it is full, their intervals add up to
    /// `ticks_room` or more, or there is nothing more to emit now: the motion task fills the
    /// step queue this way, one slice at a time in a tight loop.
    pub fn fill(&mut self, out: &mut [StepCmd], ticks_room: u32) -> Emitted {
        let (mut written, mut ticks, mut dx, mut dy) = (0usize, 0u32, 0i32, 0i32);
        let end = loop {
            if written >= out.len() || ticks >= ticks_room {
                break None;
            }
            if self.slice.left == 0 {
                match self.next_slice() {
                    SliceStart::Ready => {}
                    SliceStart::Empty => break Some(Ok(())),
                    SliceStart::Failed(e) => break Some(Err(e)),
                }
            }
            let room = out.len() - written;
            let steps = self.steps.front_slice((self.slice.left as usize).min(room));
            let (mut carry, frac, whole) = (self.carry, self.slice.frac, self.slice.ticks);
            let mut taken = 0;
            for (slot, &step) in out[written..].iter_mut().zip(steps) {
                let (c, over) = carry.overflowing_add(frac);
                carry = c;
                let interval_ticks = whole + u32::from(over);
                *slot = StepCmd { step, interval_ticks };
                ticks = ticks.wrapping_add(interval_ticks);
                dx += i32::from(step.x);
                dy += i32::from(step.y);
                taken += 1;
                if ticks >= ticks_room {
                    break;
                }
            }
            if taken == 0 {
                // A slice is never longer than the steps scanned; only a bug gets here.
                self.slice.cut();
                continue;
            }
            self.carry = carry;
            self.steps.drop_front(taken);
            self.slice.left -= taken as u32;
            written += taken;
            if self.slice.left == 0 {
                self.retire_slice();
            }
        };
        Emitted { steps: written, ticks, moved: Point::new(dx, dy), end }
    }

    /// Plans the next slice.
    #[inline(never)]
    fn next_slice(&mut self) -> SliceStart {
        self.slice.cut();
        self.retire_slice();
        self.apply_pending_if_idle();
        if self.request == Request::Hold && self.speed.is_none() {
            return SliceStart::Empty;
        }
        // Keep the scan ahead: twice what was emitted since it last ran, and a chunk more.
        if self.steps.free() >= CHUNK_STEPS {
            self.scan(2 * self.emitted_since_scan + CHUNK_STEPS);
            self.emitted_since_scan = 0;
        }
        // Every pass returns, drops a finished block, or scans where the motion has caught up
        // with the scan; the bound only guards against the unforeseen.
        for _ in 0..(N + crate::planner::PLANNER_BLOCKS + 8) {
            let Some(block) = self.blocks.front().copied() else {
                // Nothing scanned: scan on (at rest or at the start rate), unless nothing is left.
                if self.scan_chunk().is_some() {
                    self.replan();
                    continue;
                }
                self.rest();
                return SliceStart::Empty;
            };
            if let Some(e) = block.error {
                self.finish_block();
                self.rest();
                return SliceStart::Failed(e);
            }
            if block.done_steps >= block.steps {
                if block.open {
                    // The motion has caught up with the scan (the plan brought it to the start
                    // rate there).
                    if self.scan_chunk().is_some() {
                        self.replan();
                        continue;
                    }
                    self.rest();
                    return SliceStart::Empty;
                }
                self.finish_block();
                continue;
            }
            let start = math::min(self.limits.start_speed_mm_per_s, block.caps.speed_mm_per_s);
            if self.request != Request::Run && self.speed.is_none_or(|w| w <= start) {
                self.rest();
                return SliceStart::Empty;
            }
            let Some(chunk) = self.chunks.front().copied() else {
                // Every scanned step is in a chunk; only a bug gets here.
                self.rest();
                return SliceStart::Empty;
            };
            self.plan_slice(&block, &chunk, start);
            return SliceStart::Ready;
        }
        SliceStart::Empty
    }

    /// The speed and interval of the next slice, in `block` and `chunk` (the front ones), with
    /// `start` the speed from rest; see the planner's module documentation.
    fn plan_slice(&mut self, block: &Block, chunk: &Chunk, start: f32) {
        let step_mm = chunk.step_mm;
        let a = block.caps.accel_mm_per_s2;
        let cap = block.caps.speed_mm_per_s;
        let exit = block.exit_mm_per_s;
        let rem_mm = block.left_mm(block.done_nm);
        let available = chunk.left.min(block.steps - block.done_steps);
        let braking = self.request != Request::Run;
        let n = match self.speed {
            None => 1,
            Some(p) => {
                let mut n = (SLICE_SPEED_GAIN * p * p / (2.0 * a * step_mm)) as u32;
                if !braking && p >= cap {
                    // Cruising: as far as the way is clear of braking to the block's exit.
                    let clear_mm = rem_mm - (cap * cap - exit * exit) / (2.0 * a);
                    n = n.max((clear_mm / step_mm) as u32);
                }
                n.clamp(1, SLICE_MAX_STEPS)
            }
        }
        .min(available);
        let run_mm = n as f32 * step_mm;
        let mut w = match self.speed {
            None => start,
            Some(p) => math::sqrt(p * p + 2.0 * a * run_mm),
        };
        w = math::min(w, cap);
        w = math::min(w, block.brake_limit(block.done_nm.saturating_add(chunk.nm(n))));
        if let (true, Some(p)) = (braking, self.speed) {
            w = math::min(w, math::max(math::sqrt(math::max(p * p - 2.0 * a * run_mm, 0.0)), start));
        }
        // `max` also replaces a NaN, which valid limits never produce.
        w = math::max(w, MIN_SPEED_MM_PER_S);
        let exact_ticks = step_mm / w * TICK_HZ as f32;
        let mut ticks = exact_ticks as u32;
        let mut frac = ((exact_ticks - ticks as f32) * TICK_FRACTION_SCALE) as u32;
        if ticks < self.limits.min_interval_ticks {
            ticks = self.limits.min_interval_ticks;
            frac = 0;
        }
        if self.speed.is_none() {
            self.carry = HALF_TICK;
        }
        self.speed = Some(w);
        self.slice = Slice { steps: n, left: n, ticks, frac };
    }

    /// Books the steps emitted in the slice just ended against its chunk and block; rests when
    /// the plan is done, or a hold or an abort has braked to the start rate.
    #[inline(never)]
    pub(crate) fn retire_slice(&mut self) {
        let emitted = self.slice.steps;
        self.slice = Slice::EMPTY;
        if emitted == 0 {
            return;
        }
        self.emitted_since_scan += emitted as usize;
        let Some(chunk) = self.chunks.front_mut() else { return };
        let emitted_nm = chunk.nm(emitted);
        chunk.left = chunk.left.saturating_sub(emitted);
        if chunk.left == 0 {
            self.chunks.pop_front();
        }
        let Some(block) = self.blocks.front_mut() else { return };
        block.done_steps = block.done_steps.saturating_add(emitted);
        block.done_nm = block.done_nm.saturating_add(emitted_nm);
        let start = math::min(self.limits.start_speed_mm_per_s, block.caps.speed_mm_per_s);
        if block.done_steps >= block.steps && !block.open {
            self.finish_block();
        }
        let stopped = self.request != Request::Run && self.speed.is_some_and(|w| w <= start);
        if self.held == 0 || stopped {
            self.rest();
        }
    }

    /// Drops the front block, emitted to its end (or a failure block, reported).
    fn finish_block(&mut self) {
        if let Some(block) = self.blocks.pop_front()
            && block.ends_segment
        {
            self.held = self.held.saturating_sub(1);
        }
    }
}

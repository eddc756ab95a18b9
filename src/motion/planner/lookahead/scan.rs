//! The scan: steps each queued curve once, ahead of the motion, into the look-ahead's ring of
//! steps; cuts the steps into chunks (one step length each) and blocks (one cap each); plans the
//! blocks' exit speeds (the backward pass). Floating point here runs once per chunk, not per
//! step. It runs under the planner's limits and overrides, given with each call.

use super::{BLOCK_MARGIN, Lookahead, ScanPoint};
use crate::math;
use crate::motion::interp::{CurveError, Interpolator, Tangent};
use crate::motion::planner::block::{Block, Chunk};
use crate::motion::planner::limits::{Bend, Caps, Limits, StepGeometry, UnitDir};
use crate::motion::planner::scaling::{CapBasis, ChunkCaps, Factors, Scale};
use crate::motion::planner::sizes::{CHUNK_STEPS, STRAIGHT_CHUNK_STEPS};

/// Caps of a segment's first block sit this far below those of its first chunk: only float
/// noise, so a straight line runs at its own caps.
const FIRST_BLOCK_MARGIN: f32 = 1e-4;

/// A chunk allowing this much (relative) more speed than its block starts a new block.
const BLOCK_SPLIT_GAIN: f32 = 0.1;

impl Block {
    /// Whether steps with caps `own` can join this block.
    fn takes(&self, own: Caps) -> bool {
        let cap = self.caps.speed_mm_per_s;
        self.open
            && own.speed_mm_per_s >= cap
            && own.accel_mm_per_s2 >= self.caps.accel_mm_per_s2
            && own.speed_mm_per_s <= cap * (1.0 + BLOCK_SPLIT_GAIN)
    }
}

/// The turn between two unit directions, radians (0 to π).
fn turn_rad(from: [f32; 2], to: [f32; 2]) -> f32 {
    let cross = from[0] * to[1] - from[1] * to[0];
    let dot = from[0] * to[0] + from[1] * to[1];
    math::atan2(cross.abs(), dot)
}

impl<C: Interpolator, const N: usize> Lookahead<C, N> {
    /// Scans up to about `budget` steps of the queued segments, as far as there is room, then
    /// plans the blocks' exit speeds again.
    pub fn scan(&mut self, limits: &Limits, factors: Factors, budget: usize) {
        let mut scanned = 0;
        let mut changed = false;
        while scanned < budget {
            match self.scan_chunk(limits, factors) {
                Some(steps) => {
                    scanned += steps.max(1);
                    changed = true;
                }
                None => break,
            }
        }
        if changed {
            self.replan(limits);
        }
    }

    /// Scans one chunk of the front segment (or finishes it); the number of steps scanned, or
    /// `None` when nothing could be done (no segment, or no room).
    pub fn scan_chunk(&mut self, limits: &Limits, factors: Factors) -> Option<usize> {
        // Room for a chunk and two blocks (a new one and, should the curve fail, its error).
        if self.chunks.is_full() || self.blocks.free() < 2 {
            return None;
        }
        let segment = self.segments.front_mut()?;
        if self.scan.fresh {
            self.scan.tangent = segment.curve.tangent();
            self.scan.at = limits.step_geometry(segment.method, UnitDir::from_tangent(self.scan.tangent, 0, 0));
        }
        let want = if self.scan.kink_from_mm.is_some() {
            1
        } else if segment.curve.straight_steps_left().is_some() {
            STRAIGHT_CHUNK_STEPS
        } else {
            CHUNK_STEPS
        };
        let buf = self.steps.free_slice(want);
        if buf.is_empty() {
            return None;
        }
        let filled = segment.curve.fill(buf);
        let n = filled.steps;
        let last_step = buf.get(n.wrapping_sub(1)).copied();
        self.steps.commit(n);
        let after = segment.curve.tangent();
        let straight_left = segment.curve.straight_steps_left();
        let (method, requested, scale) = (segment.method, segment.requested_mm_per_s, segment.scale);
        if n > 0 {
            // The tangent at the chunk's last point, before any kink there.
            let end_tangent = filled.kink.unwrap_or(after);
            let (sx, sy) = last_step.map_or((0, 0), |s| (s.x, s.y));
            let end = limits.step_geometry(method, UnitDir::from_tangent(end_tangent, sx, sy));
            self.take_chunk(limits, factors, n as u32, end, end_tangent, requested, scale);
            if let Some(left) = straight_left {
                self.see_ahead(left);
            }
            if filled.kink.is_some() {
                self.scan.kink_from_mm = Some(end.dir_mm);
            }
            self.scan.tangent = after;
            self.scan.at = if filled.kink.is_some() {
                limits.step_geometry(method, UnitDir::from_tangent(after, sx, sy))
            } else {
                end
            };
        }
        match filled.end {
            None if n == 0 => None,
            None => Some(n),
            Some(end) => {
                self.end_segment(limits, end);
                Some(n)
            }
        }
    }

    /// Files `n` scanned steps that end where a step has geometry `end` (tangent `end_tangent`)
    /// into the chunks and blocks; the feed asked for is `requested_mm_per_s`, scaled by `scale`.
    #[allow(clippy::too_many_arguments)]
    fn take_chunk(
        &mut self,
        limits: &Limits,
        factors: Factors,
        n: u32,
        end: StepGeometry,
        end_tangent: Tangent,
        requested_mm_per_s: f32,
        scale: Scale,
    ) {
        let start = self.scan.at;
        let fresh = self.scan.fresh;
        let kink_from = self.scan.kink_from_mm.take();
        let straight = kink_from.is_none() && end_tangent == self.scan.tangent;
        self.scan.fresh = false;
        if straight && self.scan.straight && !fresh && self.extend_back(n, start.step_mm) {
            return;
        }
        self.scan.straight = straight;
        // One step length and direction for the whole chunk: the mean of its ends'.
        let step_mm = 0.5 * (start.step_mm + end.step_mm);
        let (dx, dy) = (start.dir_mm[0] + end.dir_mm[0], start.dir_mm[1] + end.dir_mm[1]);
        let len = math::sqrt(dx * dx + dy * dy);
        let dir_mm = if len > 1e-3 { [dx / len, dy / len] } else { end.dir_mm };
        let g = StepGeometry { step_mm, dir_mm };
        let bend = match kink_from {
            Some(from) => Bend::Kink { from },
            None if straight => Bend::Straight,
            None => Bend::Curve { curvature_per_mm: turn_rad(start.dir_mm, end.dir_mm) / (n as f32 * step_mm) },
        };
        let caps = ChunkCaps::new(limits, &limits.step_limit(&g, bend), scale, requested_mm_per_s, factors);
        let chunk = Chunk::new(n, step_mm);
        // The open block, if any, is this segment's: the last block in the queue.
        if !fresh && let Some(back) = self.blocks.back_mut() {
            back.dirty = true;
            if back.takes(caps.own) {
                back.basis.join(&caps);
                back.steps = back.steps.saturating_add(n);
                back.len_nm = back.len_nm.saturating_add(chunk.nm(n));
                back.exit_dir_mm = end.dir_mm;
                self.push_chunk(chunk, true);
                return;
            }
            back.open = false;
            back.ahead_nm = 0;
        }
        let keep = 1.0 - if fresh { FIRST_BLOCK_MARGIN } else { BLOCK_MARGIN };
        let basis = CapBasis::new(&caps, scale, requested_mm_per_s, factors, keep);
        let block = Block {
            steps: n,
            len_nm: chunk.nm(n),
            ahead_nm: 0,
            done_steps: 0,
            done_nm: 0,
            caps: basis.scanned,
            basis,
            entry_dir_mm: start.dir_mm,
            exit_dir_mm: end.dir_mm,
            open: true,
            ends_segment: false,
            error: None,
            exit_mm_per_s: limits.start_speed_mm_per_s,
            exit_floor_mm_per_s: 0.0,
            dirty: true,
        };
        if self.blocks.push_back(block) {
            self.push_chunk(chunk, false);
        }
    }

    /// The open block's line goes on straight for `steps` more steps, as long as its last
    /// chunk's.
    fn see_ahead(&mut self, steps: u64) {
        let step_nm = self.chunks.back_mut().map_or(0, |c| c.step_nm);
        if let Some(back) = self.blocks.back_mut()
            && back.open
        {
            back.ahead_nm = u32::try_from(steps.saturating_mul(u64::from(step_nm))).unwrap_or(u32::MAX);
        }
    }

    /// Adds `n` steps of `step_mm` to the open block and its last chunk (a straight run going
    /// on); false when there is no such block.
    fn extend_back(&mut self, n: u32, step_mm: f32) -> bool {
        let Some(back) = self.blocks.back_mut() else { return false };
        if !back.open {
            return false;
        }
        let chunk = Chunk::new(n, step_mm);
        back.steps = back.steps.saturating_add(n);
        back.len_nm = back.len_nm.saturating_add(chunk.nm(n));
        back.dirty = true;
        self.push_chunk(chunk, true);
        true
    }

    /// Appends `chunk`, or adds its steps to the last one when it is in the same block
    /// (`same_block`) and its steps have the same length.
    fn push_chunk(&mut self, chunk: Chunk, same_block: bool) {
        if same_block
            && let Some(back) = self.chunks.back_mut()
            && back.step_mm == chunk.step_mm
            && back.left > 0
        {
            back.left = back.left.saturating_add(chunk.left);
            return;
        }
        // The scan checked for room before it took the steps.
        let _ = self.chunks.push_back(chunk);
    }

    /// The front segment is scanned to its end (`Ok`) or to the point where it fails.
    fn end_segment(&mut self, limits: &Limits, end: Result<(), CurveError>) {
        let fresh = self.scan.fresh;
        let exit_dir_mm = self.scan.at.dir_mm;
        if !fresh && let Some(back) = self.blocks.back_mut() {
            back.open = false;
            back.ahead_nm = 0;
            back.ends_segment = end.is_ok();
            back.exit_dir_mm = exit_dir_mm;
            back.dirty = true;
        }
        match end {
            Ok(()) if fresh => {
                // Not a single step: nothing to emit.
                self.held = self.held.saturating_sub(1);
            }
            Ok(()) => {}
            Err(e) => {
                let start = limits.start_speed_mm_per_s;
                let failure = Block {
                    caps: Caps { speed_mm_per_s: start, accel_mm_per_s2: limits.accel_mm_per_s2[0] },
                    entry_dir_mm: exit_dir_mm,
                    exit_dir_mm,
                    ends_segment: true,
                    error: Some(e),
                    exit_mm_per_s: start,
                    dirty: true,
                    ..Block::default()
                };
                // The scan checked for room before it took the steps.
                let _ = self.blocks.push_back(failure);
            }
        }
        self.segments.pop_front();
        self.scan = ScanPoint::new();
    }

    /// Backward pass: each block's exit speed, from a stop at the end of the plan, and never
    /// below its floor (see [`Block::exit_floor_mm_per_s`]). Stops early where nothing changes
    /// any more (the scan only changes the last blocks).
    pub fn replan(&mut self, limits: &Limits) {
        let start = limits.start_speed_mm_per_s;
        let len = self.blocks.len();
        // (entry direction, caps, highest speed it can be entered at) of the next block.
        let mut next: Option<([f32; 2], Caps, f32)> = None;
        for i in (0..len).rev() {
            let Some(block) = self.blocks.get_mut(i) else { continue };
            let exit = match next {
                Some((entry, caps, reachable)) if !block.open && block.error.is_none() => {
                    let mut exit = math::min(math::max(caps.speed_mm_per_s, start), reachable);
                    if block.ends_segment {
                        let a = math::min(caps.accel_mm_per_s2, block.caps.accel_mm_per_s2);
                        exit = math::min(exit, math::max(limits.junction_speed(a, block.exit_dir_mm, entry), start));
                    }
                    math::max(exit, block.exit_floor_mm_per_s)
                }
                _ => start,
            };
            let unchanged = exit == block.exit_mm_per_s && !block.dirty;
            block.exit_mm_per_s = exit;
            block.dirty = false;
            if unchanged {
                return;
            }
            next = Some((block.entry_dir_mm, block.caps, block.brake_limit(block.done_nm)));
        }
    }
}

//! The scan: runs a clone of each queued interpolator ahead of the motion, cuts the path into
//! blocks of steps with one cap each, and plans the blocks' exit speeds (the backward pass).

use crate::geom::Step;
use crate::interp::{CurveError, Interpolator, Method};
use crate::planner::limits::{Caps, UnitDir};
use crate::planner::{BLOCK_MARGIN, Planner};

/// Caps of a segment's first block sit this far below those of its first step: only float
/// noise, so a straight line runs at its own caps.
const FIRST_BLOCK_MARGIN: f32 = 1e-4;

/// A step allowing this much (relative) more speed than its block starts a new block.
const BLOCK_SPLIT_GAIN: f32 = 0.1;

/// Distances are counted in whole nanometres so that the scan and the motion agree exactly.
const NM_PER_MM: f32 = 1.0e6;

/// One queued segment: its interpolator and the clone that scans ahead of it.
pub(crate) struct Track<C> {
    pub curve: C,
    pub scout: C,
    pub method: Method,
    /// The feed, mm/s (unbounded for rapid).
    pub requested_mm_per_s: f32,
    /// The scout has not reached the end (or an error) yet.
    pub scanning: bool,
    /// Direction (mm) of the last scanned step; `None` before the first.
    pub scout_dir_mm: Option<[f32; 2]>,
    pub last_scanned: Step,
    /// How many blocks in the queue belong to this segment.
    pub blocks: usize,
}

/// Consecutive steps of one segment sharing one cap.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Block {
    pub steps: u32,
    pub len_nm: u64,
    pub done_steps: u32,
    pub done_nm: u64,
    pub caps: Caps,
    /// Direction (mm) of the first step, and after the last one when `ends_segment`.
    pub entry_dir_mm: [f32; 2],
    pub exit_dir_mm: [f32; 2],
    /// The scan is still adding steps: its end is the scan's front.
    pub open: bool,
    /// The last block of its segment: a junction follows.
    pub ends_segment: bool,
    /// A block without steps: the segment's curve fails here.
    pub error: Option<CurveError>,
    /// Highest speed allowed at the end, from the backward pass.
    pub exit_mm_per_s: f32,
    /// Changed by the scan since the last backward pass.
    pub dirty: bool,
}

impl Block {
    /// Highest speed at `at_nm` from which the motion can still brake to `exit_mm_per_s` at the
    /// block's (known) end.
    pub fn brake_limit(&self, at_nm: u64) -> f32 {
        let left_mm = self.len_nm.saturating_sub(at_nm) as f32 / NM_PER_MM;
        libm::sqrtf(self.exit_mm_per_s * self.exit_mm_per_s + 2.0 * self.caps.accel_mm_per_s2 * left_mm)
    }

    /// Whether a step with speed cap `speed` and acceleration `accel` can join this block.
    fn takes(&self, speed: f32, accel: f32) -> bool {
        let cap = self.caps.speed_mm_per_s;
        self.open && speed >= cap && accel >= self.caps.accel_mm_per_s2 && speed <= cap * (1.0 + BLOCK_SPLIT_GAIN)
    }
}

pub(crate) fn to_nm(mm: f32) -> u64 {
    // Saturating float-to-int conversion; steps are micrometres long, far from either end.
    (mm * NM_PER_MM + 0.5) as u64
}

impl<C: Interpolator + Clone, const N: usize> Planner<C, N> {
    /// One scan step for the front segment, whatever the budget: the motion has caught up with
    /// the scan (the plan has brought it to the start rate there).
    pub(crate) fn scan_front(&mut self) {
        let popped_block = self.blocks.front().is_some_and(|b| b.done_steps >= b.steps && !b.open && b.error.is_none());
        if popped_block {
            self.pop_front_block();
            return;
        }
        if self.tracks.front().is_some_and(|t| t.scanning) {
            self.scan_one(0);
        } else {
            // Nothing left to scan nor to emit: the segment is done.
            self.drop_front_track();
        }
        self.replan();
    }

    /// Runs the scan of the first unfinished segments for up to `budget` steps.
    pub(crate) fn scan(&mut self, budget: u32) {
        let mut scanned = false;
        let mut index = 0;
        for _ in 0..budget {
            while self.tracks.get(index).is_some_and(|t| !t.scanning) {
                index += 1;
            }
            if index >= self.tracks.len() || self.blocks.is_full() {
                break;
            }
            self.scan_one(index);
            scanned = true;
        }
        if scanned {
            self.replan();
        }
    }

    /// Advances the scan of segment `index` by one step, adding it to the open block or starting
    /// a new one, or ending the segment. Needs a free block.
    fn scan_one(&mut self, index: usize) {
        let limits = self.limits;
        let Some(track) = self.tracks.get_mut(index) else { return };
        if !track.scanning || self.blocks.is_full() {
            return;
        }
        let tangent = track.scout.tangent();
        let outcome = track.scout.next_step();
        let step = match outcome {
            Ok(Some(step)) => step,
            Ok(None) | Err(_) => {
                track.scanning = false;
                let last = track.last_scanned;
                let exit = UnitDir::from_tangent(track.scout.tangent(), last.x, last.y);
                let exit_dir_mm = limits.step_geometry(track.method, exit).dir_mm;
                let owns_back = track.blocks > 0;
                if let (true, Some(back)) = (owns_back, self.blocks.back_mut()) {
                    back.open = false;
                    // A junction follows the end; a failure block follows a failure.
                    back.ends_segment = outcome.is_ok();
                    back.exit_dir_mm = exit_dir_mm;
                    back.dirty = true;
                }
                if let Err(e) = outcome {
                    let start = limits.start_speed_mm_per_s;
                    let failure = Block {
                        steps: 0,
                        len_nm: 0,
                        done_steps: 0,
                        done_nm: 0,
                        caps: Caps { speed_mm_per_s: start, accel_mm_per_s2: limits.accel_mm_per_s2[0] },
                        entry_dir_mm: exit_dir_mm,
                        exit_dir_mm,
                        open: false,
                        ends_segment: true,
                        error: Some(e),
                        exit_mm_per_s: start,
                        dirty: true,
                    };
                    if self.blocks.push_back(failure).is_ok() {
                        track.blocks += 1;
                    }
                }
                return;
            }
        };
        let g = limits.step_geometry(track.method, UnitDir::from_tangent(tangent, step.x, step.y));
        let first = track.scout_dir_mm.is_none();
        if first {
            self.bend.reset();
        }
        let own = limits.step_caps(&g, self.bend.bend(&g), track.requested_mm_per_s);
        let speed = own.speed_mm_per_s;
        track.scout_dir_mm = Some(g.dir_mm);
        track.last_scanned = step;
        let step_nm = to_nm(g.step_mm);
        // The open block, if any, is this segment's: the last block in the queue.
        if let (false, true, Some(back)) = (first, track.blocks > 0, self.blocks.back_mut()) {
            back.dirty = true;
            if back.takes(speed, own.accel_mm_per_s2) {
                back.steps = back.steps.saturating_add(1);
                back.len_nm = back.len_nm.saturating_add(step_nm);
                return;
            }
            back.open = false;
        }
        let keep = 1.0 - if first { FIRST_BLOCK_MARGIN } else { BLOCK_MARGIN };
        let block = Block {
            steps: 1,
            len_nm: step_nm,
            done_steps: 0,
            done_nm: 0,
            caps: Caps {
                // The margin only where the machine limits the speed: the feed itself is kept.
                speed_mm_per_s: if own.speed_mm_per_s >= track.requested_mm_per_s {
                    own.speed_mm_per_s
                } else {
                    own.speed_mm_per_s * keep
                },
                accel_mm_per_s2: own.accel_mm_per_s2 * keep,
            },
            entry_dir_mm: g.dir_mm,
            exit_dir_mm: g.dir_mm,
            open: true,
            ends_segment: false,
            error: None,
            exit_mm_per_s: limits.start_speed_mm_per_s,
            dirty: true,
        };
        if self.blocks.push_back(block).is_ok() {
            track.blocks += 1;
        }
    }

    /// Backward pass: each block's exit speed, from a stop at the end of the plan. Stops early
    /// where nothing changes any more (the scan only changes the last blocks).
    pub(crate) fn replan(&mut self) {
        let limits = self.limits;
        let start = limits.start_speed_mm_per_s;
        let len = self.blocks.len();
        // (entry direction, caps, highest speed it can be entered at) of the next block.
        let mut next: Option<([f32; 2], Caps, f32)> = None;
        for i in (0..len).rev() {
            let Some(block) = self.blocks.get_mut(i) else { continue };
            let exit = match next {
                Some((entry, caps, reachable)) if !block.open && block.error.is_none() => {
                    let mut exit = caps.speed_mm_per_s.max(start).min(reachable);
                    if block.ends_segment {
                        let a = caps.accel_mm_per_s2.min(block.caps.accel_mm_per_s2);
                        exit = exit.min(limits.junction_speed(a, block.exit_dir_mm, entry).max(start));
                    }
                    exit
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

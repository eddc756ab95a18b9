//! What the scan leaves for the step generator: the scanned steps cut into chunks (one step
//! length each) and blocks (one cap each), with distances in whole nanometres.

use crate::math;
use crate::motion::interp::CurveError;
use crate::motion::planner::limits::Caps;
use crate::motion::planner::scaling::CapBasis;

/// Distances along the path are also counted in whole nanometres, so that the scan's block
/// lengths and the generator's progress agree exactly and the motion ends exactly at the end.
pub(crate) const NM_PER_MM: f32 = 1.0e6;

/// Consecutive scanned steps that advance the same distance along the ideal curve.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Chunk {
    /// Steps not yet emitted.
    pub left: u32,
    /// Distance one step advances along the ideal curve, mm, and in whole nanometres.
    pub step_mm: f32,
    pub step_nm: u32,
}

impl Chunk {
    pub fn new(left: u32, step_mm: f32) -> Chunk {
        // Saturating float-to-int conversion; steps are micrometres long, far from either end.
        Chunk { left, step_mm, step_nm: (step_mm * NM_PER_MM + 0.5) as u32 }
    }

    /// Length of `n` of its steps, nm.
    pub fn nm(&self, n: u32) -> u32 {
        self.step_nm.saturating_mul(n)
    }
}

/// Consecutive scanned steps of one segment sharing one cap.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Block {
    pub steps: u32,
    /// Length, and distance emitted so far, nm (`u32`: up to 4.2 m, longer than any path on the
    /// machine).
    pub len_nm: u32,
    /// Length of the straight rest of its line beyond the scan's front, nm: known steps of the
    /// same caps, so the block brakes for the line's end, not for the scan's front.
    pub ahead_nm: u32,
    pub done_steps: u32,
    pub done_nm: u32,
    /// The caps in force, and what they are made of (to apply a change of override).
    pub caps: Caps,
    pub basis: CapBasis,
    /// Direction (mm) at the block's start, and at its end.
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
    /// The least speed the motion can have slowed to by the end, at the last change of override:
    /// the backward pass allows at least this much (0: no floor), so a lower override brakes at
    /// the acceleration, not at once.
    pub exit_floor_mm_per_s: f32,
    /// Changed by the scan since the last backward pass.
    pub dirty: bool,
}

/// What lies ahead of the motion in its block, as the step generator plans a run: a copy of a
/// few of the block's figures, not of the block.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ahead {
    pub caps: Caps,
    pub exit_mm_per_s: f32,
    /// Steps not yet emitted, and the distance to brake in, nm (see [`Block::end_nm`]).
    pub steps: u32,
    pub left_nm: u32,
}

impl Block {
    /// What lies ahead of the motion in the block.
    pub fn ahead(&self) -> Ahead {
        Ahead {
            caps: self.caps,
            exit_mm_per_s: self.exit_mm_per_s,
            steps: self.steps - self.done_steps,
            left_nm: self.end_nm().saturating_sub(self.done_nm),
        }
    }

    /// Where the motion must have braked to `exit_mm_per_s`, nm into the block: its end, or the
    /// end of its line.
    pub fn end_nm(&self) -> u32 {
        self.len_nm.saturating_add(self.ahead_nm)
    }

    /// Distance left to [`Self::end_nm`] after `at_nm` into the block, mm.
    pub fn left_mm(&self, at_nm: u32) -> f32 {
        self.end_nm().saturating_sub(at_nm) as f32 / NM_PER_MM
    }

    /// Highest speed at `at_nm` into the block from which the motion can still brake to
    /// `exit_mm_per_s` at the block's (known) end.
    pub fn brake_limit(&self, at_nm: u32) -> f32 {
        math::sqrt(self.exit_mm_per_s * self.exit_mm_per_s + 2.0 * self.caps.accel_mm_per_s2 * self.left_mm(at_nm))
    }
}

//! A change of the feed or rapid override, applied to the motion already queued: every queued
//! block takes the caps the new overrides give it, and the braking plan is worked out again.
//!
//! Three rules keep the motion within its limits while the speed changes:
//!
//! - A lower override lowers the caps at once, and the step generator brakes from the speed the
//!   motion has down to the new cap at the acceleration limit. Where that braking cannot reach a
//!   block end as slowly as the new caps would have it, the block's exit may stay faster: its
//!   *floor* is the least speed the motion can have slowed to there, braking all the way from
//!   now. The old plan, which obeyed every machine limit (junctions, curvature, the stop at the
//!   end), was at least that fast there, so the floor never allows what the machine does not.
//! - A block's acceleration holds for every speed the motion may have in it: its new cap, and the
//!   speed it may still carry in while braking from now.
//! - A higher override can lower a curve's acceleration (more speed, more centripetal
//!   acceleration). Should the motion then no longer be able to brake in time for what lies
//!   ahead (it was braking already, on such a curve), the blocks it may be braking through keep
//!   the caps they had: braking needs the acceleration it was planned with. The blocks beyond
//!   take the new caps at once.

use super::Lookahead;
use crate::math;
use crate::motion::interp::Interpolator;
use crate::motion::planner::limits::{Caps, Limits};
use crate::motion::planner::scaling::Factors;
use crate::motion::planner::sizes::PLANNER_BLOCKS;

/// Braking from a speed up to this factor above the brake limit counts as in time (float noise).
const BRAKE_TOLERANCE: f32 = 1.0 + 1.0e-4;

impl<C: Interpolator, const N: usize> Lookahead<C, N> {
    /// The overrides are now `factors`, the motion at `speed` (mm/s; `None` at rest), its steps
    /// so far booked: every queued block takes its new caps, and the plan is worked out again.
    pub fn apply_factors(&mut self, limits: &Limits, factors: Factors, speed: Option<f32>) {
        let mut before = [Caps::default(); PLANNER_BLOCKS];
        for (i, caps) in before.iter_mut().enumerate().take(self.blocks.len()) {
            *caps = self.blocks.get_mut(i).map_or(Caps::default(), |b| b.caps);
        }
        self.recap(limits, factors, speed, &before, false);
        self.replan(limits);
        if let (Some(speed), Some(front)) = (speed, self.blocks.front())
            && speed > front.brake_limit(front.done_nm) * BRAKE_TOLERANCE
        {
            self.recap(limits, factors, Some(speed), &before, true);
            self.replan(limits);
        }
        // The scan may add steps to the last block: they are compared with its caps in force.
        if let Some(back) = self.blocks.back_mut()
            && back.open
        {
            back.basis.rebase(back.caps);
        }
    }

    /// Gives every queued block its caps at the factors in force, and its exit floor. With
    /// `keep_braking`, a block the motion may be braking through keeps its caps from `before`
    /// where the new ones would take acceleration away.
    fn recap(&mut self, limits: &Limits, factors: Factors, speed: Option<f32>, before: &[Caps], keep_braking: bool) {
        let start = limits.start_speed_mm_per_s;
        // The least speed², braking from the speed now, at the end of each block in turn.
        let mut least2 = speed.map_or(0.0, |v| v * v);
        for i in 0..self.blocks.len() {
            let Some(block) = self.blocks.get_mut(i) else { break };
            block.dirty = true;
            if block.error.is_some() {
                // The motion stops here; the next segment starts from rest.
                least2 = 0.0;
                continue;
            }
            let braking_through = least2 > start * start;
            let carried = if braking_through { math::sqrt(least2) } else { 0.0 };
            let speed = block.basis.speed(factors);
            block.caps = Caps {
                speed_mm_per_s: speed,
                accel_mm_per_s2: block.basis.accel_at(limits, math::max(speed, carried)),
            };
            if let Some(&old) = before.get(i)
                && keep_braking
                && braking_through
                && block.caps.accel_mm_per_s2 < old.accel_mm_per_s2
            {
                block.caps = old;
            }
            least2 = math::max(least2 - 2.0 * block.caps.accel_mm_per_s2 * block.left_mm(block.done_nm), 0.0);
            block.exit_floor_mm_per_s = if least2 > start * start { math::sqrt(least2) } else { 0.0 };
        }
    }
}

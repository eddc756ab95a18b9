//! How far the queued steps advance along the ideal curve, batch by batch, so that the pen's
//! speed is read from the step being emitted, not from the steps queued last (the queue holds up
//! to 20 ms of motion, over which a curve's step length changes).
//!
//! The motion task records each batch it queues: the number of steps queued before it, and its
//! `δ_mm`. The status and the LCD look up the batch of the step being emitted. One writer,
//! readers anywhere: atomics only; a reader racing the writer over a slot about to be reused
//! reads a neighbouring batch's length at worst (the slots outnumber the batches a full queue
//! holds twice over).

use core::sync::atomic::{AtomicU32, Ordering};

/// Batches remembered: twice what a full step queue holds (1,024 steps in batches of 32).
pub const PATH_STEP_BATCHES: usize = 64;

pub(super) struct PathSteps {
    /// Per slot: the steps queued before the batch, and its `δ_mm` as `f32` bits.
    first: [AtomicU32; PATH_STEP_BATCHES],
    step_mm_bits: [AtomicU32; PATH_STEP_BATCHES],
    /// Batches recorded so far (wraps).
    recorded: AtomicU32,
}

impl PathSteps {
    pub(super) const fn new() -> Self {
        PathSteps {
            first: [const { AtomicU32::new(0) }; PATH_STEP_BATCHES],
            step_mm_bits: [const { AtomicU32::new(0) }; PATH_STEP_BATCHES],
            recorded: AtomicU32::new(0),
        }
    }

    /// A batch queued after `first` steps, each advancing `step_mm`. Only the motion task calls
    /// this.
    pub(super) fn record(&self, first: u32, step_mm: f32) {
        let n = self.recorded.load(Ordering::Relaxed);
        let slot = n as usize % PATH_STEP_BATCHES;
        self.first[slot].store(first, Ordering::Relaxed);
        self.step_mm_bits[slot].store(step_mm.to_bits(), Ordering::Relaxed);
        self.recorded.store(n.wrapping_add(1), Ordering::Release);
    }

    /// How far step number `step` (counted as the queue counts) advances: the newest batch
    /// that begins at or before it; 0 if none remembered does.
    pub(super) fn at(&self, step: u32) -> f32 {
        let n = self.recorded.load(Ordering::Acquire);
        let remembered = (n as usize).min(PATH_STEP_BATCHES);
        (1..=remembered)
            .map(|back| n.wrapping_sub(back as u32) as usize % PATH_STEP_BATCHES)
            .find(|&slot| step.wrapping_sub(self.first[slot].load(Ordering::Relaxed)) < 1 << 31)
            .map_or(0.0, |slot| f32::from_bits(self.step_mm_bits[slot].load(Ordering::Relaxed)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_reads_the_length_of_its_own_batch() {
        let p = PathSteps::new();
        assert_eq!(p.at(0), 0.0, "nothing recorded");
        p.record(0, 0.01);
        p.record(32, 0.02);
        p.record(40, 0.03);
        assert_eq!((p.at(0), p.at(31), p.at(32), p.at(39), p.at(40), p.at(1000)), (0.01, 0.01, 0.02, 0.02, 0.03, 0.03));
        // Across the counters' wrap, and once the oldest slots are reused.
        for k in 0..(2 * PATH_STEP_BATCHES as u32) {
            p.record((u32::MAX - 100).wrapping_add(10 * k), k as f32);
        }
        let last = 2 * PATH_STEP_BATCHES as u32 - 1;
        assert_eq!(p.at((u32::MAX - 100).wrapping_add(10 * last + 5)), last as f32);
        assert_eq!(p.at((u32::MAX - 100).wrapping_add(10 * (last - 3))), (last - 3) as f32);
    }
}

//! The look-ahead, GRBL's planner buffer: the segments queued and not yet scanned, the steps the
//! scan took from them, cut into chunks (one step length each) and blocks (one cap and one
//! planned exit speed each). The scan ([`scan`]) alone fills it and plans it, and plans it again
//! when the overrides change ([`overriding`]); the step generator takes from its front through
//! the narrow methods below, as GRBL's stepper takes its `plan_block_t`s: the front steps, the
//! front chunk and block, and what a finished run used of them.

mod overriding;
mod scan;

use crate::geom::Step;
use crate::motion::interp::{Interpolator, Tangent};
use crate::motion::planner::block::{Block, Chunk};
use crate::motion::planner::limits::StepGeometry;
use crate::motion::planner::ring::{CopyRing, Ring, StepRing};
use crate::motion::planner::segment::Segment;
use crate::motion::planner::sizes::{CHUNK_RING_LEN, PLANNER_BLOCKS};

/// Caps of a curve's later blocks sit this far (relative) below those of their first chunk.
pub const BLOCK_MARGIN: f32 = 0.02;

/// Where the scan stands on the front segment.
#[derive(Clone, Copy)]
struct ScanPoint {
    /// The segment's first chunk is still to come.
    fresh: bool,
    /// The tangent at the scan point, and the geometry of a step along it.
    tangent: Tangent,
    at: StepGeometry,
    /// The last chunk ran straight (the tangent did not change over it): the next one extends
    /// it if it runs straight on.
    straight: bool,
    /// The last step scanned reached a kink from this direction (mm): the next step is a chunk
    /// and a block of its own, passed by the junction rule.
    kink_from_mm: Option<[f32; 2]>,
}

impl ScanPoint {
    const fn new() -> Self {
        ScanPoint {
            fresh: true,
            tangent: Tangent { x: 1.0, y: 0.0 },
            at: StepGeometry { step_mm: 0.0, dir_mm: [1.0, 0.0] },
            straight: false,
            kink_from_mm: None,
        }
    }
}

/// The look-ahead of a planner of `N` segments; see the module documentation.
pub struct Lookahead<C: Interpolator, const N: usize> {
    /// Pushed segments not yet fully scanned, in order; the scan works on the front one.
    segments: Ring<Segment<C>, N>,
    /// Segments pushed and not yet fully emitted (scanned or not).
    held: usize,
    /// Where the scan stands on the front segment.
    scan: ScanPoint,
    /// Steps scanned and not yet emitted.
    steps: StepRing,
    /// The scanned steps, cut into chunks with one length per step.
    chunks: CopyRing<Chunk, CHUNK_RING_LEN>,
    /// The scanned steps, cut into blocks with one cap each.
    blocks: CopyRing<Block, PLANNER_BLOCKS>,
}

impl<C: Interpolator, const N: usize> Lookahead<C, N> {
    /// Nothing queued.
    pub fn new() -> Self {
        Lookahead {
            segments: Ring::new(),
            held: 0,
            scan: ScanPoint::new(),
            steps: StepRing::new(),
            chunks: CopyRing::new(),
            blocks: CopyRing::new(),
        }
    }

    /// [`new`](Self::new), built where it lies.
    ///
    /// # Safety
    ///
    /// `this` is valid for writes and aligned; whatever it held is overwritten, not dropped.
    pub unsafe fn init_in_place(this: *mut Self) {
        use core::ptr::addr_of_mut;
        // SAFETY: the caller's promise; every field is written once, in place, below.
        unsafe {
            Ring::init_in_place(addr_of_mut!((*this).segments));
            addr_of_mut!((*this).held).write(0);
            addr_of_mut!((*this).scan).write(ScanPoint::new());
            CopyRing::init_in_place(addr_of_mut!((*this).steps));
            CopyRing::init_in_place(addr_of_mut!((*this).chunks));
            CopyRing::init_in_place(addr_of_mut!((*this).blocks));
        }
    }

    /// Every field: this pattern stops compiling when one is added, a reminder that
    /// [`init_in_place`](Self::init_in_place) must write it too.
    #[allow(dead_code)]
    fn every_field(self) {
        let Lookahead { segments: _, held: _, scan: _, steps: _, chunks: _, blocks: _ } = self;
    }

    /// Queues `segment` to be scanned; gives it back when `N` segments are held.
    pub fn push(&mut self, segment: Segment<C>) -> Result<(), Segment<C>> {
        if self.held >= N {
            return Err(segment);
        }
        self.segments.push_back(segment)?;
        self.held += 1;
        Ok(())
    }

    /// Segments pushed and not yet emitted to their end.
    pub fn held(&self) -> usize {
        self.held
    }

    /// Drops every segment, step, chunk and block: an abort at rest.
    pub fn clear(&mut self) {
        self.segments.clear();
        self.held = 0;
        self.scan = ScanPoint::new();
        self.steps.clear();
        self.chunks.clear();
        self.blocks.clear();
    }

    /// Up to `max` of the steps scanned and not yet emitted, from the front.
    #[inline(always)]
    pub fn front_steps(&self, max: usize) -> &[Step] {
        self.steps.front_slice(max)
    }

    /// The first `n` of [`front_steps`](Self::front_steps) are emitted.
    #[inline(always)]
    pub fn drop_steps(&mut self, n: usize) {
        self.steps.drop_front(n);
    }

    /// Room for more scanned steps.
    pub fn steps_free(&self) -> usize {
        self.steps.free()
    }

    /// The block the motion is in (or is about to enter).
    pub fn front_block(&self) -> Option<&Block> {
        self.blocks.front()
    }

    /// The chunk the motion is in.
    pub fn front_chunk(&self) -> Option<Chunk> {
        self.chunks.front().copied()
    }

    /// A run emitted `emitted` steps of the front chunk and block: books them there, and drops
    /// the block once it is emitted to its end. The cap of the block they were in, mm/s; `None`
    /// when there was no chunk or no block (nothing booked).
    pub fn book(&mut self, emitted: u32) -> Option<f32> {
        let chunk = self.chunks.front_mut()?;
        let emitted_nm = chunk.nm(emitted);
        chunk.left = chunk.left.saturating_sub(emitted);
        if chunk.left == 0 {
            self.chunks.pop_front();
        }
        let block = self.blocks.front_mut()?;
        block.done_steps = block.done_steps.saturating_add(emitted);
        block.done_nm = block.done_nm.saturating_add(emitted_nm);
        let cap_mm_per_s = block.caps.speed_mm_per_s;
        if block.done_steps >= block.steps && !block.open {
            self.finish_block();
        }
        Some(cap_mm_per_s)
    }

    /// Drops the front block, emitted to its end (or a failure block, reported).
    pub fn finish_block(&mut self) {
        if self.blocks.front().is_some_and(|b| b.ends_segment) {
            self.held = self.held.saturating_sub(1);
        }
        self.blocks.drop_front(1);
    }

    /// True while the scan's front may cap the motion: what is scanned ahead of it (with a
    /// straight line's known rest) is shorter than `share` times the distance to brake from the
    /// highest cap scanned at the lowest acceleration scanned.
    pub fn lead_short(&self, share: f32) -> bool {
        let (mut lead_nm, mut top_mm_per_s, mut accel_mm_per_s2) = (0u64, 0.0f32, f32::INFINITY);
        for i in 0..self.blocks.len() {
            if let Some(block) = self.blocks.get(i) {
                lead_nm += u64::from(block.end_nm().saturating_sub(block.done_nm));
                top_mm_per_s = crate::math::max(top_mm_per_s, block.caps.speed_mm_per_s);
                accel_mm_per_s2 = crate::math::min(accel_mm_per_s2, block.caps.accel_mm_per_s2);
            }
        }
        let brake_nm = top_mm_per_s * top_mm_per_s / (2.0 * accel_mm_per_s2) * crate::motion::planner::block::NM_PER_MM;
        (lead_nm as f32) < share * brake_nm
    }
}

//! How much the planner holds and how finely it scans: the capacities of its queues (segments,
//! blocks, chunks, the ring of steps) and the steps it scans at a time.

/// Segments the planner holds (pushed and not yet fully emitted): its look-ahead depth in
/// segments. At the default limits 16 segments of a 2,000-segment polyline circle of 100 mm
/// diameter (0.16 mm each) are enough braking distance to cruise at about 3,000 mm/min.
pub const PLANNER_SEGMENTS: usize = 16;

/// Blocks of steps with one cap each (see the [planner's documentation](crate::motion::planner)), for
/// all queued segments. A line takes one; a curve one per few percent of change of its caps.
/// When they run out the scan waits, and the motion brakes for the scan's front.
pub const PLANNER_BLOCKS: usize = 64;

/// Steps scanned ahead of the motion, at most: the look-ahead horizon on curves (a straight
/// line brakes for its own end). A curve runs no faster than it can brake within it: 16,384
/// steps are 82 mm at 200 steps/mm, enough to brake from 1,000 mm/s at 10,000 mm/s² (50 mm),
/// so a curve can reach the drivers' 200 kHz; at the defaults (100 steps/mm, 6,000 mm/min,
/// 500 mm/s²) sixteen times the braking distance. 32 KiB of steps. A power of two.
pub const STEP_RING_LEN: usize = 16_384;

/// Chunks in the ring, at most: a chunk is at least one step, usually [`CHUNK_STEPS`] or a
/// straight run, so a curve's chunks cover the whole ring. When they run out the scan waits,
/// as for blocks.
pub const CHUNK_RING_LEN: usize = STEP_RING_LEN / CHUNK_STEPS;

/// Steps per chunk on a curve: the scan reads the tangent, and works out the caps, once per
/// chunk. 32 steps turn by 6° on a circle of 300 steps radius, so the caps follow the curve
/// closely; kinks do not wait for a chunk's end (a fill stops at each).
pub const CHUNK_STEPS: usize = 32;

/// Steps per chunk on a straight line
/// ([`Interpolator::straight_steps_left`](crate::motion::interp::Interpolator::straight_steps_left)): its steps all have
/// the same length and caps.
pub const STRAIGHT_CHUNK_STEPS: usize = 256;

/// Steps scanned by [`Planner::push`](crate::motion::planner::Planner::push) at once: a short segment is
/// planned in full at once.
pub const SCAN_STEPS_PER_PUSH: usize = 64;

/// The step generator scans again once this many steps were emitted since the scan last ran
/// (and at the start of every run): often, so that the scan's work comes in small pieces
/// between the steps, never in one long stretch the step queue must cover.
pub const SCAN_EVERY_STEPS: usize = 128;

/// Most steps the step generator scans in one call: about 10,000 instructions on a straight
/// line, 80,000 on a function of a dozen operations, under a millisecond of the F407: well
/// within what the step queue holds at the highest pulse rate (see
/// [`STEP_QUEUE_LEN`](crate::motion::pulse::STEP_QUEUE_LEN)).
pub const SCAN_STEPS_PER_CALL: usize = 256;

/// How far ahead the scan keeps, at least, as a share of the distance to brake from the highest
/// cap scanned: beyond it the scan only keeps pace with the motion (see `keep_scanning`).
pub const LEAD_SHARE: f32 = 1.25;

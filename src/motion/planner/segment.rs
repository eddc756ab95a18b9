//! What the scan works from: a queued segment, a curve with its method and feed.

use crate::motion::interp::Method;
use crate::motion::planner::scaling::Scale;

/// One queued curve, waiting to be scanned or being scanned.
pub(crate) struct Segment<C> {
    pub curve: C,
    pub method: Method,
    /// The feed, mm/s (unbounded for rapid), and which override scales it.
    pub requested_mm_per_s: f32,
    pub scale: Scale,
}

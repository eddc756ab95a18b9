//! What the scan works from: the queued segments (a curve with its method and feed), and where
//! the scan stands on the front one.

use crate::interp::{Method, Tangent};
use crate::planner::limits::StepGeometry;
use crate::planner::scaling::Scale;

/// One queued curve, waiting to be scanned or being scanned.
pub(crate) struct Segment<C> {
    pub curve: C,
    pub method: Method,
    /// The feed, mm/s (unbounded for rapid), and which override scales it.
    pub requested_mm_per_s: f32,
    pub scale: Scale,
}

/// Where the scan stands on the front segment.
#[derive(Clone, Copy)]
pub(crate) struct ScanPoint {
    /// The segment's first chunk is still to come.
    pub(super) fresh: bool,
    /// The tangent at the scan point, and the geometry of a step along it.
    pub(super) tangent: Tangent,
    pub(super) at: StepGeometry,
    /// The last chunk ran straight (the tangent did not change over it): the next one extends
    /// it if it runs straight on.
    pub(super) straight: bool,
    /// The last step scanned reached a kink from this direction (mm): the next step is a chunk
    /// and a block of its own, passed by the junction rule.
    pub(super) kink_from_mm: Option<[f32; 2]>,
}

impl ScanPoint {
    pub const fn new() -> Self {
        ScanPoint {
            fresh: true,
            tangent: Tangent { x: 1.0, y: 0.0 },
            at: StepGeometry { step_mm: 0.0, dir_mm: [1.0, 0.0] },
            straight: false,
            kink_from_mm: None,
        }
    }
}

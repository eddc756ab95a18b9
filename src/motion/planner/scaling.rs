//! What a block's caps are made of, so that the feed and rapid overrides can set them again on
//! motion already queued: the machine's own cap kept apart from the feed asked for, and which
//! override scales that block.
//!
//! A step's speed cap is `min(feed · feed override, machine)` for feed motion, `machine · rapid
//! override` for a rapid (its feed is unbounded) and `min(feed, machine)` for a jog, never below
//! [`MIN_SPEED_MM_PER_S`]. "Machine" is everything [`Limits::step_limit`] caps (axis max rates,
//! the drivers' pulse rate, curvature, kinks), so no override ever goes beyond it, as in GRBL.
//!
//! The tangential acceleration a step allows falls as its speed rises on a curve (the
//! centripetal part grows, [`Limits::accel_at`]). A block keeps the acceleration found when it
//! was scanned, which holds up to the speed it was scanned at, and its largest curvature, from
//! which [`Limits::accel_floor`] gives one that holds at the machine's cap. Per step, the
//! acceleration is a concave function of `v²` (the least of affine ones), so the straight line
//! between those two points in `v²` lies below it: [`CapBasis::accel_at`] is safe at every speed
//! up to the machine's cap. The scan pays for this with a few comparisons per chunk.

use crate::math;
use crate::motion::overrides::Overrides;
use crate::motion::planner::limits::{Caps, Limits, MIN_SPEED_MM_PER_S, StepLimit};

/// Percent in a whole: a factor of 1 is 100 %.
const PERCENT_PER_UNIT: f32 = 100.0;

/// Which override scales a segment's speed.
///
/// A word, not a byte: a [`CapBasis`] then has no padding, and the planner's queue of blocks
/// starts as a plain clear (its default is all zeros), not as many small copies.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(u32)]
pub(crate) enum Scale {
    /// A jog (or a block that fails): no override.
    #[default]
    Fixed,
    /// Feed motion: the feed override scales the feed.
    Feed,
    /// A rapid: the rapid override scales the machine's speed.
    Rapid,
}

/// The speed overrides in force, as factors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Factors {
    pub feed: f32,
    pub rapid: f32,
}

impl Factors {
    /// Speeds as programmed.
    pub const NONE: Factors = Factors { feed: 1.0, rapid: 1.0 };

    pub fn from_overrides(overrides: Overrides) -> Factors {
        Factors {
            feed: f32::from(overrides.feed_percent) / PERCENT_PER_UNIT,
            rapid: f32::from(overrides.rapid_percent) / PERCENT_PER_UNIT,
        }
    }
}

impl Scale {
    /// The speed asked of a step the machine allows `machine_mm_per_s`, for a feed of
    /// `requested_mm_per_s`.
    pub fn speed(self, requested_mm_per_s: f32, machine_mm_per_s: f32, factors: Factors) -> f32 {
        let speed = match self {
            Scale::Feed => math::min(requested_mm_per_s * factors.feed, machine_mm_per_s),
            Scale::Rapid => math::min(requested_mm_per_s, machine_mm_per_s * factors.rapid),
            Scale::Fixed => math::min(requested_mm_per_s, machine_mm_per_s),
        };
        math::max(speed, MIN_SPEED_MM_PER_S)
    }

    /// True when the machine, not the feed, decides the speed of a step it allows
    /// `machine_mm_per_s`.
    pub fn machine_binds(self, requested_mm_per_s: f32, machine_mm_per_s: f32, factors: Factors) -> bool {
        match self {
            Scale::Feed => machine_mm_per_s < requested_mm_per_s * factors.feed,
            Scale::Rapid => true,
            Scale::Fixed => machine_mm_per_s < requested_mm_per_s,
        }
    }
}

/// What a chunk of steps allows: its caps at the overrides in force, and what the machine
/// allows it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ChunkCaps {
    pub own: Caps,
    pub machine_mm_per_s: f32,
    /// The path's curvature there, 1/mm (0 where it runs straight).
    pub curvature_per_mm: f32,
}

impl ChunkCaps {
    /// The caps of steps within `limit`, asked to go at `requested_mm_per_s` scaled by `scale`.
    #[inline]
    pub fn new(limits: &Limits, limit: &StepLimit, scale: Scale, requested_mm_per_s: f32, factors: Factors) -> Self {
        let speed = scale.speed(requested_mm_per_s, limit.speed_mm_per_s, factors);
        ChunkCaps {
            own: Caps { speed_mm_per_s: speed, accel_mm_per_s2: limits.accel_at(limit, speed) },
            machine_mm_per_s: limit.speed_mm_per_s,
            curvature_per_mm: limit.curvature_per_mm,
        }
    }
}

/// What a block's caps are made of; see the module documentation.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct CapBasis {
    pub scale: Scale,
    /// The feed asked for, mm/s (unbounded for a rapid).
    pub requested_mm_per_s: f32,
    /// What the machine allows every step of the block, mm/s.
    pub machine_mm_per_s: f32,
    /// The largest curvature of its steps, 1/mm: what [`Limits::accel_floor`] needs.
    pub curvature_per_mm: f32,
    /// The caps it was scanned with (or, for the block at the scan's front, those in force at
    /// the last change of override): their acceleration holds for every step of the block up to
    /// their speed.
    pub scanned: Caps,
}

impl CapBasis {
    /// The basis of a block whose first chunk allows `chunk`, with its caps `keep` (a fraction just
    /// below 1) of the chunk's where the machine decides them.
    pub fn new(chunk: &ChunkCaps, scale: Scale, requested_mm_per_s: f32, factors: Factors, keep: f32) -> Self {
        let machine_mm_per_s = chunk.machine_mm_per_s;
        // The margin only where the machine limits the speed: the feed itself is kept.
        let machine_mm_per_s = if scale.machine_binds(requested_mm_per_s, machine_mm_per_s, factors) {
            machine_mm_per_s * keep
        } else {
            machine_mm_per_s
        };
        CapBasis {
            scale,
            requested_mm_per_s,
            machine_mm_per_s,
            curvature_per_mm: chunk.curvature_per_mm,
            scanned: Caps {
                speed_mm_per_s: scale.speed(requested_mm_per_s, machine_mm_per_s, factors),
                accel_mm_per_s2: chunk.own.accel_mm_per_s2 * keep,
            },
        }
    }

    /// Takes in the steps of another chunk, allowing `chunk`, which the block takes: its own
    /// caps are no lower than the block's caps in force, and these are [`Self::scanned`] (see
    /// [`Self::rebase`]), so the scanned acceleration holds for its steps too.
    pub fn join(&mut self, chunk: &ChunkCaps) {
        self.machine_mm_per_s = math::min(self.machine_mm_per_s, chunk.machine_mm_per_s);
        self.curvature_per_mm = math::max(self.curvature_per_mm, chunk.curvature_per_mm);
    }

    /// The block's caps are now `caps` (an override changed), which hold for its steps: the
    /// steps it takes in from now on are compared with them, so they become the scanned ones.
    pub fn rebase(&mut self, caps: Caps) {
        self.scanned = caps;
    }

    /// The block's speed cap at `factors`.
    pub fn speed(&self, factors: Factors) -> f32 {
        self.scale.speed(self.requested_mm_per_s, self.machine_mm_per_s, factors)
    }

    /// An acceleration that holds for every step of the block at speeds up to `speed_mm_per_s`
    /// (at most the machine's cap): the one it was scanned with, and above that speed, on a
    /// curve, the straight line in `v²` from it down to [`Limits::accel_floor`] at the machine's
    /// cap.
    pub fn accel_at(&self, limits: &Limits, speed_mm_per_s: f32) -> f32 {
        let low = self.scanned;
        if speed_mm_per_s <= low.speed_mm_per_s || self.curvature_per_mm <= 0.0 {
            return low.accel_mm_per_s2;
        }
        let high = Caps {
            speed_mm_per_s: self.machine_mm_per_s,
            accel_mm_per_s2: limits.accel_floor(self.curvature_per_mm, self.machine_mm_per_s),
        };
        if high.accel_mm_per_s2 >= low.accel_mm_per_s2 {
            return low.accel_mm_per_s2;
        }
        let low2 = low.speed_mm_per_s * low.speed_mm_per_s;
        let span = high.speed_mm_per_s * high.speed_mm_per_s - low2;
        if span <= 0.0 {
            return high.accel_mm_per_s2;
        }
        let t = math::min((speed_mm_per_s * speed_mm_per_s - low2) / span, 1.0);
        low.accel_mm_per_s2 + (high.accel_mm_per_s2 - low.accel_mm_per_s2) * t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::planner::limits::{Bend, StepGeometry};

    const HALF: Factors = Factors { feed: 0.5, rapid: 0.25 };

    #[test]
    fn each_override_scales_its_own_kind_of_motion_within_the_machines_cap() {
        assert_eq!(Scale::Feed.speed(50.0, 100.0, HALF), 25.0);
        assert_eq!(Scale::Feed.speed(50.0, 100.0, Factors { feed: 2.0, rapid: 1.0 }), 100.0);
        assert_eq!(Scale::Feed.speed(80.0, 100.0, Factors { feed: 2.0, rapid: 1.0 }), 100.0);
        assert_eq!(Scale::Rapid.speed(f32::INFINITY, 100.0, HALF), 25.0);
        assert_eq!(Scale::Fixed.speed(50.0, 100.0, HALF), 50.0);
        assert_eq!(Scale::Feed.speed(MIN_SPEED_MM_PER_S, 100.0, HALF), MIN_SPEED_MM_PER_S, "never below the floor");
    }

    #[test]
    fn the_acceleration_floor_holds_in_every_direction() {
        let limits = Limits::try_from_settings(&crate::settings::Settings {
            accel_mm_per_s2: [500.0, 800.0],
            ..crate::settings::Settings::default()
        })
        .unwrap();
        for k in 0..72 {
            let a = k as f32 * core::f32::consts::TAU / 72.0;
            let g = StepGeometry { step_mm: 0.01, dir_mm: [math::cos(a), math::sin(a)] };
            let limit = limits.step_limit(&g, Bend::Curve { curvature_per_mm: 0.1 });
            for v in [1.0, 20.0, 40.0, limit.speed_mm_per_s] {
                let floor = limits.accel_floor(0.1, v);
                assert!(floor <= limits.accel_at(&limit, v) * 1.000_01, "{k}: {floor} at {v} mm/s");
            }
        }
        // At the curvature cap (80 % of the slower axis' 500 mm/s² is centripetal), 60 % is left.
        assert!((limits.accel_floor(0.1, math::sqrt(4_000.0)) - 300.0).abs() < 0.01);
    }

    #[test]
    fn a_curves_acceleration_falls_with_speed_and_the_basis_stays_below_it() {
        let limits = Limits::default();
        for dir_mm in [[0.6, 0.8], [1.0, 0.0], [0.0, -1.0], [-0.96, 0.28]] {
            let g = StepGeometry { step_mm: 0.01, dir_mm };
            let limit = limits.step_limit(&g, Bend::Curve { curvature_per_mm: 0.05 });
            let chunk = ChunkCaps::new(&limits, &limit, Scale::Feed, 30.0, Factors::NONE);
            assert_eq!(chunk.own.speed_mm_per_s, 30.0);
            let basis = CapBasis::new(&chunk, Scale::Feed, 30.0, Factors::NONE, 1.0);
            for i in 0..=20 {
                let v = 30.0 + (limit.speed_mm_per_s - 30.0) * i as f32 / 20.0;
                let a = basis.accel_at(&limits, v);
                assert!(a <= limits.accel_at(&limit, v) * 1.000_01, "{dir_mm:?} at {v} mm/s: {a}");
                assert!(a >= limits.accel_floor(0.05, limit.speed_mm_per_s) * 0.999_99);
            }
            assert_eq!(basis.accel_at(&limits, 10.0), chunk.own.accel_mm_per_s2);
            // Straight on, the acceleration does not depend on the speed.
            let line = limits.step_limit(&g, Bend::Straight);
            let chunk = ChunkCaps::new(&limits, &line, Scale::Feed, 30.0, Factors::NONE);
            let basis = CapBasis::new(&chunk, Scale::Feed, 30.0, Factors::NONE, 1.0);
            assert_eq!(basis.accel_at(&limits, line.speed_mm_per_s), chunk.own.accel_mm_per_s2);
        }
    }
}

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
//! centripetal part grows, [`Limits::accel_at`]). A block keeps two points of it: the
//! acceleration found when it was scanned, which holds up to the speed it was scanned at, and
//! the one at the machine's cap. Per step, the acceleration is a concave function of `v²` (the
//! least of affine ones), so the straight line between those two points in `v²` lies below it:
//! [`CapBasis::accel_at`] is safe at every speed up to the machine's cap.

use crate::math;
use crate::overrides::Overrides;
use crate::planner::limits::{Caps, Limits, MIN_SPEED_MM_PER_S, StepLimit};

/// Percent in one.
const PERCENT: f32 = 100.0;

/// Which override scales a segment's speed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum Scale {
    /// Feed motion: the feed override scales the feed.
    Feed,
    /// A rapid: the rapid override scales the machine's speed.
    Rapid,
    /// A jog (or a block that fails): no override.
    #[default]
    Fixed,
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
            feed: f32::from(overrides.feed_percent) / PERCENT,
            rapid: f32::from(overrides.rapid_percent) / PERCENT,
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

/// What a chunk of steps allows: at the overrides in force, and at the machine's own cap.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ChunkCaps {
    pub own: Caps,
    pub machine: Caps,
}

impl ChunkCaps {
    /// The caps of steps within `limit`, asked to go at `requested_mm_per_s` scaled by `scale`.
    pub fn new(limits: &Limits, limit: &StepLimit, scale: Scale, requested_mm_per_s: f32, factors: Factors) -> Self {
        let machine_mm_per_s = limit.speed_mm_per_s;
        let speed = scale.speed(requested_mm_per_s, machine_mm_per_s, factors);
        let accel = limits.accel_at(limit, speed);
        // Only a curve's acceleration depends on the speed.
        let machine_accel = if limit.curvature_per_mm > 0.0 && speed < machine_mm_per_s {
            limits.accel_at(limit, machine_mm_per_s)
        } else {
            accel
        };
        ChunkCaps {
            own: Caps { speed_mm_per_s: speed, accel_mm_per_s2: accel },
            machine: Caps { speed_mm_per_s: machine_mm_per_s, accel_mm_per_s2: machine_accel },
        }
    }
}

/// What a block's caps are made of; see the module documentation.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct CapBasis {
    pub scale: Scale,
    /// The feed asked for, mm/s (unbounded for a rapid).
    pub requested_mm_per_s: f32,
    /// What the machine allows every step of the block: speed, and an acceleration that holds up
    /// to that speed.
    pub machine: Caps,
    /// An acceleration that holds for every step of the block up to that speed (those it was
    /// scanned with).
    pub scanned: Caps,
}

impl CapBasis {
    /// The basis of a block whose first chunk allows `chunk`, with its caps `keep` (a fraction just
    /// below 1) of the chunk's where the machine decides them.
    pub fn new(chunk: &ChunkCaps, scale: Scale, requested_mm_per_s: f32, factors: Factors, keep: f32) -> Self {
        let machine_mm_per_s = chunk.machine.speed_mm_per_s;
        // The margin only where the machine limits the speed: the feed itself is kept.
        let machine_mm_per_s = if scale.machine_binds(requested_mm_per_s, machine_mm_per_s, factors) {
            machine_mm_per_s * keep
        } else {
            machine_mm_per_s
        };
        CapBasis {
            scale,
            requested_mm_per_s,
            machine: Caps { speed_mm_per_s: machine_mm_per_s, accel_mm_per_s2: chunk.machine.accel_mm_per_s2 * keep },
            scanned: Caps {
                speed_mm_per_s: scale.speed(requested_mm_per_s, machine_mm_per_s, factors),
                accel_mm_per_s2: chunk.own.accel_mm_per_s2 * keep,
            },
        }
    }

    /// Takes in the steps of another chunk, allowing `chunk`.
    pub fn join(&mut self, chunk: &ChunkCaps) {
        let least = |a: &mut Caps, b: &Caps| {
            a.speed_mm_per_s = math::min(a.speed_mm_per_s, b.speed_mm_per_s);
            a.accel_mm_per_s2 = math::min(a.accel_mm_per_s2, b.accel_mm_per_s2);
        };
        least(&mut self.machine, &chunk.machine);
        least(&mut self.scanned, &chunk.own);
    }

    /// The block's speed cap at `factors`.
    pub fn speed(&self, factors: Factors) -> f32 {
        self.scale.speed(self.requested_mm_per_s, self.machine.speed_mm_per_s, factors)
    }

    /// An acceleration that holds for every step of the block at speeds up to `speed_mm_per_s`
    /// (at most the machine's cap).
    pub fn accel_at(&self, speed_mm_per_s: f32) -> f32 {
        let (low, high) = (self.scanned, self.machine);
        let high_accel = math::min(high.accel_mm_per_s2, low.accel_mm_per_s2);
        if speed_mm_per_s <= low.speed_mm_per_s || high_accel >= low.accel_mm_per_s2 {
            return low.accel_mm_per_s2;
        }
        let low2 = low.speed_mm_per_s * low.speed_mm_per_s;
        let span = high.speed_mm_per_s * high.speed_mm_per_s - low2;
        if span <= 0.0 {
            return high_accel;
        }
        let t = math::min((speed_mm_per_s * speed_mm_per_s - low2) / span, 1.0);
        low.accel_mm_per_s2 + (high_accel - low.accel_mm_per_s2) * t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planner::limits::{Bend, StepGeometry};

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
    fn a_curves_acceleration_falls_with_speed_and_the_basis_stays_below_it() {
        let limits = Limits::default();
        let g = StepGeometry { step_mm: 0.01, dir_mm: [0.6, 0.8] };
        let limit = limits.step_limit(&g, Bend::Curve { curvature_per_mm: 0.05 });
        let chunk = ChunkCaps::new(&limits, &limit, Scale::Feed, 30.0, Factors::NONE);
        assert_eq!(chunk.own.speed_mm_per_s, 30.0);
        assert!(chunk.machine.accel_mm_per_s2 < chunk.own.accel_mm_per_s2);
        let basis = CapBasis::new(&chunk, Scale::Feed, 30.0, Factors::NONE, 1.0);
        for i in 0..=20 {
            let v = 30.0 + (limit.speed_mm_per_s - 30.0) * i as f32 / 20.0;
            let a = basis.accel_at(v);
            assert!(a <= limits.accel_at(&limit, v) * 1.000_01, "at {v} mm/s: {a}");
            assert!(a >= chunk.machine.accel_mm_per_s2 * 0.999_99);
        }
        assert_eq!(basis.accel_at(10.0), chunk.own.accel_mm_per_s2);
        // Straight on, the acceleration does not depend on the speed.
        let line = limits.step_limit(&g, Bend::Straight);
        let chunk = ChunkCaps::new(&limits, &line, Scale::Feed, 30.0, Factors::NONE);
        let basis = CapBasis::new(&chunk, Scale::Feed, 30.0, Factors::NONE, 1.0);
        assert_eq!(basis.accel_at(line.speed_mm_per_s), chunk.own.accel_mm_per_s2);
    }
}

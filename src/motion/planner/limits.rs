//! The machine limits the planner works with, and the speeds they allow a step.
//!
//! [`Limits`] is the planner's view of [`Settings`]: converted to mm/s and mm/s², checked once
//! (every value finite and inside its setting's range), so the planner's arithmetic never meets a
//! NaN, an infinity or a zero. The functions here are pure: the distance along the ideal curve one
//! step advances, the speed and acceleration caps of a step (its direction, the curve's bend
//! there), the GRBL junction speed, and [`plot_time_lower_bound`].

use crate::geom::{Point, TICK_HZ};
use crate::math;
use crate::motion::interp::{Method, Tangent};
use crate::motion::job::Feed;
use crate::settings::{SETTING_INFO, Settings};

/// Slowest feed the planner runs; a positive feed below it is raised to it. Also the
/// planner's floor for any speed, which keeps every interval far inside `u32` ticks (one step of
/// at most √2 mm at 1 mm/min lasts under 85 s).
pub const MIN_FEED_MM_PER_MIN: f32 = 1.0;

const SECONDS_PER_MINUTE: f32 = 60.0;

/// Slowest speed of any step, mm/s.
pub(crate) const MIN_SPEED_MM_PER_S: f32 = MIN_FEED_MM_PER_MIN / SECONDS_PER_MINUTE;

/// The settings the planner uses (by `$` number), each checked against its range.
const CHECKED_SETTINGS: [u16; 10] = [11, 100, 101, 110, 111, 120, 121, 201, 203, 205];

/// Why settings cannot be turned into [`Limits`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum LimitsError {
    /// The setting with this `$` number is not finite or outside its range (for the start rate
    /// ($201): also above the slower axis' max rate).
    OutOfRange(u16),
}

/// Rates, accelerations and geometry for the planner, in mm, mm/s and mm/s².
///
/// Only [`Limits::try_from_settings`] and [`Limits::from_settings`] make one, so every value is
/// known to be finite and positive (the junction deviation may be zero).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Limits {
    pub(crate) steps_per_mm: [f32; 2],
    pub(crate) max_speed_mm_per_s: [f32; 2],
    pub(crate) accel_mm_per_s2: [f32; 2],
    pub(crate) start_speed_mm_per_s: f32,
    /// Highest step rate; rounded down so that its period is a whole number of ticks.
    pub(crate) max_pulse_rate_hz: f32,
    /// Shortest interval between two pulses, `TICK_HZ / max_pulse_rate_hz`.
    pub(crate) min_interval_ticks: u32,
    pub(crate) junction_deviation_mm: f32,
    pub(crate) default_feed_mm_per_s: f32,
}

/// The limits of [`Settings::default`], written out: what [`Limits::from_settings`] falls back
/// to should the default settings themselves ever be out of range.
const FALLBACK: Limits = Limits {
    steps_per_mm: [100.0, 100.0],
    max_speed_mm_per_s: [100.0, 100.0],
    accel_mm_per_s2: [500.0, 500.0],
    start_speed_mm_per_s: 5.0,
    max_pulse_rate_hz: 20_000.0,
    min_interval_ticks: 50,
    junction_deviation_mm: 0.02,
    default_feed_mm_per_s: 50.0,
};

impl Default for Limits {
    /// The limits of the default settings.
    fn default() -> Self {
        Limits::from_settings(&Settings::default())
    }
}

/// The setting `id` among those the planner uses, to repair it.
fn setting_mut(s: &mut Settings, id: u16) -> Option<&mut f32> {
    Some(match id {
        11 => &mut s.junction_deviation_mm,
        100 | 101 => s.steps_per_mm.get_mut(usize::from(id - 100))?,
        110 | 111 => s.max_rate_mm_per_min.get_mut(usize::from(id - 110))?,
        120 | 121 => s.accel_mm_per_s2.get_mut(usize::from(id - 120))?,
        201 => &mut s.start_rate_mm_per_min,
        203 => &mut s.default_feed_mm_per_min,
        205 => &mut s.max_pulse_rate_hz,
        _ => return None,
    })
}

impl Limits {
    /// The planner's limits from the machine settings, never failing: a value out of its range
    /// is clamped into it, one that is not a number takes its default, and a start rate above the
    /// slower axis' max rate is lowered to it. [`Settings::set`] keeps settings in range, so this
    /// only matters for settings built or stored by other means.
    pub fn from_settings(s: &Settings) -> Limits {
        if let Ok(limits) = Limits::try_from_settings(s) {
            return limits;
        }
        let defaults = Settings::default();
        let mut fixed = *s;
        for id in CHECKED_SETTINGS {
            let range = SETTING_INFO.iter().find(|info| info.id == id).map(|info| (info.min, info.max));
            let default = defaults.get(id).ok();
            if let (Some(value), Some((min, max)), Some(default)) = (setting_mut(&mut fixed, id), range, default) {
                *value = if value.is_nan() { default } else { math::min(math::max(*value, min), max) };
            }
        }
        let slowest_max = math::min(fixed.max_rate_mm_per_min[0], fixed.max_rate_mm_per_min[1]);
        fixed.start_rate_mm_per_min = math::min(fixed.start_rate_mm_per_min, slowest_max);
        Limits::try_from_settings(&fixed).unwrap_or(FALLBACK)
    }

    /// The planner's limits from the machine settings, or which setting is out of range (then
    /// nothing is made).
    pub fn try_from_settings(s: &Settings) -> Result<Limits, LimitsError> {
        for id in CHECKED_SETTINGS {
            let value = s.get(id).map_err(|_| LimitsError::OutOfRange(id))?;
            let in_range = SETTING_INFO
                .iter()
                .find(|info| info.id == id)
                .is_some_and(|info| value.is_finite() && value >= info.min && value <= info.max);
            if !in_range {
                return Err(LimitsError::OutOfRange(id));
            }
        }
        let per_s = |mm_per_min: f32| mm_per_min / SECONDS_PER_MINUTE;
        let slowest_max = math::min(s.max_rate_mm_per_min[0], s.max_rate_mm_per_min[1]);
        if s.start_rate_mm_per_min > slowest_max {
            return Err(LimitsError::OutOfRange(201));
        }
        // The shortest interval is a whole number of ticks, so the speed cap below and the
        // interval floor in the planner agree exactly.
        let min_interval_ticks = math::max(math::ceil(TICK_HZ as f32 / s.max_pulse_rate_hz), 1.0) as u32;
        Ok(Limits {
            steps_per_mm: s.steps_per_mm,
            max_speed_mm_per_s: [per_s(s.max_rate_mm_per_min[0]), per_s(s.max_rate_mm_per_min[1])],
            accel_mm_per_s2: s.accel_mm_per_s2,
            start_speed_mm_per_s: per_s(s.start_rate_mm_per_min),
            max_pulse_rate_hz: TICK_HZ as f32 / min_interval_ticks as f32,
            min_interval_ticks,
            junction_deviation_mm: s.junction_deviation_mm,
            default_feed_mm_per_s: per_s(s.default_feed_mm_per_min),
        })
    }

    /// Speed at which motion starts from rest and at which it may stop, mm/s.
    pub fn start_speed_mm_per_s(&self) -> f32 {
        self.start_speed_mm_per_s
    }

    /// Fastest travel of each axis, mm/s.
    pub fn max_speed_mm_per_s(&self) -> [f32; 2] {
        self.max_speed_mm_per_s
    }

    /// Acceleration of each axis, mm/s².
    pub fn accel_mm_per_s2(&self) -> [f32; 2] {
        self.accel_mm_per_s2
    }

    /// Steps per millimetre of each axis.
    pub fn steps_per_mm(&self) -> [f32; 2] {
        self.steps_per_mm
    }

    /// Highest step rate (any interval is at least its period), Hz.
    pub fn max_pulse_rate_hz(&self) -> f32 {
        self.max_pulse_rate_hz
    }

    /// Shortest interval between two pulses, ticks: the period of [`Self::max_pulse_rate_hz`].
    pub fn min_interval_ticks(&self) -> u32 {
        self.min_interval_ticks
    }

    /// The tangential speed a feed asks for, mm/s, before the axis caps: `Rapid` is unbounded,
    /// a feed that is zero, negative or not finite means the default feed, and a positive feed
    /// below [`MIN_FEED_MM_PER_MIN`] is raised to it.
    pub fn requested_speed_mm_per_s(&self, feed: Feed) -> f32 {
        match feed {
            Feed::Rapid => f32::INFINITY,
            Feed::MmPerMin(f) if f.is_finite() && f > 0.0 => math::max(f, MIN_FEED_MM_PER_MIN) / SECONDS_PER_MINUTE,
            Feed::MmPerMin(_) => self.default_feed_mm_per_s,
        }
    }

    /// What one step along step-space direction `dir` covers, see [`StepGeometry`].
    pub(crate) fn step_geometry(&self, method: Method, dir: UnitDir) -> StepGeometry {
        let (tx, ty) = (dir.x.abs(), dir.y.abs());
        // Distance along the ideal curve per step, in step units.
        let per_step = match method {
            Method::Classic => 1.0 / (tx + ty),
            Method::Diagonal => 1.0 / math::max(tx, ty),
        };
        let mx = dir.x / self.steps_per_mm[0];
        let my = dir.y / self.steps_per_mm[1];
        let mm_per_unit = math::sqrt(mx * mx + my * my);
        StepGeometry { step_mm: per_step * mm_per_unit, dir_mm: [mx / mm_per_unit, my / mm_per_unit] }
    }

    /// Speed and tangential acceleration the machine allows for step `g` of a curve bending by
    /// `bend` there, at a feed of `requested_mm_per_s`: the feed within [`Self::step_limit`], and
    /// the acceleration [`Self::accel_at`] that speed.
    pub(crate) fn step_caps(&self, g: &StepGeometry, bend: Bend, requested_mm_per_s: f32) -> Caps {
        let limit = self.step_limit(g, bend);
        let speed = sanitize(math::min(requested_mm_per_s, limit.speed_mm_per_s), MIN_SPEED_MM_PER_S);
        Caps { speed_mm_per_s: speed, accel_mm_per_s2: self.accel_at(&limit, speed) }
    }

    /// What the machine allows step `g` of a curve bending by `bend` there, whatever the feed.
    ///
    /// Speed: each axis' share `v·|u_axis|` within its max rate; the step no shorter than one
    /// period of the max pulse rate; where the curve bends with curvature `κ`, the centripetal
    /// acceleration `v²·κ` within [`CENTRIPETAL_SHARE`] of the slower axis' acceleration; at a
    /// kink, the junction speed (as between segments). The tangential acceleration depends on the
    /// speed on a curve: see [`Self::accel_at`].
    pub(crate) fn step_limit(&self, g: &StepGeometry, bend: Bend) -> StepLimit {
        let u = g.dir_mm;
        let mut speed = self.max_pulse_rate_hz * g.step_mm;
        for (share, max) in u.iter().zip(self.max_speed_mm_per_s) {
            if share.abs() > DIR_EPSILON {
                speed = math::min(speed, max / share.abs());
            }
        }
        let slowest_accel = math::min(self.accel_mm_per_s2[0], self.accel_mm_per_s2[1]);
        let mut curvature_per_mm = 0.0;
        match bend {
            Bend::Straight => {}
            Bend::Kink { from } => {
                let a = self.direction_accel(u, [0.0; 2], 0.0);
                speed = math::min(speed, math::max(self.junction_speed(a, from, u), self.start_speed_mm_per_s));
            }
            Bend::Curve { curvature_per_mm: k } => {
                if k > 0.0 && k.is_finite() {
                    let v2 = CENTRIPETAL_SHARE * slowest_accel / k;
                    speed = math::min(speed, math::max(math::sqrt(v2), self.start_speed_mm_per_s));
                    curvature_per_mm = k;
                }
            }
        }
        // `max` also replaces a NaN, which valid limits never produce.
        StepLimit { speed_mm_per_s: math::max(speed, MIN_SPEED_MM_PER_S), dir_mm: u, curvature_per_mm }
    }

    /// The tangential acceleration a step within `limit` allows at `speed_mm_per_s`: what each
    /// axis has left after the centripetal part at that speed, `a·|u_axis| + v²κ·|n_axis| ≤
    /// accel_axis` (n the normal), so that no axis exceeds its acceleration on a curve either.
    /// It falls as the speed rises, and does not depend on it where the path runs straight.
    pub(crate) fn accel_at(&self, limit: &StepLimit, speed_mm_per_s: f32) -> f32 {
        let u = limit.dir_mm;
        // The normal (−u_y, u_x): its X share is |u_y|, its Y share |u_x|.
        let normal = [u[1].abs(), u[0].abs()];
        self.direction_accel(u, normal, speed_mm_per_s * speed_mm_per_s * limit.curvature_per_mm)
    }

    /// A tangential acceleration every step of curvature up to `curvature_per_mm` allows at
    /// `speed_mm_per_s`, whatever its direction. [`Self::accel_at`] is the least over the axes
    /// of `(A − c·|n_axis|) / |u_axis|`, with `A` the axis' acceleration and `c = v²κ`; as `u` and
    /// `n` are at right angles, `(|u_axis|, |n_axis|)` is a unit vector, and the least of that
    /// over every direction is `√(A² − c²)` (at `|n_axis| = c / A`). So `√(A² − c²)` of the
    /// slower axis holds in every direction (or, where nothing would be left, the floor
    /// [`Self::accel_at`] falls back to).
    pub(crate) fn accel_floor(&self, curvature_per_mm: f32, speed_mm_per_s: f32) -> f32 {
        let slowest_accel = math::min(self.accel_mm_per_s2[0], self.accel_mm_per_s2[1]);
        let centripetal = speed_mm_per_s * speed_mm_per_s * curvature_per_mm;
        let left2 = slowest_accel * slowest_accel - centripetal * centripetal;
        sanitize(math::sqrt(math::max(left2, 0.0)), slowest_accel * (1.0 - CENTRIPETAL_SHARE))
    }

    /// Tangential acceleration along `u` that leaves each axis room for `centripetal_mm_per_s2`
    /// along the normal (axis shares `normal`).
    fn direction_accel(&self, u: [f32; 2], normal: [f32; 2], centripetal_mm_per_s2: f32) -> f32 {
        let mut accel = f32::INFINITY;
        for axis in 0..2 {
            let share = u[axis].abs();
            if share > DIR_EPSILON {
                let room = self.accel_mm_per_s2[axis] - centripetal_mm_per_s2 * normal[axis];
                accel = math::min(accel, room / share);
            }
        }
        let slowest_accel = math::min(self.accel_mm_per_s2[0], self.accel_mm_per_s2[1]);
        sanitize(accel, slowest_accel * (1.0 - CENTRIPETAL_SHARE))
    }

    /// Highest speed through a junction from direction `exit` to direction `entry` (mm-space unit
    /// vectors), by GRBL's junction deviation rule; see the planner's module documentation.
    /// Unbounded for a straight junction, zero for a reversal; the caller applies the floor.
    pub(crate) fn junction_speed(&self, accel_mm_per_s2: f32, exit: [f32; 2], entry: [f32; 2]) -> f32 {
        let (dx, dy) = (exit[0] - entry[0], exit[1] - entry[1]);
        let (sx, sy) = (exit[0] + entry[0], exit[1] + entry[1]);
        // |exit − entry|² = 4·sin²(φ/2) and |exit + entry| / 2 = cos(φ/2) = sin(θ/2), with φ the
        // turn and θ = π − φ the angle GRBL's rule names.
        let diff2 = dx * dx + dy * dy;
        let sin_half_theta = math::min(math::sqrt(sx * sx + sy * sy) / 2.0, 1.0);
        if diff2 <= 0.0 || diff2.is_nan() {
            return f32::INFINITY;
        }
        // 1 − sin(θ/2) = sin²(φ/2) / (1 + cos(φ/2)), without cancellation for gentle turns.
        let one_minus = (diff2 / 4.0) / (1.0 + sin_half_theta);
        let v2 = accel_mm_per_s2 * self.junction_deviation_mm * sin_half_theta / one_minus;
        if v2.is_finite() { math::sqrt(math::max(v2, 0.0)) } else { f32::INFINITY }
    }
}

/// Direction components below this count as zero.
const DIR_EPSILON: f32 = 1e-6;

/// `value` if it is a positive finite number, else `fallback`.
fn sanitize(value: f32, fallback: f32) -> f32 {
    if value.is_finite() && value > 0.0 { value } else { fallback }
}

/// A unit vector in step space, always finite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct UnitDir {
    pub x: f32,
    pub y: f32,
}

impl UnitDir {
    /// The interpolator's tangent, or — when the tangent is not a usable vector — the direction
    /// of the step taken from that point.
    pub fn from_tangent(t: Tangent, step_x: i8, step_y: i8) -> UnitDir {
        let len = math::sqrt(t.x * t.x + t.y * t.y);
        if len.is_finite() && len > DIR_EPSILON {
            UnitDir { x: t.x / len, y: t.y / len }
        } else if step_x != 0 || step_y != 0 {
            let (x, y) = (step_x as f32, step_y as f32);
            let len = math::sqrt(x * x + y * y);
            UnitDir { x: x / len, y: y / len }
        } else {
            UnitDir { x: 1.0, y: 0.0 }
        }
    }
}

/// One step's geometry.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StepGeometry {
    /// Distance along the ideal curve, mm.
    pub step_mm: f32,
    /// Direction of travel as a unit vector in mm space.
    pub dir_mm: [f32; 2],
}

/// How the curve bends at a stretch of steps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Bend {
    /// No turn.
    Straight,
    /// The direction jumps (a kink, see [`crate::motion::interp::KINK_CHORD`]) from `from` (mm) at this
    /// step.
    Kink { from: [f32; 2] },
    /// A smooth turn of this curvature.
    Curve { curvature_per_mm: f32 },
}

/// Part of the slower axis' acceleration a curve's centripetal acceleration may take; the rest
/// is left for speeding up and slowing down on the curve.
pub const CENTRIPETAL_SHARE: f32 = 0.8;

/// What the machine allows one step, whatever the feed: see [`Limits::step_limit`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct StepLimit {
    /// Highest speed, mm/s.
    pub speed_mm_per_s: f32,
    /// Direction of travel, mm space.
    dir_mm: [f32; 2],
    /// Curvature of the path, 1/mm: 0 where it runs straight (or kinks).
    pub curvature_per_mm: f32,
}

/// Speed and acceleration allowed on a stretch of path.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub(crate) struct Caps {
    pub speed_mm_per_s: f32,
    pub accel_mm_per_s2: f32,
}

/// A lower bound of the time, in seconds, the planner needs to draw the polyline through
/// `points` (in steps; the first is the start) at `feed` with `method`, from rest to rest.
///
/// The bound is the time of an ideal motion that obeys only the limits no planner can escape:
/// on every segment the speed is at most that segment's cruise speed (the feed, clamped exactly
/// as the planner clamps it to the axis max rates and the max pulse rate), and it starts and ends
/// at the start rate with ramps at the largest tangential acceleration of any segment:
/// `v(s) = min(v_segment, √(v_0² + 2·a_max·s), √(v_start² + 2·a_max·(L − s)))`, integrated as
/// `∫ ds / v(s)` over the whole length `L`, where `v_0² = v_start² + 2·a_max·δ_max` grants the
/// planner's step-wise ramp one longest step `δ_max` of lead. Corners are taken at full speed and
/// the ramps use the most generous acceleration, so the planner can only be slower (give or take
/// half a tick of rounding); for long gentle paths it comes within about 1 %. Zero for fewer than
/// two points.
pub fn plot_time_lower_bound(limits: &Limits, method: Method, feed: Feed, points: &[Point]) -> f32 {
    let requested = limits.requested_speed_mm_per_s(feed);
    let segment = |pair: &[Point]| -> Option<(f32, Caps, f32)> {
        let (dx, dy) = (pair[1].x as f32 - pair[0].x as f32, pair[1].y as f32 - pair[0].y as f32);
        if dx == 0.0 && dy == 0.0 {
            return None;
        }
        let g = limits.step_geometry(method, UnitDir::from_tangent(Tangent { x: dx, y: dy }, 0, 0));
        let caps = limits.step_caps(&g, Bend::Straight, requested);
        let (mx, my) = (dx / limits.steps_per_mm[0], dy / limits.steps_per_mm[1]);
        Some((math::sqrt(mx * mx + my * my), caps, g.step_mm))
    };
    let (mut total_mm, mut accel, mut longest_step_mm) = (0.0f32, 0.0f32, 0.0f32);
    for (len, caps, step_mm) in points.windows(2).filter_map(segment) {
        total_mm += len;
        accel = accel.max(caps.accel_mm_per_s2);
        longest_step_mm = longest_step_mm.max(step_mm);
    }
    if total_mm <= 0.0 || total_mm.is_nan() {
        return 0.0;
    }
    let stop = limits.start_speed_mm_per_s;
    let start = math::sqrt(stop * stop + 2.0 * accel * longest_step_mm);
    // Where the rising ramp (from `start` at 0) meets the falling one (to `stop` at the end).
    let half = math::min(math::max((total_mm + (stop * stop - start * start) / (2.0 * accel)) / 2.0, 0.0), total_mm);
    let (mut at_mm, mut seconds) = (0.0f32, 0.0f32);
    for (len, caps, _) in points.windows(2).filter_map(segment) {
        let (from, to) = (at_mm, at_mm + len);
        let v = caps.speed_mm_per_s;
        // Rising part: distance from the start; falling part: distance to the end.
        if from < half {
            seconds += ramp_limited_time(from, to.min(half), v, start, accel);
        }
        if to > half {
            seconds += ramp_limited_time(total_mm - to, total_mm - from.max(half), v, stop, accel);
        }
        at_mm = to;
    }
    seconds
}

/// Time to cover the distances `[near, far]` (mm from a point at rest) at speed
/// `min(cap, √(start² + 2·accel·d))`.
fn ramp_limited_time(near: f32, far: f32, cap: f32, start: f32, accel: f32) -> f32 {
    if far <= near || far.is_nan() || near.is_nan() {
        return 0.0;
    }
    if cap <= start {
        return (far - near) / cap;
    }
    let reach = (cap * cap - start * start) / (2.0 * accel);
    let ramp_end = far.min(reach);
    let mut t = 0.0;
    if near < ramp_end {
        let speed = |d: f32| math::sqrt(start * start + 2.0 * accel * d);
        t += (speed(ramp_end) - speed(near)) / accel;
    }
    let cruise = far - near.max(reach);
    if cruise > 0.0 {
        t += cruise / cap;
    }
    t
}

//! Circular arcs and full circles by point-by-point comparison (逐点比较法), and the conic
//! tracer that [`crate::interp::ellipse`] shares.
//!
//! A circle and an axis-aligned ellipse are both the zero set of
//! `F(x, y) = wx·x² + wy·y² − c` around their centre (circle: `wx = wy = 1`, `c = R²`; ellipse:
//! `wx = b²`, `wy = a²`, `c = a²b²`). The tracer walks it with integer steps and keeps `F` up to
//! date by additions only (`F(x ± 1, y) = F ± wx·(±2x) + wx`), in `i64` for circles and `i128`
//! for ellipses.
//!
//! At every point the tangent of the curve gives the two forward moves, one along each axis:
//! the one that brings the point nearer the centre on its axis ("inward") and the other
//! ("outward"). An axis whose tangent component is zero (the point lies on an axis) moves
//! inward. This reproduces the textbook tables for all four quadrants and both directions:
//!
//! - `classic`: one axis per step; `F >= 0` steps inward, `F < 0` outward (first quadrant,
//!   counter-clockwise: `F >= 0` → −X, `F < 0` → +Y). Error <= 1 step; a full circle of radius
//!   `R` started on an axis takes exactly `8R` steps, a quarter `2R`.
//! - `diagonal`: the candidates are the inward, outward and diagonal (both) moves. If the
//!   diagonal point is outside the curve the curve passes between it and the inward point,
//!   otherwise between it and the outward point; the midpoint between those two (evaluated as
//!   `4·F` in integers) picks the nearer. Every point is then within half a step of the curve
//!   along a row or a column, hence within half a step of it.
//!
//! Clockwise travel is traced as counter-clockwise travel in a frame with Y mirrored (both
//! curves are symmetric about the X axis), so one set of rules serves both directions.
//!
//! Thin tips: where an ellipse is narrower than a step or two about its long axis (`b > a²`,
//! roughly), a trace reaches that axis before the tip. The literal tables would then leave the
//! axis at once and cut the tip off; the tracer instead climbs the axis while the tip lies
//! more than half a step farther out, turns there and comes back, so tips are drawn (a pen
//! stroke up the tip and back). Everywhere else the classic steps are exactly the tables'.
//!
//! The end: the tracer counts the quadrant boundaries it crosses (a climb toward a tip still
//! belongs to the quadrant before the tip) and, in the end's quadrant, stops where its path
//! passes the line normal to the curve through the curve point nearest the end (for a circle:
//! the ray from the centre through the end). If that point is not the end (an integer end point
//! is rarely exactly on a real curve), it finishes with a few straight steps that stay as
//! close to the curve as they can. Every step moves forward in angle or along a radius, a step
//! budget caps the curve part, and the straight finish shortens the distance to the end with
//! every step, so a trace always ends, exactly on its end point.

use core::ops::{Add, Mul, Sub};

use crate::geom::{Point, Rotation, Step};
use crate::interp::{CurveError, Interpolator, Method, Tangent};

/// How far an end point (and an ellipse's start point) may lie from the curve, in steps.
/// Integer end points of real arcs are generally off the curve by up to ~0.71 step; farther
/// than this is refused with [`ArcError::EndOffCurve`].
pub const ARC_END_TOLERANCE_STEPS: u32 = 2;

/// Largest radius or semi-axis, and largest offset of a given point from the centre on either
/// axis, in steps. Five times the machine's ±100_000-step travel; keeps every discriminant far
/// from overflow (`i64` for circles, `i128` for ellipses).
pub const MAX_RADIUS_STEPS: i32 = 1_000_000;

/// Extra steps per quadrant in the curve budget, beyond the semi-axes, for starts off the curve.
const QUARTER_SLACK_STEPS: i64 = 8;

/// Why an arc or an ellipse could not be set up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum ArcError {
    /// The start point is the centre, or a radius or semi-axis is not positive.
    ZeroRadius,
    /// The start point is more than [`ARC_END_TOLERANCE_STEPS`] from the ellipse.
    StartOffCurve,
    /// The end point is more than [`ARC_END_TOLERANCE_STEPS`] from the curve, or is its centre.
    EndOffCurve,
    /// A radius, semi-axis or point offset exceeds [`MAX_RADIUS_STEPS`], or a computed point
    /// falls outside the `i32` step range.
    TooLarge,
    /// An angle is NaN or infinite.
    NotFinite,
}

/// A circular arc or full circle; see the module documentation.
#[derive(Clone, Debug)]
pub struct ArcInterp {
    tracer: Tracer<i64>,
    center: Point,
    end: Point,
    rotation: Rotation,
}

impl ArcInterp {
    /// An arc from `start` around `center` to `end`, in absolute steps.
    ///
    /// The radius is `|start − center|`. `end` may lie up to [`ARC_END_TOLERANCE_STEPS`] off the
    /// circle; the arc still ends exactly on it. `end == start`, or an end on the ray from the
    /// centre through the start, means one full turn.
    pub fn new(start: Point, center: Point, end: Point, rotation: Rotation, method: Method) -> Result<Self, ArcError> {
        let s = offset(start, center);
        let e = offset(end, center);
        if s == (0, 0) {
            return Err(ArcError::ZeroRadius);
        }
        let max = MAX_RADIUS_STEPS as i64;
        if s.0.abs() > max || s.1.abs() > max {
            return Err(ArcError::TooLarge);
        }
        // Beyond twice the limit an end cannot be within tolerance; checked before squaring.
        if e == (0, 0) || e.0.abs() > 2 * max || e.1.abs() > 2 * max {
            return Err(ArcError::EndOffCurve);
        }
        let r2 = s.0 * s.0 + s.1 * s.1;
        let off = libm::sqrt((e.0 * e.0 + e.1 * e.1) as f64) - libm::sqrt(r2 as f64);
        if libm::fabs(off) > ARC_END_TOLERANCE_STEPS as f64 {
            return Err(ArcError::EndOffCurve);
        }
        // The nearest point of the circle lies on the end's own ray.
        let plan = Plan::ToEnd { near: (e.0 as f64, e.1 as f64) };
        Ok(Self::build(s, e, r2, center, end, rotation, method, plan))
    }

    /// An arc that starts at the pen point `start`, which lies at `start_angle_rad` on a circle
    /// of `radius` steps; the centre is `start − radius·(cos, sin)`, rounded to the lattice
    /// (so the actual radius, `|start − center|`, is within 0.71 step of `radius`).
    ///
    /// A positive `sweep_rad` turns counter-clockwise, a negative one clockwise; a sweep of at
    /// least 2π either way draws the full circle (one turn). The end is the lattice point
    /// nearest to the ideal end ([`end`](Self::end) tells it). The number of quadrants swept
    /// comes from the angles, not from the rounded points, so rounding never turns a short arc
    /// into a full turn or back: an arc shorter than half a turn whose end rounds onto the
    /// start takes no steps.
    pub fn from_angles(
        start: Point,
        radius: i32,
        start_angle_rad: f32,
        sweep_rad: f32,
        method: Method,
    ) -> Result<Self, ArcError> {
        if !start_angle_rad.is_finite() || !sweep_rad.is_finite() {
            return Err(ArcError::NotFinite);
        }
        if radius <= 0 {
            return Err(ArcError::ZeroRadius);
        }
        if radius > MAX_RADIUS_STEPS {
            return Err(ArcError::TooLarge);
        }
        let (theta, sweep, r) = (start_angle_rad as f64, sweep_rad as f64, radius as f64);
        let s = (round(r * libm::cos(theta)), round(r * libm::sin(theta)));
        if s == (0, 0) {
            return Err(ArcError::ZeroRadius);
        }
        let center = point_at(start, (-s.0, -s.1))?;
        let r2 = s.0 * s.0 + s.1 * s.1;
        let rotation = if sweep < 0.0 { Rotation::Clockwise } else { Rotation::CounterClockwise };
        let start_angle = libm::atan2(s.1 as f64, s.0 as f64);
        let from = (s.0 as f64, s.1 as f64);
        let (e, plan) = if libm::fabs(sweep) >= core::f64::consts::TAU {
            (s, Plan::ToEnd { near: from })
        } else {
            let r_actual = libm::sqrt(r2 as f64);
            let end_angle = start_angle + sweep;
            let to = (r_actual * libm::cos(end_angle), r_actual * libm::sin(end_angle));
            let e = (round(to.0), round(to.1));
            (e, Plan::between(from, to, sweep, e == s))
        };
        let end = point_at(center, e)?;
        Ok(Self::build(s, e, r2, center, end, rotation, method, plan))
    }

    #[allow(clippy::too_many_arguments)]
    fn build(
        s: (i64, i64),
        e: (i64, i64),
        r2: i64,
        center: Point,
        end: Point,
        rotation: Rotation,
        method: Method,
        plan: Plan,
    ) -> Self {
        // Ceiling of the radius, for the step budget.
        let r = libm::sqrt(r2 as f64) as i64 + 1;
        let tracer = Tracer::new(s, e, plan, (1, 1), r2, (r, r), rotation, method);
        ArcInterp { tracer, center, end, rotation }
    }

    /// The centre, in absolute steps.
    pub fn center(&self) -> Point {
        self.center
    }

    /// The point where the arc ends, in absolute steps.
    pub fn end(&self) -> Point {
        self.end
    }

    /// The direction of travel.
    pub fn rotation(&self) -> Rotation {
        self.rotation
    }
}

impl Interpolator for ArcInterp {
    fn next_step(&mut self) -> Result<Option<Step>, CurveError> {
        Ok(self.tracer.next())
    }

    fn tangent(&self) -> Tangent {
        self.tracer.tangent()
    }
}

/// `p − origin` in `i64` (cannot overflow).
pub(crate) fn offset(p: Point, origin: Point) -> (i64, i64) {
    (p.x as i64 - origin.x as i64, p.y as i64 - origin.y as i64)
}

/// `origin + (dx, dy)`, or [`ArcError::TooLarge`] outside the `i32` range.
pub(crate) fn point_at(origin: Point, d: (i64, i64)) -> Result<Point, ArcError> {
    let x = i32::try_from(origin.x as i64 + d.0).map_err(|_| ArcError::TooLarge)?;
    let y = i32::try_from(origin.y as i64 + d.1).map_err(|_| ArcError::TooLarge)?;
    Ok(Point::new(x, y))
}

/// Nearest integer (saturating; callers bound their inputs).
pub(crate) fn round(v: f64) -> i64 {
    libm::round(v) as i64
}

/// How a tracer finds its end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Plan {
    /// To the end point given as a lattice point: the curve part stops at the [`Gate`] through
    /// `near`, the point of the curve nearest to the end (machine frame, relative to the
    /// centre). An end on the start's own ray (the start itself included) takes one full turn.
    ToEnd { near: (f64, f64) },
    /// Along the ideal arc from its point `from` to its point `to` (machine frame, relative to
    /// the centre), `long` when it sweeps half a turn or more; the lattice start and end are
    /// these points rounded, and may lie on either side of them.
    Between { from: (f64, f64), to: (f64, f64), long: bool },
    /// No steps: the end is the start.
    Empty,
}

impl Plan {
    /// The plan of an ideal arc from `from` to `to` sweeping `sweep` radians (less than a
    /// turn), whose end rounds onto the start when `same_point`: nothing to draw for a short
    /// sweep, which is shorter than the rounding.
    pub(crate) fn between(from: (f64, f64), to: (f64, f64), sweep: f64, same_point: bool) -> Plan {
        let long = libm::fabs(sweep) >= core::f64::consts::PI;
        if same_point && !long { Plan::Empty } else { Plan::Between { from, to, long } }
    }
}

/// Integer type of a discriminant: `i64` for circles, `i128` for ellipses.
pub(crate) trait Discriminant:
    Copy + Ord + core::fmt::Debug + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + From<i64>
{
    fn to_f32(self) -> f32;
}

impl Discriminant for i64 {
    fn to_f32(self) -> f32 {
        self as f32
    }
}

impl Discriminant for i128 {
    fn to_f32(self) -> f32 {
        self as f32
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Phase {
    /// Following the curve.
    Curve,
    /// Straight finish to the end point.
    Tail,
    /// At the end.
    Done,
}

/// The quadrant of `(x, y)`, counted counter-clockwise from +X; each quadrant includes the
/// half-axis where it begins, so a counter-clockwise path enters quadrants in order 0, 1, 2, 3.
fn quadrant(x: i64, y: i64) -> u8 {
    if x > 0 && y >= 0 {
        0
    } else if x <= 0 && y > 0 {
        1
    } else if x < 0 && y <= 0 {
        2
    } else {
        3
    }
}

/// Scale of [`Gate`] coordinates: a fractional curve point is kept to 1/1024 step.
const GATE_SCALE: f64 = 1024.0;

/// Scale of [`Gate`]'s unit direction.
const GATE_DIRECTION_SCALE: f64 = 1_048_576.0;

/// Where the curve part of a trace ends: the line through a point of the curve, normal to the
/// curve there. A trace in the end's quadrant is past it when it has moved beyond that line
/// in the direction of travel. (The normal line, not the ray from the centre: on a flat
/// ellipse the ray meets the band of lattice points around the curve over many steps.)
#[derive(Clone, Copy, Debug)]
pub(crate) struct Gate {
    /// The curve point, scaled by [`GATE_SCALE`].
    point: (i64, i64),
    /// The unit tangent there in the direction of travel, scaled by [`GATE_DIRECTION_SCALE`].
    along: (i64, i64),
}

impl Gate {
    /// The gate at curve point `p` (frame coordinates) of `wx·x² + wy·y² = c`, travelling
    /// counter-clockwise, with `p` first moved into `quadrant` (the end point's) should it lie
    /// just across an axis.
    fn new(p: (f64, f64), quadrant: u8, weights: (i64, i64)) -> Self {
        const NUDGE: f64 = 1.0 / GATE_SCALE;
        let (mut x, mut y) = p;
        match quadrant {
            0 => (x, y) = (x.max(NUDGE), y.max(0.0)),
            1 => (x, y) = (x.min(0.0), y.max(NUDGE)),
            2 => (x, y) = (x.min(-NUDGE), y.min(0.0)),
            _ => (x, y) = (x.max(0.0), y.min(-NUDGE)),
        }
        let (tx, ty) = (-(weights.1 as f64) * y, weights.0 as f64 * x);
        let len = libm::hypot(tx, ty);
        let along = if len > 0.0 {
            (round(tx / len * GATE_DIRECTION_SCALE), round(ty / len * GATE_DIRECTION_SCALE))
        } else {
            (0, 0)
        };
        Gate { point: (round(x * GATE_SCALE), round(y * GATE_SCALE)), along }
    }

    /// True when lattice point `n` lies strictly beyond the gate.
    fn passed_by(&self, n: (i64, i64)) -> bool {
        let dx = n.0 * GATE_SCALE as i64 - self.point.0;
        let dy = n.1 * GATE_SCALE as i64 - self.point.1;
        dx * self.along.0 + dy * self.along.1 > 0
    }
}

/// On an axis, inside the curve, with the curve's crossing of that axis more than half a step
/// farther out (the tip of an ellipse narrower than a step, or a start inside the curve): the
/// move out along the axis. Not right after moving in along the same axis (`last`), so that a
/// trace turns at a tip instead of climbing it again.
fn climb_move<D: Discriminant>(p: (i64, i64), f: D, last: (i64, i64), weights: (i64, i64)) -> Option<(i64, i64)> {
    if f >= D::from(0) {
        return None;
    }
    let (m, w, c) = if p.0 == 0 {
        ((0, p.1.signum()), weights.1, p.1)
    } else if p.1 == 0 {
        ((p.0.signum(), 0), weights.0, p.0)
    } else {
        return None;
    };
    if m == (0, 0) || last == (-m.0, -m.1) {
        return None;
    }
    // 4·F half a step out: 4F + w·(4·|c| + 1).
    let mid = D::from(4) * f + D::from(w) * D::from(4 * c.abs() + 1);
    if mid < D::from(0) { Some(m) } else { None }
}

/// See [`Tracer::progress_quadrant`].
fn progress_quadrant<D: Discriminant>(p: (i64, i64), f: D, last: (i64, i64), weights: (i64, i64)) -> u8 {
    let q = quadrant(p.0, p.1);
    if climb_move(p, f, last, weights).is_some() { (q + 3) % 4 } else { q }
}

/// [`quadrant`] of a fractional point.
fn quadrant_f(p: (f64, f64)) -> u8 {
    let (x, y) = p;
    if x > 0.0 && y >= 0.0 {
        0
    } else if x <= 0.0 && y > 0.0 {
        1
    } else if x < 0.0 && y <= 0.0 {
        2
    } else {
        3
    }
}

/// `a × b`: positive when `b` lies counter-clockwise of `a` (within half a turn).
fn cross(a: (i64, i64), b: (i64, i64)) -> i64 {
    a.0 * b.1 - a.1 * b.0
}

/// Walks `F(x, y) = wx·x² + wy·y² − c = 0`; see the module documentation.
///
/// All coordinates are relative to the centre, in a frame where travel is counter-clockwise
/// (Y mirrored for clockwise travel).
#[derive(Clone, Debug)]
pub(crate) struct Tracer<D> {
    x: i64,
    y: i64,
    ex: i64,
    ey: i64,
    /// Where the curve part ends, in the end's quadrant.
    gate: Gate,
    wx: i64,
    wy: i64,
    /// `F` at the current point.
    f: D,
    mirror: bool,
    method: Method,
    phase: Phase,
    /// Quadrant of the current point.
    quadrant: u8,
    /// Quadrant boundaries crossed so far, and how many lie before the end's quadrant.
    crossed: u8,
    needed: u8,
    /// Curve steps left before the tracer gives up following the curve (never reached by a
    /// correct trace; a guarantee of termination).
    budget: u64,
    /// The previous move (frame coordinates).
    last: (i64, i64),
    /// Steps taken by the straight finish so far.
    tail_steps: u32,
}

impl<D: Discriminant> Tracer<D> {
    /// `start` and `end` relative to the centre (the caller checks them), `weights` = `(wx,
    /// wy)`, `half_axes` = ceilings of the semi-axes along X and Y.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        start: (i64, i64),
        end: (i64, i64),
        plan: Plan,
        weights: (i64, i64),
        c: D,
        half_axes: (i64, i64),
        rotation: Rotation,
        method: Method,
    ) -> Self {
        let mirror = rotation == Rotation::Clockwise;
        let (x, y) = (start.0, if mirror { -start.1 } else { start.1 });
        let (ex, ey) = (end.0, if mirror { -end.1 } else { end.1 });
        let (wx, wy) = weights;
        let f = D::from(wx) * D::from(x) * D::from(x) + D::from(wy) * D::from(y) * D::from(y) - c;
        let frame = |p: (f64, f64)| (p.0, if mirror { -p.1 } else { p.1 });
        // A start on an axis counts as having just come in along it, so that it does not climb
        // to a tip: whether the tip lies ahead or behind is unknown, and it is taken to be
        // behind (at the start's own angle). Unless the ideal start is known to lie before
        // the axis.
        let on_axis_in = if x == 0 {
            (0, -y.signum())
        } else if y == 0 {
            (-x.signum(), 0)
        } else {
            (0, 0)
        };
        let before_axis = match plan {
            Plan::Between { from, .. } => quadrant(x, y) == (quadrant_f(frame(from)) + 1) % 4,
            _ => false,
        };
        let last = if before_axis { (0, 0) } else { on_axis_in };
        let q = progress_quadrant((x, y), f, last, weights);
        let (needed, crossed, gate, phase) = match plan {
            Plan::ToEnd { near } => {
                // An end inside a tip, on its axis, is met on the way up to the tip: it counts in
                // the quadrant before.
                let fe = D::from(wx) * D::from(ex) * D::from(ex) + D::from(wy) * D::from(ey) * D::from(ey) - c;
                let eq = if (ex, ey) == (x, y) { q } else { progress_quadrant((ex, ey), fe, (0, 0), weights) };
                let mut needed = (eq + 4 - q) % 4;
                let ahead = cross((x, y), (ex, ey));
                if ahead == 0 && x * ex + y * ey > 0 {
                    // On the start's own ray: one full turn (less one quadrant if the end is met
                    // on the way up a tip the start has left behind).
                    needed = if needed == 3 { 3 } else { needed + 4 };
                } else if needed == 0 && ahead < 0 {
                    // Same quadrant, behind the start.
                    needed = 4;
                }
                // Back to the start itself; else to the curve point nearest the end.
                let target = if (x, y) == (ex, ey) { (x as f64, y as f64) } else { frame(near) };
                (needed, 0, Gate::new(target, eq, weights), Phase::Curve)
            }
            Plan::Between { from, to, long } => {
                let (from, to) = (frame(from), frame(to));
                let (qf, qt) = (quadrant_f(from), quadrant_f(to));
                let mut needed = (qt + 4 - qf) % 4;
                if needed == 0 && long {
                    needed = 4;
                }
                // The lattice start may have been rounded across an axis.
                let (needed, crossed) = match (q + 4 - qf) % 4 {
                    1 => (needed, 1),
                    3 => (needed + 1, 0),
                    _ => (needed, 0),
                };
                (needed, crossed, Gate::new(to, qt, weights), Phase::Curve)
            }
            Plan::Empty => {
                let gate = Gate::new((ex as f64, ey as f64), quadrant(ex, ey), weights);
                (0, 0, gate, if (x, y) == (ex, ey) { Phase::Done } else { Phase::Tail })
            }
        };
        let quarter = (half_axes.0 + half_axes.1 + QUARTER_SLACK_STEPS) as u64;
        Tracer {
            x,
            y,
            ex,
            ey,
            gate,
            wx,
            wy,
            f,
            mirror,
            method,
            phase,
            quadrant: q,
            crossed,
            needed,
            budget: 4 * (needed as u64 + 1) * quarter,
            last,
            tail_steps: 0,
        }
    }

    /// The next step in machine coordinates, `None` at the end.
    pub(crate) fn next(&mut self) -> Option<Step> {
        match self.phase {
            Phase::Done => None,
            Phase::Tail => self.tail_step(),
            Phase::Curve => {
                if self.budget == 0 {
                    warn!("curve step budget exhausted; finishing straight");
                    self.phase = Phase::Tail;
                    return self.tail_step();
                }
                self.budget -= 1;
                self.curve_step()
            }
        }
    }

    /// Unit tangent of the ideal curve at the current point in the direction of travel; the
    /// direction to the end point during the straight finish.
    pub(crate) fn tangent(&self) -> Tangent {
        let (tx, ty) = match self.phase {
            Phase::Tail => ((self.ex - self.x) as f32, (self.ey - self.y) as f32),
            Phase::Curve | Phase::Done => (-(self.wy as f32) * self.y as f32, self.wx as f32 * self.x as f32),
        };
        let ty = if self.mirror { -ty } else { ty };
        // Scale first: products of large weights and coordinates square beyond f32.
        let m = libm::fmaxf(libm::fabsf(tx), libm::fabsf(ty));
        if m > 0.0 { Tangent::along(tx / m, ty / m) } else { Tangent::along(0.0, 0.0) }
    }

    /// `F` at the current point.
    #[cfg(test)]
    pub(crate) fn discriminant(&self) -> D {
        self.f
    }

    /// Steps taken by the straight finish so far.
    #[cfg(test)]
    pub(crate) fn tail_steps(&self) -> u32 {
        self.tail_steps
    }

    /// Change of `F` for a step `sx` along X (and `sy` along Y) from the current point.
    fn df_x(&self, sx: i64) -> D {
        D::from(self.wx) * D::from(2 * sx * self.x + 1)
    }

    fn df_y(&self, sy: i64) -> D {
        D::from(self.wy) * D::from(2 * sy * self.y + 1)
    }

    fn df(&self, m: (i64, i64)) -> D {
        let zero = D::from(0);
        (if m.0 != 0 { self.df_x(m.0) } else { zero }) + (if m.1 != 0 { self.df_y(m.1) } else { zero })
    }

    fn climb(&self) -> Option<(i64, i64)> {
        climb_move((self.x, self.y), self.f, self.last, (self.wx, self.wy))
    }

    /// The quadrant the trace counts point `p` (with discriminant `f`, reached by move `last`)
    /// in: its own, except while it climbs an axis toward a tip, which still belongs to the
    /// quadrant before the tip.
    fn progress_quadrant(&self, p: (i64, i64), f: D, last: (i64, i64)) -> u8 {
        progress_quadrant(p, f, last, (self.wx, self.wy))
    }

    /// The move the curve rule chooses at the current point.
    fn curve_move(&self) -> (i64, i64) {
        if let Some(m) = self.climb() {
            return m;
        }
        let zero = D::from(0);
        // Forward directions: along the tangent (−wy·y, wx·x); a zero component moves inward.
        let sx = if self.y != 0 { -self.y.signum() } else { -self.x.signum() };
        let sy = if self.x != 0 { self.x.signum() } else { -self.y.signum() };
        let x_inward = sx * self.x < 0;
        let (inward, outward) = if x_inward { ((sx, 0), (0, sy)) } else { ((0, sy), (sx, 0)) };
        let diagonal = (sx, sy);
        let chosen = match self.method {
            Method::Classic => {
                if self.f >= zero {
                    inward
                } else {
                    outward
                }
            }
            Method::Diagonal => {
                let four = D::from(4);
                let fd = self.f + self.df(diagonal);
                if fd == zero {
                    diagonal
                } else if fd > zero {
                    // The curve passes between the inward point and the diagonal point: compare
                    // with their midpoint, half a step outward from the inward point.
                    let f_in = self.f + self.df(inward);
                    let (w, s, c) = if x_inward { (self.wy, sy, self.y) } else { (self.wx, sx, self.x) };
                    let mid = four * f_in + D::from(w) * D::from(4 * s * c + 1);
                    if mid > zero { inward } else { diagonal }
                } else {
                    // Between the outward point and the diagonal point.
                    let f_out = self.f + self.df(outward);
                    let (w, s, c) = if x_inward { (self.wx, sx, self.x) } else { (self.wy, sy, self.y) };
                    let mid = four * f_out + D::from(w) * D::from(4 * s * c + 1);
                    if mid < zero { outward } else { diagonal }
                }
            }
        };
        // Never onto the centre (only a classic circle of radius 1 would go there); the outward
        // move never leads there.
        if self.x + chosen.0 == 0 && self.y + chosen.1 == 0 { outward } else { chosen }
    }

    fn curve_step(&mut self) -> Option<Step> {
        let m = self.curve_move();
        let n = (self.x + m.0, self.y + m.1);
        let nq = self.progress_quadrant(n, self.f + self.df(m), m);
        let crossed = self.crossed.saturating_add((nq != self.quadrant) as u8);
        let end = (self.ex, self.ey);
        let reached = crossed > self.needed || (crossed == self.needed && (n == end || self.gate.passed_by(n)));
        if reached && n != end && self.distance_to_end(n) >= self.distance_to_end((self.x, self.y)) {
            // Stepping past the gate would lead away from the end: finish from here.
            self.phase = Phase::Tail;
            return self.tail_step();
        }
        self.quadrant = nq;
        self.crossed = crossed;
        let step = self.apply(m);
        if reached {
            self.phase = if n == end { Phase::Done } else { Phase::Tail };
        }
        Some(step)
    }

    /// Distance to the end in steps of the method (one axis or both axes per step).
    fn distance_to_end(&self, p: (i64, i64)) -> i64 {
        let (dx, dy) = ((self.ex - p.0).abs(), (self.ey - p.1).abs());
        match self.method {
            Method::Classic => dx + dy,
            Method::Diagonal => dx.max(dy),
        }
    }

    /// One straight step toward the end: among the moves that shorten the distance, the one
    /// that lands nearest the curve (`|F| / |∇F|`).
    fn tail_step(&mut self) -> Option<Step> {
        let (rx, ry) = (self.ex - self.x, self.ey - self.y);
        if rx == 0 && ry == 0 {
            self.phase = Phase::Done;
            return None;
        }
        let (sx, sy) = (rx.signum(), ry.signum());
        let candidates = match self.method {
            Method::Classic => [(sx, 0), (0, sy)],
            Method::Diagonal if rx.abs() > ry.abs() => [(sx, 0), (sx, sy)],
            Method::Diagonal if ry.abs() > rx.abs() => [(0, sy), (sx, sy)],
            Method::Diagonal => [(sx, sy), (sx, sy)],
        };
        let mut best: Option<((i64, i64), f32)> = None;
        for m in candidates {
            if m == (0, 0) {
                continue;
            }
            let score = self.off_curve(m);
            if best.is_none_or(|(_, s)| score < s) {
                best = Some((m, score));
            }
        }
        let m = best.map_or((sx, sy), |(m, _)| m);
        let step = self.apply(m);
        self.tail_steps = self.tail_steps.saturating_add(1);
        if self.x == self.ex && self.y == self.ey {
            self.phase = Phase::Done;
        }
        Some(step)
    }

    /// First-order distance from the curve after move `m`.
    fn off_curve(&self, m: (i64, i64)) -> f32 {
        let f = (self.f + self.df(m)).to_f32();
        let (x, y) = ((self.x + m.0) as f32, (self.y + m.1) as f32);
        let gx = 2.0 * self.wx as f32 * x;
        let gy = 2.0 * self.wy as f32 * y;
        let g = libm::fmaxf(libm::hypotf(gx, gy), 1.0);
        libm::fabsf(f) / g
    }

    /// Takes move `m` (frame coordinates) and returns it as a machine step.
    fn apply(&mut self, m: (i64, i64)) -> Step {
        self.f = self.f + self.df(m);
        self.x += m.0;
        self.y += m.1;
        self.last = m;
        let dy = if self.mirror { -m.1 } else { m.1 };
        Step::new(m.0 as i8, dy as i8)
    }
}

/// Helpers shared by the circle and ellipse tests.
#[cfg(test)]
pub(crate) mod test_support {
    extern crate std;
    use crate::geom::{Point, Step};
    use crate::interp::Interpolator;
    use std::vec::Vec;

    /// Error bounds the tests hold the methods to, in steps.
    pub const CLASSIC_BOUND_STEPS: f64 = 1.0;
    pub const DIAGONAL_BOUND_STEPS: f64 = 0.5;
    /// Bounds on the distance from the ideal curve to the traced polyline, in steps.
    pub fn path_bound(method: crate::interp::Method) -> f64 {
        match method {
            crate::interp::Method::Classic => CLASSIC_PATH_BOUND_STEPS,
            crate::interp::Method::Diagonal => DIAGONAL_PATH_BOUND_STEPS,
        }
    }
    pub const CLASSIC_PATH_BOUND_STEPS: f64 = 1.0;
    pub const DIAGONAL_PATH_BOUND_STEPS: f64 = 0.5;
    /// Float tolerance of the distance measurement itself.
    pub const MEASURE_TOLERANCE_STEPS: f64 = 1e-9;

    /// A traced path: every point from the start, the steps, and which points the straight
    /// finish produced.
    pub struct Walk {
        pub points: Vec<Point>,
        pub steps: Vec<Step>,
        pub tail: Vec<bool>,
    }

    impl Walk {
        pub fn last(&self) -> Point {
            *self.points.last().unwrap()
        }
        pub fn len(&self) -> usize {
            self.steps.len()
        }
        pub fn tail_len(&self) -> usize {
            self.tail.iter().filter(|t| **t).count()
        }
    }

    /// Runs `interp` from `start` to its end (at most `cap` steps), checking that every step
    /// goes to a lattice neighbour, that a classic trace never moves both axes, and that the
    /// interpolator keeps answering `None` at the end.
    pub fn walk<I: Interpolator>(
        interp: &mut I,
        start: Point,
        classic: bool,
        tail_steps: impl Fn(&I) -> u32,
        cap: usize,
    ) -> Walk {
        let mut w = Walk { points: Vec::from([start]), steps: Vec::new(), tail: Vec::from([false]) };
        let mut p = start;
        let mut tails = tail_steps(interp);
        while let Some(s) = interp.next_step().unwrap() {
            assert!(s.is_neighbour(), "{s:?} after {} steps is not a step to a neighbour", w.len());
            if classic {
                assert!(!s.is_diagonal(), "classic moved both axes at {p:?}");
            }
            p = p.stepped(s);
            let t = tail_steps(interp);
            w.points.push(p);
            w.steps.push(s);
            w.tail.push(t != tails);
            tails = t;
            assert!(w.len() <= cap, "no end after {cap} steps");
        }
        for _ in 0..3 {
            assert_eq!(interp.next_step(), Ok(None), "steps after the end");
        }
        w
    }

    /// L1 (classic) and L∞ (diagonal) lengths of the parametric curve `f` over `[t0, t1]`: the
    /// analytic step counts of a monotone lattice path following it.
    pub fn ideal_lengths(f: impl Fn(f64) -> (f64, f64), t0: f64, t1: f64, samples: usize) -> (f64, f64) {
        let (mut l1, mut linf) = (0.0, 0.0);
        let mut prev = f(t0);
        for i in 1..=samples {
            let p = f(t0 + (t1 - t0) * i as f64 / samples as f64);
            let (dx, dy) = ((p.0 - prev.0).abs(), (p.1 - prev.1).abs());
            l1 += dx + dy;
            linf += dx.max(dy);
            prev = p;
        }
        (l1, linf)
    }

    /// Quadrant boundaries (axes) an ideal arc from angle `a0` sweeping `t` radians in
    /// direction `sign` crosses.
    pub fn axes_crossed(a0: f64, t: f64, sign: f64) -> f64 {
        use core::f64::consts::FRAC_PI_2;
        if sign > 0.0 {
            libm::floor((a0 + t) / FRAC_PI_2) - libm::floor(a0 / FRAC_PI_2)
        } else {
            libm::ceil(a0 / FRAC_PI_2) - libm::ceil((a0 - t) / FRAC_PI_2)
        }
    }

    /// Largest difference between a trace's step count and the ideal arc's L1 / L∞ length:
    /// the lattice path meets each axis up to a step away from the ideal curve (counted on
    /// both sides of it), and its ends are lattice points.
    pub fn count_slack(axes: f64) -> f64 {
        2.0 + 2.0 * axes
    }

    /// Largest distance from the ideal curve `f` over `[t0, t1]` (sampled at least every
    /// `1/8` step) to the traced polyline through `points`: how far the drawing strays from the
    /// curve seen from the curve (cut-off tips show here, not in the points' own distances).
    /// Distances above [`FAR_STEPS`] report as `FAR_STEPS`.
    pub fn curve_to_path(points: &[Point], f: impl Fn(f64) -> (f64, f64), t0: f64, t1: f64, samples: usize) -> f64 {
        use std::collections::HashMap;
        const CELL: i32 = 4;
        let mut cells: HashMap<(i32, i32), Vec<usize>> = HashMap::new();
        for (i, p) in points.iter().enumerate() {
            cells.entry((p.x.div_euclid(CELL), p.y.div_euclid(CELL))).or_default().push(i);
        }
        let seg = |i: usize, q: (f64, f64)| {
            let a = points[i];
            let b = points[(i + 1).min(points.len() - 1)];
            let (ax, ay, bx, by) = (a.x as f64, a.y as f64, b.x as f64, b.y as f64);
            let (dx, dy) = (bx - ax, by - ay);
            let l2 = dx * dx + dy * dy;
            let t = if l2 > 0.0 { (((q.0 - ax) * dx + (q.1 - ay) * dy) / l2).clamp(0.0, 1.0) } else { 0.0 };
            libm::hypot(q.0 - (ax + t * dx), q.1 - (ay + t * dy))
        };
        let mut worst: f64 = 0.0;
        for k in 0..=samples {
            let q = f(t0 + (t1 - t0) * k as f64 / samples as f64);
            let (cx, cy) = ((libm::floor(q.0) as i32).div_euclid(CELL), (libm::floor(q.1) as i32).div_euclid(CELL));
            let mut best = FAR_STEPS;
            for gx in cx - 2..=cx + 2 {
                for gy in cy - 2..=cy + 2 {
                    for &i in cells.get(&(gx, gy)).map(|v| &v[..]).unwrap_or(&[]) {
                        best = best.min(seg(i, q));
                        if i > 0 {
                            best = best.min(seg(i - 1, q));
                        }
                    }
                }
            }
            worst = worst.max(best);
        }
        worst
    }

    /// Longest trace whose curve-to-path distance is measured (the largest curves are checked
    /// point by point only).
    pub const STRAY_CHECK_MAX_STEPS: usize = 50_000;

    /// Most curve samples a check takes (large curves are sampled more coarsely).
    pub const CURVE_SAMPLES_MAX: usize = 100_000;

    /// Cap of [`curve_to_path`].
    pub const FAR_STEPS: f64 = 4.0;

    /// Travel angle from angle `a` to angle `b` in the direction `sign` (+1 CCW), in (0, 2π].
    pub fn travel(a: f64, b: f64, sign: f64) -> f64 {
        use core::f64::consts::TAU;
        let mut d = ((b - a) * sign) % TAU;
        if d <= 1e-12 {
            d += TAU;
        }
        d
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::test_support::*;
    use super::*;
    use Method::{Classic, Diagonal};
    use Rotation::{Clockwise as Cw, CounterClockwise as Ccw};
    use core::f64::consts::{PI, SQRT_2, TAU};
    use proptest::prelude::*;
    use std::vec::Vec;

    impl ArcInterp {
        fn tail_steps(&self) -> u32 {
            self.tracer.tail_steps()
        }
    }

    fn trace(arc: &mut ArcInterp, start: Point, method: Method) -> Walk {
        let r = libm::sqrt(r2(start, arc.center) as f64) as usize;
        walk(arc, start, method == Classic, ArcInterp::tail_steps, 16 * r + 64)
    }

    fn r2(p: Point, c: Point) -> i64 {
        let d = offset(p, c);
        d.0 * d.0 + d.1 * d.1
    }

    /// Distance of `p` from the circle around `c` through `s`.
    fn off_circle(p: Point, c: Point, s: Point) -> f64 {
        (libm::sqrt(r2(p, c) as f64) - libm::sqrt(r2(s, c) as f64)).abs()
    }

    fn bound(method: Method) -> f64 {
        let b = match method {
            Classic => CLASSIC_BOUND_STEPS,
            Diagonal => DIAGONAL_BOUND_STEPS,
        };
        b + MEASURE_TOLERANCE_STEPS
    }

    fn angle(p: Point, c: Point) -> f64 {
        let d = offset(p, c);
        libm::atan2(d.1 as f64, d.0 as f64)
    }

    /// Checks a finished arc: exact end, every curve point within the method's bound, the
    /// straight finish short and within the bound plus the end's own distance, and the step
    /// count against the ideal arc's L1 / L∞ length.
    fn check_arc(w: &Walk, start: Point, center: Point, end: Point, rotation: Rotation, method: Method) {
        assert_eq!(w.last(), end, "did not end on the end point");
        let b = bound(method);
        let end_off = off_circle(end, center, start);
        for (p, tail) in w.points.iter().zip(&w.tail) {
            let d = off_circle(*p, center, start);
            if *tail {
                assert!(d <= b + end_off, "finish point {p:?} is {d} off (end {end_off} off)");
            } else {
                assert!(d <= b, "{p:?} is {d} off the circle ({method:?})");
            }
        }
        assert!(w.tail_len() <= ARC_END_TOLERANCE_STEPS as usize + 2, "finish of {} steps", w.tail_len());
        let sign = if rotation == Ccw { 1.0 } else { -1.0 };
        let a0 = angle(start, center);
        let sweep = travel(a0, angle(end, center), sign);
        let r = libm::sqrt(r2(start, center) as f64);
        let (l1, linf) = ideal_lengths(
            |t| (r * libm::cos(a0 + sign * t), r * libm::sin(a0 + sign * t)),
            0.0,
            sweep,
            4096.max(8 * r as usize),
        );
        let analytic = if method == Classic { l1 } else { linf };
        let slack = count_slack(axes_crossed(a0, sweep, sign));
        assert!((w.len() as f64 - analytic).abs() <= slack, "{} steps, analytic {analytic} ± {slack}", w.len());
        if w.len() > STRAY_CHECK_MAX_STEPS {
            return;
        }
        let (cx, cy) = (center.x as f64, center.y as f64);
        let h = curve_to_path(
            &w.points,
            |t| (cx + r * libm::cos(a0 + sign * t), cy + r * libm::sin(a0 + sign * t)),
            0.0,
            sweep,
            (4 * l1 as usize + 64).min(CURVE_SAMPLES_MAX),
        );
        assert!(
            h <= path_bound(method) + end_off + MEASURE_TOLERANCE_STEPS,
            "the curve strays {h} from the path ({method:?})"
        );
    }

    #[test]
    fn classic_first_quadrant_counter_clockwise_follows_the_textbook() {
        // NR1 from A(4, 0) to B(0, 4): F0 = 0 → −X (F = −7) → +Y (−6) → +Y (−3) → +Y (2) → −X (−3)
        // → +Y (4) → −X (1) → −X (0); 2R = 8 steps.
        let c = Point::new(100, -50);
        let at = |x, y| Point::new(c.x + x, c.y + y);
        let mut arc = ArcInterp::new(at(4, 0), c, at(0, 4), Ccw, Classic).unwrap();
        let (mut steps, mut fs) = (Vec::new(), Vec::new());
        while let Some(s) = arc.next_step().unwrap() {
            steps.push(s);
            fs.push(arc.tracer.discriminant());
        }
        use Step as S;
        assert_eq!(steps, [S::XN, S::YP, S::YP, S::YP, S::XN, S::YP, S::XN, S::XN]);
        assert_eq!(fs, [-7, -6, -3, 2, -3, 4, 1, 0]);
    }

    #[test]
    fn first_quadrant_arc_of_radius_five_step_by_step() {
        let mut arc = ArcInterp::new(Point::new(5, 0), Point::ORIGIN, Point::new(0, 5), Ccw, Classic).unwrap();
        let w = trace(&mut arc, Point::new(5, 0), Classic);
        use Step as S;
        assert_eq!(w.steps, [S::XN, S::YP, S::YP, S::YP, S::XN, S::YP, S::XN, S::YP, S::XN, S::XN]);
        // Diagonal: the nearest lattice point of each row (below 45°) or column (above).
        let mut arc = ArcInterp::new(Point::new(5, 0), Point::ORIGIN, Point::new(0, 5), Ccw, Diagonal).unwrap();
        let w = trace(&mut arc, Point::new(5, 0), Diagonal);
        let expected = [(5, 0), (5, 1), (5, 2), (4, 3), (3, 4), (2, 5), (1, 5), (0, 5)].map(|(x, y)| Point::new(x, y));
        assert_eq!(w.points, expected);
    }

    /// The textbook tables, literally: the quadrant by the signs of (x, y) with the axis that
    /// the direction of travel leaves from, then the move for F >= 0 and for F < 0.
    fn table_move(x: i64, y: i64, f: i64, rotation: Rotation) -> Step {
        use Step as S;
        // (move for F >= 0, move for F < 0)
        let (ge, lt) = match rotation {
            Ccw if x > 0 && y >= 0 => (S::XN, S::YP), // NR1
            Ccw if x <= 0 && y > 0 => (S::YN, S::XN), // NR2
            Ccw if x < 0 && y <= 0 => (S::XP, S::YN), // NR3
            Ccw => (S::YP, S::XP),                    // NR4
            Cw if x >= 0 && y > 0 => (S::YN, S::XP),  // SR1
            Cw if x < 0 && y >= 0 => (S::XP, S::YP),  // SR2
            Cw if x <= 0 && y < 0 => (S::YP, S::XN),  // SR3
            Cw => (S::XN, S::YN),                     // SR4
        };
        if f >= 0 { ge } else { lt }
    }

    /// Walks the literal tables (F recomputed from scratch at every point) until `end`.
    fn table_walk(start: (i64, i64), end: (i64, i64), rotation: Rotation, full: bool, cap: usize) -> Vec<Step> {
        let r2 = start.0 * start.0 + start.1 * start.1;
        let (mut x, mut y) = start;
        let mut steps = Vec::new();
        loop {
            let s = table_move(x, y, x * x + y * y - r2, rotation);
            x += s.x as i64;
            y += s.y as i64;
            steps.push(s);
            assert!(steps.len() <= cap, "table walk did not reach {end:?}");
            if (x, y) == end && (!full || steps.len() > 4) {
                return steps;
            }
        }
    }

    #[test]
    fn classic_matches_the_tables_in_every_quadrant_and_direction() {
        for r in 2..=25i64 {
            let axes = [(r, 0), (0, r), (-r, 0), (0, -r)];
            for rotation in [Ccw, Cw] {
                for (i, s) in axes.iter().enumerate() {
                    // Quarter, half and three-quarter arcs, and the full circle.
                    for k in 1..=4 {
                        let e = if rotation == Ccw { axes[(i + k) % 4] } else { axes[(i + 4 - k) % 4] };
                        let start = Point::new(s.0 as i32, s.1 as i32);
                        let end = Point::new(e.0 as i32, e.1 as i32);
                        let mut arc = ArcInterp::new(start, Point::ORIGIN, end, rotation, Classic).unwrap();
                        let w = trace(&mut arc, start, Classic);
                        let expected = table_walk(*s, e, rotation, k == 4, 10 * r as usize);
                        assert_eq!(w.steps, expected, "r {r} from {s:?} {k} quarters {rotation:?}");
                        assert_eq!(w.len() as i64, 2 * r * k as i64, "classic takes 2R per quarter");
                        assert_eq!(w.tail_len(), 0);
                    }
                }
            }
        }
        // Starts off the axes: every lattice point of a few circles, full turns.
        for (x, y) in [(3, 4), (-4, 3), (-3, -4), (4, -3), (5, 12), (-12, -5), (1, 1), (2, -7), (-6, 9)] {
            for rotation in [Ccw, Cw] {
                let start = Point::new(x as i32, y as i32);
                let mut arc = ArcInterp::new(start, Point::ORIGIN, start, rotation, Classic).unwrap();
                let w = trace(&mut arc, start, Classic);
                assert_eq!(w.steps, table_walk((x, y), (x, y), rotation, true, 200), "from ({x}, {y}) {rotation:?}");
            }
        }
    }

    #[test]
    fn full_circles_take_8r_classic_and_about_4_root_2_r_diagonal_steps() {
        for r in 1..=40 {
            for (x, y) in [(r, 0), (0, r), (-r, 0), (0, -r)] {
                for rotation in [Ccw, Cw] {
                    let c = Point::new(-17, 33);
                    let start = Point::new(c.x + x, c.y + y);
                    let mut arc = ArcInterp::new(start, c, start, rotation, Classic).unwrap();
                    let w = trace(&mut arc, start, Classic);
                    assert_eq!(w.len(), 8 * r as usize, "classic r {r}");
                    check_arc(&w, start, c, start, rotation, Classic);

                    let mut arc = ArcInterp::new(start, c, start, rotation, Diagonal).unwrap();
                    let w = trace(&mut arc, start, Diagonal);
                    let analytic = 4.0 * SQRT_2 * r as f64;
                    assert!((w.len() as f64 - analytic).abs() <= 4.0, "diagonal r {r}: {} vs {analytic}", w.len());
                    assert_eq!(w.last(), start);
                    check_arc(&w, start, c, start, rotation, Diagonal);
                }
            }
        }
    }

    #[test]
    fn arcs_across_quadrants_end_on_their_end_points() {
        // (3, 4) → (4, −3) counter-clockwise sweeps 270° through three boundaries.
        let cases = [
            ((3, 4), (4, -3), Ccw),
            ((3, 4), (4, -3), Cw),
            ((-5, 0), (5, 0), Ccw),
            ((0, 13), (-12, -5), Cw),
            ((7, -1), (-1, 7), Ccw),
            ((7, -1), (-1, 7), Cw),
        ];
        for ((sx, sy), (ex, ey), rotation) in cases {
            for method in [Classic, Diagonal] {
                let (start, end) = (Point::new(sx, sy), Point::new(ex, ey));
                let mut arc = ArcInterp::new(start, Point::ORIGIN, end, rotation, method).unwrap();
                let w = trace(&mut arc, start, method);
                check_arc(&w, start, Point::ORIGIN, end, rotation, method);
                assert_eq!(w.tail_len(), 0, "end on the circle is on the path");
            }
        }
    }

    #[test]
    fn tiny_radii_and_every_tolerated_end_terminate_exactly() {
        // Every start with |s| <= 4 and every end within the tolerance, both methods and
        // directions: the trace ends on the end and stays short.
        for sx in -4..=4 {
            for sy in -4..=4 {
                let s = Point::new(sx, sy);
                if s == Point::ORIGIN || r2(s, Point::ORIGIN) > 16 {
                    continue;
                }
                for ex in -7..=7 {
                    for ey in -7..=7 {
                        let e = Point::new(ex, ey);
                        for rotation in [Ccw, Cw] {
                            for method in [Classic, Diagonal] {
                                match ArcInterp::new(s, Point::ORIGIN, e, rotation, method) {
                                    Ok(mut arc) => {
                                        let w = walk(&mut arc, s, method == Classic, ArcInterp::tail_steps, 100);
                                        assert_eq!(w.last(), e, "{s:?}→{e:?} {rotation:?} {method:?}");
                                        if off_circle(e, Point::ORIGIN, s) == 0.0 {
                                            check_arc(&w, s, Point::ORIGIN, e, rotation, method);
                                        }
                                    }
                                    Err(err) => {
                                        assert_eq!(err, ArcError::EndOffCurve);
                                        assert!(e == Point::ORIGIN || off_circle(e, Point::ORIGIN, s) > 2.0);
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn a_radius_of_one_goes_around_the_centre_not_through_it() {
        let s = Point::new(1, 0);
        let mut arc = ArcInterp::new(s, Point::ORIGIN, s, Ccw, Classic).unwrap();
        let w = trace(&mut arc, s, Classic);
        assert_eq!(w.len(), 8);
        assert!(!w.points.contains(&Point::ORIGIN));
        let mut arc = ArcInterp::new(s, Point::ORIGIN, Point::new(0, 1), Ccw, Classic).unwrap();
        assert_eq!(trace(&mut arc, s, Classic).len(), 2);
    }

    #[test]
    fn bad_arcs_are_refused() {
        let p = Point::new(10, 0);
        assert_eq!(ArcInterp::new(p, p, p, Ccw, Classic).err(), Some(ArcError::ZeroRadius));
        assert_eq!(
            ArcInterp::new(p, Point::ORIGIN, Point::new(0, 13), Ccw, Classic).err(),
            Some(ArcError::EndOffCurve)
        );
        assert_eq!(
            ArcInterp::new(p, Point::ORIGIN, Point::new(0, 12), Ccw, Classic).map(|a| a.end()),
            Ok(Point::new(0, 12))
        );
        assert_eq!(ArcInterp::new(p, Point::ORIGIN, Point::ORIGIN, Ccw, Classic).err(), Some(ArcError::EndOffCurve));
        let far = Point::new(MAX_RADIUS_STEPS + 1, 0);
        assert_eq!(ArcInterp::new(far, Point::ORIGIN, far, Ccw, Classic).err(), Some(ArcError::TooLarge));
        let corner = Point::new(i32::MIN, i32::MAX);
        assert_eq!(
            ArcInterp::new(corner, Point::new(i32::MAX, i32::MIN), corner, Cw, Diagonal).err(),
            Some(ArcError::TooLarge)
        );
        assert_eq!(ArcInterp::from_angles(p, 0, 0.0, 1.0, Classic).err(), Some(ArcError::ZeroRadius));
        assert_eq!(ArcInterp::from_angles(p, -5, 0.0, 1.0, Classic).err(), Some(ArcError::ZeroRadius));
        assert_eq!(ArcInterp::from_angles(p, 5, f32::NAN, 1.0, Classic).err(), Some(ArcError::NotFinite));
        assert_eq!(ArcInterp::from_angles(p, 5, 0.0, f32::INFINITY, Classic).err(), Some(ArcError::NotFinite));
        assert_eq!(ArcInterp::from_angles(p, MAX_RADIUS_STEPS + 1, 0.0, 1.0, Classic).err(), Some(ArcError::TooLarge));
        let edge = Point::new(i32::MAX - 5, 0);
        assert_eq!(ArcInterp::from_angles(edge, 100, PI as f32, 1.0, Classic).err(), Some(ArcError::TooLarge));
    }

    #[test]
    fn from_angles_draws_what_the_menu_asks_for() {
        let pen = Point::new(1000, -2000);
        // Quarter turn counter-clockwise from angle 0: centre 50 to the left, end above it.
        let mut arc = ArcInterp::from_angles(pen, 50, 0.0, core::f32::consts::FRAC_PI_2, Classic).unwrap();
        assert_eq!(arc.center(), Point::new(950, -2000));
        assert_eq!(arc.end(), Point::new(950, -1950));
        assert_eq!(arc.rotation(), Ccw);
        assert_eq!(trace(&mut arc, pen, Classic).len(), 100);
        // Negative sweep turns clockwise: from the top of the circle to its right end.
        let mut arc =
            ArcInterp::from_angles(pen, 50, core::f32::consts::FRAC_PI_2, -core::f32::consts::FRAC_PI_2, Diagonal)
                .unwrap();
        assert_eq!((arc.center(), arc.end(), arc.rotation()), (Point::new(1000, -2050), Point::new(1050, -2050), Cw));
        let w = trace(&mut arc, pen, Diagonal);
        check_arc(&w, pen, arc.center(), arc.end(), Cw, Diagonal);
        // A full turn, and more than one, returns to the pen after 8R classic steps.
        for sweep in [TAU as f32, -TAU as f32, 10.0] {
            let mut arc = ArcInterp::from_angles(pen, 50, 0.0, sweep, Classic).unwrap();
            assert_eq!(arc.end(), pen);
            assert_eq!(trace(&mut arc, pen, Classic).len(), 400);
        }
        // Nearly a full turn, whose end rounds to the pen: still (almost) a full turn.
        let mut arc = ArcInterp::from_angles(pen, 50, 0.3, TAU as f32 - 0.001, Diagonal).unwrap();
        assert!(trace(&mut arc, pen, Diagonal).len() > 250);
        // Nearly a full turn whose end rounds to just below the pen.
        let mut arc = ArcInterp::from_angles(pen, 50, 0.0, TAU as f32 - 0.015, Classic).unwrap();
        assert_eq!(arc.end(), Point::new(1000, -2001));
        assert_eq!(trace(&mut arc, pen, Classic).len(), 399);
        // Shorter than a step: nothing to do.
        let mut arc = ArcInterp::from_angles(pen, 50, 0.0, 0.001, Classic).unwrap();
        assert_eq!(arc.next_step(), Ok(None));
        let mut arc = ArcInterp::from_angles(pen, 50, 0.0, 0.0, Diagonal).unwrap();
        assert_eq!(arc.next_step(), Ok(None));
    }

    #[test]
    fn rounding_never_turns_a_short_arc_into_a_long_one_or_back() {
        // Sweeps of a few steps, and a few steps short of a full turn, from many start angles:
        // the rounded ends may fall on either side of the rounded start, the trace still
        // sweeps what was asked.
        let pen = Point::new(40, -40);
        for radius in [3, 10, 50] {
            let full = 8 * radius as usize;
            for k in 0..200 {
                let a0 = k as f32 * 0.0317;
                for steps in [0.3f32, 0.8, 1.5, 3.0] {
                    let sweep = steps / radius as f32;
                    for (s, method) in [
                        (sweep, Classic),
                        (-sweep, Diagonal),
                        (TAU as f32 - sweep, Classic),
                        (sweep - TAU as f32, Diagonal),
                    ] {
                        let mut arc = ArcInterp::from_angles(pen, radius, a0, s, method).unwrap();
                        let end = arc.end();
                        let w = trace(&mut arc, pen, method);
                        assert_eq!(w.last(), end);
                        if s.abs() < PI as f32 {
                            let most = libm::ceil(steps as f64 * SQRT_2) as usize + 4;
                            assert!(w.len() <= most, "r {radius} from {a0} sweep {s}: {} steps", w.len());
                        } else {
                            let turn = if method == Classic { full as f64 } else { full as f64 / SQRT_2 };
                            assert!(
                                (w.len() as f64 - turn).abs() <= 10.0,
                                "r {radius} from {a0} sweep {s}: {} steps",
                                w.len()
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn the_tangent_is_perpendicular_to_the_radius_in_the_direction_of_travel() {
        let s = Point::new(30, 0);
        let arc = ArcInterp::new(s, Point::ORIGIN, s, Ccw, Classic).unwrap();
        let t = arc.tangent();
        assert!(t.x.abs() < 1e-6 && (t.y - 1.0).abs() < 1e-6, "{t:?}");
        let arc = ArcInterp::new(s, Point::ORIGIN, s, Cw, Classic).unwrap();
        let t = arc.tangent();
        assert!(t.x.abs() < 1e-6 && (t.y + 1.0).abs() < 1e-6, "{t:?}");
        // Along whole circles: unit length, perpendicular to the radius, and every step goes
        // forward along it.
        for rotation in [Ccw, Cw] {
            for method in [Classic, Diagonal] {
                let c = Point::new(7, -3);
                let s = Point::new(7 + 37, -3 + 11);
                let mut arc = ArcInterp::new(s, c, s, rotation, method).unwrap();
                let mut p = s;
                loop {
                    let t = arc.tangent();
                    let (rx, ry) = ((p.x - c.x) as f32, (p.y - c.y) as f32);
                    assert!(((t.x * t.x + t.y * t.y) - 1.0).abs() < 1e-5);
                    assert!(
                        (t.x * rx + t.y * ry).abs() / (rx * rx + ry * ry).sqrt() < 1e-5,
                        "not perpendicular at {p:?}"
                    );
                    let turn = rx * t.y - ry * t.x;
                    assert!(if rotation == Ccw { turn > 0.0 } else { turn < 0.0 }, "wrong way at {p:?}");
                    let Some(step) = arc.next_step().unwrap() else { break };
                    assert!(
                        t.x * step.x as f32 + t.y * step.y as f32 >= 0.0,
                        "step {step:?} against the tangent at {p:?}"
                    );
                    p = p.stepped(step);
                }
            }
        }
    }

    #[test]
    fn the_largest_circles_do_not_overflow() {
        // Radius 100_000 around the origin, and a circle through opposite corners of the
        // ±100_000 machine (radius 282_843); a quarter at the radius limit.
        let cases = [
            (Point::new(100_000, 0), Point::ORIGIN, Point::new(100_000, 0), Ccw),
            (Point::new(100_000, 100_000), Point::new(-100_000, -100_000), Point::new(100_000, 100_000), Cw),
            (Point::new(MAX_RADIUS_STEPS, 0), Point::ORIGIN, Point::new(0, MAX_RADIUS_STEPS), Ccw),
            (Point::new(-100_000, 100_000), Point::new(100_000, -100_000), Point::new(-100_000, -300_000), Ccw),
        ];
        for (start, center, end, rotation) in cases {
            for method in [Classic, Diagonal] {
                let mut arc = ArcInterp::new(start, center, end, rotation, method).unwrap();
                let w = trace(&mut arc, start, method);
                check_arc(&w, start, center, end, rotation, method);
            }
        }
        // The full circle of radius 100_000 from an axis: exactly 8R classic steps, 4·√2·R ± 4
        // diagonal ones; the quarter at the limit exactly 2R classic steps.
        let s = Point::new(100_000, 0);
        let n = |method| trace(&mut ArcInterp::new(s, Point::ORIGIN, s, Ccw, method).unwrap(), s, method).len();
        assert_eq!(n(Classic), 800_000);
        assert!((n(Diagonal) as f64 - 400_000.0 * SQRT_2).abs() <= 4.0);
        let (s, e) = (Point::new(0, -MAX_RADIUS_STEPS), Point::new(MAX_RADIUS_STEPS, 0));
        let mut arc = ArcInterp::new(s, Point::ORIGIN, e, Ccw, Classic).unwrap();
        assert_eq!(trace(&mut arc, s, Classic).len(), 2 * MAX_RADIUS_STEPS as usize);
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

        /// Random arcs with lattice ends rounded from random angles (so generally off the circle).
        #[test]
        fn random_arcs_stay_on_the_circle_and_end_exactly(
            cx in -100_000i32..100_000, cy in -100_000i32..100_000,
            sx in -300i32..300, sy in -300i32..300,
            end_angle in 0.0f64..TAU, ccw: bool, classic: bool,
        ) {
            prop_assume!((sx, sy) != (0, 0));
            let (c, method, rotation) = (Point::new(cx, cy), if classic { Classic } else { Diagonal }, if ccw { Ccw } else { Cw });
            let start = Point::new(cx + sx, cy + sy);
            let r = libm::sqrt((sx * sx + sy * sy) as f64);
            let end = Point::new(cx + round(r * libm::cos(end_angle)) as i32, cy + round(r * libm::sin(end_angle)) as i32);
            let mut arc = ArcInterp::new(start, c, end, rotation, method).unwrap();
            let w = trace(&mut arc, start, method);
            check_arc(&w, start, c, end, rotation, method);
        }

        /// An arc to any point of a full circle's path is that path's prefix, with no finish.
        #[test]
        fn arcs_to_points_of_the_path_follow_the_full_circle(
            sx in -200i32..200, sy in -200i32..200, pick in 0.0f64..1.0, ccw: bool, classic: bool,
        ) {
            prop_assume!((sx, sy) != (0, 0));
            let (method, rotation) = (if classic { Classic } else { Diagonal }, if ccw { Ccw } else { Cw });
            let start = Point::new(sx, sy);
            let mut full = ArcInterp::new(start, Point::ORIGIN, start, rotation, method).unwrap();
            let circle = trace(&mut full, start, method);
            prop_assert_eq!(circle.last(), start);
            prop_assert_eq!(circle.tail_len(), 0);
            let k = 1 + ((circle.len() - 2) as f64 * pick) as usize;
            let end = circle.points[k];
            prop_assume!(cross(offset(start, Point::ORIGIN), offset(end, Point::ORIGIN)) != 0);
            let mut arc = ArcInterp::new(start, Point::ORIGIN, end, rotation, method).unwrap();
            let w = trace(&mut arc, start, method);
            prop_assert_eq!(&w.points[..], &circle.points[..=k]);
        }

        /// Arcs given by angles, as the keypad and serial commands give them.
        #[test]
        fn arcs_from_angles_sweep_what_was_asked(
            px in -100_000i32..100_000, py in -100_000i32..100_000, radius in 1i32..400,
            start_angle in -7.0f32..7.0, sweep in -7.0f32..7.0, classic: bool,
        ) {
            let method = if classic { Classic } else { Diagonal };
            let pen = Point::new(px, py);
            let mut arc = ArcInterp::from_angles(pen, radius, start_angle, sweep, method).unwrap();
            let (c, end, rotation) = (arc.center(), arc.end(), arc.rotation());
            prop_assert!((libm::sqrt(r2(pen, c) as f64) - radius as f64).abs() <= 0.71);
            prop_assert!(off_circle(end, c, pen) <= 0.71);
            let w = trace(&mut arc, pen, method);
            prop_assert_eq!(w.last(), end);
            if w.len() == 0 {
                prop_assert_eq!(end, pen);
                prop_assert!((sweep.abs() as f64) * radius as f64 <= 1.0);
            } else if sweep.abs() as f64 >= TAU {
                prop_assert_eq!(end, pen);
                check_arc(&w, pen, c, end, rotation, method);
            } else {
                // The drawn sweep: the arc's step count against the L1 / L∞ length of the
                // requested ideal arc.
                let r = libm::sqrt(r2(pen, c) as f64);
                let a0 = angle(pen, c);
                let (s, t) = (sweep as f64, sweep.abs() as f64);
                let sign = s.signum();
                let (l1, linf) = ideal_lengths(|u| (r * libm::cos(a0 + sign * u), r * libm::sin(a0 + sign * u)), 0.0, t, 4096);
                let analytic = if classic { l1 } else { linf };
                // The rounded end adds up to a step on each axis.
                let slack = count_slack(axes_crossed(a0, t, sign)) + 2.0;
                prop_assert!((w.len() as f64 - analytic).abs() <= slack, "{} steps for {} ± {}", w.len(), analytic, slack);
            }
        }

        /// Garbage in never panics and never hangs.
        #[test]
        fn any_input_is_refused_or_drawn(
            s in any::<(i32, i32)>(), c in any::<(i32, i32)>(), e in any::<(i32, i32)>(),
            radius in any::<i32>(), a0 in any::<f32>(), sweep in any::<f32>(), ccw: bool, classic: bool,
        ) {
            let (method, rotation) = (if classic { Classic } else { Diagonal }, if ccw { Ccw } else { Cw });
            let (s, c, e) = (Point::new(s.0, s.1), Point::new(c.0, c.1), Point::new(e.0, e.1));
            if let Ok(mut arc) = ArcInterp::new(s, c, e, rotation, method) {
                // Within tolerance only by chance; tiny circles are walked.
                if r2(s, c) < 10_000 {
                    trace(&mut arc, s, method);
                }
            }
            if let Ok(mut arc) = ArcInterp::from_angles(s, radius.rem_euclid(2000) + 1, a0, sweep, method) {
                let end = arc.end();
                prop_assert_eq!(trace(&mut arc, s, method).last(), end);
            }
            let _ = ArcInterp::from_angles(s, radius, a0, sweep, method);
        }
    }
}

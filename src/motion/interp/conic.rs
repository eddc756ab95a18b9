//! The conic tracer: circles and axis-aligned ellipses by point-by-point comparison (逐点比较法).
//! [`crate::motion::interp::arc`] and [`crate::motion::interp::ellipse`] set a trace up (check the points, find
//! where it ends); this module owns the stepping, from the first step to the end point.
//!
//! A circle and an axis-aligned ellipse are both the zero set of
//! `F(x, y) = wx·x² + wy·y² − c` around their centre (circle: `wx = wy = 1`, `c = R²`; ellipse:
//! `wx = b²`, `wy = a²`, `c = a²b²`). The tracer walks it with integer steps and keeps `F` up to
//! date by additions only (`F(x ± 1, y) = F + wx·(±2x + 1)`).
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
//! passes the line normal to the curve through the curve point nearest the end (the [`Gate`];
//! for a circle: the ray from the centre through the end). If that point is not the end (an
//! integer end point is rarely exactly on a real curve), it finishes with a few straight steps
//! that stay as close to the curve as they can. Every step moves forward in angle or along a
//! radius, a step budget caps the curve part, and the straight finish shortens the distance to
//! the end with every step, so a trace always ends, exactly on its end point.
//!
//! # Batches
//!
//! [`Tracer::step`] takes one step by the rules above, checking everything at every step.
//! [`Tracer::fill`] takes the very same steps, most of them in a tight loop, and
//! [`Tracer::next_step`] is `fill` with a buffer of one. Strictly inside a
//! quadrant (off both axes) only the curve rule matters, and it is the same in every quadrant
//! once the quadrant is turned onto the first one: in that quadrant's own frame `(u, v)`
//! (`u > 0`, `v >= 0`, travel counter-clockwise, weights `wu`, `wv`) the inward move is always
//! −u, the outward one +v. With `du = wu·(1 − 2u)` and `dv = wv·(2v + 1)`, the changes of `F`
//! for those moves, classic steps −u when `F >= 0`, else +v. Diagonal, with `D = 4·(F + du + dv)`
//! (four times `F` at the diagonal point), steps −u when `D > 2dv + wv`, +v when
//! `D < 2du + wu`, and both otherwise: the midpoint tests above, rearranged. `D` and both
//! thresholds change by additions of constants, so a step is two comparisons and a few
//! additions.
//!
//! The loop runs only where nothing else can happen, for a count of "quiet" steps worked out
//! before it starts: fewer than `u − 1` steps cannot reach the next axis, fewer than the
//! Chebyshev distance to the end point cannot land on it, a step moves a point's [`Gate`] value
//! by at most `GATE_SCALE·(|along.x| + |along.y|)` so a point well behind the gate cannot pass
//! it within the next few steps, and the budget is counted down. Such a run (`Run`: the point
//! in the quadrant's frame, `F` or `D`, the two changes or thresholds) lasts across batches
//! until its count is used up, so a batch only loads it, loops and stores it back. Everything
//! else (points on an axis, climbing a tip, crossing into the next quadrant, the last steps
//! before the gate, the straight finish) goes through [`Tracer::step`].
//!
//! # Arithmetic
//!
//! Everything the tracer keeps per step is `i64`; no step needs wider arithmetic. The bound:
//! every point the tracer visits, and every point it evaluates `F` at (candidate moves,
//! midpoints), lies within `d <= 8` steps of the curve (start and end within
//! [`ARC_END_TOLERANCE_STEPS`](crate::motion::interp::arc::ARC_END_TOLERANCE_STEPS), curve points within
//! a step, candidates a step farther, the straight finish between a curve point and the end).
//! There `|F| <= |∇F|·d + W·d²` with `W = max(wx, wy)` and `|∇F| <= 2·W·S` on the curve, `S` the
//! largest semi-axis:
//!
//! - circles (`W = 1`, `S <= √2·MAX_RADIUS_STEPS < 2²¹`): `|F| < 2²⁶`, every quantity below
//!   `2³⁰`;
//! - ellipses (`W <= 2³⁶`, `S <= MAX_ELLIPSE_AXIS_STEPS = 2¹⁸`): `|F| <= 2⁵⁵·8 + 2³⁶·64 < 2^58.01`,
//!   `D = 4F < 2^60.02`, the thresholds `w·(4c + 3) < 2^56.01`, the changes of `D`
//!   (`2·threshold + 6w`) `< 2^57.1`: all well inside `i64` (`2⁶³`).
//!
//! A quiet run's values (`F` or `D`, the changes, the thresholds and the sums the loop forms)
//! stay below `396·W·S` in magnitude, so where `W·S <= 2²²` ([`run::NARROW_SIZE_MAX`]: every
//! circle, ellipses up to about 160 steps) the loop computes in `i32`, which the Cortex-M4 does
//! in one instruction per operation and with half the registers.
//!
//! `c = a²b²` itself does not fit (up to `2⁷²`): it is kept modulo `2⁶⁴`, and `F` at the start
//! and at the end (the only places it is computed from scratch) is evaluated with wrapping
//! arithmetic, which is exact because the true value lies within the bound. A [`Gate`] value is
//! at most `GATE_SCALE·2²² · 2²⁰ = 2⁵²` per axis. Should the budget ever run out (it never does
//! on a correct trace) the straight finish may start far from the curve; it updates `F` with
//! wrapping arithmetic, so the worst that can happen there is a less well chosen finishing step.

use crate::geom::{Rotation, Step};
use crate::math;
use crate::motion::interp::interpolator::{Filled, Tangent};
use crate::motion::method::Method;

mod run;

use run::{Run, to_local};
#[cfg(test)]
pub(crate) mod test_support;
#[cfg(test)]
mod tests;

/// Extra steps per quadrant in the curve budget, beyond the semi-axes, for starts off the curve.
const QUARTER_SLACK_STEPS: u32 = 8;

/// [`Gate`] points are kept in 1/`GATE_SCALE` step.
pub(crate) const GATE_SCALE: i64 = 1024;

/// Scale of [`Gate`]'s unit direction.
const GATE_DIRECTION_SCALE: f32 = 1_048_576.0;

/// One step changes a [`Gate`] value by at most `GATE_SCALE·(|along.x| + |along.y|)`, less than
/// `2^GATE_STEP_SHIFT` (`|along.x| + |along.y| <= √2·GATE_DIRECTION_SCALE + 1 < 2²¹`): a value
/// of `−g` is at least `g >> GATE_STEP_SHIFT` steps behind the gate.
const GATE_STEP_SHIFT: u32 = 31;

/// A point in 1/[`GATE_SCALE`] step, relative to the centre.
pub(crate) type Fine = (i64, i64);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// Following the curve.
    Curve,
    /// Straight finish to the end point.
    Tail,
    /// At the end.
    Done,
}

/// The quadrant of `(x, y)`, counted counter-clockwise from +X; each quadrant includes the
/// half-axis where it begins, so a counter-clockwise path enters quadrants in order 0, 1, 2, 3.
fn quadrant(x: i32, y: i32) -> u8 {
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

/// `a × b`: positive when `b` lies counter-clockwise of `a` (within half a turn).
pub(crate) fn cross(a: (i64, i64), b: (i64, i64)) -> i64 {
    a.0 * b.1 - a.1 * b.0
}

/// `wx·x² + wy·y² − c`, modulo 2⁶⁴: exact wherever the true value fits in `i64`, which it does
/// within [`ARC_END_TOLERANCE_STEPS`](crate::motion::interp::arc::ARC_END_TOLERANCE_STEPS) of the
/// curve (see the module documentation).
fn discriminant_at(p: (i32, i32), weights: (i64, i64), c: i64) -> i64 {
    let (x, y) = (p.0 as i64, p.1 as i64);
    weights.0.wrapping_mul(x * x).wrapping_add(weights.1.wrapping_mul(y * y)).wrapping_sub(c)
}

/// Where the curve part of a trace ends: the line through a point of the curve, normal to the
/// curve there. A trace in the end's quadrant is past it when it has moved beyond that line
/// in the direction of travel. (The normal line, not the ray from the centre: on a flat
/// ellipse the ray meets the band of lattice points around the curve over many steps.)
#[derive(Clone, Copy, Debug)]
struct Gate {
    /// The curve point, in 1/[`GATE_SCALE`] step.
    point: Fine,
    /// The unit tangent there in the direction of travel, scaled by [`GATE_DIRECTION_SCALE`].
    along: (i32, i32),
}

impl Gate {
    /// The gate at curve point `p` (frame coordinates, 1/[`GATE_SCALE`] step) of a curve with
    /// weights proportional to `tw`, travelling counter-clockwise, with `p` first moved into
    /// `quadrant` (the end point's) should it lie just across an axis.
    fn new(p: Fine, quadrant: u8, tw: (f32, f32)) -> Self {
        let (x, y) = match quadrant {
            0 => (p.0.max(1), p.1.max(0)),
            1 => (p.0.min(0), p.1.max(1)),
            2 => (p.0.min(-1), p.1.min(0)),
            _ => (p.0.max(0), p.1.min(-1)),
        };
        let (tx, ty) = (-tw.1 * y as f32, tw.0 * x as f32);
        let len = math::hypot(tx, ty);
        let along = if len > 0.0 {
            let k = GATE_DIRECTION_SCALE / len;
            (math::round(tx * k) as i32, math::round(ty * k) as i32)
        } else {
            (0, 0)
        };
        Gate { point: (x, y), along }
    }

    /// How far lattice point `n` lies beyond the gate (positive) or before it, in units of
    /// 1/(`GATE_SCALE`·`GATE_DIRECTION_SCALE`) step.
    fn value(&self, n: (i32, i32)) -> i64 {
        let dx = n.0 as i64 * GATE_SCALE - self.point.0;
        let dy = n.1 as i64 * GATE_SCALE - self.point.1;
        dx * self.along.0 as i64 + dy * self.along.1 as i64
    }

    /// True when lattice point `n` lies strictly beyond the gate.
    fn passed_by(&self, n: (i32, i32)) -> bool {
        self.value(n) > 0
    }
}

/// On an axis, inside the curve, with the curve's crossing of that axis more than half a step
/// farther out (the tip of an ellipse narrower than a step, or a start inside the curve): the
/// move out along the axis. Not right after moving in along the same axis (`last`), so that a
/// trace turns at a tip instead of climbing it again.
fn climb_move(p: (i32, i32), f: i64, last: (i32, i32), weights: (i64, i64)) -> Option<(i32, i32)> {
    if f >= 0 {
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
    let mid = 4 * f + w * (4 * c.unsigned_abs() as i64 + 1);
    if mid < 0 { Some(m) } else { None }
}

/// See [`Tracer::progress_quadrant`].
fn progress_quadrant(p: (i32, i32), f: i64, last: (i32, i32), weights: (i64, i64)) -> u8 {
    let q = quadrant(p.0, p.1);
    if climb_move(p, f, last, weights).is_some() { (q + 3) % 4 } else { q }
}

/// The unit vector along `(x, y)`; `(1, 0)` for a zero vector.
/// (Inputs are at most a few million: their squares stay finite.)
fn unit(x: f32, y: f32) -> Tangent {
    let len = math::sqrt(x * x + y * y);
    if len > 0.0 { Tangent { x: x / len, y: y / len } } else { Tangent { x: 1.0, y: 0.0 } }
}

/// Walks `F(x, y) = wx·x² + wy·y² − c = 0`; see the module documentation.
///
/// All coordinates are relative to the centre, in a frame where travel is counter-clockwise
/// (Y mirrored for clockwise travel).
#[derive(Clone, Debug)]
pub(crate) struct Tracer {
    x: i32,
    y: i32,
    ex: i32,
    ey: i32,
    /// Where the curve part ends, in the end's quadrant.
    gate: Gate,
    wx: i64,
    wy: i64,
    /// The weights divided by the larger one, for directions.
    tw: (f32, f32),
    /// `F` at the current point.
    f: i64,
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
    budget: u32,
    /// The previous move (frame coordinates); during a quiet run brought up to date only when
    /// the run ends (it only matters on an axis, and a run neither starts nor ends on one).
    last: (i32, i32),
    /// Steps taken by the straight finish so far.
    tail_steps: u32,
    /// Quiet steps left in the run under way (see the module documentation); 0 outside runs.
    /// During a run `f` is not kept: `run` holds the state.
    quiet: u32,
    run: Run,
    /// Quiet runs compute in `i32` (see [`run::NARROW_SIZE_MAX`]).
    narrow: bool,
}

impl Tracer {
    /// `start` and `end` relative to the centre (the caller checks them: within
    /// [`ARC_END_TOLERANCE_STEPS`](crate::motion::interp::arc::ARC_END_TOLERANCE_STEPS) of the curve),
    /// `near` the point of the curve nearest to the end (machine frame, relative to the centre,
    /// in 1/[`GATE_SCALE`] step), where the curve part stops at the [`Gate`]; an end on the
    /// start's own ray (the start itself included) takes one full turn. `weights` = `(wx, wy)`,
    /// `c` modulo 2⁶⁴, `half_axes` = ceilings of the semi-axes along X and Y.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        start: (i32, i32),
        end: (i32, i32),
        near: Fine,
        weights: (i64, i64),
        c: i64,
        half_axes: (i32, i32),
        rotation: Rotation,
        method: Method,
    ) -> Self {
        let mirror = rotation == Rotation::Clockwise;
        let (x, y) = (start.0, if mirror { -start.1 } else { start.1 });
        let (ex, ey) = (end.0, if mirror { -end.1 } else { end.1 });
        let (wx, wy) = weights;
        let big = wx.max(wy) as f32;
        let tw = (wx as f32 / big, wy as f32 / big);
        let f = discriminant_at((x, y), weights, c);
        // A start on an axis counts as having just come in along it, so that it does not climb
        // to a tip: whether the tip lies ahead or behind is unknown, and it is taken to be
        // behind (at the start's own angle).
        let last = if x == 0 {
            (0, -y.signum())
        } else if y == 0 {
            (-x.signum(), 0)
        } else {
            (0, 0)
        };
        let q = progress_quadrant((x, y), f, last, weights);
        // An end inside a tip, on its axis, is met on the way up to the tip: it counts in the
        // quadrant before.
        let fe = discriminant_at((ex, ey), weights, c);
        let eq = if (ex, ey) == (x, y) { q } else { progress_quadrant((ex, ey), fe, (0, 0), weights) };
        let mut needed = (eq + 4 - q) % 4;
        let (s, e) = ((x as i64, y as i64), (ex as i64, ey as i64));
        let ahead = cross(s, e);
        if ahead == 0 && s.0 * e.0 + s.1 * e.1 > 0 {
            // On the start's own ray: one full turn (less one quadrant if the end is met on the
            // way up a tip the start has left behind).
            needed = if needed == 3 { 3 } else { needed + 4 };
        } else if needed == 0 && ahead < 0 {
            // Same quadrant, behind the start.
            needed = 4;
        }
        // Back to the start itself; else to the curve point nearest the end.
        let target = if (x, y) == (ex, ey) {
            (x as i64 * GATE_SCALE, y as i64 * GATE_SCALE)
        } else {
            (near.0, if mirror { -near.1 } else { near.1 })
        };
        let gate = Gate::new(target, eq, tw);
        let quarter = half_axes.0 as u32 + half_axes.1 as u32 + QUARTER_SLACK_STEPS;
        Tracer {
            x,
            y,
            ex,
            ey,
            gate,
            wx,
            wy,
            tw,
            f,
            mirror,
            method,
            phase: Phase::Curve,
            quadrant: q,
            crossed: 0,
            needed,
            budget: 4 * (needed as u32 + 1) * quarter,
            last,
            tail_steps: 0,
            quiet: 0,
            run: Run::default(),
            narrow: wx.max(wy) * half_axes.0.max(half_axes.1) as i64 <= run::NARROW_SIZE_MAX,
        }
    }

    /// The next step in machine coordinates, `None` at the end: [`fill`](Self::fill) with a
    /// buffer of one.
    pub(crate) fn next_step(&mut self) -> Option<Step> {
        let mut one = [Step::NONE];
        if self.fill(&mut one).steps == 1 { Some(one[0]) } else { None }
    }

    /// Writes the next steps into `out`, exactly those [`step`](Self::step) would take one by
    /// one, until `out` is full or the trace ends. A conic never kinks: its tangent turns
    /// smoothly, even round a tip narrower than a step, which the planner slows for by its
    /// curvature.
    pub(crate) fn fill(&mut self, out: &mut [Step]) -> Filled {
        let mut i = 0;
        while i < out.len() {
            if self.quiet == 0 {
                self.quiet = self.begin_run();
            }
            if self.quiet > 0 {
                let n = (self.quiet as usize).min(out.len() - i);
                self.take_run(&mut out[i..i + n]);
                i += n;
            } else {
                match self.step() {
                    Some(step) => {
                        out[i] = step;
                        i += 1;
                    }
                    None => return Filled::ended(i, Ok(())),
                }
            }
        }
        if self.phase == Phase::Done { Filled::ended(i, Ok(())) } else { Filled::more(i) }
    }

    /// One step by the rules, checking everything: the reference the quiet runs follow. Never
    /// during a run.
    pub(crate) fn step(&mut self) -> Option<Step> {
        debug_assert_eq!(self.quiet, 0, "a step by the rules during a quiet run");
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
            Phase::Curve | Phase::Done => (-self.tw.1 * self.y as f32, self.tw.0 * self.x as f32),
        };
        unit(tx, if self.mirror { -ty } else { ty })
    }

    /// `F` at the current point.
    #[cfg(test)]
    pub(crate) fn discriminant(&self) -> i64 {
        if self.quiet > 0 { self.run.discriminant() } else { self.f }
    }

    /// Steps taken by the straight finish so far.
    #[cfg(test)]
    pub(crate) fn tail_steps(&self) -> u32 {
        self.tail_steps
    }

    /// Change of `F` for a step `sx` along X (and `sy` along Y) from the current point.
    /// How many of the next steps need no check beyond the curve rule: none unless the point
    /// lies strictly inside its quadrant; fewer than it takes to reach the next axis, to reach
    /// the end point or to pass the gate, and no more than the budget. If any, starts a run.
    fn begin_run(&mut self) -> u32 {
        if self.phase != Phase::Curve || self.crossed > self.needed {
            return 0;
        }
        // Climbing toward a tip, the quadrant counted is the one before the point's own: there
        // `u` is 0 in this frame.
        let q = self.quadrant;
        let (u, v) = to_local(q, self.x, self.y);
        if u < 2 || v < 1 {
            return 0;
        }
        let mut quiet = ((u - 1) as u32).min(self.budget);
        if self.crossed == self.needed {
            let g = self.gate.value((self.x, self.y));
            if g >= 0 {
                return 0;
            }
            let to_end = (self.ex - self.x).unsigned_abs().max((self.ey - self.y).unsigned_abs());
            let to_gate = ((-g) >> GATE_STEP_SHIFT).min(u32::MAX as i64) as u32;
            quiet = quiet.min(to_end.saturating_sub(1)).min(to_gate);
        }
        if quiet > 0 {
            self.run = Run::new(q, (u, v), (self.wx, self.wy), self.f, self.mirror, self.method, self.narrow);
        }
        quiet
    }

    /// Takes `out.len()` steps of the run under way (no more than are left) by the curve rule
    /// alone; at the end of the run, the tracer's own state takes over again.
    fn take_run(&mut self, out: &mut [Step]) {
        self.run.take(out);
        (self.x, self.y) = self.run.point();
        let n = out.len() as u32;
        self.budget -= n;
        self.quiet -= n;
        if self.quiet == 0 {
            self.f = self.run.discriminant();
            if let Some(s) = out.last() {
                self.last = (s.x as i32, if self.mirror { -(s.y as i32) } else { s.y as i32 });
            }
        }
    }

    fn df_x(&self, sx: i32) -> i64 {
        self.wx * (2 * sx as i64 * self.x as i64 + 1)
    }

    fn df_y(&self, sy: i32) -> i64 {
        self.wy * (2 * sy as i64 * self.y as i64 + 1)
    }

    fn df(&self, m: (i32, i32)) -> i64 {
        (if m.0 != 0 { self.df_x(m.0) } else { 0 }) + (if m.1 != 0 { self.df_y(m.1) } else { 0 })
    }

    fn climb(&self) -> Option<(i32, i32)> {
        climb_move((self.x, self.y), self.f, self.last, (self.wx, self.wy))
    }

    /// The quadrant the trace counts point `p` (with discriminant `f`, reached by move `last`)
    /// in: its own, except while it climbs an axis toward a tip, which still belongs to the
    /// quadrant before the tip.
    fn progress_quadrant(&self, p: (i32, i32), f: i64, last: (i32, i32)) -> u8 {
        progress_quadrant(p, f, last, (self.wx, self.wy))
    }

    /// The move the curve rule chooses at the current point.
    fn curve_move(&self) -> (i32, i32) {
        if let Some(m) = self.climb() {
            return m;
        }
        // Forward directions: along the tangent (−wy·y, wx·x); a zero component moves inward.
        let sx = if self.y != 0 { -self.y.signum() } else { -self.x.signum() };
        let sy = if self.x != 0 { self.x.signum() } else { -self.y.signum() };
        let x_inward = sx * self.x < 0;
        let (inward, outward) = if x_inward { ((sx, 0), (0, sy)) } else { ((0, sy), (sx, 0)) };
        let diagonal = (sx, sy);
        let chosen = match self.method {
            Method::Classic => {
                if self.f >= 0 {
                    inward
                } else {
                    outward
                }
            }
            Method::Diagonal => {
                let fd = self.f + self.df(diagonal);
                if fd == 0 {
                    diagonal
                } else if fd > 0 {
                    // The curve passes between the inward point and the diagonal point: compare
                    // with their midpoint, half a step outward from the inward point.
                    let f_in = self.f + self.df(inward);
                    let (w, s, c) = if x_inward { (self.wy, sy, self.y) } else { (self.wx, sx, self.x) };
                    let mid = 4 * f_in + w * (4 * (s * c) as i64 + 1);
                    if mid > 0 { inward } else { diagonal }
                } else {
                    // Between the outward point and the diagonal point.
                    let f_out = self.f + self.df(outward);
                    let (w, s, c) = if x_inward { (self.wx, sx, self.x) } else { (self.wy, sy, self.y) };
                    let mid = 4 * f_out + w * (4 * (s * c) as i64 + 1);
                    if mid < 0 { outward } else { diagonal }
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
        let step = self.apply(m, self.f + self.df(m));
        if reached {
            self.phase = if n == end { Phase::Done } else { Phase::Tail };
        }
        Some(step)
    }

    /// Distance to the end in steps of the method (one axis or both axes per step).
    fn distance_to_end(&self, p: (i32, i32)) -> u32 {
        let (dx, dy) = ((self.ex - p.0).unsigned_abs(), (self.ey - p.1).unsigned_abs());
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
        let mut best: Option<((i32, i32), f32)> = None;
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
        let step = self.apply(m, self.f.wrapping_add(self.df(m)));
        self.tail_steps = self.tail_steps.saturating_add(1);
        if self.x == self.ex && self.y == self.ey {
            self.phase = Phase::Done;
        }
        Some(step)
    }

    /// First-order distance from the curve after move `m`.
    fn off_curve(&self, m: (i32, i32)) -> f32 {
        let f = self.f.wrapping_add(self.df(m)) as f32;
        let (x, y) = ((self.x + m.0) as f32, (self.y + m.1) as f32);
        let gx = 2.0 * self.wx as f32 * x;
        let gy = 2.0 * self.wy as f32 * y;
        let g = math::max(math::hypot(gx, gy), 1.0);
        f.abs() / g
    }

    /// Takes move `m` (frame coordinates), after which `F` is `f`, and returns it as a machine
    /// step.
    fn apply(&mut self, m: (i32, i32), f: i64) -> Step {
        self.f = f;
        self.x += m.0;
        self.y += m.1;
        self.last = m;
        let dy = if self.mirror { -m.1 } else { m.1 };
        Step::new(m.0 as i8, dy as i8)
    }
}

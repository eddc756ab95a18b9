//! Quiet runs: the steps strictly inside a quadrant, where the curve rule alone decides,
//! taken in a tight loop in the quadrant's own frame (see [`crate::interp::conic`], "Batches"
//! and "Arithmetic"). Owns the run's state between batches and the loops.

use core::ops::{Add, AddAssign};

use super::{GATE_STEP_SHIFT, Phase, Tracer, from_local, to_local};
use crate::geom::Step;
use crate::interp::Method;

/// Largest `W·S` (largest weight times largest semi-axis, in steps) whose quiet runs compute in
/// `i32`: all circles (`W = 1`) and ellipses up to about 160 steps. The run's values are at most
/// `396·W·S` (see [`crate::interp::conic`], "Arithmetic"), below 2³¹ up to `W·S = 2²²`.
pub(super) const NARROW_SIZE_MAX: i64 = 1 << 22;

/// A quiet run under way: the curve rule's state in the quadrant's own frame, kept from one
/// batch to the next.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Run {
    /// The point in the quadrant's own frame.
    u: i32,
    v: i32,
    /// The weights along u and v.
    wu: i64,
    wv: i64,
    /// Classic: `F`. Diagonal: `D`, four times `F` at the diagonal point.
    lead: i64,
    /// Classic: `du`, the change of `F` for −u. Diagonal: the threshold `2du + wu`.
    along_u: i64,
    /// Classic: `dv`, the change of `F` for +v. Diagonal: the threshold `2dv + wv`.
    along_v: i64,
    /// The machine steps for −u, +v and both.
    moves: [Step; 3],
}

impl Tracer {
    /// How many of the next steps need no check beyond the curve rule: none unless the point
    /// lies strictly inside its quadrant; fewer than it takes to reach the next axis, to reach
    /// the end point or to pass the gate, and no more than the budget. If any, starts a run.
    pub(super) fn begin_run(&mut self) -> u32 {
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
        if quiet == 0 {
            return 0;
        }
        let (wu, wv) = if q & 1 == 0 { (self.wx, self.wy) } else { (self.wy, self.wx) };
        // −u and +v in the frame, and as machine steps.
        let (mu, mv) = match q {
            0 => ((-1, 0), (0, 1)),
            1 => ((0, -1), (-1, 0)),
            2 => ((1, 0), (0, -1)),
            _ => ((0, 1), (1, 0)),
        };
        let y_sign = if self.mirror { -1 } else { 1 };
        let step = |m: (i8, i8)| Step::new(m.0, m.1 * y_sign);
        let moves = [step(mu), step(mv), step((mu.0 + mv.0, mu.1 + mv.1))];
        let du = wu * (1 - 2 * u as i64);
        let dv = wv * (2 * v as i64 + 1);
        let (lead, along_u, along_v) = match self.method {
            Method::Classic => (self.f, du, dv),
            Method::Diagonal => (4 * (self.f + du + dv), 2 * du + wu, 2 * dv + wv),
        };
        self.run = Run { u, v, wu, wv, lead, along_u, along_v, moves };
        quiet
    }

    /// Takes `out.len()` steps of the run under way (no more than are left) by the curve rule
    /// alone; at the end of the run, the tracer's own state takes over again.
    pub(super) fn run(&mut self, out: &mut [Step]) {
        match (self.method, self.narrow) {
            (Method::Classic, true) => run_classic::<i32>(&mut self.run, out),
            (Method::Classic, false) => run_classic::<i64>(&mut self.run, out),
            (Method::Diagonal, true) => run_diagonal::<i32>(&mut self.run, out),
            (Method::Diagonal, false) => run_diagonal::<i64>(&mut self.run, out),
        }
        (self.x, self.y) = from_local(self.quadrant, self.run.u, self.run.v);
        let n = out.len() as u32;
        self.budget -= n;
        self.quiet -= n;
        if self.quiet == 0 {
            self.f = self.run_discriminant();
            if let Some(s) = out.last() {
                self.last = (s.x as i32, if self.mirror { -(s.y as i32) } else { s.y as i32 });
            }
        }
    }

    /// `F` at the current point of the run under way.
    pub(super) fn run_discriminant(&self) -> i64 {
        let r = &self.run;
        match self.method {
            Method::Classic => r.lead,
            // du = (along_u − wu)/2, dv = (along_v − wv)/2.
            Method::Diagonal => (r.lead >> 2) - ((r.along_u - r.wu) >> 1) - ((r.along_v - r.wv) >> 1),
        }
    }
}

/// The integer a quiet run computes in: `i32` where every value of the run fits (see
/// [`NARROW_SIZE_MAX`]), `i64` elsewhere. The run only compares and adds.
trait Word: Copy + PartialOrd + Add<Output = Self> + AddAssign + Into<i64> {
    /// `v`, which the caller knows to fit.
    fn narrow(v: i64) -> Self;
}

impl Word for i32 {
    fn narrow(v: i64) -> Self {
        v as i32
    }
}

impl Word for i64 {
    fn narrow(v: i64) -> Self {
        v
    }
}

/// Classic steps of run `r`: −u when `F >= 0`, else +v.
#[inline(always)]
fn run_classic<T: Word>(r: &mut Run, out: &mut [Step]) {
    let (mut f, mut du, mut dv) = (T::narrow(r.lead), T::narrow(r.along_u), T::narrow(r.along_v));
    let (ddu, ddv) = (T::narrow(2 * r.wu), T::narrow(2 * r.wv));
    let zero = T::narrow(0);
    let [s_in, s_out, _] = r.moves;
    let mut inward = 0;
    for slot in out.iter_mut() {
        if f >= zero {
            f += du;
            du += ddu;
            *slot = s_in;
            inward += 1;
        } else {
            f += dv;
            dv += ddv;
            *slot = s_out;
        }
    }
    (r.lead, r.along_u, r.along_v) = (f.into(), du.into(), dv.into());
    r.u -= inward;
    r.v += out.len() as i32 - inward;
}

/// Diagonal steps of run `r`: −u when `D > t_in`, +v when `D < t_out`, else both.
#[inline(always)]
fn run_diagonal<T: Word>(r: &mut Run, out: &mut [Step]) {
    let (mut d, mut t_out, mut t_in) = (T::narrow(r.lead), T::narrow(r.along_u), T::narrow(r.along_v));
    let (wu, wv) = (r.wu, r.wv);
    let (d_in, d_out, d_both) = (T::narrow(6 * wu), T::narrow(6 * wv), T::narrow(6 * (wu + wv)));
    let (k_u, k_v) = (T::narrow(4 * wu), T::narrow(4 * wv));
    let [s_in, s_out, s_both] = r.moves;
    let (mut inward, mut outward) = (0, 0);
    for slot in out.iter_mut() {
        if d > t_in {
            d += t_out + t_out + d_in;
            t_out += k_u;
            *slot = s_in;
            inward += 1;
        } else if d < t_out {
            d += t_in + t_in + d_out;
            t_in += k_v;
            *slot = s_out;
            outward += 1;
        } else {
            let t = t_in + t_out;
            d += t + t + d_both;
            t_in += k_v;
            t_out += k_u;
            *slot = s_both;
        }
    }
    (r.lead, r.along_u, r.along_v) = (d.into(), t_out.into(), t_in.into());
    let both = out.len() as i32 - inward - outward;
    r.u -= inward + both;
    r.v += outward + both;
}

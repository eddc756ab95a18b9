//! Quiet runs: the steps strictly inside a quadrant, where the curve rule alone decides,
//! taken in a tight loop in the quadrant's own frame (see [`crate::motion::interp::conic`], "Batches"
//! and "Arithmetic"). Owns the quadrant frames, a run's state between batches and the loops;
//! the tracer decides when a run starts and how long it lasts.

use core::ops::{Add, AddAssign};

use crate::geom::Step;
use crate::motion::method::Method;

/// Largest `W·S` (largest weight times largest semi-axis, in steps) whose quiet runs compute in
/// `i32`: all circles (`W = 1`) and ellipses up to about 160 steps. The run's values are at most
/// `396·W·S` (see [`crate::motion::interp::conic`], "Arithmetic"), below 2³¹ up to `W·S = 2²²`.
pub(super) const NARROW_SIZE_MAX: i64 = 1 << 22;

/// `(x, y)` in the own frame `(u, v)` of quadrant `q`: the quadrant turned onto the first one,
/// so that its points have `u > 0`, `v >= 0`.
pub(super) fn to_local(q: u8, x: i32, y: i32) -> (i32, i32) {
    match q {
        0 => (x, y),
        1 => (y, -x),
        2 => (-x, -y),
        _ => (-y, x),
    }
}

/// The inverse of [`to_local`].
pub(super) fn from_local(q: u8, u: i32, v: i32) -> (i32, i32) {
    match q {
        0 => (u, v),
        1 => (-v, u),
        2 => (-u, -v),
        _ => (v, -u),
    }
}

/// A quiet run under way: the curve rule's state in the quadrant's own frame, kept from one
/// batch to the next.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Run {
    /// The quadrant whose frame the run is in.
    quadrant: u8,
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
    method: Method,
    /// The loops compute in `i32` (see [`NARROW_SIZE_MAX`]).
    narrow: bool,
}

impl Run {
    /// A run from `(u, v)` in the frame of quadrant `q`, where `F` is `f`, for a curve with
    /// weights `(wx, wy)` (Y mirrored in machine steps when `mirror`).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn new(
        q: u8,
        (u, v): (i32, i32),
        (wx, wy): (i64, i64),
        f: i64,
        mirror: bool,
        method: Method,
        narrow: bool,
    ) -> Run {
        let (wu, wv) = if q & 1 == 0 { (wx, wy) } else { (wy, wx) };
        // −u and +v in the frame, and as machine steps.
        let (mu, mv) = match q {
            0 => ((-1, 0), (0, 1)),
            1 => ((0, -1), (-1, 0)),
            2 => ((1, 0), (0, -1)),
            _ => ((0, 1), (1, 0)),
        };
        let y_sign = if mirror { -1 } else { 1 };
        let step = |m: (i8, i8)| Step::new(m.0, m.1 * y_sign);
        let moves = [step(mu), step(mv), step((mu.0 + mv.0, mu.1 + mv.1))];
        let du = wu * (1 - 2 * u as i64);
        let dv = wv * (2 * v as i64 + 1);
        let (lead, along_u, along_v) = match method {
            Method::Classic => (f, du, dv),
            Method::Diagonal => (4 * (f + du + dv), 2 * du + wu, 2 * dv + wv),
        };
        Run { quadrant: q, u, v, wu, wv, lead, along_u, along_v, moves, method, narrow }
    }

    /// Takes `out.len()` steps by the curve rule alone (the caller knows they are quiet).
    pub(super) fn take(&mut self, out: &mut [Step]) {
        match (self.method, self.narrow) {
            (Method::Classic, true) => run_classic::<i32>(self, out),
            (Method::Classic, false) => run_classic::<i64>(self, out),
            (Method::Diagonal, true) => run_diagonal::<i32>(self, out),
            (Method::Diagonal, false) => run_diagonal::<i64>(self, out),
        }
    }

    /// The current point, in the curve's frame.
    pub(super) fn point(&self) -> (i32, i32) {
        from_local(self.quadrant, self.u, self.v)
    }

    /// `F` at the current point.
    pub(super) fn discriminant(&self) -> i64 {
        match self.method {
            Method::Classic => self.lead,
            // du = (along_u − wu)/2, dv = (along_v − wv)/2.
            Method::Diagonal => (self.lead >> 2) - ((self.along_u - self.wu) >> 1) - ((self.along_v - self.wv) >> 1),
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

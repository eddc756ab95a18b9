//! What every interpolator offers the planner: the [`Interpolator`] trait, the steps' tangent
//! ([`Tangent`], [`KINK_CHORD`]), what a batch of steps did ([`Filled`]) and why a curve ends
//! early ([`CurveError`]).

use crate::geom::Step;

/// Why a curve ended before its end point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum CurveError {
    /// The function left its domain (sqrt of a negative, ln of zero, ...).
    Domain,
    /// Division by zero.
    DivisionByZero,
    /// A value too large for the machine's range.
    Overflow,
    /// The curve jumps by more than the allowed distance between two points.
    Jump,
    /// Between two columns the curve strays from its chord further than the columns show: it
    /// changes faster than the steps sample it (see `crate::motion::interp::explicit::between`).
    Aliased,
    /// The curve would leave the machine's travel area (`$130`, `$131`): it ends at the last
    /// point inside, before any step toward the first point outside.
    Travel,
}

/// A unit vector in step space: the direction of travel of the ideal curve.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Tangent {
    pub x: f32,
    pub y: f32,
}

impl Tangent {
    /// The unit vector along `(x, y)`; `(1, 0)` for a zero vector.
    pub fn along(x: f32, y: f32) -> Self {
        let len = crate::math::sqrt(x * x + y * y);
        if len > 0.0 && len.is_finite() { Tangent { x: x / len, y: y / len } } else { Tangent { x: 1.0, y: 0.0 } }
    }
}

/// A change of direction between two steps larger than this chord between their unit tangents
/// (≈ 5.7°) is a kink: no smooth curve turns so much in one step unless its radius is under
/// about ten steps. The planner passes a kink by the junction rule, as a joint between two
/// segments; [`Interpolator::fill`] stops at every kink so that the planner sees it.
pub const KINK_CHORD: f32 = 0.1;

/// What [`Interpolator::fill`] did: how many steps it wrote, and why it stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Filled {
    /// Steps written, from the start of the buffer.
    pub steps: usize,
    /// `None`: the buffer is full, or the curve kinks (see `kink`), and goes on. `Some(Ok(()))`:
    /// the curve reached its end point after these steps; `Some(Err(e))`: it failed there (see
    /// [`Interpolator::next_step`]).
    pub end: Option<Result<(), CurveError>>,
    /// The last step written reached a kink (see [`KINK_CHORD`]): the unit tangent before that
    /// step. [`Interpolator::tangent`] now gives the direction after the kink.
    pub kink: Option<Tangent>,
}

impl Filled {
    /// `steps` written and the buffer full: the curve goes on.
    pub const fn more(steps: usize) -> Filled {
        Filled { steps, end: None, kink: None }
    }

    /// `steps` written, then the curve ended (`Ok`) or failed.
    pub const fn ended(steps: usize, end: Result<(), CurveError>) -> Filled {
        Filled { steps, end: Some(end), kink: None }
    }

    /// `steps` written, the last reaching a kink from direction `before`.
    pub const fn kink(steps: usize, before: Tangent) -> Filled {
        Filled { steps, end: None, kink: Some(before) }
    }
}

impl Tangent {
    /// True when the direction jumps from `self` to `next` by more than [`KINK_CHORD`].
    pub fn kinks_to(self, next: Tangent) -> bool {
        let (dx, dy) = (next.x - self.x, next.y - self.y);
        dx * dx + dy * dy > KINK_CHORD * KINK_CHORD
    }
}

/// What every interpolator offers the motion planner.
pub trait Interpolator {
    /// The next step, `Ok(None)` once the end point is reached. After `None` or an error the
    /// interpolator keeps returning `Ok(None)`.
    fn next_step(&mut self) -> Result<Option<Step>, CurveError>;

    /// The unit tangent of the ideal curve at the current point, in the direction of travel.
    fn tangent(&self) -> Tangent;

    /// `Some(n)` when the rest of the curve is `n` steps along one straight line (its tangent
    /// never changes again): the planner then takes its steps in long chunks, and plans its
    /// braking from the curve's end rather than from what it has stepped so far.
    fn straight_steps_left(&self) -> Option<u64> {
        None
    }

    /// Writes the next steps into `out`, exactly those `next_step` would hand out one by one,
    /// until `out` is full, the curve ends or fails, or a step reaches a kink: a point where the
    /// tangent jumps from the one before the step by more than [`KINK_CHORD`]. The planner takes
    /// steps this way: a curve steps in a tight loop, without a call per step, and every kink
    /// falls at the end of a fill. This default compares the tangent at every step; a curve
    /// that cannot kink, or knows where it does, does better.
    fn fill(&mut self, out: &mut [Step]) -> Filled {
        let mut before = self.tangent();
        for (i, slot) in out.iter_mut().enumerate() {
            match self.next_step() {
                Ok(Some(step)) => *slot = step,
                Ok(None) => return Filled::ended(i, Ok(())),
                Err(e) => return Filled::ended(i, Err(e)),
            }
            let now = self.tangent();
            if before.kinks_to(now) {
                return Filled::kink(i + 1, before);
            }
            before = now;
        }
        Filled::more(out.len())
    }
}

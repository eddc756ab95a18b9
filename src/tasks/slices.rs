//! Long work in slices: a drawing is built by walking its curve a slice at a time
//! ([`crate::motion::drawing::Builder`]), and between two slices the task that builds it lets the other
//! tasks run. [`BetweenSlices`] is that pause. On the board the slice has taken its real time,
//! and the pause is a yield to the executor ([`Yield`]); the simulator's virtual time stands
//! still while code runs, and its model of the board's processor spends the slice's time there,
//! holding up the other tasks of thread mode as the board's one core would.

use core::future::Future;

use crate::motion::drawing::Slice;

/// The pause between two slices of a build; see the module documentation.
pub trait BetweenSlices {
    /// `slice` was walked: the future ends once the other tasks have had their turn (and, in a
    /// model of the board, once the processor would have walked it).
    fn after(&mut self, slice: &Slice) -> impl Future<Output = ()>;
}

/// The board's [`BetweenSlices`]: a yield to the executor, which polls every other task that is
/// ready before it comes back.
pub struct Yield;

impl BetweenSlices for Yield {
    fn after(&mut self, _slice: &Slice) -> impl Future<Output = ()> {
        embassy_futures::yield_now()
    }
}

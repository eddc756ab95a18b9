//! Static storage for a task's future that is too large to be spawned the usual way: embassy
//! builds a task's future by value and then copies it into the task's pool, so the whole future
//! passes through a stack frame (15 KB for the host link's). A [`FutureSlot`] is filled where
//! it lies instead, by a constructor called out of line with the slot as its destination, and
//! the task spawned only holds the pinned future and awaits it.

use core::cell::UnsafeCell;
use core::future::Future;
use core::mem::{MaybeUninit, align_of, size_of};
use core::pin::Pin;
use core::sync::atomic::{AtomicBool, Ordering};

/// Storage alignment: a future's alignment on the Cortex-M4 is at most 8.
#[repr(C, align(8))]
struct Aligned<const BYTES: usize>([MaybeUninit<u8>; BYTES]);

/// Room for one future of at most `BYTES` bytes.
pub struct FutureSlot<const BYTES: usize> {
    storage: UnsafeCell<Aligned<BYTES>>,
    taken: AtomicBool,
}

// SAFETY: the storage is handed out once (`taken`), as a pinned `&'static mut`.
unsafe impl<const BYTES: usize> Sync for FutureSlot<BYTES> {}

impl<const BYTES: usize> FutureSlot<BYTES> {
    pub const fn new() -> Self {
        FutureSlot { storage: UnsafeCell::new(Aligned([MaybeUninit::uninit(); BYTES])), taken: AtomicBool::new(false) }
    }

    /// The future `make` returns, built in the slot, pinned there for good; `make` is called
    /// once, with the slot as the destination of its result. `None` if the slot was taken.
    // The `&'static mut` comes from a shared reference on purpose: `taken` hands it out once.
    #[allow(clippy::mut_from_ref)]
    pub fn place<F: Future + 'static>(&'static self, make: impl FnOnce() -> F) -> Option<Pin<&'static mut F>> {
        const { assert!(size_of::<F>() <= BYTES && align_of::<F>() <= 8, "the future does not fit its slot") };
        if self.taken.swap(true, Ordering::AcqRel) {
            return None;
        }
        // SAFETY: the storage is aligned and large enough for `F` (checked above), taken only
        // now, and never moved out of nor freed (it is a static), so it may be pinned.
        unsafe {
            let slot = &mut *self.storage.get().cast::<MaybeUninit<F>>();
            Some(Pin::new_unchecked(fill(slot, make)))
        }
    }
}

/// Writes `make()` into `slot`: out of line and through a unique reference, so the compiler
/// may (and does) give the constructor `slot` itself as the place of its result.
#[inline(never)]
fn fill<F>(slot: &mut MaybeUninit<F>, make: impl FnOnce() -> F) -> &mut F {
    slot.write(make())
}

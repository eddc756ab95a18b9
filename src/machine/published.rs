//! A value written in thread mode and read from any priority without a lock: two copies, one
//! that readers read and one the writer fills, swapped by one atomic store.
//!
//! Why a reader never sees a copy half written: a write fills the copy readers are not reading,
//! then makes it the one they read. A reader that comes in while a write is under way runs at
//! a higher priority than the writer (an interrupt, or the motion task's executor) and reads the
//! other copy, or the new one once it is switched, to its end before the writer goes on. A
//! reader in thread mode runs between the writer's steps only where the writer waits, and a
//! write never waits (it is one closure). So no copy is ever read and written at once, and no
//! read masks interrupts.
//!
//! What that takes, and where it would break:
//! - every writer runs at the lowest priority of all readers and writers, in thread mode, and
//!   no two writes overlap. A writer at an interrupt priority (the motion task, say) could come
//!   in while a thread-mode reader copies the copy it is about to fill, after switching once
//!   already; two writers that preempt one another would fill the one spare copy together.
//!   [`update`](Published::update) checks the latter in debug builds;
//! - readers copy the value out and keep no reference to either copy;
//! - one core: a second core reads whenever it likes, and would need a sequence count.

use core::cell::UnsafeCell;
#[cfg(debug_assertions)]
use core::sync::atomic::AtomicBool;
use core::sync::atomic::{AtomicU8, Ordering, compiler_fence};

/// See the module documentation.
pub struct Published<T> {
    copies: [UnsafeCell<T>; 2],
    /// The copy readers read.
    current: AtomicU8,
    /// A write is under way (checked in debug builds).
    #[cfg(debug_assertions)]
    writing: AtomicBool,
}

// SAFETY: `get` reads only the current copy and `update` writes only the other one, making it
// current only once it is whole; the module documentation proves that no read overlaps a write
// of the copy it reads, given writers that run in thread mode, one at a time. The value crosses
// from the writer's context to the readers', hence `T: Send`.
unsafe impl<T: Send> Sync for Published<T> {}

impl<T: Copy> Published<T> {
    pub const fn new(value: T) -> Self {
        Published {
            copies: [UnsafeCell::new(value), UnsafeCell::new(value)],
            current: AtomicU8::new(0),
            #[cfg(debug_assertions)]
            writing: AtomicBool::new(false),
        }
    }

    /// A copy of the value, from any priority.
    pub fn get(&self) -> T {
        let current = usize::from(self.current.load(Ordering::Acquire) & 1);
        // SAFETY: the current copy is whole, and no write touches it while it is current or
        // while a read of it is under way (see the `Sync` impl).
        unsafe { *self.copies[current].get() }
    }

    /// Changes the value through `f`, in thread mode only: `f` works on the spare copy, which
    /// readers see once `f` has returned. `f` must not reach this value's `update` again.
    pub fn update<R>(&self, f: impl FnOnce(&mut T) -> R) -> R {
        #[cfg(debug_assertions)]
        assert!(!self.writing.swap(true, Ordering::Acquire), "two writes of a published value at once");
        let current = usize::from(self.current.load(Ordering::Acquire) & 1);
        let spare = current ^ 1;
        // SAFETY: readers read only the current copy, and this is the only write under way (see
        // the `Sync` impl); `f` has the spare copy to itself until the store below.
        let r = unsafe {
            let spare = self.copies[spare].get();
            // Two copies, never one: a copy, not a move (which would make room for overlap).
            core::ptr::copy_nonoverlapping(self.copies[current].get(), spare, 1);
            f(&mut *spare)
        };
        // Release: the copy is whole before anyone reads it as current. The fence keeps the next
        // write's filling of the other copy after the switch: an interrupt on this core sees
        // this core's stores in program order, so only the compiler could reorder them.
        self.current.store(spare as u8, Ordering::Release);
        compiler_fence(Ordering::SeqCst);
        #[cfg(debug_assertions)]
        self.writing.store(false, Ordering::Release);
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_write_is_seen_whole_by_the_next_read_and_the_one_before_keeps_its_copy() {
        let p = Published::new([1u32; 8]);
        let before = p.get();
        let r = p.update(|v| {
            v[0] = 2;
            v[7] = 3;
            // Readers still see the old value while the write is under way.
            assert_eq!(p.get(), [1; 8]);
            "done"
        });
        assert_eq!(r, "done");
        assert_eq!(before, [1; 8]);
        assert_eq!(p.get(), [2, 1, 1, 1, 1, 1, 1, 3]);
    }

    #[test]
    fn writes_build_on_each_other_however_many_there_are() {
        let p = Published::new(0u64);
        for n in 1..=5 {
            p.update(|v| *v += n);
        }
        assert_eq!(p.get(), 15);
    }

    #[test]
    fn a_write_that_changes_its_mind_still_leaves_the_value_whole() {
        let p = Published::new((1u8, 2u8));
        let refused: Result<(), ()> = p.update(|v| {
            let mut next = *v;
            next.0 = 9;
            if next.0 > 5 {
                return Err(());
            }
            *v = next;
            Ok(())
        });
        assert_eq!(refused, Err(()));
        assert_eq!(p.get(), (1, 2));
    }
}

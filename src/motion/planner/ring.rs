//! Fixed-capacity first-in first-out queues of the planner: the segments waiting to be scanned
//! ([`Ring`]), and the scanned steps, chunks and blocks ([`CopyRing`]).

use crate::geom::Step;
use crate::motion::planner::sizes::STEP_RING_LEN;

/// A queue of values that are moved in and out (the segments, which own their curves).
pub(crate) struct Ring<T, const N: usize> {
    slots: [Option<T>; N],
    head: usize,
    len: usize,
}

impl<T, const N: usize> Ring<T, N> {
    pub const fn new() -> Self {
        Ring { slots: [const { None }; N], head: 0, len: 0 }
    }

    /// Makes `*this` an empty ring where it lies, a slot at a time (never a whole ring on the
    /// stack).
    ///
    /// # Safety
    ///
    /// `this` is valid for writes and aligned; what it held is overwritten, not dropped.
    pub unsafe fn init_in_place(this: *mut Self) {
        // SAFETY: the caller's promise; `addr_of_mut!` takes each field's place without
        // reading or referencing what is there.
        unsafe {
            let slots = core::ptr::addr_of_mut!((*this).slots).cast::<Option<T>>();
            for i in 0..N {
                slots.add(i).write(None);
            }
            core::ptr::addr_of_mut!((*this).head).write(0);
            core::ptr::addr_of_mut!((*this).len).write(0);
        }
    }

    pub fn is_full(&self) -> bool {
        self.len >= N
    }

    fn slot(&self, i: usize) -> usize {
        (self.head + i) % N.max(1)
    }

    pub fn front_mut(&mut self) -> Option<&mut T> {
        if self.len == 0 {
            return None;
        }
        self.slots.get_mut(self.head)?.as_mut()
    }

    /// Appends `value`, or hands it back when the queue is full.
    pub fn push_back(&mut self, value: T) -> Result<(), T> {
        if self.is_full() {
            return Err(value);
        }
        let slot = self.slot(self.len);
        match self.slots.get_mut(slot) {
            Some(s) => {
                *s = Some(value);
                self.len += 1;
                Ok(())
            }
            None => Err(value),
        }
    }

    pub fn pop_front(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        let value = self.slots.get_mut(self.head)?.take();
        self.head = self.slot(1);
        self.len -= 1;
        value
    }

    pub fn clear(&mut self) {
        for slot in self.slots.iter_mut() {
            *slot = None;
        }
        self.head = 0;
        self.len = 0;
    }
}

/// A queue of plain values, `N` a power of two: indices wrap with a mask, and the free space
/// can be handed out as a slice to write into.
pub(crate) struct CopyRing<T: Copy + Default, const N: usize> {
    slots: [T; N],
    /// Pops and pushes so far, counted with wrapping: the slot of each is its count modulo `N`,
    /// and the length is their difference.
    head: u32,
    tail: u32,
}

/// The ring of scanned steps.
pub(crate) type StepRing = CopyRing<Step, STEP_RING_LEN>;

impl<T: Copy + Default, const N: usize> CopyRing<T, N> {
    const MASK: u32 = {
        assert!(N.is_power_of_two() && N <= 1 << 16, "a CopyRing's capacity is a power of two up to 65536");
        (N - 1) as u32
    };

    pub fn new() -> Self {
        CopyRing { slots: [T::default(); N], head: 0, tail: 0 }
    }

    /// Makes `*this` an empty ring where it lies, a slot at a time (never a whole ring on the
    /// stack).
    ///
    /// # Safety
    ///
    /// `this` is valid for writes and aligned.
    pub unsafe fn init_in_place(this: *mut Self) {
        // SAFETY: as for `Ring::init_in_place`; `T` is `Copy`: nothing is dropped.
        unsafe {
            let slots = core::ptr::addr_of_mut!((*this).slots).cast::<T>();
            for i in 0..N {
                slots.add(i).write(T::default());
            }
            core::ptr::addr_of_mut!((*this).head).write(0);
            core::ptr::addr_of_mut!((*this).tail).write(0);
        }
    }

    pub fn len(&self) -> usize {
        self.tail.wrapping_sub(self.head) as usize
    }

    pub fn is_empty(&self) -> bool {
        self.head == self.tail
    }

    pub fn is_full(&self) -> bool {
        self.len() >= N
    }

    /// Free slots.
    pub fn free(&self) -> usize {
        N - self.len()
    }

    pub fn clear(&mut self) {
        self.head = 0;
        self.tail = 0;
    }

    pub fn front(&self) -> Option<&T> {
        if self.is_empty() { None } else { self.slots.get((self.head & Self::MASK) as usize) }
    }

    pub fn front_mut(&mut self) -> Option<&mut T> {
        if self.is_empty() { None } else { self.slots.get_mut((self.head & Self::MASK) as usize) }
    }

    pub fn back_mut(&mut self) -> Option<&mut T> {
        if self.is_empty() { None } else { self.slots.get_mut((self.tail.wrapping_sub(1) & Self::MASK) as usize) }
    }

    /// The `i`-th element from the front.
    pub fn get(&self, i: usize) -> Option<&T> {
        if i < self.len() { self.slots.get((self.head.wrapping_add(i as u32) & Self::MASK) as usize) } else { None }
    }

    /// The `i`-th element from the front.
    pub fn get_mut(&mut self, i: usize) -> Option<&mut T> {
        if i < self.len() { self.slots.get_mut((self.head.wrapping_add(i as u32) & Self::MASK) as usize) } else { None }
    }

    /// Appends `value`; `false` (and nothing changes) when the queue is full.
    pub fn push_back(&mut self, value: T) -> bool {
        if self.is_full() {
            return false;
        }
        if let Some(slot) = self.slots.get_mut((self.tail & Self::MASK) as usize) {
            *slot = value;
            self.tail = self.tail.wrapping_add(1);
        }
        true
    }

    pub fn pop_front(&mut self) -> Option<T> {
        if self.is_empty() {
            return None;
        }
        let value = self.slots.get((self.head & Self::MASK) as usize).copied();
        self.head = self.head.wrapping_add(1);
        value
    }

    /// Up to `max` elements from the front, as far as they lie in one piece (to the end of the
    /// buffer); [`drop_front`](Self::drop_front) them once used.
    pub fn front_slice(&self, max: usize) -> &[T] {
        let start = (self.head & Self::MASK) as usize;
        let n = self.len().min(N - start).min(max);
        self.slots.get(start..start + n).unwrap_or(&[])
    }

    /// Drops `n` elements from the front.
    pub fn drop_front(&mut self, n: usize) {
        let n = n.min(self.len());
        self.head = self.head.wrapping_add(n as u32);
    }

    /// The free slots from the back up to the end of the buffer, at most `max` of them: write
    /// into them, then [`commit`](Self::commit) how many were written.
    pub fn free_slice(&mut self, max: usize) -> &mut [T] {
        let start = (self.tail & Self::MASK) as usize;
        let until_wrap = N - start;
        let n = self.free().min(until_wrap).min(max);
        self.slots.get_mut(start..start + n).unwrap_or(&mut [])
    }

    /// Appends the `n` slots written through [`free_slice`](Self::free_slice).
    pub fn commit(&mut self, n: usize) {
        let n = n.min(self.free());
        self.tail = self.tail.wrapping_add(n as u32);
    }
}

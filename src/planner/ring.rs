//! A fixed-capacity first-in first-out queue: the planner's segments and blocks.

pub(crate) struct Ring<T, const N: usize> {
    slots: [Option<T>; N],
    head: usize,
    len: usize,
}

impl<T, const N: usize> Ring<T, N> {
    pub const fn new() -> Self {
        Ring { slots: [const { None }; N], head: 0, len: 0 }
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    pub fn is_full(&self) -> bool {
        self.len >= N
    }

    fn slot(&self, i: usize) -> usize {
        (self.head + i) % N.max(1)
    }

    /// The `i`-th element from the front.
    pub fn get(&self, i: usize) -> Option<&T> {
        if i < self.len { self.slots.get(self.slot(i))?.as_ref() } else { None }
    }

    pub fn get_mut(&mut self, i: usize) -> Option<&mut T> {
        if i < self.len {
            let slot = self.slot(i);
            self.slots.get_mut(slot)?.as_mut()
        } else {
            None
        }
    }

    pub fn front(&self) -> Option<&T> {
        self.get(0)
    }

    pub fn front_mut(&mut self) -> Option<&mut T> {
        self.get_mut(0)
    }

    pub fn back_mut(&mut self) -> Option<&mut T> {
        self.get_mut(self.len.checked_sub(1)?)
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

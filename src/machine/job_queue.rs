//! The job queue: values (jobs, with the plan's end they were planned from) handed from the
//! inputs to the motion task without a lock around them.
//!
//! A job is 648 bytes: copied inside a critical section it would mask the pulse interrupt for
//! about a thousand instructions. Here a producer claims a free slot with one atomic
//! compare-and-swap, writes the value into it with interrupts enabled, and publishes it with one
//! store; the consumer claims a published slot the same way, moves the value out (or drops it in
//! place), and frees the slot with one store. This is D. Vyukov's bounded queue: each slot has a
//! turn counter saying which position it waits for and whether that position's value is in it.
//!
//! It takes any number of producers and consumers at any priorities; a producer or a consumer
//! interrupted half way through its slot holds up only the positions behind it (they read as
//! not yet there, or full), never a value. The machine has its producers in thread mode and one
//! consumer, the motion task.
//!
//! The only locks are the wakers': a waker (8 bytes) put in, or the few waiting taken out and
//! woken outside the lock.

use core::cell::{RefCell, UnsafeCell};
use core::future::poll_fn;
use core::mem::MaybeUninit;
use core::sync::atomic::{AtomicU32, Ordering};
use core::task::{Context, Poll, Waker};

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use heapless::Vec;

/// One slot of the queue.
struct Slot<T> {
    /// The slot's turn less its index, so that every slot of an empty queue starts at 0 (see
    /// [`JobQueue::turn`]).
    turn: AtomicU32,
    value: UnsafeCell<MaybeUninit<T>>,
}

impl<T> Slot<T> {
    const fn new() -> Self {
        Slot { turn: AtomicU32::new(0), value: UnsafeCell::new(MaybeUninit::uninit()) }
    }
}

/// Tasks waiting on the queue: at most `W` wakers, each put in and taken out under a critical
/// section, woken outside it.
struct Waiters<const W: usize> {
    wakers: Mutex<CriticalSectionRawMutex, RefCell<Vec<Waker, W>>>,
}

impl<const W: usize> Waiters<W> {
    const fn new() -> Self {
        Waiters { wakers: Mutex::new(RefCell::new(Vec::new())) }
    }

    /// Wakes `waker` on the next [`wake`](Self::wake). With `W` others waiting already, those
    /// are woken now (they look again, and wait again if they must).
    fn register(&self, waker: &Waker) {
        let full = self.wakers.lock(|w| {
            let mut w = w.borrow_mut();
            if w.iter().any(|known| known.will_wake(waker)) {
                return None;
            }
            match w.push(waker.clone()) {
                Ok(()) => None,
                Err(waker) => Some((core::mem::take(&mut *w), waker)),
            }
        });
        if let Some((woken, waker)) = full {
            woken.into_iter().for_each(Waker::wake);
            self.wakers.lock(|w| {
                // Room was made just above: emptied, and only registrations since then fill it.
                let _ = w.borrow_mut().push(waker);
            });
        }
    }

    /// Wakes every waiting task.
    fn wake(&self) {
        let woken = self.wakers.lock(|w| core::mem::take(&mut *w.borrow_mut()));
        woken.into_iter().for_each(Waker::wake);
    }
}

/// See the module documentation: `N` slots (a power of two, two at least), up to `W` producers
/// waiting for room at once (more are woken to look again, not lost).
pub struct JobQueue<T, const N: usize, const W: usize> {
    slots: [Slot<T>; N],
    /// Positions claimed by producers so far (wraps).
    tail: AtomicU32,
    /// Positions claimed by consumers so far (wraps).
    head: AtomicU32,
    /// The consumer waiting for a value.
    ready: Waiters<1>,
    /// Producers waiting for room.
    room: Waiters<W>,
}

// SAFETY: a slot's value is written only by the producer whose compare-and-swap moved `tail`
// past the slot's position while the slot's turn said it was free for that position, and read
// or dropped only by the consumer whose compare-and-swap moved `head` past it while the turn
// said the value was in. Each hands the slot on with a Release store of the turn, which the
// other's Acquire load sees before it touches the value, so no two contexts ever touch one
// value at once, whatever their priorities. Values cross from the producer's context to the
// consumer's, hence `T: Send`.
unsafe impl<T: Send, const N: usize, const W: usize> Sync for JobQueue<T, N, W> {}

impl<T, const N: usize, const W: usize> Default for JobQueue<T, N, W> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T, const N: usize, const W: usize> JobQueue<T, N, W> {
    /// An empty queue.
    pub const fn new() -> Self {
        // Two slots at least: with one, a slot freed for the next position and a slot holding
        // a value would have the same turn.
        const { assert!(N.is_power_of_two() && N >= 2 && N <= 1 << 16) };
        JobQueue {
            slots: [const { Slot::new() }; N],
            tail: AtomicU32::new(0),
            head: AtomicU32::new(0),
            ready: Waiters::new(),
            room: Waiters::new(),
        }
    }

    /// An empty queue whose next position is `start` (for the tests of the counters' wrap).
    #[cfg(test)]
    fn starting_at(start: u32) -> Self {
        let q = Self::new();
        for position in (0..N as u32).map(|i| start.wrapping_add(i)) {
            q.set_turn(position, position);
        }
        q.tail.store(start, Ordering::Relaxed);
        q.head.store(start, Ordering::Relaxed);
        q
    }

    /// The slot of `position` and its turn: the position `p` it waits for while it is free for
    /// a producer of `p`, or `p + 1` once the value of position `p` is in it (both wrap). Slot
    /// `i` starts at turn `i`, the first position it waits for.
    fn turn(&self, position: u32) -> (&Slot<T>, u32) {
        let index = position % N as u32;
        let slot = &self.slots[index as usize];
        (slot, slot.turn.load(Ordering::Acquire).wrapping_add(index))
    }

    /// Sets the turn of `position`'s slot: hands it on.
    fn set_turn(&self, position: u32, turn: u32) {
        let index = position % N as u32;
        self.slots[index as usize].turn.store(turn.wrapping_sub(index), Ordering::Release);
    }

    /// Queues `value` if there is room now, and wakes the consumer; gives it back if not.
    pub fn push(&self, value: T) -> Result<(), T> {
        let mut position = self.tail.load(Ordering::Relaxed);
        loop {
            let (slot, turn) = self.turn(position);
            let ahead = turn.wrapping_sub(position) as i32;
            if ahead < 0 {
                // The slot still holds (or is getting) the value of `N` positions before.
                return Err(value);
            }
            if ahead > 0 {
                // Another producer took this position: try the next.
                position = self.tail.load(Ordering::Relaxed);
                continue;
            }
            let next = position.wrapping_add(1);
            match self.tail.compare_exchange_weak(position, next, Ordering::Relaxed, Ordering::Relaxed) {
                Ok(_) => {
                    // SAFETY: this producer alone claimed `position`, and the slot is free for it
                    // (see the `Sync` impl).
                    unsafe { (*slot.value.get()).write(value) };
                    self.set_turn(position, next);
                    self.ready.wake();
                    return Ok(());
                }
                Err(now) => position = now,
            }
        }
    }

    /// Claims the oldest value if it is in, hands its place to `f` and frees the slot; wakes no
    /// one.
    fn take<R>(&self, f: impl FnOnce(*mut T) -> R) -> Option<R> {
        let mut position = self.head.load(Ordering::Relaxed);
        loop {
            let (slot, turn) = self.turn(position);
            let next = position.wrapping_add(1);
            let ahead = turn.wrapping_sub(next) as i32;
            if ahead < 0 {
                // Empty, or the oldest position's value is still being written.
                return None;
            }
            if ahead > 0 {
                position = self.head.load(Ordering::Relaxed);
                continue;
            }
            match self.head.compare_exchange_weak(position, next, Ordering::Relaxed, Ordering::Relaxed) {
                Ok(_) => {
                    let r = f(slot.value.get().cast::<T>());
                    self.set_turn(position, position.wrapping_add(N as u32));
                    return Some(r);
                }
                Err(now) => position = now,
            }
        }
    }

    /// Takes the oldest value, if one is in, and wakes the producers waiting for room.
    pub fn pop(&self) -> Option<T> {
        // SAFETY: `take` hands over the place of a value written and published, claimed by this
        // consumer alone (see the `Sync` impl); it is read once and its slot freed after.
        let value = self.take(|value| unsafe { value.read() })?;
        self.room.wake();
        Some(value)
    }

    /// Drops every value in, in place, and wakes the producers waiting for room.
    pub fn clear(&self) {
        // SAFETY: as in `pop`; the value is dropped instead of read.
        while self.take(|value| unsafe { value.drop_in_place() }).is_some() {}
        self.room.wake();
    }

    /// Values queued and not yet taken, counting those a producer is writing.
    pub fn len(&self) -> usize {
        // `head` first: `tail` read after it is never behind it.
        let head = self.head.load(Ordering::Acquire);
        let tail = self.tail.load(Ordering::Acquire);
        (tail.wrapping_sub(head) as usize).min(N)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// True when the oldest value is in, ready to be taken.
    fn has_ready(&self) -> bool {
        let head = self.head.load(Ordering::Acquire);
        self.turn(head).1 == head.wrapping_add(1)
    }

    /// Waits until a value is ready to be taken (it may already be). For one consumer.
    pub async fn ready(&self) {
        poll_fn(|cx| {
            if self.has_ready() {
                return Poll::Ready(());
            }
            self.ready.register(cx.waker());
            // A value published between the look and the registration woke no one: look again.
            if self.has_ready() { Poll::Ready(()) } else { Poll::Pending }
        })
        .await
    }

    /// Queues the value in `value` if there is room now, taking it; otherwise leaves it there
    /// and wakes `cx`'s task when room is made (or on [`clear`](Self::clear)).
    pub fn poll_push(&self, value: &mut Option<T>, cx: &mut Context<'_>) -> Poll<()> {
        let Some(v) = value.take() else { return Poll::Ready(()) };
        let v = match self.push(v) {
            Ok(()) => return Poll::Ready(()),
            Err(v) => v,
        };
        self.room.register(cx.waker());
        // Room made between the try and the registration woke no one: try again.
        match self.push(v) {
            Ok(()) => Poll::Ready(()),
            Err(v) => {
                *value = Some(v);
                Poll::Pending
            }
        }
    }
}

impl<T, const N: usize, const W: usize> Drop for JobQueue<T, N, W> {
    fn drop(&mut self) {
        self.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::pin::pin;
    use std::sync::Arc;
    use std::sync::atomic::{AtomicUsize, Ordering as StdOrdering};
    use std::task::Wake;

    type Queue = JobQueue<u32, 4, 2>;

    /// A waker that counts its wakes.
    #[derive(Default)]
    struct Counting(AtomicUsize);

    impl Wake for Counting {
        fn wake(self: Arc<Self>) {
            self.0.fetch_add(1, StdOrdering::SeqCst);
        }
    }

    fn counting() -> (Arc<Counting>, Waker) {
        let count = Arc::new(Counting::default());
        (count.clone(), Waker::from(count))
    }

    #[test]
    fn values_come_out_in_the_order_they_went_in_across_the_counters_wrap() {
        for start in [0, u32::MAX - 5, u32::MAX] {
            let q = Queue::starting_at(start);
            let mut next_in = 0u32;
            let mut next_out = 0u32;
            // Uneven fills and drains, many times around the slots and past the wrap.
            for round in 0..40u32 {
                for _ in 0..(round % 4 + 1) {
                    if q.push(next_in).is_ok() {
                        next_in += 1;
                    }
                }
                for _ in 0..(round % 3 + 1) {
                    if let Some(v) = q.pop() {
                        assert_eq!(v, next_out, "start {start}");
                        next_out += 1;
                    }
                }
                assert_eq!(q.len(), (next_in - next_out) as usize);
            }
            while let Some(v) = q.pop() {
                assert_eq!(v, next_out);
                next_out += 1;
            }
            assert_eq!(next_out, next_in);
            assert!(next_in > 40, "the slots went around many times");
        }
    }

    #[test]
    fn a_full_queue_gives_the_value_back_and_takes_it_once_one_is_taken() {
        let q = Queue::new();
        for v in 0..4 {
            assert_eq!(q.push(v), Ok(()));
        }
        assert_eq!(q.push(99), Err(99));
        assert_eq!(q.len(), 4);
        assert_eq!(q.pop(), Some(0));
        assert_eq!(q.push(4), Ok(()));
        assert_eq!([q.pop(), q.pop(), q.pop(), q.pop(), q.pop()], [Some(1), Some(2), Some(3), Some(4), None]);
        assert!(q.is_empty());
    }

    /// Counts the values dropped.
    struct Counted<'a>(&'a AtomicUsize);

    impl Drop for Counted<'_> {
        fn drop(&mut self) {
            self.0.fetch_add(1, StdOrdering::SeqCst);
        }
    }

    #[test]
    fn cleared_and_left_over_values_are_dropped_once_each() {
        let dropped = AtomicUsize::new(0);
        {
            let q: JobQueue<Counted, 4, 2> = JobQueue::new();
            for _ in 0..3 {
                assert!(q.push(Counted(&dropped)).is_ok());
            }
            q.clear();
            assert_eq!(dropped.load(StdOrdering::SeqCst), 3);
            assert!(q.is_empty() && q.pop().is_none());
            for _ in 0..2 {
                assert!(q.push(Counted(&dropped)).is_ok());
            }
            let taken = q.pop();
            assert_eq!(dropped.load(StdOrdering::SeqCst), 3, "taken, not dropped");
            drop(taken);
        }
        assert_eq!(dropped.load(StdOrdering::SeqCst), 5, "the one left in dropped with the queue");
    }

    #[test]
    fn the_consumer_waits_until_a_value_is_pushed() {
        let q = Queue::new();
        let (count, waker) = counting();
        let mut cx = Context::from_waker(&waker);
        let mut ready = pin!(q.ready());
        assert!(ready.as_mut().poll(&mut cx).is_pending());
        q.push(7).unwrap();
        assert_eq!(count.0.load(StdOrdering::SeqCst), 1, "woken by the push");
        assert!(ready.as_mut().poll(&mut cx).is_ready());
        assert_eq!(q.pop(), Some(7));
    }

    #[test]
    fn producers_wait_for_room_and_are_woken_by_a_take_or_a_clear() {
        let q = Queue::new();
        for v in 0..4 {
            q.push(v).unwrap();
        }
        let (first, first_waker) = counting();
        let (second, second_waker) = counting();
        let mut a = Some(10);
        let mut b = Some(11);
        assert!(q.poll_push(&mut a, &mut Context::from_waker(&first_waker)).is_pending());
        assert!(q.poll_push(&mut b, &mut Context::from_waker(&second_waker)).is_pending());
        assert_eq!((a, b), (Some(10), Some(11)), "kept by their producers");
        assert_eq!(q.pop(), Some(0));
        assert_eq!((first.0.load(StdOrdering::SeqCst), second.0.load(StdOrdering::SeqCst)), (1, 1));
        assert!(q.poll_push(&mut a, &mut Context::from_waker(&first_waker)).is_ready());
        assert_eq!(a, None);
        assert!(q.poll_push(&mut b, &mut Context::from_waker(&second_waker)).is_pending());
        q.clear();
        assert_eq!(second.0.load(StdOrdering::SeqCst), 2, "woken by the clear");
        assert!(q.poll_push(&mut b, &mut Context::from_waker(&second_waker)).is_ready());
        assert_eq!([q.pop(), q.pop()], [Some(11), None]);
    }

    #[test]
    fn more_waiting_producers_than_places_are_woken_not_lost() {
        let q: JobQueue<u32, 2, 1> = JobQueue::new();
        q.push(0).unwrap();
        q.push(1).unwrap();
        let (first, first_waker) = counting();
        let (second, second_waker) = counting();
        let (mut a, mut b) = (Some(1), Some(2));
        assert!(q.poll_push(&mut a, &mut Context::from_waker(&first_waker)).is_pending());
        assert!(q.poll_push(&mut b, &mut Context::from_waker(&second_waker)).is_pending());
        assert_eq!(first.0.load(StdOrdering::SeqCst), 1, "woken to make room for the second");
        assert_eq!(q.pop(), Some(0));
        assert_eq!(second.0.load(StdOrdering::SeqCst), 1);
    }

    #[test]
    fn producers_and_a_consumer_on_three_threads_lose_and_reorder_nothing() {
        const PER_PRODUCER: u32 = 50_000;
        let q: JobQueue<u32, 4, 2> = JobQueue::new();
        std::thread::scope(|s| {
            for producer in 0..2u32 {
                let q = &q;
                s.spawn(move || {
                    for n in 0..PER_PRODUCER {
                        let mut v = producer << 31 | n;
                        while let Err(back) = q.push(v) {
                            v = back;
                            std::hint::spin_loop();
                        }
                    }
                });
            }
            let mut next = [0u32; 2];
            while next != [PER_PRODUCER; 2] {
                if let Some(v) = q.pop() {
                    let producer = (v >> 31) as usize;
                    assert_eq!(v & !(1 << 31), next[producer], "each producer's values in order");
                    next[producer] += 1;
                }
            }
        });
        assert!(q.is_empty());
    }
}

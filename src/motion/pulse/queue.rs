//! The step queue: step commands from the motion task (the one producer) to the pulse engine
//! (the one consumer), without a lock. The producer writes a whole batch into the free slots
//! and publishes it with one store; the consumer takes one command per pulse. The producer also
//! publishes where its motion comes to rest, so that the consumer can tell a queue run dry at a
//! rest from one run dry because the producer fell behind.

use core::cell::UnsafeCell;
use core::sync::atomic::{AtomicU32, Ordering};

use crate::geom::StepCmd;

/// Commands the queue holds (a power of two). At 200 kHz, 1,024 steps are 5.1 ms of motion; the
/// motion task refills the queue when half of it is emitted, so the 2.6 ms left cover its
/// longest piece of work between two batches of steps (a scan of
/// [`SCAN_STEPS_PER_CALL`](crate::motion::planner::SCAN_STEPS_PER_CALL) steps of a function, under a
/// millisecond) with room for the interrupts above it. 8 KiB.
pub const STEP_QUEUE_LEN: usize = 1024;

const MASK: u32 = {
    assert!(STEP_QUEUE_LEN.is_power_of_two() && STEP_QUEUE_LEN <= 1 << 16);
    (STEP_QUEUE_LEN - 1) as u32
};

/// See the module documentation. [`split`](StepQueue::split) it into its two ends.
pub struct StepQueue {
    slots: UnsafeCell<[StepCmd; STEP_QUEUE_LEN]>,
    /// Commands taken so far (written by the consumer only), commands published so far, and
    /// the count published at the last rest (written by the producer only); all wrap, and the
    /// slot of a command is its count modulo the length.
    taken: AtomicU32,
    published: AtomicU32,
    rest_at: AtomicU32,
}

// SAFETY: the slots are shared between the two ends only as the counters allow: the producer
// writes only slots not yet published (and no longer unread), the consumer reads only slots
// published and not yet taken. A slot is handed from one to the other by a Release store of a
// counter and the other's Acquire load of it. `split` makes sure there is one of each end.
unsafe impl Sync for StepQueue {}

impl Default for StepQueue {
    fn default() -> Self {
        Self::new()
    }
}

impl StepQueue {
    /// An empty queue, at rest.
    pub const fn new() -> Self {
        StepQueue {
            slots: UnsafeCell::new([StepCmd::NONE; STEP_QUEUE_LEN]),
            taken: AtomicU32::new(0),
            published: AtomicU32::new(0),
            rest_at: AtomicU32::new(0),
        }
    }

    /// The producer and the consumer end; the queue stays borrowed while they live.
    pub fn split(&mut self) -> (StepProducer<'_>, StepConsumer<'_>) {
        let (taken, published) = (*self.taken.get_mut(), *self.published.get_mut());
        let queue = &*self;
        (StepProducer { queue }, StepConsumer { queue, taken, published })
    }

    fn base(&self) -> *mut StepCmd {
        self.slots.get().cast::<StepCmd>()
    }
}

/// The motion task's end of the [`StepQueue`].
pub struct StepProducer<'q> {
    queue: &'q StepQueue,
}

impl StepProducer<'_> {
    /// Commands published and not yet taken.
    pub fn len(&self) -> usize {
        let published = self.queue.published.load(Ordering::Relaxed);
        published.wrapping_sub(self.queue.taken.load(Ordering::Acquire)) as usize
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The free slots after the last published command, up to the end of the ring: write into
    /// them, then [`publish`](Self::publish) how many were written.
    pub fn free_slots(&mut self) -> &mut [StepCmd] {
        let published = self.queue.published.load(Ordering::Relaxed);
        let free = STEP_QUEUE_LEN - self.len();
        let start = (published & MASK) as usize;
        let n = free.min(STEP_QUEUE_LEN - start);
        // SAFETY: slots `start..start + n` lie within the ring and are free: the consumer has
        // taken every command that was in them (the Acquire load in `len`) and reads none of
        // them until they are published. `&mut self` is the only producer, so no other
        // reference to them exists while this one lives.
        unsafe { core::slice::from_raw_parts_mut(self.queue.base().add(start), n) }
    }

    /// Publishes the first `n` commands written through [`free_slots`](Self::free_slots).
    pub fn publish(&mut self, n: usize) {
        let n = n.min(STEP_QUEUE_LEN - self.len()) as u32;
        let published = self.queue.published.load(Ordering::Relaxed);
        self.queue.published.store(published.wrapping_add(n), Ordering::Release);
    }

    /// The motion comes to rest after the commands published so far: the queue running dry
    /// there is no underrun.
    pub fn rest(&mut self) {
        let published = self.queue.published.load(Ordering::Relaxed);
        self.queue.rest_at.store(published, Ordering::Release);
    }

    /// Takes back every command published and not yet taken, and rests there. Only while the
    /// consumer takes nothing: the pulse engine halted by a trip (see [`crate::machine::Machine::trip`]);
    /// it sees the change at its next [`ready`](StepConsumer::ready).
    pub fn retract(&mut self) {
        let taken = self.queue.taken.load(Ordering::Acquire);
        self.queue.published.store(taken, Ordering::Release);
        self.rest();
    }
}

/// The pulse engine's end of the [`StepQueue`]. It keeps its own copy of the commands taken
/// (it alone changes them) and of the count published when it last looked, which it reads
/// again only once it has taken that many: most commands cost no load of the producer's
/// counter.
pub struct StepConsumer<'q> {
    queue: &'q StepQueue,
    taken: u32,
    published: u32,
}

impl StepConsumer<'_> {
    /// The next command, if one is published.
    #[inline(always)]
    pub fn pop(&mut self) -> Option<StepCmd> {
        let taken = self.taken;
        if taken == self.published {
            self.published = self.queue.published.load(Ordering::Acquire);
            if taken == self.published {
                return None;
            }
        }
        // SAFETY: the slot of command `taken` lies within the ring and is published (an Acquire
        // load of `published`, now or before): the producer wrote it and writes it again only
        // after `taken` moves past it (the Release store below). `&mut self` is the only
        // consumer.
        let cmd = unsafe { self.queue.base().add((taken & MASK) as usize).read() };
        self.taken = taken.wrapping_add(1);
        self.queue.taken.store(self.taken, Ordering::Release);
        Some(cmd)
    }

    /// True when a command is published and not yet taken. Reads what the producer published
    /// (and took back) anew.
    pub fn ready(&mut self) -> bool {
        self.published = self.queue.published.load(Ordering::Acquire);
        self.taken != self.published
    }

    /// True when the commands taken end exactly at the producer's last rest: if the queue is
    /// empty now, the motion has ended (and not merely run ahead of the producer).
    pub fn at_rest(&self) -> bool {
        self.taken == self.queue.rest_at.load(Ordering::Acquire)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::geom::Step;
    use std::vec::Vec;

    fn cmd(i: u32) -> StepCmd {
        StepCmd::new(Step::new(1, 0), i)
    }

    /// Publishes `cmds` in as few batches as the ring allows; how many it took.
    fn push(p: &mut StepProducer<'_>, cmds: &[StepCmd]) -> usize {
        let mut done = 0;
        while done < cmds.len() {
            let slots = p.free_slots();
            let n = slots.len().min(cmds.len() - done);
            if n == 0 {
                break;
            }
            slots[..n].copy_from_slice(&cmds[done..done + n]);
            p.publish(n);
            done += n;
        }
        done
    }

    #[test]
    fn commands_come_out_in_order_across_the_wrap_and_never_more_than_fit() {
        let mut q = StepQueue::new();
        let (mut p, mut c) = q.split();
        // Three times round the queue: it fills (more pushed than popped) and wraps.
        let all: Vec<StepCmd> = (0..3 * STEP_QUEUE_LEN as u32).map(cmd).collect();
        let mut out = Vec::new();
        let mut at = 0;
        while out.len() < all.len() {
            at += push(&mut p, &all[at..(at + 100).min(all.len())]);
            assert!(p.len() <= STEP_QUEUE_LEN);
            for _ in 0..70 {
                if let Some(x) = c.pop() {
                    out.push(x);
                }
            }
        }
        assert_eq!(out, all);
        assert_eq!(c.pop(), None);
        // Full: no free slot until one is taken.
        assert_eq!(push(&mut p, &all[..STEP_QUEUE_LEN + 5]), STEP_QUEUE_LEN);
        assert!(p.free_slots().is_empty());
        p.publish(3);
        assert_eq!(p.len(), STEP_QUEUE_LEN, "publishing beyond the free slots does nothing");
        assert_eq!(c.pop(), Some(all[0]));
        assert_eq!(p.free_slots().len(), 1);
    }

    #[test]
    fn a_queue_run_dry_is_at_rest_only_after_the_producers_rest() {
        let mut q = StepQueue::new();
        let (mut p, mut c) = q.split();
        assert!(c.at_rest() && !c.ready());
        push(&mut p, &[cmd(1), cmd(2)]);
        assert!(c.ready());
        assert_eq!(c.pop(), Some(cmd(1)));
        p.rest();
        assert!(!c.at_rest(), "a command before the rest is still queued");
        assert_eq!(c.pop(), Some(cmd(2)));
        assert!(c.at_rest());
        push(&mut p, &[cmd(3)]);
        assert_eq!(c.pop(), Some(cmd(3)));
        assert!(!c.at_rest(), "steps after the rest, and no new rest: the producer is behind");
    }

    #[test]
    fn a_producer_and_a_consumer_on_two_threads_lose_and_reorder_nothing() {
        const N: u32 = 200_000;
        let mut q = StepQueue::new();
        let (mut p, mut c) = q.split();
        std::thread::scope(|s| {
            s.spawn(move || {
                let mut next = 0u32;
                while next < N {
                    let slots = p.free_slots();
                    let n = slots.len().min((N - next) as usize).min(1 + (next % 37) as usize);
                    for (k, slot) in slots[..n].iter_mut().enumerate() {
                        *slot = cmd(next + k as u32);
                    }
                    p.publish(n);
                    next += n as u32;
                }
                p.rest();
            });
            let mut expected = 0u32;
            while expected < N {
                if let Some(x) = c.pop() {
                    assert_eq!(x, cmd(expected));
                    expected += 1;
                }
            }
            while !c.at_rest() {
                std::hint::spin_loop();
            }
            assert_eq!(c.pop(), None);
        });
    }
}

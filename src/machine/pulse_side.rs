//! The part of the machine the pulse interrupt writes, through its handle
//! ([`PulseWriter`](super::PulseWriter)): the pulses emitted (the position before machine zero
//! is taken off), the emitted totals (steps and the sum of their intervals), the interval of the
//! step emitted last, the underruns and missed updates, whether the step timer runs, and the
//! news not yet delivered.
//!
//! One writer: the pulse interrupt (the pulse engine, [`crate::motion::pulse`]). Readers: every task,
//! through the narrow reads on [`Machine`](super::Machine) (the position, the queued work, the
//! speed, the status, the watchdog's look), and the news interrupt, which takes the news.
//!
//! The interrupt runs above every critical section (they mask every interrupt but it, see
//! `critical`, on the chip), so it takes no lock and wakes no task itself: it leaves its news in
//! the machine's pulse news (atomics only), and the board then pends an interrupt below it whose
//! handler hands the news on
//! ([`Machine::deliver_pulse_news`](super::Machine::deliver_pulse_news)): the trip to the motion
//! task, the stop to those waiting for it, the warnings to the log.

use core::sync::atomic::{AtomicBool, AtomicI32, AtomicU32, Ordering};

use super::pulse_news::{News, PulseNews};
use crate::geom::StepCmd;
use crate::machine_io::inputs::Trip;

/// What the pulse interrupt writes (see the module documentation); its writes are called only
/// through [`PulseWriter`](super::PulseWriter).
pub(super) struct PulseSide {
    /// Pulses emitted per axis.
    position: [AtomicI32; 2],
    /// Steps emitted so far and the sum of their intervals (both wrap).
    emitted_steps: AtomicU32,
    emitted_ticks: AtomicU32,
    /// The interval of the step emitted last, ticks.
    last_interval_ticks: AtomicU32,
    /// Times the pulse engine found the queue empty while the motion was not at rest.
    underruns: AtomicU32,
    /// Times the step timer's interrupt came a whole period late.
    missed_updates: AtomicU32,
    /// The step timer runs.
    pulsing: AtomicBool,
    /// What the pulse interrupt has to tell, not yet delivered (see [`super::pulse_news`]).
    news: PulseNews,
}

impl PulseSide {
    pub(super) const fn new() -> Self {
        PulseSide {
            position: [AtomicI32::new(0), AtomicI32::new(0)],
            emitted_steps: AtomicU32::new(0),
            emitted_ticks: AtomicU32::new(0),
            last_interval_ticks: AtomicU32::new(0),
            underruns: AtomicU32::new(0),
            missed_updates: AtomicU32::new(0),
            pulsing: AtomicBool::new(false),
            news: PulseNews::new(),
        }
    }

    /// Pulses emitted on `axis` (0 for X, 1 for Y) since power-on.
    pub(super) fn emitted_on(&self, axis: usize) -> i32 {
        self.position[axis].load(Ordering::Relaxed)
    }

    /// Steps emitted so far (wraps).
    pub(super) fn emitted_steps(&self) -> u32 {
        self.emitted_steps.load(Ordering::Acquire)
    }

    /// The sum of the intervals of the steps emitted so far, ticks (wraps).
    pub(super) fn emitted_ticks(&self) -> u32 {
        self.emitted_ticks.load(Ordering::Acquire)
    }

    /// The interval of the step emitted last, ticks.
    pub(super) fn last_interval_ticks(&self) -> u32 {
        self.last_interval_ticks.load(Ordering::Relaxed)
    }

    /// Times the pulse engine found the queue empty while the motion was not at rest.
    pub(super) fn underruns(&self) -> u32 {
        self.underruns.load(Ordering::Relaxed)
    }

    /// Times the step timer's interrupt came a whole period late.
    pub(super) fn missed_updates(&self) -> u32 {
        self.missed_updates.load(Ordering::Relaxed)
    }

    /// True while the step timer runs.
    pub(super) fn pulsing(&self) -> bool {
        self.pulsing.load(Ordering::Acquire)
    }

    /// Takes the news not yet delivered.
    pub(super) fn take_news(&self) -> News {
        self.news.take()
    }

    /// Counts the pulses of `cmd`, emitted.
    #[inline(always)]
    pub(super) fn emitted(&self, cmd: StepCmd) {
        // Single writer: a load and a store, no read-modify-write cycle.
        let [x, y] = &self.position;
        x.store(x.load(Ordering::Relaxed).wrapping_add(i32::from(cmd.step.x)), Ordering::Relaxed);
        y.store(y.load(Ordering::Relaxed).wrapping_add(i32::from(cmd.step.y)), Ordering::Relaxed);
        self.last_interval_ticks.store(cmd.interval_ticks, Ordering::Relaxed);
        let t = self.emitted_ticks.load(Ordering::Relaxed).wrapping_add(cmd.interval_ticks);
        self.emitted_ticks.store(t, Ordering::Release);
        let n = self.emitted_steps.load(Ordering::Relaxed).wrapping_add(1);
        self.emitted_steps.store(n, Ordering::Release);
    }

    /// The step timer starts or stops.
    pub(super) fn set_pulsing(&self, on: bool) {
        self.pulsing.store(on, Ordering::Release);
    }

    /// `trip`, for the news interrupt to deliver.
    pub(super) fn tripped(&self, trip: Trip) {
        self.news.tripped(trip);
    }

    /// The pulses stopped, emitting all they had.
    pub(super) fn stopped(&self) {
        self.news.stopped();
    }

    /// The queue ran dry while the motion was not at rest.
    pub(super) fn count_underrun(&self) {
        self.underruns.store(self.underruns.load(Ordering::Relaxed).wrapping_add(1), Ordering::Relaxed);
        self.news.underrun();
    }

    /// The interrupt came a whole period late.
    pub(super) fn count_missed_update(&self) {
        self.missed_updates.store(self.missed_updates.load(Ordering::Relaxed).wrapping_add(1), Ordering::Relaxed);
        self.news.missed_update();
    }
}

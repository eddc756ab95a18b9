//! What the pulse interrupt writes into the machine, and how its news reaches the tasks. The
//! interrupt runs above every critical section (they mask every interrupt but it, see
//! `critical`, on the chip), so it takes no lock and wakes no task itself: it leaves its news in the
//! machine's pulse news (atomics only), and the board then pends an interrupt below it whose
//! handler hands the news on ([`Machine::deliver_pulse_news`](crate::machine::Machine::deliver_pulse_news)): the trip to the motion task, the
//! stop to those waiting for it, the warnings to the log.

use core::sync::atomic::Ordering;

use super::Machine;
use crate::inputs::Trip;

impl Machine {
    /// The pulse interrupt saw `trip`: as [`trip`](Self::trip), the pulse engine halted at once,
    /// the rest in the news. Only the pulse engine calls this.
    pub fn pulse_trip(&self, trip: Trip) {
        if self.halted.swap(true, Ordering::AcqRel) {
            return;
        }
        if !self.is_homing_switch(trip) {
            self.position_lost.store(true, Ordering::Relaxed);
        }
        self.pulse_news.tripped(trip);
    }

    /// The pulse engine emitted everything queued and stopped. Only the pulse engine calls this.
    pub fn pulses_stopped(&self) {
        self.pulse_news.stopped();
    }

    /// The pulse engine found the queue empty while the motion was not at rest. Only the pulse
    /// engine calls this.
    pub fn count_underrun(&self) {
        self.underruns.store(self.underruns.load(Ordering::Relaxed).wrapping_add(1), Ordering::Relaxed);
        self.pulse_news.underrun();
    }

    /// The step timer's interrupt came a whole period late or later: the timer repeated a
    /// period the engine then counted (see [`crate::pulse`]). Only the pulse engine calls this.
    pub fn count_missed_update(&self) {
        self.missed_updates.store(self.missed_updates.load(Ordering::Relaxed).wrapping_add(1), Ordering::Relaxed);
        self.pulse_news.missed_update();
    }

    /// Hands the pulse interrupt's news on: below it (the board's interrupt for it, or the
    /// simulator's step timer after each period), never in it.
    pub fn deliver_pulse_news(&self) {
        let news = self.pulse_news.take();
        if let Some(trip) = news.trip {
            self.trip.lock(|t| t.set(Some(trip)));
            self.control_requested.signal(());
            self.changed.signal(());
        }
        if news.stopped {
            self.pulses_done.signal(());
            self.changed.signal(());
        }
        if news.underrun {
            warn!("step queue underrun: the motion task fell behind the pulses");
        }
        if news.missed_update {
            warn!("missed step timer update: the pulse interrupt came a whole period late");
        }
    }
}

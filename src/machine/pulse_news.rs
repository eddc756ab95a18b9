//! What the pulse interrupt tells the tasks. The interrupt runs above every critical section
//! (they mask every interrupt but it, see [`crate::critical`]), so it takes no lock and wakes no
//! task itself: it leaves its news here, a bit each and the trip's code, with atomics only, and
//! the board then pends an interrupt below it whose handler hands the news on
//! ([`Machine::deliver_pulse_news`]): the trip to the motion task, the stop to those waiting for
//! it, the warnings to the log.

use core::sync::atomic::{AtomicU8, Ordering};

use super::Machine;
use crate::geom::Axis;
use crate::inputs::Trip;

/// The pulses stopped, emitting all they had.
const STOPPED: u8 = 1 << 0;
/// An input tripped the machine (the trip in `trip`).
const TRIPPED: u8 = 1 << 1;
/// The queue ran dry while the motion was not at rest.
const UNDERRUN: u8 = 1 << 2;
/// The interrupt came a whole period late.
const MISSED_UPDATE: u8 = 1 << 3;

/// The news not yet delivered.
pub(super) struct PulseNews {
    bits: AtomicU8,
    /// The trip, as [`code`].
    trip: AtomicU8,
}

impl PulseNews {
    pub(super) const fn new() -> Self {
        PulseNews { bits: AtomicU8::new(0), trip: AtomicU8::new(0) }
    }

    fn raise(&self, bit: u8) {
        self.bits.fetch_or(bit, Ordering::Release);
    }
}

/// A trip as one byte, for an atomic.
fn code(trip: Trip) -> u8 {
    match trip {
        Trip::Limit { axis, max } => 1 + axis.index() as u8 + 2 * u8::from(max),
        Trip::DriverAlarm(axis) => 5 + axis.index() as u8,
        Trip::EStop => 7,
        Trip::MissedUpdate => 8,
    }
}

fn decode(code: u8) -> Option<Trip> {
    let axis = |k: u8| if k.is_multiple_of(2) { Axis::X } else { Axis::Y };
    Some(match code {
        1..=4 => Trip::Limit { axis: axis(code - 1), max: code > 2 },
        5 | 6 => Trip::DriverAlarm(axis(code - 5)),
        7 => Trip::EStop,
        8 => Trip::MissedUpdate,
        _ => return None,
    })
}

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
        self.pulse_news.trip.store(code(trip), Ordering::Relaxed);
        self.pulse_news.raise(TRIPPED);
    }

    /// The pulse engine emitted everything queued and stopped. Only the pulse engine calls this.
    pub fn pulses_stopped(&self) {
        self.pulse_news.raise(STOPPED);
    }

    /// The pulse engine found the queue empty while the motion was not at rest. Only the pulse
    /// engine calls this.
    pub fn count_underrun(&self) {
        self.underruns.store(self.underruns.load(Ordering::Relaxed).wrapping_add(1), Ordering::Relaxed);
        self.pulse_news.raise(UNDERRUN);
    }

    /// The step timer's interrupt came a whole period late or later: the timer repeated a
    /// period the engine then counted (see [`crate::pulse`]). Only the pulse engine calls this.
    pub fn count_missed_update(&self) {
        self.missed_updates.store(self.missed_updates.load(Ordering::Relaxed).wrapping_add(1), Ordering::Relaxed);
        self.pulse_news.raise(MISSED_UPDATE);
    }

    /// Hands the pulse interrupt's news on: below it (the board's interrupt for it, or the
    /// simulator's step timer after each period), never in it.
    pub fn deliver_pulse_news(&self) {
        let bits = self.pulse_news.bits.swap(0, Ordering::Acquire);
        if bits & TRIPPED != 0
            && let Some(trip) = decode(self.pulse_news.trip.load(Ordering::Relaxed))
        {
            self.trip.lock(|t| t.set(Some(trip)));
            self.control_requested.signal(());
            self.changed.signal(());
        }
        if bits & STOPPED != 0 {
            self.pulses_done.signal(());
            self.changed.signal(());
        }
        if bits & UNDERRUN != 0 {
            warn!("step queue underrun: the motion task fell behind the pulses");
        }
        if bits & MISSED_UPDATE != 0 {
            warn!("missed step timer update: the pulse interrupt came a whole period late");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_trip_survives_its_code() {
        for trip in [
            Trip::Limit { axis: Axis::X, max: false },
            Trip::Limit { axis: Axis::Y, max: false },
            Trip::Limit { axis: Axis::X, max: true },
            Trip::Limit { axis: Axis::Y, max: true },
            Trip::DriverAlarm(Axis::X),
            Trip::DriverAlarm(Axis::Y),
            Trip::EStop,
            Trip::MissedUpdate,
        ] {
            assert_eq!(decode(code(trip)), Some(trip));
        }
        assert_eq!(decode(0), None);
    }
}

//! What the pulse interrupt has to tell the tasks, not yet told: a bit for each kind of news
//! and the trip's code, in atomics only (the interrupt runs above every critical section and
//! takes no lock; see [`crate::machine::Machine::deliver_pulse_news`]).

use core::sync::atomic::{AtomicU8, Ordering};

use crate::geom::Axis;
use crate::machine_io::inputs::Trip;

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

    /// An input tripped the machine.
    pub(super) fn tripped(&self, trip: Trip) {
        self.trip.store(code(trip), Ordering::Relaxed);
        self.raise(TRIPPED);
    }

    /// The pulses stopped, emitting all they had.
    pub(super) fn stopped(&self) {
        self.raise(STOPPED);
    }

    /// The queue ran dry while the motion was not at rest.
    pub(super) fn underrun(&self) {
        self.raise(UNDERRUN);
    }

    /// The interrupt came a whole period late.
    pub(super) fn missed_update(&self) {
        self.raise(MISSED_UPDATE);
    }

    /// The news raised since the last take, cleared.
    pub(super) fn take(&self) -> News {
        let bits = self.bits.swap(0, Ordering::Acquire);
        News {
            trip: if bits & TRIPPED != 0 { decode(self.trip.load(Ordering::Relaxed)) } else { None },
            stopped: bits & STOPPED != 0,
            underrun: bits & UNDERRUN != 0,
            missed_update: bits & MISSED_UPDATE != 0,
        }
    }
}

/// The news taken at once.
pub(super) struct News {
    pub trip: Option<Trip>,
    pub stopped: bool,
    pub underrun: bool,
    pub missed_update: bool,
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

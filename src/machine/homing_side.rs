//! The part of the machine the homing task writes, through its handle
//! ([`HomingWriter`](super::HomingWriter)): where machine zero is (the pulses emitted at it),
//! whether a homing cycle runs, and the switch a homing approach stopped at.
//!
//! One writer for machine zero: the homing task ([`crate::tasks::homing`]), at rest. The homing
//! flag and the switch found are mailboxes the homing task takes from: anyone may request a
//! cycle ([`Machine::request_homing`](super::Machine::request_homing), which sets the flag; the
//! homing task clears it when the cycle ends), and the motion task posts the switch an approach
//! stopped at ([`MotionWriter::found_switch`](super::MotionWriter::found_switch)). Readers: the
//! position and the state everywhere, the pulse engine (a cycle watches the switches ahead),
//! through the narrow reads on [`Machine`](super::Machine).

use core::cell::Cell;
use core::sync::atomic::{AtomicBool, AtomicI32, Ordering};

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;

use crate::machine_io::inputs::Trip;

/// What the homing task writes, and its mailboxes (see the module documentation).
pub(super) struct HomingSide {
    /// Pulses emitted at machine zero.
    origin: [AtomicI32; 2],
    /// A homing cycle runs: limit switches ahead are watched, and one found is no alarm.
    running: AtomicBool,
    /// Wakes the homing task.
    requested: Signal<CriticalSectionRawMutex, ()>,
    /// The switch a homing approach stopped at, until the homing task takes it.
    switch_found: Mutex<CriticalSectionRawMutex, Cell<Option<Trip>>>,
}

impl HomingSide {
    pub(super) const fn new() -> Self {
        HomingSide {
            origin: [AtomicI32::new(0), AtomicI32::new(0)],
            running: AtomicBool::new(false),
            requested: Signal::new(),
            switch_found: Mutex::new(Cell::new(None)),
        }
    }

    /// The pulses emitted on `axis` (0 for X, 1 for Y) at machine zero.
    pub(super) fn origin(&self, axis: usize) -> i32 {
        self.origin[axis].load(Ordering::Relaxed)
    }

    pub(super) fn set_origin(&self, axis: usize, emitted: i32) {
        self.origin[axis].store(emitted, Ordering::Relaxed);
    }

    pub(super) fn running(&self) -> bool {
        self.running.load(Ordering::Acquire)
    }

    /// Asks for a cycle: false if one runs already.
    pub(super) fn request(&self) -> bool {
        if self.running.swap(true, Ordering::AcqRel) {
            return false;
        }
        self.requested.signal(());
        true
    }

    pub(super) async fn requested(&self) {
        self.requested.wait().await
    }

    pub(super) fn end(&self) {
        self.running.store(false, Ordering::Release);
    }

    pub(super) fn post_switch_found(&self, trip: Trip) {
        self.switch_found.lock(|f| f.set(Some(trip)));
    }

    pub(super) fn take_switch_found(&self) -> Option<Trip> {
        self.switch_found.lock(|f| f.take())
    }
}

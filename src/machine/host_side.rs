//! The part of the machine the host link writes, through its handle
//! ([`HostWriter`](super::HostWriter)): the overrides in force, the work offset, check mode
//! (`$C`), sleep (`$SLP`) and how deep the pen goes down (`M3 S…`).
//!
//! One writer: the host link ([`crate::tasks::serial`]). Readers: the motion task (the
//! overrides, at each refill), the reports, the LCD and the servo task (the state, sleep), through
//! the narrow reads on [`Machine`](super::Machine).

use core::cell::Cell;
use core::sync::atomic::{AtomicBool, AtomicU16, AtomicU32, Ordering};

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;

use crate::machine_io::pen::PenDepth;
use crate::motion::overrides::Overrides;

/// What the host link writes (see the module documentation).
pub(super) struct HostSide {
    /// The overrides in force, [`Overrides::to_bits`].
    overrides: AtomicU32,
    /// Machine position minus work position, mm.
    work_offset_mm: Mutex<CriticalSectionRawMutex, Cell<[f32; 2]>>,
    /// The host link is in check mode (`$C`): reported as `Check` while idle.
    check_mode: AtomicBool,
    /// `$SLP`: the servos are off until a reset.
    asleep: AtomicBool,
    /// How deep the pen goes down, per mille ([`PenDepth`]): the last `M3 S…`'s.
    pen_depth: AtomicU16,
}

impl HostSide {
    pub(super) const fn new() -> Self {
        HostSide {
            overrides: AtomicU32::new(Overrides::NONE.to_bits()),
            work_offset_mm: Mutex::new(Cell::new([0.0; 2])),
            check_mode: AtomicBool::new(false),
            asleep: AtomicBool::new(false),
            pen_depth: AtomicU16::new(PenDepth::FULL.permille()),
        }
    }

    pub(super) fn overrides(&self) -> Overrides {
        Overrides::from_bits(self.overrides.load(Ordering::Relaxed))
    }

    /// Sets the overrides; true if they changed.
    pub(super) fn set_overrides(&self, overrides: Overrides) -> bool {
        let bits = overrides.to_bits();
        self.overrides.swap(bits, Ordering::Relaxed) != bits
    }

    pub(super) fn work_offset_mm(&self) -> [f32; 2] {
        self.work_offset_mm.lock(|o| o.get())
    }

    /// Sets the work offset; true if it changed.
    pub(super) fn set_work_offset_mm(&self, offset_mm: [f32; 2]) -> bool {
        self.work_offset_mm.lock(|o| o.replace(offset_mm)) != offset_mm
    }

    pub(super) fn check_mode(&self) -> bool {
        self.check_mode.load(Ordering::Relaxed)
    }

    /// Enters or leaves check mode; true if it changed.
    pub(super) fn set_check_mode(&self, on: bool) -> bool {
        self.check_mode.swap(on, Ordering::Relaxed) != on
    }

    pub(super) fn asleep(&self) -> bool {
        self.asleep.load(Ordering::Relaxed)
    }

    /// Falls asleep or wakes; true if it was asleep.
    pub(super) fn set_asleep(&self, asleep: bool) -> bool {
        self.asleep.swap(asleep, Ordering::Relaxed)
    }

    pub(super) fn pen_depth(&self) -> PenDepth {
        PenDepth::from_permille(self.pen_depth.load(Ordering::Relaxed))
    }

    pub(super) fn set_pen_depth(&self, depth: PenDepth) {
        self.pen_depth.store(depth.permille(), Ordering::Relaxed);
    }
}

//! The coordinate data GRBL keeps beside its modal state, all in machine millimetres: the
//! offsets of the six work coordinate systems G54–G59, the positions G28 and G30 go to, and the
//! G92 offset.
//!
//! A machine position is a work position plus the active system's offset plus the G92 offset.
//! GRBL stores G54–G59, G28 and G30 in EEPROM: they outlive a soft reset and are cleared only by
//! `$RST=#` (or `$RST=*`), while the G92 offset is lost at every reset. The plotter keeps the
//! same rules: [`crate::store`] keeps the [`kept_mm`](Offsets::kept_mm) ones in flash.

use super::modal::{WORK_SYSTEMS, WorkSystem};

/// The offsets a power cycle keeps: G54 to G59, then G28 and G30.
pub const KEPT_OFFSETS: usize = WORK_SYSTEMS + 2;

/// The two stored positions: G28 and G30 go to them, G28.1 and G30.1 set them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum StoredPosition {
    G28,
    G30,
}

impl StoredPosition {
    const fn index(self) -> usize {
        self as usize
    }
}

/// The coordinate data; see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Offsets {
    /// G54 to G59.
    systems_mm: [[f32; 2]; WORK_SYSTEMS],
    /// G28, G30: machine positions.
    stored_mm: [[f32; 2]; 2],
    g92_mm: [f32; 2],
}

impl Default for Offsets {
    fn default() -> Self {
        Self::new()
    }
}

impl Offsets {
    /// Power-on: everything zero.
    pub const fn new() -> Self {
        Offsets { systems_mm: [[0.0; 2]; WORK_SYSTEMS], stored_mm: [[0.0; 2]; 2], g92_mm: [0.0; 2] }
    }

    /// The offset of work coordinate system `system` from the machine's.
    pub fn system_mm(&self, system: WorkSystem) -> [f32; 2] {
        self.systems_mm[system.index()]
    }

    pub(super) fn set_system_mm(&mut self, system: WorkSystem, offset_mm: [f32; 2]) {
        self.systems_mm[system.index()] = offset_mm;
    }

    /// The machine position G28 or G30 goes to.
    pub fn stored_mm(&self, which: StoredPosition) -> [f32; 2] {
        self.stored_mm[which.index()]
    }

    pub(super) fn store(&mut self, which: StoredPosition, position_mm: [f32; 2]) {
        self.stored_mm[which.index()] = position_mm;
    }

    /// The G92 offset, on top of the active system's.
    pub fn g92_mm(&self) -> [f32; 2] {
        self.g92_mm
    }

    pub(super) fn set_g92_mm(&mut self, offset_mm: [f32; 2]) {
        self.g92_mm = offset_mm;
    }

    /// Machine position minus work position while `active` is selected: its offset plus G92's.
    pub fn work_offset_mm(&self, active: WorkSystem) -> [f32; 2] {
        let system = self.system_mm(active);
        [system[0] + self.g92_mm[0], system[1] + self.g92_mm[1]]
    }

    /// What a power cycle keeps: G54 to G59, then G28 and G30, machine millimetres.
    pub fn kept_mm(&self) -> [[f32; 2]; KEPT_OFFSETS] {
        core::array::from_fn(|i| if i < WORK_SYSTEMS { self.systems_mm[i] } else { self.stored_mm[i - WORK_SYSTEMS] })
    }

    /// The offsets at power-on, from what the last power cycle kept ([`kept_mm`](Self::kept_mm)).
    pub fn from_kept_mm(kept: [[f32; 2]; KEPT_OFFSETS]) -> Offsets {
        Offsets {
            systems_mm: core::array::from_fn(|i| kept[i]),
            stored_mm: [kept[WORK_SYSTEMS], kept[WORK_SYSTEMS + 1]],
            g92_mm: [0.0; 2],
        }
    }

    /// What a soft reset keeps: all but the G92 offset.
    pub(super) fn after_reset(&self) -> Offsets {
        Offsets { g92_mm: [0.0; 2], ..*self }
    }
}

//! The coordinate data GRBL keeps beside its modal state, all in machine millimetres: the
//! offsets of the six work coordinate systems G54–G59, the positions G28 and G30 go to, and the
//! G92 offset.
//!
//! A machine position is a work position plus the active system's offset plus the G92 offset.
//! GRBL stores G54–G59, G28 and G30 in EEPROM: they outlive a soft reset and are cleared only by
//! `$RST=#` (or `$RST=*`), while the G92 offset is lost at every reset. The plotter keeps the
//! same rules, but in RAM: there is no flash store yet, so a power cycle loses them all.

use super::modal::{WORK_SYSTEMS, WorkSystem};

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
#[derive(Clone, Debug, PartialEq)]
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

    /// What a soft reset keeps: all but the G92 offset.
    pub(super) fn after_reset(&self) -> Offsets {
        Offsets { g92_mm: [0.0; 2], ..self.clone() }
    }
}

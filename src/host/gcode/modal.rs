//! The values of GRBL's modal state that a line sets and later lines keep: the modal groups
//! (motion, units, distance, spindle, work coordinate system) and the range of the tool number.

pub const MM_PER_INCH: f32 = 25.4;

/// Largest T tool number, GRBL's.
pub const TOOL_NUMBER_MAX: f32 = 255.0;

/// M8/M9: flood coolant on or off. Kept for `$G` only, as GRBL keeps it: the plotter has no
/// coolant output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Coolant {
    Flood,
    Off,
}

/// Length units of X, Y, I, J, R and F (G20/G21).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Units {
    Mm,
    Inch,
}

impl Units {
    pub const fn mm_per_unit(self) -> f32 {
        match self {
            Units::Mm => 1.0,
            Units::Inch => MM_PER_INCH,
        }
    }
}

/// G90/G91.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Distance {
    Absolute,
    Incremental,
}

/// The motion modal group: G0, G1, G2, G3, G80.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum MotionMode {
    Rapid,
    Linear,
    ArcCw,
    ArcCcw,
    Off,
}

/// M3/M4/M5: kept for `$G` only, the plotter has no spindle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Spindle {
    Cw,
    Ccw,
    Off,
}

/// Work coordinate systems, G54 to G59: GRBL's six.
pub const WORK_SYSTEMS: usize = 6;

/// The G-code number of the first work coordinate system, G54.
const FIRST_WORK_SYSTEM_GCODE: u8 = 54;

/// The coordinate system select modal group: G54 (the power-on one) to G59.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct WorkSystem(u8);

impl WorkSystem {
    pub const G54: WorkSystem = WorkSystem(0);

    /// The system `index` places after G54 (0 is G54, 5 is G59); `None` beyond G59.
    pub const fn from_index(index: usize) -> Option<WorkSystem> {
        if index < WORK_SYSTEMS { Some(WorkSystem(index as u8)) } else { None }
    }

    /// The system selected by G`number` (54 to 59).
    pub const fn from_gcode(number: u16) -> Option<WorkSystem> {
        match number.checked_sub(FIRST_WORK_SYSTEM_GCODE as u16) {
            Some(index) => WorkSystem::from_index(index as usize),
            None => None,
        }
    }

    /// 0 for G54 to 5 for G59.
    pub const fn index(self) -> usize {
        self.0 as usize
    }

    /// 54 to 59.
    pub const fn gcode(self) -> u8 {
        FIRST_WORK_SYSTEM_GCODE + self.0
    }

    /// G54 to G59, in order.
    pub fn all() -> impl Iterator<Item = WorkSystem> {
        (0..WORK_SYSTEMS as u8).map(WorkSystem)
    }
}

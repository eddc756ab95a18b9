//! The values of GRBL's modal state that a line sets and later lines keep: the modal groups
//! (motion, units, distance, spindle) and the range of the tool number.

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

//! The units numbers are typed and shown in: the keypad forms' and the settings'.

/// The unit of a number the user types or reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Unit {
    Mm,
    Deg,
    MmPerMin,
    MmPerS2,
    StepsPerMm,
    Us,
    Ms,
    Hz,
    /// A count, a bit mask or a choice, whose meaning its name and range tell.
    Plain,
}

impl Unit {
    pub const fn symbol(self) -> &'static str {
        match self {
            Unit::Mm => "mm",
            Unit::Deg => "deg",
            Unit::MmPerMin => "mm/min",
            Unit::MmPerS2 => "mm/s2",
            Unit::StepsPerMm => "step/mm",
            Unit::Us => "us",
            Unit::Ms => "ms",
            Unit::Hz => "Hz",
            Unit::Plain => "",
        }
    }
}

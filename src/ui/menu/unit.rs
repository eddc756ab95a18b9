//! The units a number field is typed in, and their symbols on the screen.

/// Unit of a number field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Unit {
    Mm,
    Deg,
}

impl Unit {
    pub const fn symbol(self) -> &'static str {
        match self {
            Unit::Mm => "mm",
            Unit::Deg => "deg",
        }
    }
}

//! The menu's top-level modes: their order in the mode list, their titles and labels. The
//! fields of a mode's form are the forms' own (`form`).

/// A top-level mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Mode {
    Jog,
    Line,
    Circle,
    Ellipse,
    Sine,
    Function,
    Settings,
    /// Speed presets for the pen in use.
    Presets,
    /// Runs the homing cycle (`$H`) at once.
    Home,
}

impl Mode {
    /// Every mode, in menu order: `1` picks the first.
    pub const ALL: [Mode; 9] = [
        Mode::Jog,
        Mode::Line,
        Mode::Circle,
        Mode::Ellipse,
        Mode::Sine,
        Mode::Function,
        Mode::Settings,
        Mode::Home,
        Mode::Presets,
    ];

    /// Screen title.
    pub const fn title(self) -> &'static str {
        match self {
            Mode::Jog => "JOG",
            Mode::Line => "LINE",
            Mode::Circle => "CIRCLE/ARC",
            Mode::Ellipse => "ELLIPSE",
            Mode::Sine => "SINE",
            Mode::Function => "FUNCTION",
            Mode::Settings => "SETTINGS",
            Mode::Presets => "PRESETS",
            Mode::Home => "HOME",
        }
    }

    /// Entry in the mode list.
    pub const fn label(self) -> &'static str {
        match self {
            Mode::Jog => "Jog",
            Mode::Line => "Line",
            Mode::Circle => "Circle/arc",
            Mode::Ellipse => "Ellipse",
            Mode::Sine => "Sine wave",
            Mode::Function => "Function y=f(x)",
            Mode::Settings => "Settings",
            Mode::Presets => "Speed presets",
            Mode::Home => "Home ($H)",
        }
    }

    /// Position in [`Mode::ALL`].
    pub fn index(self) -> usize {
        Mode::ALL.iter().position(|&m| m == self).unwrap_or(0)
    }
}

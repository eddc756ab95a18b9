//! The menu's top-level modes: their order in the mode list, their titles and labels. The
//! fields of a mode's form are the forms' own (`form`).

use crate::panel::texts::Msg;

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
    /// Switches the LCD's language (`$216`) at once.
    Language,
    /// Lists the card's G-code files and plots the one chosen.
    Card,
}

impl Mode {
    /// Every mode, in menu order: `1` picks the first, `0` the tenth; the ones after the tenth
    /// only with `A`/`B` and `#`.
    pub const ALL: [Mode; 11] = [
        Mode::Jog,
        Mode::Line,
        Mode::Circle,
        Mode::Ellipse,
        Mode::Sine,
        Mode::Function,
        Mode::Settings,
        Mode::Home,
        Mode::Presets,
        Mode::Language,
        Mode::Card,
    ];

    /// Screen title.
    pub const fn title(self) -> Msg {
        match self {
            Mode::Jog => Msg::TitleJog,
            Mode::Line => Msg::TitleLine,
            Mode::Circle => Msg::TitleCircle,
            Mode::Ellipse => Msg::TitleEllipse,
            Mode::Sine => Msg::TitleSine,
            Mode::Function => Msg::TitleFunction,
            Mode::Settings => Msg::TitleSettings,
            Mode::Presets => Msg::TitlePresets,
            Mode::Home => Msg::TitleHome,
            Mode::Language => Msg::TitleLanguage,
            Mode::Card => Msg::TitleCard,
        }
    }

    /// Entry in the mode list.
    pub const fn label(self) -> Msg {
        match self {
            Mode::Jog => Msg::LabelJog,
            Mode::Line => Msg::LabelLine,
            Mode::Circle => Msg::LabelCircle,
            Mode::Ellipse => Msg::LabelEllipse,
            Mode::Sine => Msg::LabelSine,
            Mode::Function => Msg::LabelFunction,
            Mode::Settings => Msg::LabelSettings,
            Mode::Presets => Msg::LabelPresets,
            Mode::Home => Msg::LabelHome,
            Mode::Language => Msg::LabelLanguage,
            Mode::Card => Msg::LabelCard,
        }
    }

    /// Position in [`Mode::ALL`].
    pub fn index(self) -> usize {
        Mode::ALL.iter().position(|&m| m == self).unwrap_or(0)
    }
}

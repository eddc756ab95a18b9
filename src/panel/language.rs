//! The language of the machine's own screen (setting `$216`): the keypad menu and the LCD speak
//! English or 中文. The texts themselves are the UI's ([`crate::panel::texts`]); the language lives
//! apart because the settings hold it, and the settings must not depend on the UI.

/// The language of the LCD.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Language {
    #[default]
    English,
    /// Simplified Chinese.
    Chinese,
}

impl Language {
    /// The other one: the menu's language entry switches between the two.
    pub const fn other(self) -> Language {
        match self {
            Language::English => Language::Chinese,
            Language::Chinese => Language::English,
        }
    }
}

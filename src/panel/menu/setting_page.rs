//! The settings on the keypad: one `$` setting at a time, with its name, value, unit and range.
//! A number key or `#` starts typing a new value; `#` checks it against the setting's range and
//! hands it on as a [`MenuAction::SetSetting`], which the keypad task applies (the serial task
//! then keeps it in flash); `C` does so too and moves on to the next setting. No setting takes
//! a negative value, so `A` is no sign here.

use super::action::MenuAction;
use super::error::UiError;
use super::form::ranged_value;
use super::list;
use crate::panel::entry::NumberEntry;
use crate::panel::keypad::Key;
use crate::settings::{SETTING_INFO, SettingInfo, Settings};

/// The settings screen: the setting shown, and the new value being typed, if any.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SettingPage {
    /// Into [`SETTING_INFO`].
    index: usize,
    edit: Option<NumberEntry>,
}

impl SettingPage {
    /// The first setting, shown.
    pub const fn new() -> Self {
        SettingPage { index: 0, edit: None }
    }

    /// The setting shown.
    pub fn info(&self) -> &'static SettingInfo {
        &SETTING_INFO[self.index.min(SETTING_INFO.len() - 1)]
    }

    /// Its position in [`SETTING_INFO`].
    pub fn index(&self) -> usize {
        self.index
    }

    /// The new value being typed, if any.
    pub fn edit(&self) -> Option<&NumberEntry> {
        self.edit.as_ref()
    }

    /// Drops the value being typed.
    pub(super) fn cancel(&mut self) {
        self.edit = None;
    }

    /// Shows setting `$id` (if there is one), nothing typed.
    pub(super) fn show(&mut self, id: u16) {
        if let Some(index) = SETTING_INFO.iter().position(|info| info.id == id) {
            *self = SettingPage { index, edit: None };
        }
    }

    /// Takes a key. Showing a setting: `A`/`B` step through the list, a number key or `#`
    /// starts a new value. Typing one: the number keys edit it ([`NumberEntry::press`]) but `A`
    /// (the sign) and `C`, `B` on an empty value goes back, `#` gives it, checked, and `C` gives
    /// it and moves on to the next setting.
    pub(super) fn press(&mut self, key: Key, repeated: bool, settings: &Settings) -> Result<MenuAction, UiError> {
        let info = self.info();
        let Some(entry) = &mut self.edit else {
            match key {
                Key::A | Key::B => self.index = list::moved(self.index, SETTING_INFO.len(), key),
                Key::Hash => self.edit = Some(NumberEntry::new()),
                Key::Digit(_) | Key::Star => {
                    let mut entry = NumberEntry::new();
                    entry.press(key).map_err(UiError::Entry)?;
                    self.edit = Some(entry);
                }
                Key::C | Key::D => {}
            }
            return Ok(MenuAction::None);
        };
        match key {
            Key::Hash | Key::C => {}
            Key::A => return Ok(MenuAction::None),
            _ => {
                if !entry.press(key).map_err(UiError::Entry)? && !repeated {
                    self.edit = None;
                }
                return Ok(MenuAction::None);
            }
        }
        let value = ranged_value(entry, None, &(info.min..=info.max), info.unit)?;
        if settings.is_whole(info.id) && value != crate::math::floor(value) {
            return Err(UiError::NotWhole);
        }
        self.edit = None;
        if key == Key::C {
            self.index = list::moved(self.index, SETTING_INFO.len(), Key::B);
        }
        Ok(MenuAction::SetSetting { id: info.id, value })
    }
}

//! The settings and the keypad menu as the tasks share them: each read as a copy and changed in
//! one place, which wakes whoever shows or keeps it.

use super::Machine;
use crate::settings::Settings;
use crate::ui::Menu;

impl Machine {
    /// A copy of the current settings. Out of line: a dozen places read them, none per step.
    #[inline(never)]
    pub fn settings(&self) -> Settings {
        self.settings.lock(|s| *s.borrow())
    }

    /// Changes the settings through `f`; the planner picks them up for the next job, the LCD
    /// shows them, and the serial task keeps them in flash.
    pub fn update_settings<R>(&self, f: impl FnOnce(&mut Settings) -> R) -> R {
        let r = self.settings.lock(|s| f(&mut s.borrow_mut()));
        self.changed.signal(());
        self.settings_changed.signal(());
        r
    }

    /// Waits until the settings may have changed since the last wait (for the serial task).
    pub async fn settings_changed(&self) {
        self.settings_changed.wait().await
    }

    /// A copy of the keypad menu (the keypad task changes it, the LCD task draws it). Work on
    /// the menu happens on the copy, never inside the lock.
    pub fn menu(&self) -> Menu {
        self.menu.lock(|m| m.borrow().clone())
    }

    pub fn set_menu(&self, menu: Menu) {
        self.menu.lock(|m| *m.borrow_mut() = menu);
        self.changed.signal(());
    }

    /// Changes the menu in place through `f`, inside the lock; tells displays if `f` says so.
    pub fn update_menu(&self, f: impl FnOnce(&mut Menu) -> bool) {
        if self.menu.lock(|m| f(&mut m.borrow_mut())) {
            self.changed.signal(());
        }
    }
}

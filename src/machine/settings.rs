//! The settings as the tasks share them: read as a copy and changed in one place, which wakes
//! whoever shows or keeps them.

use super::Machine;
use crate::settings::Settings;

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
}

//! The settings as the tasks share them: written in thread mode (the host link, the keypad),
//! read from every priority (the motion task and the pulse engine too), each read a copy taken
//! without masking interrupts ([`Published`](super::published::Published)). A mailbox: either
//! input updates them; the host link, woken by each update, keeps them in flash
//! ([`HostWriter::settings_changed`](super::HostWriter::settings_changed)).

use super::Machine;
use crate::settings::Settings;

impl Machine {
    /// A copy of the current settings. Out of line: a dozen places read them, none per step.
    #[inline(never)]
    pub fn settings(&self) -> Settings {
        self.settings.get()
    }

    /// Changes the settings through `f`; the planner picks them up for the next job, the LCD
    /// shows them, and the serial task keeps them in flash. Only thread-mode tasks call this
    /// (see [`Published`](super::published::Published)): the host link and the keypad.
    pub fn update_settings<R>(&self, f: impl FnOnce(&mut Settings) -> R) -> R {
        let r = self.settings.update(f);
        self.changed.signal(());
        self.settings_changed.signal(());
        r
    }
}

//! The panel: the keypad menu as the keypad task (which changes it) and the LCD task (which
//! draws it) share it, and the signal that tells the LCD it changed.
//!
//! Both tasks run in thread mode, on one executor, so neither ever runs while the other is
//! inside the menu: the menu is borrowed in place, never copied, and no critical section is
//! taken. A `Panel` is not `Sync`, so it cannot be handed to a task on another executor or
//! priority. The board makes one, in static storage (the menu is 2 KiB), and hands it to both
//! tasks.

use core::cell::RefCell;

use embassy_sync::blocking_mutex::raw::NoopRawMutex;
use embassy_sync::signal::Signal;

use crate::panel::Menu;

/// The keypad menu and its change signal; see the module documentation.
pub struct Panel {
    menu: RefCell<Menu>,
    /// Wakes the LCD task after the menu changed.
    changed: Signal<NoopRawMutex, ()>,
}

impl Default for Panel {
    fn default() -> Self {
        Self::new()
    }
}

impl Panel {
    /// The menu at power-on.
    pub const fn new() -> Self {
        Panel { menu: RefCell::new(Menu::new()), changed: Signal::new() }
    }

    /// Reads the menu through `f`. `f` runs to its end without waiting and does not reach the
    /// panel again.
    pub fn read<R>(&self, f: impl FnOnce(&Menu) -> R) -> R {
        f(&self.menu.borrow())
    }

    /// Changes the menu through `f` and tells the LCD. `f` runs to its end without waiting and
    /// does not reach the panel again.
    pub fn update<R>(&self, f: impl FnOnce(&mut Menu) -> R) -> R {
        let r = f(&mut self.menu.borrow_mut());
        self.changed.signal(());
        r
    }

    /// Changes the menu through `f`, and tells the LCD if `f` says it changed.
    pub fn update_if(&self, f: impl FnOnce(&mut Menu) -> bool) {
        if f(&mut self.menu.borrow_mut()) {
            self.changed.signal(());
        }
    }

    /// Waits until the menu may have changed since the last wait (for the LCD task).
    pub async fn changed(&self) {
        self.changed.wait().await
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::panel::keypad::{Key, KeyEvent};
    use crate::settings::Settings;
    use crate::status::Status;
    use core::pin::pin;
    use core::task::{Context, Waker};

    /// True if `f` is done at its first poll.
    fn ready_at_once(f: impl Future<Output = ()>) -> bool {
        let mut f = pin!(f);
        f.as_mut().poll(&mut Context::from_waker(Waker::noop())).is_ready()
    }

    #[test]
    fn a_key_handled_in_place_is_seen_by_the_reader_and_wakes_it() {
        let panel = Panel::new();
        let before = panel.read(|menu| menu.screen().clone());
        assert!(!ready_at_once(panel.changed()), "nothing changed yet");
        let (status, settings) = (Status::default(), Settings::default());
        panel.update(|menu| menu.handle(KeyEvent::Press(Key::Digit(8)), &status, &settings));
        assert!(ready_at_once(panel.changed()), "the LCD is woken");
        assert_ne!(panel.read(|menu| menu.screen().clone()), before, "the key moved off the splash");
        assert!(!ready_at_once(panel.changed()), "woken once per change");
    }

    #[test]
    fn an_update_that_changes_nothing_does_not_wake_the_reader() {
        let panel = Panel::new();
        panel.update_if(|_| false);
        assert!(!ready_at_once(panel.changed()));
        panel.update_if(|_| true);
        assert!(ready_at_once(panel.changed()));
    }
}

//! How the keys move through the menu's short lists (modes, function presets, speed presets,
//! settings): `A` up, `B` down, stopping at the ends, and a digit picks its entry.

use crate::panel::keypad::Key;

/// Where `key` moves the cursor from `at` in a list of `len` entries: `A` one up, `B` one down
/// (no wrap), digit `d` to entry `d` (1 the first, 0 the tenth) if there is one; any other key
/// leaves it.
pub fn moved(at: usize, len: usize, key: Key) -> usize {
    match key {
        Key::A => at.saturating_sub(1),
        Key::B => (at + 1).min(len.saturating_sub(1)),
        Key::Digit(d) if (usize::from(d) + 9) % 10 < len => (usize::from(d) + 9) % 10,
        _ => at,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cursor_stops_at_the_ends_and_digits_pick() {
        assert_eq!((moved(0, 3, Key::A), moved(2, 3, Key::B), moved(1, 3, Key::B)), (0, 2, 2));
        assert_eq!((moved(0, 3, Key::Digit(3)), moved(1, 3, Key::Digit(4)), moved(1, 3, Key::Digit(0))), (2, 1, 1));
        assert_eq!(moved(1, 3, Key::C), 1);
        assert_eq!((moved(1, 10, Key::Digit(0)), moved(1, 10, Key::Digit(1))), (9, 0));
    }
}

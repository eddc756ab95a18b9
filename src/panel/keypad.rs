//! 4x4 matrix keypad decoding: raw scans in, debounced key events out.
//!
//! The keypad task drives the column lines, reads the rows and hands one raw 16-bit scan to
//! [`KeypadDecoder::update`] every [`KEYPAD_SCAN_PERIOD_MS`], together with the time of the scan.
//! Bit `row * 4 + col` is set when the key at (`row`, `col`) reads pressed. This module owns
//! debouncing, ghost rejection and auto-repeat; it knows nothing of pins (the task owns them) nor
//! of what a key means (the menu decides).
//!
//! Key map (rows top to bottom, columns left to right):
//!
//! | row | col 0 | col 1 | col 2 | col 3 |
//! |-----|-------|-------|-------|-------|
//! | 0   | `1`   | `2`   | `3`   | `A`   |
//! | 1   | `4`   | `5`   | `6`   | `B`   |
//! | 2   | `7`   | `8`   | `9`   | `C`   |
//! | 3   | `*`   | `0`   | `#`   | `D`   |
//!
//! - Debounce: the whole scan must read the same for [`KEYPAD_DEBOUNCE_MS`] before presses and
//!   releases count, so chatter on a contact never yields a second press.
//! - Ghosts: in a plain matrix (no diodes) three keys on the corners of a rectangle make the
//!   fourth corner read pressed too. A scan with such a rectangle, or with more than
//!   [`KEYPAD_MAX_KEYS`] keys, is ignored entirely (no event, nothing changes) until it clears.
//! - Repeat: a held navigation key ([`Key::is_navigation`]) repeats after
//!   [`KEYPAD_REPEAT_DELAY_MS`], then every [`KEYPAD_REPEAT_PERIOD_MS`]. Each repeat is timed from
//!   the previous one, so a late scan yields one repeat, never a burst; no repeat comes once the
//!   raw scan shows the key up (so a repeat never lands inside the release debounce).
//! - Time: `now_ms` is a free-running millisecond counter; all arithmetic on it wraps.

use heapless::Vec;

/// Rows of the key matrix.
pub const KEYPAD_ROWS: usize = 4;
/// Columns of the key matrix.
pub const KEYPAD_COLS: usize = 4;
/// How often the keypad task scans the matrix.
pub const KEYPAD_SCAN_PERIOD_MS: u32 = 5;
/// How long a scan must stay unchanged before its presses and releases count.
pub const KEYPAD_DEBOUNCE_MS: u32 = 15;
/// Time from the press of a navigation key to its first repeat.
pub const KEYPAD_REPEAT_DELAY_MS: u32 = 500;
/// Time between two repeats of a held navigation key.
pub const KEYPAD_REPEAT_PERIOD_MS: u32 = 100;
/// Most keys held at once that a scan may show; more is treated as a ghost pattern.
pub const KEYPAD_MAX_KEYS: u32 = 2;
/// Most events one scan can produce: every held key released (at most [`KEYPAD_MAX_KEYS`]) and
/// as many new ones pressed. A repeat never comes with a press (a press stops repeating) and
/// its key stays held, so it adds at most one event to at most one release.
pub const KEYPAD_MAX_EVENTS_PER_SCAN: usize = 2 * KEYPAD_MAX_KEYS as usize;

/// One key of the keypad.
///
/// `Digit` holds 0..=9; [`Key::from_row_col`] and [`KEY_MAP`] produce no other digit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Key {
    Digit(u8),
    A,
    B,
    C,
    D,
    Star,
    Hash,
}

/// The key at each (row, column) of the matrix.
pub const KEY_MAP: [[Key; KEYPAD_COLS]; KEYPAD_ROWS] = [
    [Key::Digit(1), Key::Digit(2), Key::Digit(3), Key::A],
    [Key::Digit(4), Key::Digit(5), Key::Digit(6), Key::B],
    [Key::Digit(7), Key::Digit(8), Key::Digit(9), Key::C],
    [Key::Star, Key::Digit(0), Key::Hash, Key::D],
];

impl Key {
    /// The key at `row`, `col`; `None` outside the matrix.
    pub const fn from_row_col(row: usize, col: usize) -> Option<Key> {
        if row < KEYPAD_ROWS && col < KEYPAD_COLS { Some(KEY_MAP[row][col]) } else { None }
    }

    /// Navigation keys auto-repeat while held: `A` (up, or sign) and `B` (down, or backspace).
    pub const fn is_navigation(self) -> bool {
        matches!(self, Key::A | Key::B)
    }

    /// The printed legend: `'0'..='9'`, `'A'..='D'`, `'*'`, `'#'`.
    pub const fn legend(self) -> char {
        match self {
            Key::Digit(d) if d <= 9 => (b'0' + d) as char,
            Key::Digit(_) => '?',
            Key::A => 'A',
            Key::B => 'B',
            Key::C => 'C',
            Key::D => 'D',
            Key::Star => '*',
            Key::Hash => '#',
        }
    }
}

/// What happened to a key.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum KeyEvent {
    Press(Key),
    /// The key is still held (navigation keys only).
    Repeat(Key),
    Release(Key),
}

/// The events of one scan, releases before presses.
pub type KeyEvents = Vec<KeyEvent, KEYPAD_MAX_EVENTS_PER_SCAN>;

/// The column mask of `row` in a raw scan.
const fn row_bits(raw: u16, row: usize) -> u16 {
    (raw >> (row * KEYPAD_COLS)) & ((1 << KEYPAD_COLS) - 1)
}

/// True when a raw scan can be trusted: at most [`KEYPAD_MAX_KEYS`] keys and no two rows sharing
/// two columns (the rectangle a ghost key completes).
///
/// With two keys at most no rectangle can form; the rectangle test keeps the rule right should
/// [`KEYPAD_MAX_KEYS`] ever grow.
pub fn is_ghost_free(raw: u16) -> bool {
    if raw.count_ones() > KEYPAD_MAX_KEYS {
        return false;
    }
    for r1 in 0..KEYPAD_ROWS {
        for r2 in r1 + 1..KEYPAD_ROWS {
            if (row_bits(raw, r1) & row_bits(raw, r2)).count_ones() >= 2 {
                return false;
            }
        }
    }
    true
}

/// A held navigation key waiting for its next repeat.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Repeat {
    key: Key,
    bit: u16,
    /// When the press or the last repeat was reported.
    since_ms: u32,
    /// Time from `since_ms` to the next repeat.
    wait_ms: u32,
}

/// Turns raw scans into key events; see the module documentation.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct KeypadDecoder {
    /// The debounced set of held keys.
    stable: u16,
    /// The last trusted raw scan, and since when it has read the same.
    candidate: u16,
    candidate_since_ms: u32,
    repeat: Option<Repeat>,
}

impl Default for KeypadDecoder {
    fn default() -> Self {
        Self::new()
    }
}

impl KeypadDecoder {
    /// A decoder with every key up.
    pub const fn new() -> Self {
        KeypadDecoder { stable: 0, candidate: 0, candidate_since_ms: 0, repeat: None }
    }

    /// The debounced set of held keys, one bit per key as in a raw scan.
    pub const fn held(&self) -> u16 {
        self.stable
    }

    /// Feeds one raw scan taken at `now_ms`; returns what it completed.
    pub fn update(&mut self, raw: u16, now_ms: u32) -> KeyEvents {
        let mut events = KeyEvents::new();
        if !is_ghost_free(raw) {
            return events;
        }
        if raw != self.candidate {
            self.candidate = raw;
            self.candidate_since_ms = now_ms;
        } else if raw != self.stable && now_ms.wrapping_sub(self.candidate_since_ms) >= KEYPAD_DEBOUNCE_MS {
            let released = self.stable & !raw;
            let pressed = raw & !self.stable;
            self.stable = raw;
            for (bit, key) in keys_in(released) {
                push(&mut events, KeyEvent::Release(key));
                if self.repeat.is_some_and(|r| r.bit == bit) {
                    self.repeat = None;
                }
            }
            for (bit, key) in keys_in(pressed) {
                push(&mut events, KeyEvent::Press(key));
                // The newest press owns the repeat; a key that does not repeat ends it.
                self.repeat = key.is_navigation().then_some(Repeat {
                    key,
                    bit,
                    since_ms: now_ms,
                    wait_ms: KEYPAD_REPEAT_DELAY_MS,
                });
            }
        }
        if let Some(r) = &mut self.repeat {
            let still_down = self.candidate & r.bit != 0;
            if still_down && now_ms.wrapping_sub(r.since_ms) >= r.wait_ms {
                push(&mut events, KeyEvent::Repeat(r.key));
                r.since_ms = now_ms;
                r.wait_ms = KEYPAD_REPEAT_PERIOD_MS;
            }
        }
        events
    }
}

/// The keys whose bits are set in `bits`, in matrix order.
fn keys_in(bits: u16) -> impl Iterator<Item = (u16, Key)> {
    (0..KEYPAD_ROWS * KEYPAD_COLS)
        .filter(move |i| bits & (1 << i) != 0)
        .filter_map(|i| Key::from_row_col(i / KEYPAD_COLS, i % KEYPAD_COLS).map(|k| (1u16 << i, k)))
}

fn push(events: &mut KeyEvents, event: KeyEvent) {
    // Cannot overflow: see KEYPAD_MAX_EVENTS_PER_SCAN.
    let _ = events.push(event);
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    /// Where `key` sits in the matrix; `None` for a digit above 9.
    fn row_col(key: Key) -> Option<(usize, usize)> {
        (0..KEYPAD_ROWS).flat_map(|r| (0..KEYPAD_COLS).map(move |c| (r, c))).find(|&(r, c)| KEY_MAP[r][c] == key)
    }

    /// `key`'s bit in a raw scan.
    fn bit(key: Key) -> u16 {
        let (r, c) = row_col(key).unwrap();
        1 << (r * KEYPAD_COLS + c)
    }

    /// Scans `raw` every scan period from `*now` for `duration_ms`, collecting (time, event).
    fn hold(d: &mut KeypadDecoder, now: &mut u32, raw: u16, duration_ms: u32, out: &mut Vec<(u32, KeyEvent)>) {
        let end = now.wrapping_add(duration_ms);
        while *now != end {
            for e in d.update(raw, *now) {
                out.push((*now, e));
            }
            *now = now.wrapping_add(KEYPAD_SCAN_PERIOD_MS);
        }
    }

    fn events_only(v: &[(u32, KeyEvent)]) -> Vec<KeyEvent> {
        v.iter().map(|&(_, e)| e).collect()
    }

    #[test]
    fn key_map_matches_the_legends() {
        let legends = ["123A", "456B", "789C", "*0#D"];
        for (r, row) in legends.iter().enumerate() {
            for (c, ch) in row.chars().enumerate() {
                let key = Key::from_row_col(r, c).unwrap();
                assert_eq!(key.legend(), ch);
                assert_eq!(row_col(key), Some((r, c)));
            }
        }
        assert_eq!(Key::from_row_col(4, 0), None);
        assert_eq!(Key::from_row_col(0, 4), None);
        assert_eq!(row_col(Key::Digit(10)), None);
    }

    #[test]
    fn clean_press_and_release_after_the_debounce_time() {
        let (mut d, mut now, mut ev) = (KeypadDecoder::new(), 0, Vec::new());
        hold(&mut d, &mut now, 0, 20, &mut ev);
        hold(&mut d, &mut now, bit(Key::Digit(5)), 100, &mut ev);
        hold(&mut d, &mut now, 0, 100, &mut ev);
        assert_eq!(
            ev,
            [
                (20 + KEYPAD_DEBOUNCE_MS, KeyEvent::Press(Key::Digit(5))),
                (120 + KEYPAD_DEBOUNCE_MS, KeyEvent::Release(Key::Digit(5)))
            ]
        );
        assert_eq!(d.held(), 0);
    }

    #[test]
    fn chatter_on_press_and_release_gives_one_press_and_one_release() {
        let k = bit(Key::Hash);
        let (mut d, mut now, mut ev) = (KeypadDecoder::new(), 0, Vec::new());
        // Bouncing contact: each level shorter than the debounce time.
        for level in [k, 0, k, 0, k, 0, k] {
            hold(&mut d, &mut now, level, 10, &mut ev);
        }
        assert!(ev.is_empty(), "no event while the contact bounces: {ev:?}");
        hold(&mut d, &mut now, k, 200, &mut ev);
        for level in [0, k, 0, k, 0] {
            hold(&mut d, &mut now, level, 10, &mut ev);
        }
        hold(&mut d, &mut now, 0, 100, &mut ev);
        assert_eq!(events_only(&ev), [KeyEvent::Press(Key::Hash), KeyEvent::Release(Key::Hash)]);
    }

    #[test]
    fn a_single_scan_glitch_changes_nothing() {
        let k = bit(Key::Digit(1));
        let (mut d, mut now, mut ev) = (KeypadDecoder::new(), 0, Vec::new());
        hold(&mut d, &mut now, k, 100, &mut ev);
        hold(&mut d, &mut now, 0, KEYPAD_SCAN_PERIOD_MS, &mut ev);
        hold(&mut d, &mut now, k, 100, &mut ev);
        assert_eq!(events_only(&ev), [KeyEvent::Press(Key::Digit(1))]);
    }

    #[test]
    fn ghost_rectangles_and_crowds_are_ignored_until_they_clear() {
        let (k1, k2, k4, k5) = (bit(Key::Digit(1)), bit(Key::Digit(2)), bit(Key::Digit(4)), bit(Key::Digit(5)));
        assert!(is_ghost_free(k1 | k5));
        assert!(!is_ghost_free(k1 | k2 | k4 | k5), "rectangle with its ghost");
        assert!(!is_ghost_free(k1 | bit(Key::Digit(6)) | bit(Key::Digit(8))), "three keys");

        let (mut d, mut now, mut ev) = (KeypadDecoder::new(), 0, Vec::new());
        hold(&mut d, &mut now, k1, 50, &mut ev);
        // 2 and 4 join 1: the matrix shows 5 as well. Nothing may change while it lasts.
        hold(&mut d, &mut now, k1 | k2 | k4 | k5, 300, &mut ev);
        assert_eq!(events_only(&ev), [KeyEvent::Press(Key::Digit(1))]);
        assert_eq!(d.held(), k1);
        // 4 is let go: the scan is trusted again and 2 counts once it is stable.
        hold(&mut d, &mut now, k1 | k2, 50, &mut ev);
        hold(&mut d, &mut now, 0, 50, &mut ev);
        assert_eq!(
            events_only(&ev),
            [
                KeyEvent::Press(Key::Digit(1)),
                KeyEvent::Press(Key::Digit(2)),
                KeyEvent::Release(Key::Digit(1)),
                KeyEvent::Release(Key::Digit(2)),
            ]
        );
    }

    #[test]
    fn navigation_keys_repeat_on_time_and_others_do_not() {
        let (mut d, mut now, mut ev) = (KeypadDecoder::new(), 0, Vec::new());
        hold(&mut d, &mut now, bit(Key::B), 1_000, &mut ev);
        let press_at = KEYPAD_DEBOUNCE_MS;
        let expected: Vec<(u32, KeyEvent)> = core::iter::once((press_at, KeyEvent::Press(Key::B)))
            .chain(
                (0..)
                    .map(|n| press_at + KEYPAD_REPEAT_DELAY_MS + n * KEYPAD_REPEAT_PERIOD_MS)
                    .take_while(|&t| t < 1_000)
                    .map(|t| (t, KeyEvent::Repeat(Key::B))),
            )
            .collect();
        assert_eq!(ev, expected);
        assert_eq!(ev.len(), 1 + 5, "press, then repeats at 515, 615, 715, 815, 915 ms");

        let (mut d, mut now, mut ev) = (KeypadDecoder::new(), 0, Vec::new());
        hold(&mut d, &mut now, bit(Key::Digit(8)), 2_000, &mut ev);
        assert_eq!(events_only(&ev), [KeyEvent::Press(Key::Digit(8))]);
    }

    #[test]
    fn no_repeat_burst_after_a_blocked_period() {
        let a = bit(Key::A);
        let (mut d, mut now, mut ev) = (KeypadDecoder::new(), 0, Vec::new());
        hold(&mut d, &mut now, a, 600, &mut ev);
        assert_eq!(ev.len(), 2, "press and one repeat: {ev:?}");
        // The scanning task stalls for two seconds (20 repeat periods) ...
        now += 2_000;
        ev.clear();
        hold(&mut d, &mut now, a, KEYPAD_REPEAT_PERIOD_MS, &mut ev);
        // ... and catches up with exactly one repeat, the next a full period later.
        assert_eq!(events_only(&ev), [KeyEvent::Repeat(Key::A)]);
        ev.clear();
        // A ghost pattern blocks the keypad for a second: no repeats, and none owed afterwards.
        hold(&mut d, &mut now, 0xFFFF, 1_000, &mut ev);
        assert!(ev.is_empty());
        hold(&mut d, &mut now, a, 2 * KEYPAD_REPEAT_PERIOD_MS, &mut ev);
        assert_eq!(events_only(&ev), [KeyEvent::Repeat(Key::A), KeyEvent::Repeat(Key::A)]);
        assert_eq!(ev[1].0 - ev[0].0, KEYPAD_REPEAT_PERIOD_MS);
    }

    #[test]
    fn no_repeat_once_the_key_reads_up() {
        let a = bit(Key::A);
        let (mut d, mut now, mut ev) = (KeypadDecoder::new(), 0, Vec::new());
        // Press reported at 15 ms, first repeat due at 515 ms; the key is let go at 510 ms.
        hold(&mut d, &mut now, a, 510, &mut ev);
        hold(&mut d, &mut now, 0, 100, &mut ev);
        assert_eq!(events_only(&ev), [KeyEvent::Press(Key::A), KeyEvent::Release(Key::A)]);
    }

    #[test]
    fn a_new_press_takes_over_the_repeat() {
        let (a, b) = (bit(Key::A), bit(Key::B));
        let (mut d, mut now, mut ev) = (KeypadDecoder::new(), 0, Vec::new());
        hold(&mut d, &mut now, a, 300, &mut ev);
        hold(&mut d, &mut now, a | b, 600, &mut ev);
        let repeats: Vec<KeyEvent> =
            events_only(&ev).into_iter().filter(|e| matches!(e, KeyEvent::Repeat(_))).collect();
        assert_eq!(repeats, [KeyEvent::Repeat(Key::B)], "B repeats once (at 815 ms), A no more");
        ev.clear();
        // A stays down but B's release ends all repeating.
        hold(&mut d, &mut now, a, 1_000, &mut ev);
        assert_eq!(events_only(&ev), [KeyEvent::Release(Key::B)]);
    }

    #[test]
    fn time_wraps_around() {
        let a = bit(Key::A);
        let start = u32::MAX - 100;
        let (mut d, mut now, mut ev) = (KeypadDecoder::new(), start, Vec::new());
        hold(&mut d, &mut now, 0, 20, &mut ev);
        hold(&mut d, &mut now, a, 800, &mut ev);
        hold(&mut d, &mut now, 0, 50, &mut ev);
        let at = |t: u32| start.wrapping_add(t);
        assert_eq!(
            ev,
            [
                (at(35), KeyEvent::Press(Key::A)),
                (at(535), KeyEvent::Repeat(Key::A)),
                (at(635), KeyEvent::Repeat(Key::A)),
                (at(735), KeyEvent::Repeat(Key::A)),
                (at(835), KeyEvent::Release(Key::A)),
            ]
        );
    }

    proptest::proptest! {
        /// Whatever the contacts do, each key's events read Press, Repeat*, Release, ..., only
        /// navigation keys repeat, and the held set never exceeds the key limit.
        #[test]
        fn events_are_well_formed(scans in proptest::collection::vec((0u16..=0xFFFF, 1u32..40), 1..300)) {
            let mut d = KeypadDecoder::new();
            let mut now = 0u32;
            let mut down = [false; 16];
            for (raw, dt) in scans {
                // Mostly few keys, as real hands press.
                let raw = if raw.count_ones() > 3 { raw & 0x0421 } else { raw };
                for e in d.update(raw, now) {
                    let (k, expect_down) = match e {
                        KeyEvent::Press(k) => (k, false),
                        KeyEvent::Repeat(k) => {
                            proptest::prop_assert!(k.is_navigation());
                            (k, true)
                        }
                        KeyEvent::Release(k) => (k, true),
                    };
                    let (r, c) = row_col(k).unwrap();
                    proptest::prop_assert_eq!(down[r * 4 + c], expect_down, "{:?}", e);
                    down[r * 4 + c] = !matches!(e, KeyEvent::Release(_));
                }
                proptest::prop_assert!(d.held().count_ones() <= KEYPAD_MAX_KEYS);
                now = now.wrapping_add(dt);
            }
        }
    }
}

//! A simulated 4x4 key matrix without diodes, pressed by a script in virtual time.
//!
//! Columns are driven low one at a time by the scan task; a row reads low when a chain of pressed
//! keys connects it to a low column. Three keys on the corners of a rectangle therefore make the
//! fourth appear, as on the real keypad.
//!
//! The board's columns are open-drain: a column not driven low is released and drives nothing.
//! A push-pull column ([`KeyMatrix::push_pull_column`]) drives high instead; keys that join it to
//! a low column short the two outputs, which the model counts ([`KeyMatrix::shorts_seen`]), and a
//! row caught between them reads high (a level between the two, not a press).

use std::cell::RefCell;
use std::rc::Rc;
use std::string::String;
use std::vec::Vec;

use crate::sim::clock;

/// Key legends by row and column, as printed on the keypad.
pub const KEY_LEGENDS: [[char; 4]; 4] =
    [['1', '2', '3', 'A'], ['4', '5', '6', 'B'], ['7', '8', '9', 'C'], ['*', '0', '#', 'D']];

/// How long a scripted key stays down, and the pause after it, unless the script says otherwise.
pub const SCRIPT_PRESS_MS: u64 = 80;
pub const SCRIPT_GAP_MS: u64 = 80;

/// A keypad script: from each instant on, the pressed keys (bit `row * 4 + col`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct KeyScript {
    pub events: Vec<(u64, u16)>,
}

impl KeyScript {
    /// Parses a script: whitespace-separated tokens, each a key legend (`1`, `#`, `A`, ...) pressed
    /// briefly, `KEY:MS` to hold a key MS milliseconds, or `wait:MS` to pause. Lines starting with
    /// `//` are comments.
    pub fn parse(text: &str) -> Result<KeyScript, String> {
        let mut t_ms = 0u64;
        let mut events = Vec::new();
        for token in text.lines().filter(|l| !l.trim_start().starts_with("//")).flat_map(str::split_whitespace) {
            let (name, hold_ms) = match token.split_once(':') {
                Some((n, ms)) => (n, ms.parse::<u64>().map_err(|_| std::format!("bad time in `{token}`"))?),
                None => (token, SCRIPT_PRESS_MS),
            };
            if name.eq_ignore_ascii_case("wait") {
                // The script lasts to the end of the wait: no key is down then.
                t_ms += hold_ms;
                events.push((t_ms * 1000, 0));
                continue;
            }
            let mut chars = name.chars();
            let (Some(c), None) = (chars.next(), chars.next()) else {
                return Err(std::format!("unknown key `{name}`"));
            };
            let c = c.to_ascii_uppercase();
            let bit =
                (0..16).find(|i| KEY_LEGENDS[i / 4][i % 4] == c).ok_or_else(|| std::format!("unknown key `{name}`"))?;
            events.push((t_ms * 1000, 1u16 << bit));
            t_ms += hold_ms;
            events.push((t_ms * 1000, 0));
            t_ms += SCRIPT_GAP_MS;
        }
        Ok(KeyScript { events })
    }

    /// Keys pressed at virtual time `t_us`.
    pub fn pressed_at(&self, t_us: u64) -> u16 {
        self.events.iter().take_while(|(t, _)| *t <= t_us).last().map_or(0, |(_, k)| *k)
    }

    /// When the last scripted change happens.
    pub fn end_us(&self) -> u64 {
        self.events.last().map_or(0, |(t, _)| *t)
    }
}

#[derive(Debug, Default)]
struct MatrixState {
    script: KeyScript,
    /// When the script's time zero is, once it has started.
    started_at_us: Option<u64>,
    /// Columns driven low, bit per column.
    low_columns: u8,
    /// Push-pull columns driven high, bit per column.
    high_columns: u8,
    /// Rows read while joined to a low and a high column.
    shorts_seen: u32,
}

/// The key matrix shared by its column and row pins.
#[derive(Clone, Default)]
pub struct KeyMatrix {
    state: Rc<RefCell<MatrixState>>,
}

impl KeyMatrix {
    /// A matrix whose script starts at once.
    pub fn new(script: KeyScript) -> Self {
        let m = Self::waiting(script);
        m.start();
        m
    }

    /// A matrix whose script waits for [`KeyMatrix::start`].
    pub fn waiting(script: KeyScript) -> Self {
        KeyMatrix { state: Rc::new(RefCell::new(MatrixState { script, ..MatrixState::default() })) }
    }

    /// Starts the script now, unless it has started already.
    pub fn start(&self) {
        let mut s = self.state.borrow_mut();
        s.started_at_us.get_or_insert(clock::now_ticks());
    }

    pub fn started(&self) -> bool {
        self.state.borrow().started_at_us.is_some()
    }

    /// An open-drain column output, as the board's: low, or released.
    pub fn column(&self, col: u8) -> ColumnPin {
        ColumnPin { matrix: self.clone(), col, push_pull: false }
    }

    /// A push-pull column output, driven high (as it starts) or low.
    pub fn push_pull_column(&self, col: u8) -> ColumnPin {
        self.state.borrow_mut().high_columns |= 1 << col;
        ColumnPin { matrix: self.clone(), col, push_pull: true }
    }

    /// How many row reads found a column driven low joined to one driven high.
    pub fn shorts_seen(&self) -> u32 {
        self.state.borrow().shorts_seen
    }

    pub fn row(&self, row: u8) -> RowPin {
        RowPin { matrix: self.clone(), row }
    }

    /// True once the script has played to its end.
    pub fn script_done(&self) -> bool {
        let s = self.state.borrow();
        s.started_at_us.is_some_and(|t0| clock::now_ticks() >= t0 + s.script.end_us())
    }

    fn row_is_low(&self, row: u8) -> bool {
        let mut s = self.state.borrow_mut();
        let pressed = s.started_at_us.map_or(0, |t0| s.script.pressed_at(clock::now_ticks().saturating_sub(t0)));
        // Rows and columns joined by pressed keys conduct: grow the set reachable from `row`.
        let (mut rows, mut cols) = (1u8 << row, 0u8);
        loop {
            let (r0, c0) = (rows, cols);
            for i in 0..16 {
                if pressed & (1 << i) != 0 {
                    let (r, c) = (i / 4, i % 4);
                    if rows & (1 << r) != 0 || cols & (1 << c) != 0 {
                        rows |= 1 << r;
                        cols |= 1 << c;
                    }
                }
            }
            if (rows, cols) == (r0, c0) {
                break;
            }
        }
        let low = cols & s.low_columns != 0;
        if low && cols & s.high_columns != 0 {
            s.shorts_seen += 1;
            return false;
        }
        low
    }
}

/// A column output of the matrix.
pub struct ColumnPin {
    matrix: KeyMatrix,
    col: u8,
    /// Driven high when not low (else released).
    push_pull: bool,
}

impl embedded_hal::digital::ErrorType for ColumnPin {
    type Error = core::convert::Infallible;
}

impl embedded_hal::digital::OutputPin for ColumnPin {
    fn set_low(&mut self) -> Result<(), Self::Error> {
        let mut s = self.matrix.state.borrow_mut();
        s.low_columns |= 1 << self.col;
        s.high_columns &= !(1 << self.col);
        Ok(())
    }

    fn set_high(&mut self) -> Result<(), Self::Error> {
        let mut s = self.matrix.state.borrow_mut();
        s.low_columns &= !(1 << self.col);
        if self.push_pull {
            s.high_columns |= 1 << self.col;
        }
        Ok(())
    }
}

/// A row input of the matrix, pulled up.
pub struct RowPin {
    matrix: KeyMatrix,
    row: u8,
}

impl embedded_hal::digital::ErrorType for RowPin {
    type Error = core::convert::Infallible;
}

impl embedded_hal::digital::InputPin for RowPin {
    fn is_high(&mut self) -> Result<bool, Self::Error> {
        Ok(!self.matrix.row_is_low(self.row))
    }

    fn is_low(&mut self) -> Result<bool, Self::Error> {
        Ok(self.matrix.row_is_low(self.row))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use embedded_hal::digital::{InputPin, OutputPin};

    #[test]
    fn a_script_presses_and_releases_keys_in_time() {
        let s = KeyScript::parse("1 #:200 wait:50 d").unwrap();
        assert_eq!(s.pressed_at(0), 1 << 0);
        assert_eq!(s.pressed_at(80_000), 0);
        assert_eq!(s.pressed_at(160_000), 1 << 14);
        assert_eq!(s.pressed_at(359_999), 1 << 14);
        assert_eq!(s.pressed_at(360_000), 0);
        assert_eq!(s.pressed_at(490_000), 1 << 15);
        assert_eq!(KeyScript::parse("1 wait:2000").unwrap().end_us(), 2_160_000, "a wait at the end counts");
        assert!(KeyScript::parse("E").is_err());
        assert!(KeyScript::parse("1:x").is_err());
    }

    #[test]
    fn three_keys_on_a_rectangle_ghost_the_fourth() {
        clock::reset();
        // Keys 1 (r0c0), 2 (r0c1) and 4 (r1c0) pressed: driving column 1 also pulls row 1 low.
        let m = KeyMatrix::new(KeyScript { events: std::vec![(0, 0b1_0011)] });
        let (mut col1, mut row1) = (m.column(1), m.row(1));
        col1.set_low().unwrap();
        assert!(row1.is_low().unwrap());
        col1.set_high().unwrap();
        assert!(row1.is_high().unwrap());
    }

    /// One pass over the matrix as the keypad task makes it: each column driven low in turn,
    /// the rows read, the column let go.
    fn scan(columns: &mut [ColumnPin; 4], rows: &mut [RowPin; 4]) -> u16 {
        let mut raw = 0;
        for (c, column) in columns.iter_mut().enumerate() {
            column.set_low().unwrap();
            for (r, row) in rows.iter_mut().enumerate() {
                if row.is_low().unwrap() {
                    raw |= 1 << (r * 4 + c);
                }
            }
            column.set_high().unwrap();
        }
        raw
    }

    #[test]
    fn two_keys_of_one_row_read_as_both_with_open_drain_columns_and_short_push_pull_ones() {
        use crate::panel::keypad::{Key, KeyEvent, KeypadDecoder};
        clock::reset();
        // Keys 1 (row 0, column 0) and 2 (row 0, column 1) held together.
        let both = KeyScript { events: std::vec![(0, 0b11)] };
        let open = KeyMatrix::new(both.clone());
        let (mut columns, mut rows) = ([0, 1, 2, 3].map(|c| open.column(c)), [0, 1, 2, 3].map(|r| open.row(r)));
        let mut decoder = KeypadDecoder::new();
        let mut events = std::vec::Vec::new();
        for scan_ms in (0..60).step_by(5) {
            events.extend(decoder.update(scan(&mut columns, &mut rows), scan_ms));
        }
        assert_eq!(events, [KeyEvent::Press(Key::Digit(1)), KeyEvent::Press(Key::Digit(2))]);
        assert_eq!(open.shorts_seen(), 0);

        // Push-pull columns: the column scanned low is joined through the two keys to one
        // driven high; the row reads neither level and both keys are lost.
        let push_pull = KeyMatrix::new(both);
        let (mut columns, mut rows) =
            ([0, 1, 2, 3].map(|c| push_pull.push_pull_column(c)), [0, 1, 2, 3].map(|r| push_pull.row(r)));
        assert_eq!(scan(&mut columns, &mut rows), 0);
        assert_eq!(push_pull.shorts_seen(), 2, "one short per column scanned with a key down");
    }
}

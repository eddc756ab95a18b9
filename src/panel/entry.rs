//! Number entry on the keypad: the text of one field being typed, and its value.
//!
//! Digits append, `*` is the decimal point, `A` toggles the sign, `B` deletes the last
//! character. The text is bounded ([`ENTRY_MAX_CHARS`]); the value is parsed without floating
//! point formatting code and only when the field is confirmed. This module knows nothing of
//! ranges or units (the menu's field specs do).

use heapless::String;

use crate::panel::keypad::Key;

/// Most characters (digits and the decimal point, not the sign) a field holds:
/// enough for `1000.000` and `-500.000`.
pub const ENTRY_MAX_CHARS: usize = 8;

/// Why typed text is not a number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum EntryError {
    /// The field is full.
    TooLong,
    /// Only a decimal point was typed.
    NotANumber,
}

/// The text of one field: an optional minus sign, digits and at most one decimal point.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct NumberEntry {
    negative: bool,
    text: String<ENTRY_MAX_CHARS>,
}

impl NumberEntry {
    pub const fn new() -> Self {
        NumberEntry { negative: false, text: String::new() }
    }

    /// True when nothing, not even a sign, was typed.
    pub fn is_empty(&self) -> bool {
        self.text.is_empty() && !self.negative
    }

    /// Empties the field.
    pub fn clear(&mut self) {
        *self = NumberEntry::new();
    }

    /// True when the value will be negative.
    pub fn is_negative(&self) -> bool {
        self.negative
    }

    /// The digits and decimal point, without the sign.
    pub fn digits(&self) -> &str {
        &self.text
    }

    /// Appends a digit (0..=9). A lone leading zero is replaced rather than kept.
    pub fn push_digit(&mut self, digit: u8) -> Result<(), EntryError> {
        if digit > 9 {
            return Ok(());
        }
        if self.text.as_str() == "0" {
            self.text.clear();
        }
        self.text.push((b'0' + digit) as char).map_err(|_| EntryError::TooLong)
    }

    /// Appends the decimal point (a second one is ignored); a leading point becomes `0.`.
    pub fn push_point(&mut self) -> Result<(), EntryError> {
        if self.text.bytes().any(|b| b == b'.') {
            return Ok(());
        }
        let needed = if self.text.is_empty() { 2 } else { 1 };
        if self.text.len() + needed > ENTRY_MAX_CHARS {
            return Err(EntryError::TooLong);
        }
        if self.text.is_empty() {
            self.text.push('0').map_err(|_| EntryError::TooLong)?;
        }
        self.text.push('.').map_err(|_| EntryError::TooLong)
    }

    /// Flips the sign.
    pub fn toggle_sign(&mut self) {
        self.negative = !self.negative;
    }

    /// Deletes the last character, then the sign. Returns false when there was nothing to delete.
    pub fn backspace(&mut self) -> bool {
        if self.text.pop().is_some() {
            true
        } else if self.negative {
            self.negative = false;
            true
        } else {
            false
        }
    }

    /// Takes a key of the number keys: digits, `*`, `A` (sign), `B` (delete), `C` (clear).
    /// Returns false for `B` on an empty entry (nothing to delete), true otherwise.
    pub fn press(&mut self, key: Key) -> Result<bool, EntryError> {
        match key {
            Key::Digit(d) => self.push_digit(d)?,
            Key::Star => self.push_point()?,
            Key::A => self.toggle_sign(),
            Key::B => return Ok(self.backspace()),
            Key::C => self.clear(),
            Key::D | Key::Hash => {}
        }
        Ok(true)
    }

    /// The typed value; `Ok(None)` when the field is empty.
    pub fn value(&self) -> Result<Option<f32>, EntryError> {
        if self.is_empty() {
            return Ok(None);
        }
        // At most ENTRY_MAX_CHARS digits: the mantissa fits a u32.
        let mut mantissa: u32 = 0;
        let mut decimals: i32 = 0;
        let mut any_digit = false;
        let mut after_point = false;
        for ch in self.text.chars() {
            match ch {
                '.' => after_point = true,
                '0'..='9' => {
                    mantissa = mantissa.saturating_mul(10).saturating_add(ch as u32 - '0' as u32);
                    any_digit = true;
                    if after_point {
                        decimals += 1;
                    }
                }
                _ => return Err(EntryError::NotANumber),
            }
        }
        if !any_digit {
            return Err(EntryError::NotANumber);
        }
        // 10^decimals is exact in f32 for every count an entry can hold, so the quotient is the
        // f32 nearest the typed number.
        let scale = (0..decimals).fold(1.0f32, |scale, _| scale * 10.0);
        let magnitude = mantissa as f32 / scale;
        Ok(Some(if self.negative { -magnitude } else { magnitude }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn typed(keys: &str) -> NumberEntry {
        let mut e = NumberEntry::new();
        for ch in keys.chars() {
            match ch {
                '0'..='9' => {
                    let _ = e.push_digit(ch as u8 - b'0');
                }
                '*' => {
                    let _ = e.push_point();
                }
                'A' => e.toggle_sign(),
                'B' => {
                    e.backspace();
                }
                _ => unreachable!(),
            }
        }
        e
    }

    #[test]
    fn digits_point_sign_and_backspace() {
        assert_eq!(typed("").value(), Ok(None));
        assert_eq!(typed("12*5").value(), Ok(Some(12.5)));
        assert_eq!(typed("*25").value(), Ok(Some(0.25)));
        assert_eq!(typed("*25").digits(), "0.25");
        assert_eq!(typed("1*2*3").value(), Ok(Some(1.23)), "a second point is ignored");
        assert_eq!(typed("A7").value(), Ok(Some(-7.0)));
        assert_eq!(typed("7AA").value(), Ok(Some(7.0)));
        assert_eq!(typed("123B4").value(), Ok(Some(124.0)));
        assert_eq!(typed("A5BB").value(), Ok(None), "backspace removes the digit, then the sign");
        assert_eq!(typed("007").digits(), "7");
        assert_eq!(typed("*B").value(), Ok(Some(0.0)), "`0.` less the point is 0");
        assert_eq!(typed("A").value(), Err(EntryError::NotANumber));
    }

    #[test]
    fn the_field_is_bounded() {
        let mut e = typed("1234567");
        assert_eq!(e.push_digit(8), Ok(()));
        assert_eq!(e.push_digit(9), Err(EntryError::TooLong));
        assert_eq!(e.push_point(), Err(EntryError::TooLong));
        assert_eq!(e.value(), Ok(Some(12_345_678.0)));
        assert_eq!(typed("*1234567").digits(), "0.123456");
    }
}

//! Typing a function y = f(x) on 16 keys. Digits and `*` (the decimal point) type themselves;
//! every other token of the expression language (x, the operators, parentheses, the functions,
//! pi) comes from a wheel: `A` turns it back, `B` on (as they move up and down the menu's lists),
//! `C` puts its token. `D` deletes the last character, or a whole function name with its
//! parenthesis. The text goes to the host link's parser
//! ([`crate::motion::expr`]), so a typed function is the very expression a sender would send, and is
//! refused with the same column-numbered errors.

use heapless::String;

use crate::motion::expr::{ParseError, ParseErrorKind};
use crate::panel::keypad::Key;

/// Longest expression typed on the keypad.
pub const EXPR_ENTRY_MAX_CHARS: usize = 40;

/// The wheel's tokens, the most used first; `B` steps on through them, `A` back, and both wrap.
pub const EXPR_TOKENS: [&str; 25] = [
    "x", "(", ")", "+", "-", "*", "/", "^", "sin(", "cos(", "sqrt(", "exp(", "ln(", "abs(", "tan(", "pi", "asin(",
    "acos(", "atan(", "log10(", "floor(", "ceil(", "min(", "max(", ",",
];

/// The expression being typed and the wheel's position.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ExprEntry {
    text: String<EXPR_ENTRY_MAX_CHARS>,
    wheel: usize,
}

impl ExprEntry {
    /// Starts from `text` (a preset's, to change it); a text too long starts empty.
    pub fn new(text: &str) -> Self {
        let mut entry = ExprEntry::default();
        let _ = entry.text.push_str(text);
        entry
    }

    pub fn text(&self) -> &str {
        &self.text
    }

    /// The token `C` puts.
    pub fn token(&self) -> &'static str {
        EXPR_TOKENS[self.wheel % EXPR_TOKENS.len()]
    }

    /// Takes a key: digits, `*`, `A`/`B` (turn the wheel back/on), `C` (put its token), `D`
    /// (delete). Returns false for `D` on an empty text (nothing to delete), true otherwise; `#`
    /// is the form's. A full text refuses more as the parser refuses a text too long.
    pub fn press(&mut self, key: Key) -> Result<bool, ParseError> {
        let put = match key {
            Key::Digit(d) => self.text.push(char::from(b'0' + d % 10)),
            Key::Star => self.text.push('.'),
            Key::C => self.text.push_str(self.token()),
            Key::A => {
                self.wheel = (self.wheel + EXPR_TOKENS.len() - 1) % EXPR_TOKENS.len();
                Ok(())
            }
            Key::B => {
                self.wheel = (self.wheel + 1) % EXPR_TOKENS.len();
                Ok(())
            }
            Key::D => return Ok(self.delete()),
            Key::Hash => Ok(()),
        };
        put.map(|()| true).map_err(|_| ParseError { kind: ParseErrorKind::TooLong, pos: self.text.len() })
    }

    /// Deletes the last character; after a `(`, the function name before it too.
    fn delete(&mut self) -> bool {
        let bytes = self.text.as_bytes();
        let Some(mut keep) = bytes.len().checked_sub(1) else { return false };
        if bytes[keep] == b'(' {
            while keep > 0 && bytes[keep - 1].is_ascii_alphanumeric() {
                keep -= 1;
            }
        }
        self.text.truncate(keep);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Presses `keys` (spaces ignored) on `entry`: digits, `*`, `A`, `B`, `C`, `D`.
    fn press(entry: &mut ExprEntry, keys: &str) -> Result<(), ParseError> {
        for c in keys.chars().filter(|c| !c.is_whitespace()) {
            let key = match c {
                '0'..='9' => Key::Digit(c as u8 - b'0'),
                '*' => Key::Star,
                'A' => Key::A,
                'B' => Key::B,
                'C' => Key::C,
                'D' => Key::D,
                _ => panic!("no key {c}"),
            };
            entry.press(key)?;
        }
        Ok(())
    }

    /// The keys that turn the wheel on from where it stands to `token` and put it.
    fn put(entry: &ExprEntry, token: &str) -> String<32> {
        let mut keys = String::new();
        let mut probe = entry.clone();
        while probe.token() != token {
            probe.press(Key::B).unwrap();
            keys.push('B').unwrap();
        }
        keys.push('C').unwrap();
        keys
    }

    #[test]
    fn a_function_is_typed_from_digits_and_the_wheel_and_parses() {
        let mut e = ExprEntry::new("");
        for part in ["2", "0", "*", "exp(", "-", "x", "^", "2", "/", "2", "0", "0", ")"] {
            let keys =
                if part.bytes().all(|b| b.is_ascii_digit()) { String::try_from(part).unwrap() } else { put(&e, part) };
            press(&mut e, &keys).unwrap();
        }
        assert_eq!(e.text(), "20*exp(-x^2/200)");
        assert!(crate::motion::expr::parse(e.text()).is_ok());
        // * types the decimal point.
        press(&mut e, "D D D D D D 1 * 5").unwrap();
        let close = put(&e, ")");
        press(&mut e, &close).unwrap();
        assert_eq!(e.text(), "20*exp(-x^1.5)");
    }

    #[test]
    fn delete_takes_a_function_name_with_its_parenthesis() {
        let mut e = ExprEntry::new("2*sqrt(");
        press(&mut e, "D").unwrap();
        assert_eq!(e.text(), "2*");
        press(&mut e, "D D").unwrap();
        assert_eq!(e.text(), "");
        assert_eq!(e.press(Key::D), Ok(false), "nothing left to delete");
        let mut e = ExprEntry::new("(x+1)*(");
        press(&mut e, "D").unwrap();
        assert_eq!(e.text(), "(x+1)*");
    }

    #[test]
    fn a_full_text_refuses_more_as_the_parser_refuses_a_long_one() {
        let mut e = ExprEntry::new("");
        press(&mut e, &"1".repeat(EXPR_ENTRY_MAX_CHARS)).unwrap();
        let too_long = ParseError { kind: ParseErrorKind::TooLong, pos: EXPR_ENTRY_MAX_CHARS };
        assert_eq!(e.press(Key::Digit(2)), Err(too_long));
        assert_eq!(e.text().len(), EXPR_ENTRY_MAX_CHARS);
        // The wheel wraps.
        for _ in 0..EXPR_TOKENS.len() {
            e.press(Key::B).unwrap();
        }
        assert_eq!(e.token(), "x");
    }

    #[test]
    fn the_wheel_turns_both_ways() {
        let mut e = ExprEntry::new("");
        press(&mut e, "B B B").unwrap();
        assert_eq!(e.token(), "+");
        press(&mut e, "A").unwrap();
        assert_eq!(e.token(), ")");
        // Back from the first token to the last: `,` is one key away from `x`.
        press(&mut e, "A A A").unwrap();
        assert_eq!(e.token(), ",");
        press(&mut e, "C B C").unwrap();
        assert_eq!(e.text(), ",x");
    }
}

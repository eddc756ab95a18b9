//! Every text the LCD shows, in English and in 中文: the [`Msg`] of each, and [`Say`], its
//! text in a [`Language`]. The texts are written in `src/panel/texts.txt`; build.rs makes the
//! tables of this module from it, each language's texts as one run of bytes, and renders the
//! Chinese characters they use from u8g2's 7x7 GB2312 font (a font crate's, subset to these
//! texts: about 1 KB where the whole font is 100 KB).
//!
//! In the tables a Chinese character is the number of its glyph in [`GLYPHS_7X7`]: one byte
//! for the 128 most used, two for the others; and each byte value no text uses stands for a
//! pair of bytes used often (pairs nest). On the screen's lines a Chinese character is the
//! character [`HANZI_FIRST`] + k: two bytes in UTF-8, as it takes two columns on the screen, so
//! a line's length in bytes is its width in columns in either language.

use core::fmt::{self, Write};

use crate::host::GrblError;
use crate::motion::drawing::DrawError;
use crate::motion::expr::{EvalError, ParseErrorKind};
use crate::motion::interp::CurveError;
use crate::panel::language::Language;

include!(concat!(env!("OUT_DIR"), "/texts.rs"));

/// A text in a language, for format strings: `write!(out, "{} {}", Say(Msg::Range, lang), n)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Say(pub Msg, pub Language);

impl Say {
    /// The text's bytes as the tables keep them.
    fn bytes(self) -> &'static [u8] {
        let (all, lengths): (&[u8], &[u8]) = match self.1 {
            Language::English => (&ENGLISH, &ENGLISH_LENGTHS),
            Language::Chinese => (&CHINESE, &CHINESE_LENGTHS),
        };
        // The texts before it: a few hundred additions, at the LCD's pace.
        let (before, this) = lengths.split_at(self.0 as usize);
        let start: usize = before.iter().map(|&n| usize::from(n)).sum();
        let end = start + this.first().map_or(0, |&n| usize::from(n));
        all.get(start..end).unwrap_or_default()
    }

    /// Its characters: ASCII, or the character standing for a Chinese glyph.
    fn chars(self) -> impl Iterator<Item = char> {
        let mut bytes = self.bytes().iter();
        // The bytes pair codes stand for, still to come, the next last.
        let mut pending = [0u8; PAIR_DEPTH + 1];
        let mut waiting = 0;
        core::iter::from_fn(move || {
            loop {
                let b = match waiting {
                    0 => *bytes.next()?,
                    _ => {
                        waiting -= 1;
                        pending[waiting]
                    }
                };
                let glyph = match b {
                    HANZI_ESCAPE => HANZI_ONE_BYTE + usize::from(*bytes.next()?),
                    0x80.. => usize::from(b - 0x80),
                    _ if PAIR_CODES.contains(&b) => {
                        let [first, second] = PAIRS[usize::from(b - PAIR_CODES.start())];
                        *pending.get_mut(waiting)? = second;
                        *pending.get_mut(waiting + 1)? = first;
                        waiting += 2;
                        continue;
                    }
                    _ => return Some(char::from(b)),
                };
                return char::from_u32(HANZI_FIRST as u32 + glyph as u32);
            }
        })
    }

    /// How many columns it takes on the screen: two a Chinese character.
    pub fn columns(self) -> usize {
        self.chars().map(char::len_utf8).sum()
    }
}

impl fmt::Display for Say {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.chars().try_for_each(|c| f.write_char(c))
    }
}

/// Why an expression was refused, after its column: on the LCD, and in English on the host
/// link.
impl From<ParseErrorKind> for Msg {
    fn from(kind: ParseErrorKind) -> Msg {
        match kind {
            ParseErrorKind::UnexpectedChar => Msg::ExprUnexpectedChar,
            ParseErrorKind::UnexpectedEnd => Msg::ExprUnexpectedEnd,
            ParseErrorKind::UnknownName => Msg::ExprUnknownName,
            ParseErrorKind::MismatchedParen => Msg::ExprParen,
            ParseErrorKind::TooLong => Msg::ExprTooLong,
            ParseErrorKind::TooComplex => Msg::ExprTooComplex,
            ParseErrorKind::WrongArgCount => Msg::ExprArgCount,
            ParseErrorKind::NumberOutOfRange => Msg::ExprNumber,
        }
    }
}

/// Why a function cannot be evaluated: on the LCD (the host link says it at length, with
/// [`EvalError::message`]).
impl From<EvalError> for Msg {
    fn from(e: EvalError) -> Msg {
        match e {
            EvalError::SqrtOfNegative => Msg::EvalSqrt,
            EvalError::LogOfNonPositive => Msg::EvalLog,
            EvalError::ArcOutOfRange => Msg::EvalArc,
            EvalError::PowerOfNegative => Msg::EvalPower,
            EvalError::TanPole => Msg::EvalTan,
            EvalError::DivisionByZero => Msg::FaultDivision,
            EvalError::Overflow => Msg::FaultOverflow,
        }
    }
}

/// Why a drawing was refused: on the LCD.
impl From<DrawError> for Msg {
    fn from(e: DrawError) -> Msg {
        match e {
            DrawError::Travel => Msg::ErrTravel,
            DrawError::TooSteep => Msg::ErrSteep,
            DrawError::TooFine => Msg::ErrFine,
            DrawError::Imprecise => Msg::ErrImprecise,
            DrawError::BadParameter => Msg::ErrParameter,
            DrawError::Setup(_) => Msg::ErrStart,
            DrawError::Fails { error: CurveError::Jump, .. } => Msg::ErrJumps,
            DrawError::Fails { .. } => Msg::ErrUndefinedThere,
        }
    }
}

/// Why a line was refused, in words (the host link sends its number, `error:N`): on the LCD,
/// for a card file's line.
impl From<GrblError> for Msg {
    fn from(e: GrblError) -> Msg {
        match e {
            GrblError::ExpectedCommandLetter => Msg::WhyLetter,
            GrblError::BadNumberFormat => Msg::WhyNumber,
            GrblError::Expression { kind, .. } => Msg::from(kind),
            GrblError::InvalidStatement => Msg::WhyStatement,
            GrblError::NegativeValue => Msg::WhyNegative,
            GrblError::SettingDisabled => Msg::WhySettingOff,
            GrblError::NotIdle => Msg::WhyNotIdle,
            GrblError::Locked => Msg::WhyLocked,
            GrblError::LineOverflow | GrblError::LineLengthExceeded => Msg::WhyLineLong,
            GrblError::TravelExceeded => Msg::ErrTravel,
            GrblError::InvalidJog => Msg::WhyJog,
            GrblError::Unsupported => Msg::WhyUnsupported,
            GrblError::ModalGroupViolation => Msg::WhyModal,
            GrblError::UndefinedFeedRate => Msg::WhyFeed,
            GrblError::ValueNotInteger => Msg::ErrWhole,
            GrblError::AxisCommandConflict => Msg::WhyAxisConflict,
            GrblError::RepeatedWord => Msg::WhyRepeated,
            GrblError::NoAxisWords | GrblError::NoAxisWordsInPlane => Msg::WhyNoAxis,
            GrblError::InvalidLineNumber => Msg::WhyLineNumber,
            GrblError::ValueWordMissing => Msg::WhyValueMissing,
            GrblError::UnsupportedCoordSys => Msg::WhyCoordSys,
            GrblError::G53InvalidMotionMode => Msg::WhyG53,
            GrblError::AxisWordsExist => Msg::WhyAxisWords,
            GrblError::InvalidTarget => Msg::WhyArcTarget,
            GrblError::FunctionUndefined { error, .. } => Msg::from(error),
            GrblError::Drawing(e) => Msg::from(e),
            GrblError::ArcRadius => Msg::WhyArcRadius,
            GrblError::NoOffsetsInPlane => Msg::WhyArcOffsets,
            GrblError::UnusedWords => Msg::WhyUnused,
            GrblError::MaxValueExceeded => Msg::WhyTooLarge,
            GrblError::ReceiveBufferFull => Msg::WhyBufferFull,
        }
    }
}

/// `text` as a person reads it: the characters standing for Chinese glyphs turned back into
/// the Chinese characters (for tests and the simulator's logs).
#[cfg(not(target_os = "none"))]
pub fn readable(text: &str) -> std::string::String {
    text.chars()
        .map(|c| {
            let k = (c as u32).wrapping_sub(HANZI_FIRST as u32) as usize;
            HANZI.chars().nth(k).unwrap_or(c)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::panel::layout::SCREEN_COLUMNS;
    use crate::settings::SETTING_INFO;

    /// A text's length in bytes is its width in columns: one an ASCII character, two a
    /// Chinese one.
    #[test]
    fn every_text_fits_a_line_and_is_as_wide_as_it_is_long() {
        for msg in Msg::ALL {
            for language in [Language::English, Language::Chinese] {
                let text = std::format!("{}", Say(msg, language));
                assert!(!text.is_empty() && text.len() <= SCREEN_COLUMNS, "{:?} {}", msg, readable(&text));
                let columns: usize = readable(&text).chars().map(|c| if c.is_ascii() { 1 } else { 2 }).sum();
                assert_eq!((columns, Say(msg, language).columns()), (text.len(), text.len()), "{}", readable(&text));
            }
        }
    }

    /// Every text, decoded, is the file's, in the file's order.
    #[test]
    fn every_text_is_the_one_written_in_the_file() {
        let lines = include_str!("texts.txt").lines().filter(|l| !l.trim().is_empty() && !l.starts_with('#'));
        let mut count = 0;
        for (line, msg) in lines.zip(Msg::ALL) {
            let parts: std::vec::Vec<&str> = line.split(" | ").map(str::trim).collect();
            assert_eq!(parts[0], std::format!("{msg:?}"));
            assert_eq!(readable(&std::format!("{}", Say(msg, Language::English))), parts[1]);
            assert_eq!(readable(&std::format!("{}", Say(msg, Language::Chinese))), parts[2]);
            count += 1;
        }
        assert_eq!(count, Msg::ALL.len());
    }

    #[test]
    fn every_text_reads_back_in_both_languages() {
        let say = |msg, language| readable(&std::format!("{}", Say(msg, language)));
        assert_eq!(say(Msg::TitleJog, Language::English), "JOG");
        assert_eq!(say(Msg::TitleJog, Language::Chinese), "点动");
        assert_eq!(say(Msg::Setting216, Language::English), "Language 1=中文");
        assert_eq!(say(Msg::ErrSteep, Language::Chinese), "太陡: A 或 1/P 太大");
        // The least used characters take the escape.
        assert_eq!(say(Msg::Setting215, Language::Chinese), "蜂鸣器");
    }

    /// Longest setting name: "$205 " and the name fill the LCD's 20 columns.
    const SETTING_NAME_MAX_COLUMNS: usize = 15;

    #[test]
    fn every_setting_has_a_name_that_fits_and_every_name_a_setting() {
        let ids: std::vec::Vec<u16> = SETTING_INFO.iter().map(|info| info.id).collect();
        assert_eq!(ids, SETTING_NAME_IDS, "texts.txt names the settings in SETTING_INFO's order");
        for (info, &name) in SETTING_INFO.iter().zip(&SETTING_NAMES) {
            for language in [Language::English, Language::Chinese] {
                let text = std::format!("{}", Say(name, language));
                assert!(text.len() <= SETTING_NAME_MAX_COLUMNS, "${} {}", info.id, readable(&text));
            }
        }
    }
}

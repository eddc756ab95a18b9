//! Decimal numbers read from text into `f32`, and written from `f32` into text, without the core
//! library's float parsing and formatting.
//!
//! `str::parse::<f32>` and `{:.3}` work through `f64`-sized tables and big-number arithmetic
//! (kilobytes of flash); the numbers the machine reads (G-code words, expression literals) and
//! writes (positions, settings, the LCD) need far less. This module owns both: [`parse_prefix`]
//! reads one number at the start of a byte slice and says how many bytes it used, so a
//! tokenizer can go on after it; [`write_fixed`] and [`write_trimmed`] write a number with a
//! given count of decimals.
//!
//! ```text
//! number := [sign] digits ['.' [digits]] [exponent]     sign only with `Syntax::sign`
//!         | [sign] '.' digits [exponent]               (also `.5` and `2.`)
//! exponent := ('e' | 'E') ['+' | '-'] digits          only with `Syntax::exponent`
//! ```
//!
//! An `e` not followed by digits (after an optional sign) is not part of the number: `2e` reads
//! as `2` and leaves the `e` to the caller.
//!
//! # Precision
//!
//! The significant digits are gathered exactly into a `u64` integer `m` without trailing zeros
//! (the first [`DECIMAL_MANTISSA_MAX_DIGITS`]; later ones are dropped), so the number is
//! `m · 10^k`. The value is then one `f32` operation on `m` and a power of ten, `m · 10^k` or
//! `m / 10^-k`, with 10^k exact in `f32` for `|k| ≤ 10` (10^k = 2^k·5^k and 5^10 < 2^24). Before
//! it, a large `k` moves tens into `m` while `m` stays an integer (`1e15` is 10^5 · 10^10), and a
//! `k` below -10 rounds off digits of an `m` of 10 digits or more (a change below 1e-9 of `m`).
//!
//! - **Correctly rounded** (the `f32` nearest the decimal number, as `str::parse::<f32>` gives)
//!   when `m < 2^24` and `|k| ≤ 10` then: both operands are exact, so the one operation rounds
//!   once. That is every number of at most 7 significant digits whose last digit is at most 10
//!   places after the point and at most 10 places before it (`0.0000012345`, `1234567e10`).
//! - **Within 1 ulp** of the correctly rounded value (1.5 ulp of the exact number): `m` is
//!   rounded to `f32` first (more than 7 digits) or 10^k is (`|k| > 10`), not both. That is
//!   every number from 0.1 to 1e28 whatever its digits, and every number of at most 7
//!   significant digits below 1e28 whose last digit is at most 38 places after the point.
//! - **Within 2 ulp** (2.5 ulp of the exact number) otherwise: longer numbers below 0.1 with
//!   more than 10 decimals, numbers from 1e28 up, and the smallest numbers (beyond 1e-38 a
//!   second division).
//!
//! No `f64` anywhere. Numbers whose magnitude exceeds `f32::MAX` (by the rounding above, also a
//! number within 2 ulp below it), and nonzero numbers too small to be any `f32` but zero, are
//! [`DecimalError::OutOfRange`]; subnormal results are kept.

/// Significant digits gathered exactly (a `u64` holds any 19-digit integer); further digits
/// change a value by less than 1e-18 of itself and are dropped.
pub const DECIMAL_MANTISSA_MAX_DIGITS: u32 = 19;

/// Largest decimal exponent kept, in powers of ten: an exponent written larger saturates here,
/// far beyond where every nonzero number is out of range, so that its arithmetic cannot overflow.
const DECIMAL_EXPONENT_MAX_DECADES: i32 = 100_000;

/// Largest power of ten in [`POW10`]: the largest below `f32::MAX`, in decades.
const POW10_MAX_DECADES: usize = 38;

/// Largest power of ten that is exact in `f32` (5^10 < 2^24 < 5^11), in decades.
const POW10_EXACT_MAX_DECADES: i32 = 10;

/// A mantissa this large (10 digits) has more digits than an `f32` can tell apart: with a
/// small exponent its last digits are rounded off rather than dividing by an inexact power.
const MANTISSA_TRIM_MIN: u64 = 10_000_000_000;

/// 10^k for k = 0..=38, each the `f32` nearest it (exact up to 10^10).
const POW10: [f32; POW10_MAX_DECADES + 1] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20,
    1e21, 1e22, 1e23, 1e24, 1e25, 1e26, 1e27, 1e28, 1e29, 1e30, 1e31, 1e32, 1e33, 1e34, 1e35, 1e36, 1e37, 1e38,
];

/// Which optional parts a number may have.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Syntax {
    /// A leading `+` or `-` belongs to the number (G-code words); without it a sign is left to
    /// the caller (an expression's unary minus).
    pub sign: bool,
    /// An exponent `e±digits` belongs to the number (expressions); without it an `e` is left to
    /// the caller (in G-code `E` is a word letter).
    pub exponent: bool,
}

/// A number read from the start of a byte slice.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decimal {
    pub value: f32,
    /// Bytes of the slice the number used (at least 1).
    pub len_bytes: usize,
}

/// Why no number could be read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum DecimalError {
    /// The slice does not start with a number: no digit before or after the point (``, `.`,
    /// `-`, `x`, `.e5`).
    NoDigits,
    /// A well-formed number beyond `f32::MAX` in magnitude, or nonzero but nearer zero than the
    /// smallest `f32`.
    OutOfRange,
}

/// Reads the number at the start of `text` (no leading whitespace) in the given [`Syntax`].
///
/// Reading stops at the first byte that cannot continue the number; [`Decimal::len_bytes`] says
/// where. A caller that needs the whole of a token to be one number compares it with the
/// token's length.
pub fn parse_prefix(text: &[u8], syntax: Syntax) -> Result<Decimal, DecimalError> {
    let mut digits = Digits::default();
    let mut i = 0;
    let mut negative = false;
    if syntax.sign
        && let Some(&c @ (b'+' | b'-')) = text.first()
    {
        negative = c == b'-';
        i = 1;
    }
    while let Some(d) = digit(text, i) {
        digits.push(d, false);
        i += 1;
    }
    if text.get(i) == Some(&b'.') {
        i += 1;
        while let Some(d) = digit(text, i) {
            digits.push(d, true);
            i += 1;
        }
    }
    if !digits.any {
        return Err(DecimalError::NoDigits);
    }
    if syntax.exponent && matches!(text.get(i), Some(b'e' | b'E')) {
        let mut j = i + 1;
        let exp_negative = text.get(j) == Some(&b'-');
        if matches!(text.get(j), Some(b'+' | b'-')) {
            j += 1;
        }
        if digit(text, j).is_some() {
            let mut exp = 0i32;
            while let Some(d) = digit(text, j) {
                exp = (exp * 10 + i32::from(d)).min(DECIMAL_EXPONENT_MAX_DECADES);
                j += 1;
            }
            digits.exp10 = digits.exp10.saturating_add(if exp_negative { -exp } else { exp });
            i = j;
        }
    }
    let (mantissa, exp10) = digits.finish();
    let magnitude = scale(mantissa, exp10)?;
    Ok(Decimal { value: if negative { -magnitude } else { magnitude }, len_bytes: i })
}

/// The decimal digit at `text[i]`, if any.
fn digit(text: &[u8], i: usize) -> Option<u8> {
    text.get(i).filter(|c| c.is_ascii_digit()).map(|c| c - b'0')
}

/// The digits read so far: the number is `mantissa · 10^(exp10 + zeros)`.
#[derive(Default)]
struct Digits {
    /// The significant digits without trailing zeros.
    mantissa: u64,
    /// Digits in `mantissa` (leading zeros do not count).
    kept: u32,
    /// Zeros (and dropped digits) after `mantissa`, not yet multiplied in: a trailing zero
    /// never enters the mantissa, so `1.000` is the exact `1` and not `1000 / 10^3`.
    zeros: u32,
    exp10: i32,
    /// Whether any digit was seen (a lone `.` is not a number).
    any: bool,
}

impl Digits {
    /// Appends one digit; `fraction` if it is after the point.
    fn push(&mut self, d: u8, fraction: bool) {
        self.any = true;
        if fraction {
            self.exp10 = self.exp10.saturating_sub(1);
        }
        if self.mantissa == 0 && d == 0 {
            // A leading zero.
        } else if d == 0 || self.kept.saturating_add(self.zeros) >= DECIMAL_MANTISSA_MAX_DIGITS {
            // A zero waits until a nonzero digit follows; a digit beyond the mantissa's
            // capacity is dropped but keeps its place.
            self.zeros = self.zeros.saturating_add(1);
        } else {
            // kept + zeros + 1 <= 19 digits: below 10^19 < 2^64.
            for _ in 0..self.zeros {
                self.mantissa *= 10;
            }
            self.mantissa = self.mantissa * 10 + u64::from(d);
            self.kept += self.zeros + 1;
            self.zeros = 0;
        }
    }

    /// `(mantissa, exp10)` with the waiting zeros moved into the exponent.
    fn finish(&self) -> (u64, i32) {
        let zeros = i32::try_from(self.zeros).unwrap_or(i32::MAX);
        (self.mantissa, self.exp10.saturating_add(zeros))
    }
}

/// `mantissa · 10^exp10` as an `f32`, as the module documentation describes.
fn scale(mut mantissa: u64, mut exp10: i32) -> Result<f32, DecimalError> {
    if mantissa == 0 {
        return Ok(0.0);
    }
    // A large exponent: tens move into the mantissa while it stays an exact integer, so that
    // the power stays exact (1e15 is 10^5 · 10^10).
    while exp10 > POW10_EXACT_MAX_DECADES && mantissa <= u64::MAX / 10 {
        mantissa *= 10;
        exp10 -= 1;
    }
    // A small exponent: digits beyond what an f32 can tell apart are rounded off, so that the
    // power stays exact (the rounding changes the mantissa by less than 1e-9 of itself).
    while exp10 < -POW10_EXACT_MAX_DECADES && mantissa >= MANTISSA_TRIM_MIN {
        // mantissa < 10^19, far from u64::MAX.
        mantissa = crate::wide::div_rem(mantissa + 5, 10).0;
        exp10 += 1;
    }
    // Correctly rounded, exact below 2^24.
    let m = mantissa as f32;
    let k = exp10.unsigned_abs() as usize;
    let value = if exp10 >= 0 {
        // m ≥ 1, so 10^39 and beyond is out of range whatever m is.
        POW10.get(k).map_or(f32::INFINITY, |&p| m * p)
    } else if let Some(&p) = POW10.get(k) {
        m / p
    } else {
        // m < 10^19 and the smallest f32 is above 10^-46: a second division by 10^38 at most
        // (beyond it the number is zero).
        POW10.get(k - POW10_MAX_DECADES).map_or(0.0, |&p| m / POW10[POW10_MAX_DECADES] / p)
    };
    if value == 0.0 || value.is_infinite() { Err(DecimalError::OutOfRange) } else { Ok(value) }
}

/// Most decimals [`write_fixed`] writes.
pub const WRITE_MAX_DECIMALS: u8 = 6;

/// Writes `value` with exactly `decimals` decimals (at most [`WRITE_MAX_DECIMALS`]), rounded
/// to the nearest, halfway away from zero, and never as `-0.000`. The integer part is exact up
/// to 2^24 (every whole `f32` is) and rounded like the `f32` beyond; the decimals are those of
/// the `f32`'s own fraction. `nan`, `inf`, `-inf` for what is not a finite number.
pub fn write_fixed(out: &mut dyn core::fmt::Write, value: f32, decimals: u8) -> core::fmt::Result {
    let Some((negative, whole, fraction)) = split(value, decimals.min(WRITE_MAX_DECIMALS)) else {
        return out.write_str(if value.is_nan() {
            "nan"
        } else if value > 0.0 {
            "inf"
        } else {
            "-inf"
        });
    };
    let decimals = decimals.min(WRITE_MAX_DECIMALS);
    if negative && (whole != 0 || fraction != 0) {
        out.write_char('-')?;
    }
    write_digits(out, whole, 1)?;
    if decimals > 0 {
        out.write_char('.')?;
        write_digits(out, u64::from(fraction), usize::from(decimals))?;
    }
    Ok(())
}

/// Digits of the largest `u64`.
const U64_MAX_DIGITS: usize = 20;

/// Writes `value` in decimal, with leading zeros up to `min_digits` digits (at most
/// [`U64_MAX_DIGITS`]). The firmware writes every integer through here: core's integer
/// formatting and padding would cost flash for widths it never uses.
pub fn write_digits(out: &mut dyn core::fmt::Write, mut value: u64, min_digits: usize) -> core::fmt::Result {
    let mut digits = [0u8; U64_MAX_DIGITS];
    let mut start = U64_MAX_DIGITS;
    let min_start = U64_MAX_DIGITS - min_digits.clamp(1, U64_MAX_DIGITS);
    while value > 0 || start > min_start {
        start -= 1;
        let (rest, digit) = crate::wide::div_rem(value, 10);
        digits[start] = digit as u8;
        value = rest;
    }
    digits[start..].iter().try_for_each(|&d| out.write_char(char::from(b'0' + d)))
}

/// An integer, for format strings: `write!(out, "error:{}", Int(code))`. See [`write_digits`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Int(pub i64);

impl core::fmt::Display for Int {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        if self.0 < 0 {
            core::fmt::Write::write_char(f, '-')?;
        }
        write_digits(f, self.0.unsigned_abs(), 1)
    }
}

macro_rules! int_from {
    ($($t:ty),*) => {$(
        impl From<$t> for Int {
            fn from(value: $t) -> Int {
                Int(i64::from(value))
            }
        }
    )*};
}
int_from!(u8, u16, u32, i8, i16, i32);

impl From<usize> for Int {
    fn from(value: usize) -> Int {
        Int(i64::try_from(value).unwrap_or(i64::MAX))
    }
}

/// A value for format strings with up to three decimals, trailing zeros left off: `2.5`, `20`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Num(pub f32);

impl core::fmt::Display for Num {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write_trimmed(f, self.0, 0, 3)
    }
}

/// Writes `value` with at most `max_decimals` decimals, leaving off trailing zeros down to
/// `min_decimals` (`2.5` with 0 to 6 is `2.5`, `20000` is `20000`, with 3 to 6 `20000.000`).
/// Where fewer decimals read back as the same `f32` (through [`parse_prefix`]), only those are
/// written: a value typed as `182.051` is written so, not as its float's `182.050995`.
pub fn write_trimmed(
    out: &mut dyn core::fmt::Write,
    value: f32,
    min_decimals: u8,
    max_decimals: u8,
) -> core::fmt::Result {
    let max = max_decimals.min(WRITE_MAX_DECIMALS);
    if let Some(decimals) = (min_decimals..max).find(|&d| reads_back(value, d)) {
        return write_fixed(out, value, decimals);
    }
    let mut decimals = max;
    if let Some((_, _, mut fraction)) = split(value, max) {
        while decimals > min_decimals && fraction % 10 == 0 {
            fraction /= 10;
            decimals -= 1;
        }
    }
    write_fixed(out, value, decimals)
}

/// Whether `value` written with `decimals` decimals reads back as `value` itself.
fn reads_back(value: f32, decimals: u8) -> bool {
    let Some((_, whole, fraction)) = split(value, decimals) else { return false };
    let Some(mantissa) = whole.checked_mul(10u64.pow(u32::from(decimals))).map(|w| w + u64::from(fraction)) else {
        return false;
    };
    scale(mantissa, -i32::from(decimals)).unwrap_or(0.0) == value.abs()
}

/// `value` as (negative, whole part, the first `decimals` decimals as an integer), rounded to
/// the last of them; `None` if it is not finite.
fn split(value: f32, decimals: u8) -> Option<(bool, u64, u32)> {
    if !value.is_finite() {
        return None;
    }
    let scale = 10u32.pow(u32::from(decimals));
    let magnitude = value.abs();
    // Exact: every f32 at or above 2^23 is whole, and below it `trunc` and the difference are
    // exact operations.
    let whole = crate::math::trunc(magnitude);
    let fraction = magnitude - whole;
    let mut whole = whole as u64;
    let mut fraction = crate::math::round(fraction * scale as f32) as u32;
    if fraction >= scale {
        whole += 1;
        fraction -= scale;
    }
    Some((value < 0.0, whole, fraction))
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use proptest::prelude::*;
    use std::format;
    use std::string::String;

    const EXPR: Syntax = Syntax { sign: false, exponent: true };
    const SIGNED: Syntax = Syntax { sign: true, exponent: false };

    fn read(text: &str, syntax: Syntax) -> Result<(f32, usize), DecimalError> {
        parse_prefix(text.as_bytes(), syntax).map(|d| (d.value, d.len_bytes))
    }

    /// Distance in units in the last place between two finite `f32` of the same sign.
    fn ulps(a: f32, b: f32) -> u32 {
        assert_eq!(a.is_sign_negative(), b.is_sign_negative(), "{a} vs {b}");
        a.to_bits().abs_diff(b.to_bits())
    }

    #[test]
    fn reads_the_forms_of_a_number() {
        assert_eq!(read("0", EXPR), Ok((0.0, 1)));
        assert_eq!(read("42", EXPR), Ok((42.0, 2)));
        assert_eq!(read("0007", EXPR), Ok((7.0, 4)));
        assert_eq!(read("2.5", EXPR), Ok((2.5, 3)));
        assert_eq!(read(".5", EXPR), Ok((0.5, 2)));
        assert_eq!(read("2.", EXPR), Ok((2.0, 2)));
        assert_eq!(read("1.5e3", EXPR), Ok((1500.0, 5)));
        assert_eq!(read("1.5E-3", EXPR), Ok((0.0015, 6)));
        assert_eq!(read("3e+2", EXPR), Ok((300.0, 4)));
        assert_eq!(read(".5e1", EXPR), Ok((5.0, 4)));
        assert_eq!(read("2.e1", EXPR), Ok((20.0, 4)));
        assert_eq!(read("0.1", EXPR), Ok((0.1, 3)));
        assert_eq!(read("123.456", EXPR), Ok((123.456, 7)));
    }

    #[test]
    fn stops_where_the_number_ends() {
        assert_eq!(read("12+x", EXPR), Ok((12.0, 2)));
        assert_eq!(read("1.2.3", EXPR), Ok((1.2, 3)));
        assert_eq!(read("2x", EXPR), Ok((2.0, 1)));
        // An `e` without digits is the caller's.
        assert_eq!(read("2e", EXPR), Ok((2.0, 1)));
        assert_eq!(read("2e+", EXPR), Ok((2.0, 1)));
        assert_eq!(read("2e-x", EXPR), Ok((2.0, 1)));
        assert_eq!(read("2ex", EXPR), Ok((2.0, 1)));
        // Without exponents `e` is never read; without signs neither is a sign.
        assert_eq!(read("2e3", SIGNED), Ok((2.0, 1)));
        assert_eq!(read("-2", EXPR), Err(DecimalError::NoDigits));
        assert_eq!(read("1-2", SIGNED), Ok((1.0, 1)));
    }

    #[test]
    fn signs_when_the_syntax_has_them() {
        assert_eq!(read("-1.5", SIGNED), Ok((-1.5, 4)));
        assert_eq!(read("+2", SIGNED), Ok((2.0, 2)));
        assert_eq!(read("-.5", SIGNED), Ok((-0.5, 3)));
        let zero = read("-0", SIGNED).map(|(v, _)| v.to_bits());
        assert_eq!(zero, Ok((-0.0f32).to_bits()), "the sign of zero is kept");
        assert_eq!(read("--1", SIGNED), Err(DecimalError::NoDigits));
        assert_eq!(read("-", SIGNED), Err(DecimalError::NoDigits));
    }

    #[test]
    fn what_is_not_a_number() {
        for text in ["", ".", "x", "e5", ".e5", " 1", "+"] {
            assert_eq!(read(text, EXPR), Err(DecimalError::NoDigits), "{text:?}");
        }
    }

    #[test]
    fn out_of_range_both_ways() {
        assert_eq!(read("1e39", EXPR), Err(DecimalError::OutOfRange));
        assert_eq!(read("4e38", EXPR), Err(DecimalError::OutOfRange));
        assert_eq!(read("1e999999999999", EXPR), Err(DecimalError::OutOfRange));
        assert_eq!(read("1e-46", EXPR), Err(DecimalError::OutOfRange));
        assert_eq!(read("1e-99999999999", EXPR), Err(DecimalError::OutOfRange));
        assert_eq!(read(&format!("1{}", "0".repeat(39)), EXPR), Err(DecimalError::OutOfRange));
        // The largest and smallest f32 and zero with any exponent are fine.
        assert_eq!(read("3.4e38", EXPR).map(|(v, _)| ulps(v, 3.4e38) <= 2), Ok(true));
        assert_eq!(read("1.2e-38", EXPR).map(|(v, _)| v.is_normal()), Ok(true));
        assert_eq!(read("1.4e-45", EXPR), Ok((f32::from_bits(1), 7)));
        assert_eq!(read("0e99999", EXPR), Ok((0.0, 7)));
        assert_eq!(read("0.000e-99999", EXPR), Ok((0.0, 12)));
    }

    #[test]
    fn long_digit_strings_keep_their_scale() {
        let many_zeros = format!("0.{}1", "0".repeat(30));
        assert_eq!(read(&many_zeros, EXPR), Ok((1e-31, many_zeros.len())));
        let long = format!("1{}", "0".repeat(30));
        assert_eq!(read(&long, EXPR), Ok((1e30, long.len())));
        let pi = "3.14159265358979323846264338327950288";
        assert_eq!(read(pi, EXPR), Ok((core::f32::consts::PI, pi.len())));
        // Trailing zeros never enter the mantissa: `1.000…` is the exact 1.
        let one = format!("1.{}", "0".repeat(40));
        assert_eq!(read(&one, EXPR), Ok((1.0, one.len())));
    }

    #[test]
    fn short_numbers_are_correctly_rounded() {
        // Every value of at most 7 significant digits with at most 10 decimals, on a grid that
        // covers each decimal position.
        for decimals in 0..=10 {
            for m in (0..10_000_000u32).step_by(9_973).chain([1, 9_999_999, 16_777_215]) {
                let text = format!("{m}e-{decimals}");
                let want: f32 = text.parse().unwrap();
                assert_eq!(read(&text, EXPR), Ok((want, text.len())), "{text}");
            }
        }
        for k in 0..=10 {
            let text = format!("1234567e{k}");
            assert_eq!(read(&text, EXPR).map(|(v, _)| v), Ok(text.parse::<f32>().unwrap()), "{text}");
        }
    }

    proptest! {
        /// A setting typed with three decimals, as GRBL prints them, is written back so that it
        /// reads as the same value, and as typed below 4096, where an `f32` tells every
        /// thousandth apart (fewer than 2^24 digits, where the parser is exact).
        #[test]
        fn a_value_typed_with_three_decimals_is_written_as_typed(milli in 0u64..(1 << 24)) {
            let typed = format!("{}.{:03}", milli / 1000, milli % 1000);
            let (value, _) = read(&typed, SIGNED).unwrap_or((0.0, 0));
            let written = trimmed(value, 3, 6);
            prop_assert_eq!(read(&written, SIGNED).map(|r| r.0), Ok(value), "{} written as {}", typed, written);
            if milli < 4_096_000 {
                prop_assert_eq!(written, typed);
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4096))]

        /// Against the host's parsers: the precision the module documentation states, checked
        /// against the correctly rounded `f32` and the `f64` value (exact to far below an `f32`
        /// ulp).
        #[test]
        fn matches_the_host_parser(
            int in "[0-9]{0,12}",
            frac in "[0-9]{0,12}",
            exp in -40i32..30,
            with_exp in any::<bool>(),
        ) {
            if int.is_empty() && frac.is_empty() {
                // Not a number: covered by `what_is_not_a_number`.
                return Ok(());
            }
            let mut text = String::new();
            text.push_str(&int);
            if !frac.is_empty() {
                text.push('.');
                text.push_str(&frac);
            }
            if with_exp {
                text.push_str(&format!("e{exp}"));
            }
            let exact: f64 = text.parse().unwrap();
            let nearest: f32 = text.parse().unwrap();
            // The number is D · 10^shift with D its significant digits.
            let all = format!("{int}{frac}");
            let trailing = all.len() - all.trim_end_matches('0').len();
            let significant = all.trim_start_matches('0').trim_end_matches('0').len();
            let shift = (if with_exp { exp } else { 0 }) - frac.len() as i32 + trailing as i32;
            let allowed_ulps = if significant <= 7 && (-10..=10).contains(&shift) {
                0
            } else if (0.1..1e28).contains(&exact) || (significant <= 7 && shift >= -38 && exact < 1e28) {
                1
            } else {
                2
            };
            match read(&text, EXPR) {
                Ok((value, len)) => {
                    prop_assert_eq!(len, text.len());
                    prop_assert!(ulps(value, nearest) <= allowed_ulps, "{} -> {} not {}", text, value, nearest);
                    let ulp = f64::from(f32::from_bits(nearest.to_bits() + 1) - nearest);
                    let error = (f64::from(value) - exact).abs();
                    prop_assert!(error <= (f64::from(allowed_ulps) + 0.5) * ulp, "{} -> {}", text, value);
                }
                // Zero is in range; out of range are the numbers at the ends of the f32 range.
                Err(e) => {
                    prop_assert_eq!(e, DecimalError::OutOfRange);
                    prop_assert!(exact != 0.0 && (nearest.to_bits() <= 1 || nearest >= f32::MAX), "{}", text);
                }
            }
        }

        /// Signed numbers are the negation of unsigned ones and use one more byte.
        #[test]
        fn a_sign_negates(int in "[0-9]{1,9}", frac in "[0-9]{0,6}") {
            let text = if frac.is_empty() { int } else { format!("{int}.{frac}") };
            let (v, n) = read(&text, SIGNED).unwrap();
            prop_assert_eq!(read(&format!("-{text}"), SIGNED), Ok((-v, n + 1)));
            prop_assert_eq!(read(&format!("+{text}"), SIGNED), Ok((v, n + 1)));
        }
    }

    #[test]
    fn integers_are_written_like_core_writes_them() {
        for v in [0i64, 7, -7, 10, 255, 65_535, -1_000_000, i64::MAX, i64::MIN] {
            assert_eq!(format!("{}", Int(v)), format!("{v}"));
        }
        assert_eq!(format!("{}", Int::from(usize::MAX)), format!("{}", i64::MAX));
        let mut s = String::new();
        write_digits(&mut s, 42, 5).unwrap();
        write_digits(&mut s, 0, 0).unwrap();
        write_digits(&mut s, u64::MAX, 30).unwrap();
        assert_eq!(s, "00042018446744073709551615");
    }

    fn fixed(value: f32, decimals: u8) -> std::string::String {
        let mut s = std::string::String::new();
        write_fixed(&mut s, value, decimals).unwrap();
        s
    }

    fn trimmed(value: f32, min: u8, max: u8) -> std::string::String {
        let mut s = std::string::String::new();
        write_trimmed(&mut s, value, min, max).unwrap();
        s
    }

    #[test]
    fn numbers_are_written_with_the_decimals_asked_for() {
        assert_eq!(fixed(10.0, 3), "10.000");
        assert_eq!(fixed(-1234.56, 3), "-1234.560");
        assert_eq!(fixed(-0.01, 3), "-0.010");
        assert_eq!(fixed(-0.0004, 3), "0.000", "no minus zero");
        assert_eq!(fixed(0.0005, 3), "0.001", "halfway away from zero");
        assert_eq!(fixed(2.9996, 3), "3.000", "a carry into the whole part");
        assert_eq!(fixed(-2.9996, 3), "-3.000");
        assert_eq!(fixed(1_000_000.0, 3), "1000000.000");
        assert_eq!(fixed(60_000.0, 6), "60000.000000", "no float noise from scaling the whole");
        assert_eq!(fixed(12.5, 0), "13");
        assert_eq!(fixed(3.25, 9), "3.250000", "at most six decimals");
        assert_eq!(fixed(f32::NAN, 3), "nan");
        assert_eq!(fixed(f32::NEG_INFINITY, 3), "-inf");
        assert_eq!(trimmed(2.5, 0, 6), "2.5");
        assert_eq!(trimmed(20_000.0, 0, 6), "20000");
        assert_eq!(trimmed(20_000.0, 3, 6), "20000.000");
        assert_eq!(trimmed(0.02, 3, 6), "0.020");
        assert_eq!(trimmed(182.051, 3, 6), "182.051", "as typed, not the float's 182.050995");
        assert_eq!(trimmed(-0.3, 3, 6), "-0.300");
        assert_eq!(trimmed(1.2000004, 0, 3), "1.2", "nothing shorter reads back: rounded, trimmed");
        assert_eq!(trimmed(0.123456, 3, 6), "0.123456");
    }

    proptest::proptest! {
        /// What is written reads back as the nearest number with that many decimals.
        #[test]
        fn written_numbers_round_to_the_value(value in -1.0e6f32..1.0e6, decimals in 0u8..=4) {
            let text = fixed(value, decimals);
            let back: f64 = text.parse().unwrap();
            let exact = f64::from(value);
            let step = 10f64.powi(-i32::from(decimals));
            proptest::prop_assert!((back - exact).abs() <= step / 2.0 + exact.abs() * 1e-7, "{value} as {text}");
        }
    }
}

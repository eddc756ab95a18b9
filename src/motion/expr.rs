//! The expression language for function curves y = f(x): parsed once, evaluated many times.
//!
//! A source text such as `2.5*sin(2*pi*x/40) - x^2/100` is parsed into an [`Expr`], a short
//! program in reverse Polish notation held in a fixed-capacity `heapless::Vec`. Parsing checks
//! every limit up front (length, number of operations, nesting, evaluation stack depth), so
//! [`Expr::eval`] runs on a fixed array, without recursion or allocation, and cannot overflow
//! its stack. Evaluation is in `f32`, the FPU's own precision, through [`crate::math`]: about 7
//! significant digits, so a value of 100_000 steps is off by far less than a step.
//! Every domain error (sqrt of a negative, ln of zero, tan at its pole, ...) and every
//! non-finite or over-large intermediate value is an [`EvalError`], never a panic. Numbers are
//! read by [`crate::decimal`].
//!
//! Grammar (case-insensitive, ASCII whitespace ignored between tokens):
//!
//! ```text
//! expr    := term   (('+' | '-') term)*
//! term    := unary  (('*' | '/') unary)*
//! unary   := ('-' | '+') unary | power
//! power   := primary ('^' unary)?            right-associative: 2^3^2 = 2^9
//! primary := number | 'x' | 'pi' | 'e' | '(' expr ')'
//!          | f1 '(' expr ')'                 f1: sin cos tan asin acos atan sqrt abs exp ln log10 floor ceil
//!          | f2 '(' expr ',' expr ')'        f2: min max
//! number  := digits ['.' digits] [('e' | 'E') ['+' | '-'] digits]   (also `.5` and `2.`)
//! ```
//!
//! As in mathematics, `^` binds tighter than a unary minus on its left (`-x^2 = -(x^2)`) and its
//! exponent may carry its own sign (`2^-x`). There is no implicit multiplication (`2x` is an
//! error at the `x`). Angles are in radians. This module owns only the language; the curve that
//! steps along a function lives in `crate::motion::interp::function`.

mod program;

use crate::decimal::{self, DecimalError, Syntax};
use crate::math;
use heapless::Vec;
use program::{Arith, BinOp, Func1, Op};

const _: () = assert!(EXPR_MAX_CONSTS <= u8::MAX as usize, "constant indices are u8");

/// Longest accepted source text, in characters (a G-code line is at most 80 characters; the
/// keypad entry is shorter still).
pub const MAX_EXPR_LEN_CHARS: usize = 100;

/// Most operations (numbers, `x`, operators, function calls) one expression may compile to;
/// the capacity of [`Expr`]'s program (2 bytes each).
pub const EXPR_MAX_OPS: usize = 64;

/// Most distinct numbers (literals, `pi`, `e`) one expression may hold (4 bytes each). Kept
/// apart from the program so that an operation stays 2 bytes: the planner holds a copy of every
/// queued curve, so an expression's size counts many times over.
pub const EXPR_MAX_CONSTS: usize = 24;

/// Depth of the evaluation stack. Parsing computes the exact depth an expression needs and
/// refuses one that needs more, so evaluation never overflows it.
pub const EXPR_STACK_DEPTH: usize = 24;

/// Deepest nesting of parentheses, function arguments, unary signs and exponents; bounds the
/// parser's recursion.
pub const EXPR_MAX_NESTING: usize = 16;

/// Largest magnitude a literal or any intermediate or final value may have; beyond it (or on a
/// NaN or an infinity) evaluation stops with [`EvalError::Overflow`]. Far above any length on
/// the machine (millimetres or steps), and far below `f32::MAX` (3.4e38): two values within it
/// multiply to at most 1e30, so no sum, difference or product of checked values is infinite,
/// and a quotient or function that does reach infinity is caught by the same check. Above 2^24
/// (1.7e7) an `f32` no longer holds every whole number, but such intermediate values keep their
/// 7 significant digits, which is what products and quotients of them need.
pub const EXPR_MAX_MAGNITUDE: f32 = 1.0e15;

/// `tan(a)` with `|cos(a)|` below this, that is within 1e-5 rad of a pole (|tan a| > 1e5), fails
/// with [`EvalError::TanPole`] rather than returning a huge number. No `f32` is exactly at a pole:
/// the one nearest π/2 has cos ≈ -4.4e-8 and tan ≈ -2.3e7, and the spacing of `f32` numbers grows
/// with |a|, so the one nearest a pole is up to 2^-24·|a| from it. This threshold catches the
/// `f32` nearest every pole for |a| < 256 rad (spacing 1.5e-5 there) while tan(1.57) ≈ 1256 and
/// tan(1.5707) ≈ 1.04e4 still evaluate; what it refuses is beyond any travel anyway. `math::cos`
/// is accurate to 1e-10 near the poles, so the test is not blurred by its own error.
pub const TAN_POLE_MIN_COS: f32 = 1.0e-5;

/// `a^b` with an integer `b` of at most this magnitude is computed by multiplication (`x^2` is
/// `x·x`, `x^-3` is `1/(x·x·x)`): faster than the general power and exact whenever the result
/// is an `f32` (`3^4 = 81`), otherwise within 1.5 ulp; other exponents go to `math::pow`.
pub const EXPR_POW_BY_MULTIPLICATION_MAX_EXPONENT: u32 = 4;

/// What is wrong with a source text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum ParseErrorKind {
    /// A character or token that cannot stand here (`$`, `2x`, `sin x`, `(1,2)`, `()`).
    UnexpectedChar,
    /// The text ends where an operand or a name's `(` is still needed (`1+`, empty text).
    UnexpectedEnd,
    /// A name that is neither `x`, a constant nor a function (`foo`, `y`).
    UnknownName,
    /// A `(` never closed (position of the `(`) or a `)` never opened.
    MismatchedParen,
    /// Longer than [`MAX_EXPR_LEN_CHARS`] (position of the first character too many).
    TooLong,
    /// More than [`EXPR_MAX_OPS`] operations, [`EXPR_MAX_NESTING`] levels or
    /// [`EXPR_STACK_DEPTH`] stack entries.
    TooComplex,
    /// A function called with the wrong number of arguments (`sin(1,2)`, `min(1)`).
    WrongArgCount,
    /// A literal larger than [`EXPR_MAX_MAGNITUDE`], or so small that no `f32` but zero is
    /// near it (`1e-50`).
    NumberOutOfRange,
}

/// Why a source text was refused, and where: `pos` is the 0-based byte offset of the offending
/// character or token (the text's length for [`ParseErrorKind::UnexpectedEnd`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct ParseError {
    pub kind: ParseErrorKind,
    pub pos: usize,
}

/// Why an evaluation failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum EvalError {
    /// `sqrt` of a negative number.
    SqrtOfNegative,
    /// `ln` or `log10` of zero or a negative number.
    LogOfNonPositive,
    /// `asin` or `acos` outside [-1, 1].
    ArcOutOfRange,
    /// A negative number raised to a non-integer power.
    PowerOfNegative,
    /// `tan` at an odd multiple of π/2 (see [`TAN_POLE_MIN_COS`]).
    TanPole,
    /// Division by zero, or zero raised to a negative power.
    DivisionByZero,
    /// A value that is not finite or larger than [`EXPR_MAX_MAGNITUDE`] (also for a non-finite x).
    Overflow,
}

impl EvalError {
    /// A short English description, for the serial link and the display (with the column,
    /// it fits one LCD line).
    pub const fn message(self) -> &'static str {
        match self {
            EvalError::SqrtOfNegative => "sqrt of a negative number",
            EvalError::LogOfNonPositive => "logarithm of a number <= 0",
            EvalError::ArcOutOfRange => "asin/acos outside [-1, 1]",
            EvalError::PowerOfNegative => "negative number to a fractional power",
            EvalError::TanPole => "tan at its pole",
            EvalError::DivisionByZero => "division by zero",
            EvalError::Overflow => "value too large",
        }
    }
}

/// A parsed expression y = f(x): a bounded reverse-Polish program whose stack depth was checked
/// when it was parsed. Made only by [`parse`].
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    ops: Vec<Op, EXPR_MAX_OPS>,
    consts: Vec<f32, EXPR_MAX_CONSTS>,
}

/// Logs show an expression's size; its text is the host's, not the firmware's.
#[cfg(target_os = "none")]
impl defmt::Format for Expr {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(f, "Expr({=usize} ops)", self.op_count())
    }
}

/// Parses `src` into an [`Expr`]; see the module documentation for the language.
pub fn parse(src: &str) -> Result<Expr, ParseError> {
    if let Some((pos, _)) = src.char_indices().nth(MAX_EXPR_LEN_CHARS) {
        return Err(ParseError { kind: ParseErrorKind::TooLong, pos });
    }
    let mut parser = Parser { src: src.as_bytes(), pos: 0, ops: Vec::new(), consts: Vec::new(), depth: 0, nesting: 0 };
    parser.expr()?;
    let (tok, at) = parser.peek()?;
    match tok {
        Tok::End => Ok(Expr { ops: parser.ops, consts: parser.consts }),
        Tok::RParen => Err(ParseError { kind: ParseErrorKind::MismatchedParen, pos: at }),
        _ => Err(ParseError { kind: ParseErrorKind::UnexpectedChar, pos: at }),
    }
}

impl Expr {
    /// f(x). Fails on a domain error, a division by zero or a value out of range.
    pub fn eval(&self, x: f32) -> Result<f32, EvalError> {
        // The top of the stack is `top`, the values under it are in `below`: most operations
        // only change the top, and a program's first operand pushes nothing.
        let mut below = Stack(heapless::Vec::new());
        let mut top = 0.0;
        for op in self.ops.iter() {
            top = match *op {
                Op::FirstNum(i) => self.constant(i)?,
                Op::FirstX => checked(x)?,
                Op::Num(i) => {
                    below.push(top)?;
                    self.constant(i)?
                }
                Op::X => {
                    below.push(top)?;
                    checked(x)?
                }
                Op::Neg => -top,
                Op::Call(f) => match checked(call(f, top)) {
                    Ok(v) => v,
                    Err(_) => return Err(call_error(f, top)),
                },
                Op::Bin(op) => binary(op, below.pop()?, top)?,
                Op::PowInt(n) => checked(power_int(top, i32::from(n))?)?,
                Op::AddConst(i) => checked(top + self.constant(i)?)?,
                Op::SubConst(i) => checked(top - self.constant(i)?)?,
                Op::MulConst(i) => checked(top * self.constant(i)?)?,
                Op::DivConst(i) => divided(top, self.constant(i)?)?,
                Op::ConstSub(i) => checked(self.constant(i)? - top)?,
                Op::ConstDiv(i) => divided(self.constant(i)?, top)?,
            };
        }
        // A program leaves one value: its result, nothing under it.
        if below.0.is_empty() { Ok(top) } else { Err(EvalError::Overflow) }
    }

    /// The number at index `i` of the constants.
    #[inline(always)]
    fn constant(&self, i: u8) -> Result<f32, EvalError> {
        // Every index was made by the parser for this constant table.
        self.consts.get(usize::from(i)).copied().ok_or(EvalError::Overflow)
    }

    /// Number of operations in the program (at most [`EXPR_MAX_OPS`]).
    pub fn op_count(&self) -> usize {
        self.ops.len()
    }
}

/// `v` if it is finite and within [`EXPR_MAX_MAGNITUDE`] (a NaN compares false, an infinity is
/// beyond).
fn checked(v: f32) -> Result<f32, EvalError> {
    if v.abs() <= EXPR_MAX_MAGNITUDE { Ok(v) } else { Err(EvalError::Overflow) }
}

/// A function of `a`, or a NaN where `a` is outside its domain (see [`call_error`]). Out of
/// line: inlined, its many constants would be loaded at the start of every evaluation,
/// whatever the program calls; and it returns a plain `f32`, in a register.
#[inline(never)]
fn call(f: Func1, a: f32) -> f32 {
    match f {
        Func1::Sin => math::sin(a),
        Func1::Cos => math::cos(a),
        Func1::Tan => {
            let (sin, cos) = math::sin_cos(a);
            if cos.abs() < TAN_POLE_MIN_COS { f32::NAN } else { sin / cos }
        }
        Func1::Asin | Func1::Acos if !(-1.0..=1.0).contains(&a) => f32::NAN,
        Func1::Asin => math::asin(a),
        Func1::Acos => math::acos(a),
        Func1::Atan => math::atan(a),
        Func1::Sqrt if a < 0.0 => f32::NAN,
        Func1::Sqrt => math::sqrt(a),
        Func1::Abs => a.abs(),
        Func1::Exp => math::exp(a),
        Func1::Ln | Func1::Log10 if a <= 0.0 => f32::NAN,
        Func1::Ln => math::ln(a),
        Func1::Log10 => math::log10(a),
        Func1::Floor => math::floor(a),
        Func1::Ceil => math::ceil(a),
    }
}

/// Why `call(f, a)` is out of range: `a` outside the function's domain, or a value too large.
#[cold]
#[inline(never)]
fn call_error(f: Func1, a: f32) -> EvalError {
    match f {
        Func1::Tan if math::sin_cos(a).1.abs() < TAN_POLE_MIN_COS => EvalError::TanPole,
        Func1::Asin | Func1::Acos if !(-1.0..=1.0).contains(&a) => EvalError::ArcOutOfRange,
        Func1::Sqrt if a < 0.0 => EvalError::SqrtOfNegative,
        Func1::Ln | Func1::Log10 if a <= 0.0 => EvalError::LogOfNonPositive,
        _ => EvalError::Overflow,
    }
}

fn binary(op: BinOp, a: f32, b: f32) -> Result<f32, EvalError> {
    let v = match op {
        BinOp::Add => a + b,
        BinOp::Sub => a - b,
        BinOp::Mul => a * b,
        BinOp::Div => return divided(a, b),
        BinOp::Pow => power(a, b)?,
        BinOp::Min => math::min(a, b),
        BinOp::Max => math::max(a, b),
    };
    checked(v)
}

/// `a / b`.
#[inline(always)]
fn divided(a: f32, b: f32) -> Result<f32, EvalError> {
    if b == 0.0 {
        return Err(EvalError::DivisionByZero);
    }
    checked(a / b)
}

/// `a^b`, by multiplication for a small integer `b` (see
/// [`EXPR_POW_BY_MULTIPLICATION_MAX_EXPONENT`]).
fn power(a: f32, b: f32) -> Result<f32, EvalError> {
    if a == 0.0 && b < 0.0 {
        return Err(EvalError::DivisionByZero);
    }
    // Saturating: a huge b becomes i32::MAX or MIN, which is not b.
    let n = b as i32;
    if n as f32 == b && n.unsigned_abs() <= EXPR_POW_BY_MULTIPLICATION_MAX_EXPONENT {
        return power_int(a, n);
    }
    if a < 0.0 && math::trunc(b) != b {
        return Err(EvalError::PowerOfNegative);
    }
    Ok(math::pow(a, b))
}

/// `a^n` by multiplication for |n| ≤ [`EXPR_POW_BY_MULTIPLICATION_MAX_EXPONENT`] (the general
/// power beyond).
#[inline]
fn power_int(a: f32, n: i32) -> Result<f32, EvalError> {
    match n {
        1 => Ok(a),
        2 => Ok(a * a),
        3 => Ok(a * a * a),
        _ => power_int_other(a, n),
    }
}

/// [`power_int`] for the exponents other than 1, 2 and 3.
#[inline(never)]
fn power_int_other(a: f32, n: i32) -> Result<f32, EvalError> {
    if a == 0.0 && n < 0 {
        return Err(EvalError::DivisionByZero);
    }
    let p = match n.unsigned_abs() {
        0 => 1.0,
        1 => a,
        2 => a * a,
        3 => a * a * a,
        4 => {
            let square = a * a;
            square * square
        }
        m => math::pow(a, m as f32),
    };
    // a ≠ 0 when n < 0; an underflow to 0 makes 1/p infinite, which the caller's check refuses.
    Ok(if n < 0 { 1.0 / p } else { p })
}

/// The evaluation stack under its top. Parsing proved that no program exceeds it or pops an
/// empty one, so the errors below cannot occur for an [`Expr`] made by [`parse`]; they exist so
/// that evaluation has no panic path at all. Its storage is left uninitialised until pushed to:
/// clearing it on every evaluation cost more than the evaluation of a short program.
struct Stack(heapless::Vec<f32, EXPR_STACK_DEPTH>);

impl Stack {
    fn push(&mut self, v: f32) -> Result<(), EvalError> {
        self.0.push(v).map_err(|_| EvalError::Overflow)
    }

    fn pop(&mut self) -> Result<f32, EvalError> {
        self.0.pop().ok_or(EvalError::Overflow)
    }
}

/// One token of the source text.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Tok {
    Num(f32),
    X,
    /// `pi` or `e`.
    Const(f32),
    Func1(Func1),
    /// `min` or `max`.
    Func2(BinOp),
    Plus,
    Minus,
    Star,
    Slash,
    Caret,
    LParen,
    RParen,
    Comma,
    End,
}

/// Recursive-descent parser emitting reverse Polish; its recursion is bounded by
/// [`EXPR_MAX_NESTING`].
struct Parser<'a> {
    src: &'a [u8],
    /// Byte offset of the next unread character.
    pos: usize,
    ops: Vec<Op, EXPR_MAX_OPS>,
    consts: Vec<f32, EXPR_MAX_CONSTS>,
    /// Stack depth the program reaches so far at its end.
    depth: usize,
    /// Current nesting level.
    nesting: usize,
}

impl Parser<'_> {
    fn error<T>(kind: ParseErrorKind, pos: usize) -> Result<T, ParseError> {
        Err(ParseError { kind, pos })
    }

    /// The next token and its byte offset, without consuming it.
    fn peek(&self) -> Result<(Tok, usize), ParseError> {
        self.lex().map(|(tok, start, _)| (tok, start))
    }

    /// Consumes the next token and returns it with its byte offset.
    fn bump(&mut self) -> Result<(Tok, usize), ParseError> {
        let (tok, start, end) = self.lex()?;
        self.pos = end;
        Ok((tok, start))
    }

    /// Reads the token at `self.pos`: (token, start, end).
    fn lex(&self) -> Result<(Tok, usize, usize), ParseError> {
        let s = self.src;
        let mut i = self.pos;
        while i < s.len() && s[i].is_ascii_whitespace() {
            i += 1;
        }
        let Some(&c) = s.get(i) else {
            return Ok((Tok::End, s.len(), s.len()));
        };
        let single = match c {
            b'+' => Some(Tok::Plus),
            b'-' => Some(Tok::Minus),
            b'*' => Some(Tok::Star),
            b'/' => Some(Tok::Slash),
            b'^' => Some(Tok::Caret),
            b'(' => Some(Tok::LParen),
            b')' => Some(Tok::RParen),
            b',' => Some(Tok::Comma),
            _ => None,
        };
        if let Some(tok) = single {
            return Ok((tok, i, i + 1));
        }
        if c.is_ascii_digit() || c == b'.' {
            return Self::number(s, i);
        }
        if c.is_ascii_alphabetic() {
            let word = s.get(i..).unwrap_or(&[]);
            let len = word.iter().take_while(|b| b.is_ascii_alphanumeric()).count();
            return match name(word.get(..len).unwrap_or(&[])) {
                Some(tok) => Ok((tok, i, i + len)),
                None => Self::error(ParseErrorKind::UnknownName, i),
            };
        }
        Self::error(ParseErrorKind::UnexpectedChar, i)
    }

    /// The number at `start`: `digits ['.' digits] [('e' | 'E') ['+' | '-'] digits]`, unsigned
    /// (a sign is the unary operator).
    fn number(s: &[u8], start: usize) -> Result<(Tok, usize, usize), ParseError> {
        const SYNTAX: Syntax = Syntax { sign: false, exponent: true };
        match decimal::parse_prefix(s.get(start..).unwrap_or(&[]), SYNTAX) {
            Ok(d) if d.value <= EXPR_MAX_MAGNITUDE => Ok((Tok::Num(d.value), start, start + d.len_bytes)),
            Ok(_) | Err(DecimalError::OutOfRange) => Self::error(ParseErrorKind::NumberOutOfRange, start),
            // A lone '.'.
            Err(DecimalError::NoDigits) => Self::error(ParseErrorKind::UnexpectedChar, start),
        }
    }

    /// Appends `op` to the program; `pos` is the token it comes from, for errors. A number or
    /// `x` with nothing on the stack is the program's first operand.
    fn emit(&mut self, op: Op, pos: usize) -> Result<(), ParseError> {
        let op = match op {
            Op::Num(i) if self.depth == 0 => Op::FirstNum(i),
            Op::X if self.depth == 0 => Op::FirstX,
            op => op,
        };
        if self.ops.push(op).is_err() {
            return Self::error(ParseErrorKind::TooComplex, pos);
        }
        // The grammar only emits an operation when its operands are on the stack.
        self.depth = self.depth.saturating_add_signed(op.stack_effect());
        if self.depth > EXPR_STACK_DEPTH {
            return Self::error(ParseErrorKind::TooComplex, pos);
        }
        Ok(())
    }

    /// The index of `v` in the constants, adding it if new.
    fn constant(&mut self, v: f32, pos: usize) -> Result<u8, ParseError> {
        let index = match self.consts.iter().position(|c| c.to_bits() == v.to_bits()) {
            Some(i) => i,
            None => {
                if self.consts.push(v).is_err() {
                    return Self::error(ParseErrorKind::TooComplex, pos);
                }
                self.consts.len() - 1
            }
        };
        // EXPR_MAX_CONSTS is far below 256.
        Ok(index as u8)
    }

    /// Enters one nesting level at the token at `pos`.
    fn enter(&mut self, pos: usize) -> Result<(), ParseError> {
        self.nesting += 1;
        if self.nesting > EXPR_MAX_NESTING {
            return Self::error(ParseErrorKind::TooComplex, pos);
        }
        Ok(())
    }

    fn leave(&mut self) {
        self.nesting -= 1;
    }

    /// `expr := term (('+' | '-') term)*`
    fn expr(&mut self) -> Result<(), ParseError> {
        let mut left_at = Some(self.ops.len());
        self.term()?;
        loop {
            let (op, at) = match self.peek()? {
                (Tok::Plus, at) => (Arith::Add, at),
                (Tok::Minus, at) => (Arith::Sub, at),
                _ => return Ok(()),
            };
            self.bump()?;
            let left = self.lone_number(left_at.take());
            self.term()?;
            self.emit_binary(op, left, at)?;
        }
    }

    /// `term := unary (('*' | '/') unary)*`
    fn term(&mut self) -> Result<(), ParseError> {
        let mut left_at = Some(self.ops.len());
        self.unary()?;
        loop {
            let (op, at) = match self.peek()? {
                (Tok::Star, at) => (Arith::Mul, at),
                (Tok::Slash, at) => (Arith::Div, at),
                _ => return Ok(()),
            };
            self.bump()?;
            let left = self.lone_number(left_at.take());
            self.unary()?;
            self.emit_binary(op, left, at)?;
        }
    }

    /// If the operand compiled from `start` on (`None`: not a first operand) is a lone number,
    /// takes it back and returns its index: the operation will take it as its constant.
    fn lone_number(&mut self, start: Option<usize>) -> Option<u8> {
        let i = match self.ops.get(start?..)? {
            &[Op::Num(i) | Op::FirstNum(i)] => i,
            _ => return None,
        };
        self.ops.pop();
        self.depth = self.depth.saturating_sub(1);
        Some(i)
    }

    /// Emits `+ - * /` once its right operand is compiled: with the constant `left` as its left
    /// operand, or with a right operand that is a lone number as its constant, one operation.
    /// The operands and their errors come in the order of the text either way (a number has
    /// none), and `a + b`, `a * b` are exactly `b + a`, `b * a`.
    fn emit_binary(&mut self, op: Arith, left: Option<u8>, at: usize) -> Result<(), ParseError> {
        let fused = match (left, op, self.ops.last()) {
            (Some(i), Arith::Add, _) => Op::AddConst(i),
            (Some(i), Arith::Mul, _) => Op::MulConst(i),
            (Some(i), Arith::Sub, _) => Op::ConstSub(i),
            (Some(i), Arith::Div, _) => Op::ConstDiv(i),
            (None, _, Some(&Op::Num(i))) => {
                self.ops.pop();
                self.depth = self.depth.saturating_sub(1);
                match op {
                    Arith::Add => Op::AddConst(i),
                    Arith::Sub => Op::SubConst(i),
                    Arith::Mul => Op::MulConst(i),
                    Arith::Div => Op::DivConst(i),
                }
            }
            (None, Arith::Add, _) => Op::Bin(BinOp::Add),
            (None, Arith::Sub, _) => Op::Bin(BinOp::Sub),
            (None, Arith::Mul, _) => Op::Bin(BinOp::Mul),
            (None, Arith::Div, _) => Op::Bin(BinOp::Div),
        };
        self.emit(fused, at)
    }

    /// `unary := ('-' | '+') unary | power`
    fn unary(&mut self) -> Result<(), ParseError> {
        match self.peek()? {
            (sign @ (Tok::Minus | Tok::Plus), at) => {
                self.bump()?;
                self.enter(at)?;
                self.unary()?;
                self.leave();
                if sign == Tok::Minus {
                    self.emit(Op::Neg, at)?;
                }
                Ok(())
            }
            _ => self.power(),
        }
    }

    /// `power := primary ('^' unary)?`
    fn power(&mut self) -> Result<(), ParseError> {
        self.primary()?;
        if let (Tok::Caret, at) = self.peek()? {
            self.bump()?;
            self.enter(at)?;
            let exponent_at = self.ops.len();
            self.unary()?;
            self.leave();
            match self.ops.get(exponent_at..) {
                // A literal small integer exponent: one operation, no runtime test.
                Some(&[Op::Num(i)]) if let Some(n) = self.small_integer(i) => {
                    self.ops.pop();
                    self.depth = self.depth.saturating_sub(1);
                    self.emit(Op::PowInt(n), at)?;
                }
                _ => self.emit(Op::Bin(BinOp::Pow), at)?,
            }
        }
        Ok(())
    }

    /// The constant at `i` as an exponent for [`Op::PowInt`], if it is an integer of at most
    /// [`EXPR_POW_BY_MULTIPLICATION_MAX_EXPONENT`] in magnitude.
    fn small_integer(&self, i: u8) -> Option<i8> {
        let v = *self.consts.get(usize::from(i))?;
        let n = v as i8;
        (f32::from(n) == v && u32::from(n.unsigned_abs()) <= EXPR_POW_BY_MULTIPLICATION_MAX_EXPONENT).then_some(n)
    }

    fn primary(&mut self) -> Result<(), ParseError> {
        let (tok, at) = self.bump()?;
        match tok {
            Tok::Num(v) | Tok::Const(v) => {
                let index = self.constant(v, at)?;
                self.emit(Op::Num(index), at)
            }
            Tok::X => self.emit(Op::X, at),
            Tok::LParen => {
                self.enter(at)?;
                self.expr()?;
                self.close(at)?;
                self.leave();
                Ok(())
            }
            Tok::Func1(f) => {
                let open = self.open()?;
                self.enter(open)?;
                self.expr()?;
                if let (Tok::Comma, comma) = self.peek()? {
                    return Self::error(ParseErrorKind::WrongArgCount, comma);
                }
                self.close(open)?;
                self.leave();
                self.emit(Op::Call(f), at)
            }
            Tok::Func2(f) => {
                let open = self.open()?;
                self.enter(open)?;
                self.expr()?;
                match self.bump()? {
                    (Tok::Comma, _) => {}
                    (Tok::RParen, close) => return Self::error(ParseErrorKind::WrongArgCount, close),
                    (Tok::End, _) => return Self::error(ParseErrorKind::MismatchedParen, open),
                    (_, other) => return Self::error(ParseErrorKind::UnexpectedChar, other),
                }
                self.expr()?;
                if let (Tok::Comma, comma) = self.peek()? {
                    return Self::error(ParseErrorKind::WrongArgCount, comma);
                }
                self.close(open)?;
                self.leave();
                self.emit(Op::Bin(f), at)
            }
            Tok::End => Self::error(ParseErrorKind::UnexpectedEnd, at),
            Tok::Plus | Tok::Minus | Tok::Star | Tok::Slash | Tok::Caret | Tok::RParen | Tok::Comma => {
                Self::error(ParseErrorKind::UnexpectedChar, at)
            }
        }
    }

    /// Consumes the `(` after a function name; returns its offset.
    fn open(&mut self) -> Result<usize, ParseError> {
        match self.bump()? {
            (Tok::LParen, at) => Ok(at),
            (Tok::End, at) => Self::error(ParseErrorKind::UnexpectedEnd, at),
            (_, at) => Self::error(ParseErrorKind::UnexpectedChar, at),
        }
    }

    /// Consumes the `)` matching the `(` at `open`.
    fn close(&mut self, open: usize) -> Result<(), ParseError> {
        match self.bump()? {
            (Tok::RParen, _) => Ok(()),
            (Tok::End, _) => Self::error(ParseErrorKind::MismatchedParen, open),
            (_, at) => Self::error(ParseErrorKind::UnexpectedChar, at),
        }
    }
}

/// The token a name stands for, case-insensitively.
fn name(word: &[u8]) -> Option<Tok> {
    const NAMES: [(&str, Tok); 18] = [
        ("x", Tok::X),
        ("pi", Tok::Const(core::f32::consts::PI)),
        ("e", Tok::Const(core::f32::consts::E)),
        ("sin", Tok::Func1(Func1::Sin)),
        ("cos", Tok::Func1(Func1::Cos)),
        ("tan", Tok::Func1(Func1::Tan)),
        ("asin", Tok::Func1(Func1::Asin)),
        ("acos", Tok::Func1(Func1::Acos)),
        ("atan", Tok::Func1(Func1::Atan)),
        ("sqrt", Tok::Func1(Func1::Sqrt)),
        ("abs", Tok::Func1(Func1::Abs)),
        ("exp", Tok::Func1(Func1::Exp)),
        ("ln", Tok::Func1(Func1::Ln)),
        ("log10", Tok::Func1(Func1::Log10)),
        ("floor", Tok::Func1(Func1::Floor)),
        ("ceil", Tok::Func1(Func1::Ceil)),
        ("min", Tok::Func2(BinOp::Min)),
        ("max", Tok::Func2(BinOp::Max)),
    ];
    NAMES.iter().find(|(n, _)| n.as_bytes().eq_ignore_ascii_case(word)).map(|&(_, tok)| tok)
}

#[cfg(test)]
mod tests;

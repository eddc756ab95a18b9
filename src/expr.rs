//! The expression language for function curves y = f(x): parsed once, evaluated many times.
//!
//! A source text such as `2.5*sin(2*pi*x/40) - x^2/100` is parsed into an [`Expr`], a short
//! program in reverse Polish notation held in a fixed-capacity `heapless::Vec`. Parsing checks
//! every limit up front (length, number of operations, nesting, evaluation stack depth), so
//! [`Expr::eval`] runs on a fixed array, without recursion or allocation, and cannot overflow
//! its stack. Evaluation is in `f64` (via `libm`) so that curves of ±100_000 steps keep their
//! precision; every domain error (sqrt of a negative, ln of zero, tan at its pole, ...) and
//! every non-finite or over-large intermediate value is an [`EvalError`], never a panic.
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
//! steps along a function lives in `crate::interp::function`.

use heapless::Vec;

const _: () = assert!(EXPR_MAX_CONSTS <= u8::MAX as usize, "constant indices are u8");

/// Longest accepted source text, in characters (a G-code line is at most 80 characters; the
/// keypad entry is shorter still).
pub const MAX_EXPR_LEN_CHARS: usize = 100;

/// Most operations (numbers, `x`, operators, function calls) one expression may compile to;
/// the capacity of [`Expr`]'s program (2 bytes each).
pub const EXPR_MAX_OPS: usize = 64;

/// Most distinct numbers (literals, `pi`, `e`) one expression may hold (8 bytes each). Kept
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
/// the machine, far below where `f64` loses whole units.
pub const EXPR_MAX_MAGNITUDE: f64 = 1.0e15;

/// `tan(a)` with `|cos(a)|` below this is at its pole and fails with [`EvalError::TanPole`]
/// rather than returning a huge number (the `f64` nearest π/2 has `cos` ≈ 6e-17).
pub const TAN_POLE_MIN_COS: f64 = 1.0e-10;

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
    /// A literal that is infinite or larger than [`EXPR_MAX_MAGNITUDE`].
    NumberOutOfRange,
}

impl ParseErrorKind {
    /// A short English description, for the serial link and the display.
    pub const fn message(self) -> &'static str {
        match self {
            ParseErrorKind::UnexpectedChar => "unexpected character",
            ParseErrorKind::UnexpectedEnd => "unexpected end",
            ParseErrorKind::UnknownName => "unknown name",
            ParseErrorKind::MismatchedParen => "mismatched parenthesis",
            ParseErrorKind::TooLong => "expression too long",
            ParseErrorKind::TooComplex => "expression too complex",
            ParseErrorKind::WrongArgCount => "wrong number of arguments",
            ParseErrorKind::NumberOutOfRange => "number out of range",
        }
    }
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
    /// A short English description, for the serial link and the display.
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

/// Functions of one argument.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
enum Func1 {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sqrt,
    Abs,
    Exp,
    Ln,
    Log10,
    Floor,
    Ceil,
}

/// Operations on the two topmost values: `a op b` with `b` on top.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Min,
    Max,
}

/// One operation of the reverse-Polish program.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
enum Op {
    /// Push the number at this index of the constants.
    Num(u8),
    /// Push the argument `x`.
    X,
    /// Negate the top.
    Neg,
    /// Apply a one-argument function to the top.
    Call(Func1),
    /// Replace the two topmost values by their combination.
    Bin(BinOp),
}

impl Op {
    /// How the operation changes the stack's depth.
    const fn stack_effect(self) -> isize {
        match self {
            Op::Num(_) | Op::X => 1,
            Op::Neg | Op::Call(_) => 0,
            Op::Bin(_) => -1,
        }
    }
}

/// A parsed expression y = f(x): a bounded reverse-Polish program whose stack depth was checked
/// when it was parsed. Made only by [`parse`].
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    ops: Vec<Op, EXPR_MAX_OPS>,
    consts: Vec<f64, EXPR_MAX_CONSTS>,
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
    pub fn eval(&self, x: f64) -> Result<f64, EvalError> {
        let mut stack = Stack { values: [0.0; EXPR_STACK_DEPTH], len: 0 };
        for op in self.ops.iter() {
            let value = match *op {
                // Every index was made by the parser for this constant table.
                Op::Num(i) => self.consts.get(usize::from(i)).copied().ok_or(EvalError::Overflow)?,
                Op::X => checked(x)?,
                Op::Neg => -stack.pop()?,
                Op::Call(f) => call(f, stack.pop()?)?,
                Op::Bin(op) => {
                    let b = stack.pop()?;
                    let a = stack.pop()?;
                    binary(op, a, b)?
                }
            };
            stack.push(value)?;
        }
        stack.pop()
    }

    /// Number of operations in the program (at most [`EXPR_MAX_OPS`]).
    pub fn op_count(&self) -> usize {
        self.ops.len()
    }
}

/// `v` if it is finite and within [`EXPR_MAX_MAGNITUDE`].
fn checked(v: f64) -> Result<f64, EvalError> {
    if v.is_finite() && v.abs() <= EXPR_MAX_MAGNITUDE { Ok(v) } else { Err(EvalError::Overflow) }
}

fn call(f: Func1, a: f64) -> Result<f64, EvalError> {
    let v = match f {
        Func1::Sin => libm::sin(a),
        Func1::Cos => libm::cos(a),
        Func1::Tan => {
            if libm::fabs(libm::cos(a)) < TAN_POLE_MIN_COS {
                return Err(EvalError::TanPole);
            }
            libm::tan(a)
        }
        Func1::Asin | Func1::Acos if !(-1.0..=1.0).contains(&a) => return Err(EvalError::ArcOutOfRange),
        Func1::Asin => libm::asin(a),
        Func1::Acos => libm::acos(a),
        Func1::Atan => libm::atan(a),
        Func1::Sqrt if a < 0.0 => return Err(EvalError::SqrtOfNegative),
        Func1::Sqrt => libm::sqrt(a),
        Func1::Abs => libm::fabs(a),
        Func1::Exp => libm::exp(a),
        Func1::Ln | Func1::Log10 if a <= 0.0 => return Err(EvalError::LogOfNonPositive),
        Func1::Ln => libm::log(a),
        Func1::Log10 => libm::log10(a),
        Func1::Floor => libm::floor(a),
        Func1::Ceil => libm::ceil(a),
    };
    checked(v)
}

fn binary(op: BinOp, a: f64, b: f64) -> Result<f64, EvalError> {
    let v = match op {
        BinOp::Add => a + b,
        BinOp::Sub => a - b,
        BinOp::Mul => a * b,
        BinOp::Div if b == 0.0 => return Err(EvalError::DivisionByZero),
        BinOp::Div => a / b,
        BinOp::Pow if a == 0.0 && b < 0.0 => return Err(EvalError::DivisionByZero),
        BinOp::Pow if a < 0.0 && libm::trunc(b) != b => return Err(EvalError::PowerOfNegative),
        BinOp::Pow => libm::pow(a, b),
        BinOp::Min => libm::fmin(a, b),
        BinOp::Max => libm::fmax(a, b),
    };
    checked(v)
}

/// The evaluation stack. Parsing proved that no program exceeds it or pops an empty one, so the
/// errors below cannot occur for an [`Expr`] made by [`parse`]; they exist so that evaluation
/// has no panic path at all.
struct Stack {
    values: [f64; EXPR_STACK_DEPTH],
    len: usize,
}

impl Stack {
    fn push(&mut self, v: f64) -> Result<(), EvalError> {
        let slot = self.values.get_mut(self.len).ok_or(EvalError::Overflow)?;
        *slot = v;
        self.len += 1;
        Ok(())
    }

    fn pop(&mut self) -> Result<f64, EvalError> {
        self.len = self.len.checked_sub(1).ok_or(EvalError::Overflow)?;
        self.values.get(self.len).copied().ok_or(EvalError::Overflow)
    }
}

/// One token of the source text.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Tok {
    Num(f64),
    X,
    /// `pi` or `e`.
    Const(f64),
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
    consts: Vec<f64, EXPR_MAX_CONSTS>,
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
            let end = i + s[i..].iter().take_while(|b| b.is_ascii_alphanumeric()).count();
            return match name(&s[i..end]) {
                Some(tok) => Ok((tok, i, end)),
                None => Self::error(ParseErrorKind::UnknownName, i),
            };
        }
        Self::error(ParseErrorKind::UnexpectedChar, i)
    }

    fn number(s: &[u8], start: usize) -> Result<(Tok, usize, usize), ParseError> {
        let digits = |from: usize| s[from.min(s.len())..].iter().take_while(|b| b.is_ascii_digit()).count();
        let int = digits(start);
        let mut end = start + int;
        let mut frac = 0;
        if s.get(end) == Some(&b'.') {
            frac = digits(end + 1);
            end += 1 + frac;
        }
        if int + frac == 0 {
            // A lone '.'.
            return Self::error(ParseErrorKind::UnexpectedChar, start);
        }
        if matches!(s.get(end), Some(b'e' | b'E')) {
            let sign = usize::from(matches!(s.get(end + 1), Some(b'+' | b'-')));
            let exp = digits(end + 1 + sign);
            // Without digits the 'e' is not an exponent but the next token (and an error there).
            if exp > 0 {
                end += 1 + sign + exp;
            }
        }
        let text = core::str::from_utf8(&s[start..end])
            .map_err(|_| ParseError { kind: ParseErrorKind::UnexpectedChar, pos: start })?;
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() && v <= EXPR_MAX_MAGNITUDE => Ok((Tok::Num(v), start, end)),
            Ok(_) => Self::error(ParseErrorKind::NumberOutOfRange, start),
            Err(_) => Self::error(ParseErrorKind::UnexpectedChar, start),
        }
    }

    /// Appends `op` to the program; `pos` is the token it comes from, for errors.
    fn emit(&mut self, op: Op, pos: usize) -> Result<(), ParseError> {
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
    fn constant(&mut self, v: f64, pos: usize) -> Result<u8, ParseError> {
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
        self.term()?;
        loop {
            let op = match self.peek()? {
                (Tok::Plus, at) => (Op::Bin(BinOp::Add), at),
                (Tok::Minus, at) => (Op::Bin(BinOp::Sub), at),
                _ => return Ok(()),
            };
            self.bump()?;
            self.term()?;
            self.emit(op.0, op.1)?;
        }
    }

    /// `term := unary (('*' | '/') unary)*`
    fn term(&mut self) -> Result<(), ParseError> {
        self.unary()?;
        loop {
            let op = match self.peek()? {
                (Tok::Star, at) => (Op::Bin(BinOp::Mul), at),
                (Tok::Slash, at) => (Op::Bin(BinOp::Div), at),
                _ => return Ok(()),
            };
            self.bump()?;
            self.unary()?;
            self.emit(op.0, op.1)?;
        }
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
            self.unary()?;
            self.leave();
            self.emit(Op::Bin(BinOp::Pow), at)?;
        }
        Ok(())
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
        ("pi", Tok::Const(core::f64::consts::PI)),
        ("e", Tok::Const(core::f64::consts::E)),
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
mod tests {
    extern crate std;
    use super::*;
    use core::f64::consts::{E, PI};
    use proptest::prelude::*;
    use std::string::String;
    use std::vec;

    fn eval(src: &str, x: f64) -> f64 {
        match parse(src) {
            Ok(e) => match e.eval(x) {
                Ok(v) => v,
                Err(err) => panic!("{src} at x = {x}: {err:?}"),
            },
            Err(err) => panic!("{src}: {err:?}"),
        }
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * (1.0 + b.abs())
    }

    fn parse_err(src: &str) -> (ParseErrorKind, usize) {
        match parse(src) {
            Ok(e) => panic!("{src} parsed as {e:?}"),
            Err(ParseError { kind, pos }) => (kind, pos),
        }
    }

    fn eval_err(src: &str, x: f64) -> EvalError {
        match parse(src).map(|e| e.eval(x)) {
            Ok(Err(e)) => e,
            other => panic!("{src} at x = {x}: {other:?}"),
        }
    }

    #[test]
    fn operators_follow_the_usual_precedence() {
        assert_eq!(eval("1 + 2 * 3", 0.0), 7.0);
        assert_eq!(eval("(1 + 2) * 3", 0.0), 9.0);
        assert_eq!(eval("2 * 3 ^ 2", 0.0), 18.0);
        assert_eq!(eval("1 + 6 / 3 - 2", 0.0), 1.0);
        assert_eq!(eval("-x^2", 3.0), -9.0);
        assert_eq!(eval("(-x)^2", 3.0), 9.0);
        assert_eq!(eval("-2^2", 0.0), -4.0);
        assert_eq!(eval("2 * -x", 4.0), -8.0);
        assert_eq!(eval("2^-1", 0.0), 0.5);
        assert_eq!(eval("--x", 5.0), 5.0);
        assert_eq!(eval("+x - -1", 5.0), 6.0);
        assert_eq!(eval("x^2/10", -10.0), 10.0);
    }

    #[test]
    fn power_is_right_associative_and_the_others_left() {
        assert_eq!(eval("2^3^2", 0.0), 512.0);
        assert_eq!(eval("(2^3)^2", 0.0), 64.0);
        assert_eq!(eval("8 / 4 / 2", 0.0), 1.0);
        assert_eq!(eval("8 - 4 - 2", 0.0), 2.0);
        assert_eq!(eval("2^-x^2", 1.0), 0.5);
    }

    #[test]
    fn numbers_names_and_case() {
        assert_eq!(eval("1.5e3", 0.0), 1500.0);
        assert_eq!(eval("1.5E-3", 0.0), 0.0015);
        assert_eq!(eval("3e+2", 0.0), 300.0);
        assert_eq!(eval(".5 + 2.", 0.0), 2.5);
        assert_eq!(eval("0007", 0.0), 7.0);
        assert_eq!(eval("PI", 0.0), PI);
        assert_eq!(eval("e", 0.0), E);
        assert_eq!(eval("X", 2.0), 2.0);
        assert_eq!(eval("  x\t*\n2 ", 2.0), 4.0);
        assert!(close(eval("SIN(Pi/2)", 0.0), 1.0));
        assert!(close(eval("Log10(1000)", 0.0), 3.0));
    }

    #[test]
    fn every_function_computes_its_value() {
        let x = 0.3;
        let cases: [(&str, f64); 15] = [
            ("sin(x)", libm::sin(x)),
            ("cos(x)", libm::cos(x)),
            ("tan(x)", libm::tan(x)),
            ("asin(x)", libm::asin(x)),
            ("acos(x)", libm::acos(x)),
            ("atan(x)", libm::atan(x)),
            ("sqrt(x)", libm::sqrt(x)),
            ("abs(-x)", x),
            ("exp(x)", libm::exp(x)),
            ("ln(x)", libm::log(x)),
            ("log10(x)", libm::log10(x)),
            ("floor(x - 1)", -1.0),
            ("ceil(x)", 1.0),
            ("min(x, -2)", -2.0),
            ("max(x, -2)", x),
        ];
        for (src, want) in cases {
            assert!(close(eval(src, x), want), "{src} = {} instead of {want}", eval(src, x));
        }
        assert!(close(eval("ln(e^2)", 0.0), 2.0));
        assert!(close(eval("max(sin(x), cos(x)) * min(1, 2)", PI / 3.0), libm::sin(PI / 3.0)));
    }

    #[test]
    fn errors_point_at_the_offending_character() {
        assert_eq!(parse_err(""), (ParseErrorKind::UnexpectedEnd, 0));
        assert_eq!(parse_err("  "), (ParseErrorKind::UnexpectedEnd, 2));
        assert_eq!(parse_err("1+"), (ParseErrorKind::UnexpectedEnd, 2));
        assert_eq!(parse_err("1 + $"), (ParseErrorKind::UnexpectedChar, 4));
        assert_eq!(parse_err("2x"), (ParseErrorKind::UnexpectedChar, 1));
        assert_eq!(parse_err("1 2"), (ParseErrorKind::UnexpectedChar, 2));
        assert_eq!(parse_err("2e"), (ParseErrorKind::UnexpectedChar, 1));
        assert_eq!(parse_err("1.2.3"), (ParseErrorKind::UnexpectedChar, 3));
        assert_eq!(parse_err("x * . "), (ParseErrorKind::UnexpectedChar, 4));
        assert_eq!(parse_err("x */ 2"), (ParseErrorKind::UnexpectedChar, 3));
        assert_eq!(parse_err("()"), (ParseErrorKind::UnexpectedChar, 1));
        assert_eq!(parse_err("(1, 2)"), (ParseErrorKind::UnexpectedChar, 2));
        assert_eq!(parse_err("sin x"), (ParseErrorKind::UnexpectedChar, 4));
        assert_eq!(parse_err("sin"), (ParseErrorKind::UnexpectedEnd, 3));
        assert_eq!(parse_err("x + é"), (ParseErrorKind::UnexpectedChar, 4));
        assert_eq!(parse_err("é"), (ParseErrorKind::UnexpectedChar, 0));
        assert_eq!(parse_err("2 * foo(x)"), (ParseErrorKind::UnknownName, 4));
        assert_eq!(parse_err("y + 1"), (ParseErrorKind::UnknownName, 0));
        assert_eq!(parse_err("x2"), (ParseErrorKind::UnknownName, 0));
        assert_eq!(parse_err("sin(x"), (ParseErrorKind::MismatchedParen, 3));
        assert_eq!(parse_err("1 + (2 * (x)"), (ParseErrorKind::MismatchedParen, 4));
        assert_eq!(parse_err("x)"), (ParseErrorKind::MismatchedParen, 1));
        assert_eq!(parse_err("max(x, 1"), (ParseErrorKind::MismatchedParen, 3));
        assert_eq!(parse_err("min(x)"), (ParseErrorKind::WrongArgCount, 5));
        assert_eq!(parse_err("sin(x, 1)"), (ParseErrorKind::WrongArgCount, 5));
        assert_eq!(parse_err("max(1, 2, 3)"), (ParseErrorKind::WrongArgCount, 8));
        assert_eq!(parse_err("x + 1e999"), (ParseErrorKind::NumberOutOfRange, 4));
        assert_eq!(parse_err("2e16"), (ParseErrorKind::NumberOutOfRange, 0));
    }

    #[test]
    fn domain_errors_are_reported_not_computed() {
        assert_eq!(eval_err("sqrt(x)", -1.0), EvalError::SqrtOfNegative);
        assert_eq!(eval("sqrt(x)", -0.0), 0.0);
        assert_eq!(eval_err("ln(x)", 0.0), EvalError::LogOfNonPositive);
        assert_eq!(eval_err("log10(x)", -3.0), EvalError::LogOfNonPositive);
        assert_eq!(eval_err("asin(x)", 1.000_001), EvalError::ArcOutOfRange);
        assert_eq!(eval_err("acos(x)", -1.5), EvalError::ArcOutOfRange);
        assert!(close(eval("acos(x)", -1.0), PI));
        assert_eq!(eval_err("1/x", 0.0), EvalError::DivisionByZero);
        assert_eq!(eval_err("1/(x-x)", 3.0), EvalError::DivisionByZero);
        assert_eq!(eval_err("0^x", -1.0), EvalError::DivisionByZero);
        assert_eq!(eval_err("x^0.5", -4.0), EvalError::PowerOfNegative);
        assert_eq!(eval("x^3", -2.0), -8.0);
        assert_eq!(eval_err("tan(x)", PI / 2.0), EvalError::TanPole);
        assert_eq!(eval_err("tan(x)", -3.0 * PI / 2.0), EvalError::TanPole);
        assert!(close(eval("tan(x)", 1.5), libm::tan(1.5)));
        // Beyond the pole guard tan is large but finite and correct.
        assert!(eval("tan(x)", PI / 2.0 - 1e-6) > 9.9e5);
    }

    #[test]
    fn values_beyond_the_limit_overflow() {
        assert_eq!(eval_err("exp(x)", 1000.0), EvalError::Overflow);
        assert_eq!(eval_err("10^x", 16.0), EvalError::Overflow);
        assert_eq!(eval("10^x", 15.0), 1e15);
        assert_eq!(eval_err("x*x*x", 1e6), EvalError::Overflow);
        assert_eq!(eval_err("1/x", 1e-300), EvalError::Overflow);
        assert_eq!(eval_err("x", f64::NAN), EvalError::Overflow);
        assert_eq!(eval_err("0*x", f64::INFINITY), EvalError::Overflow);
    }

    #[test]
    fn length_is_limited_in_characters() {
        let mut src = String::from("x");
        src.extend(core::iter::repeat_n(' ', MAX_EXPR_LEN_CHARS - 1));
        assert_eq!(eval(&src, 3.0), 3.0);
        src.push('1');
        assert_eq!(parse_err(&src), (ParseErrorKind::TooLong, MAX_EXPR_LEN_CHARS));
        // Multi-byte characters count once; the position is a byte offset.
        let wide: String = core::iter::repeat_n('é', MAX_EXPR_LEN_CHARS + 1).collect();
        assert_eq!(parse_err(&wide), (ParseErrorKind::TooLong, 2 * MAX_EXPR_LEN_CHARS));
    }

    #[test]
    fn programs_and_nesting_are_bounded() {
        // x+x+...: 2n - 1 operations.
        let sum = |n: usize| -> String { vec!["x"; n].join("+") };
        let fits = sum(EXPR_MAX_OPS / 2);
        assert_eq!(eval(&fits, 1.0), (EXPR_MAX_OPS / 2) as f64);
        assert_eq!(parse(&fits).map(|e| e.op_count()), Ok(EXPR_MAX_OPS - 1));
        let too_many = sum(EXPR_MAX_OPS / 2 + 1);
        assert_eq!(parse_err(&too_many).0, ParseErrorKind::TooComplex);

        let nested = |n: usize| -> String { "(".repeat(n) + "x" + &")".repeat(n) };
        assert_eq!(eval(&nested(EXPR_MAX_NESTING), 2.0), 2.0);
        assert_eq!(parse_err(&nested(EXPR_MAX_NESTING + 1)), (ParseErrorKind::TooComplex, EXPR_MAX_NESTING));
        assert_eq!(parse_err(&"-".repeat(EXPR_MAX_NESTING + 1)).0, ParseErrorKind::TooComplex);
        assert_eq!(parse_err("2^2^2^2^2^2^2^2^2^2^2^2^2^2^2^2^2^2").0, ParseErrorKind::TooComplex);
    }

    #[test]
    fn the_evaluation_stack_depth_is_checked_when_parsing() {
        // Each level leaves three values waiting (x, x and x) until its parenthesis closes, and
        // nests twice (the exponent and the parenthesis).
        let levels = |n: usize| -> String { "x+x*x^(".repeat(n) + "x" + &")".repeat(n) };
        let deepest = (EXPR_STACK_DEPTH - 1) / 3;
        assert!(2 * (deepest + 1) <= EXPR_MAX_NESTING, "nesting would be refused first");
        // At x = 1 every level is 1 + 1 * 1^(...) = 2.
        assert_eq!(parse(&levels(deepest)).map(|e| e.eval(1.0)), Ok(Ok(2.0)));
        let err = parse(&levels(deepest + 1)).unwrap_err();
        assert_eq!(err.kind, ParseErrorKind::TooComplex);
        // Refused at the innermost x, which would be the stack's 25th entry.
        assert_eq!(err.pos, (deepest + 1) * "x+x*x^(".len());
    }

    #[test]
    fn a_realistic_curve_parses_once_and_evaluates_everywhere() {
        let e = parse("2.5*sin(2*pi*x/40) * exp(-x/100) + 0.1*x - abs(x - 50)^1.5/100").unwrap();
        let f = |x: f64| {
            2.5 * libm::sin(2.0 * PI * x / 40.0) * libm::exp(-x / 100.0) + 0.1 * x
                - libm::pow(libm::fabs(x - 50.0), 1.5) / 100.0
        };
        for i in 0..=100 {
            let x = i as f64;
            let got = e.eval(x).unwrap();
            assert!((got - f(x)).abs() < 1e-12, "x = {x}: {got} vs {}", f(x));
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]

        /// Whatever the text, parsing answers and an accepted expression evaluates without
        /// panicking, to a finite value within the limit or an error.
        #[test]
        fn any_text_parses_or_fails_and_never_panics(
            tokens in proptest::collection::vec(
                prop_oneof![
                    Just("x"), Just("1"), Just("2.5"), Just("1e3"), Just("pi"), Just("e"),
                    Just("+"), Just("-"), Just("*"), Just("/"), Just("^"), Just("("), Just(")"),
                    Just(","), Just("sin("), Just("tan("), Just("sqrt("), Just("ln("), Just("min("),
                    Just("exp("), Just("asin("), Just(" "), Just("$"), Just("q"),
                ],
                0..60,
            ),
            x in -1e3f64..1e3,
        ) {
            let src: String = tokens.concat();
            match parse(&src) {
                Ok(e) => {
                    prop_assert!(e.op_count() <= EXPR_MAX_OPS);
                    for x in [x, 0.0, -1.0, PI / 2.0] {
                        if let Ok(v) = e.eval(x) {
                            prop_assert!(v.is_finite() && v.abs() <= EXPR_MAX_MAGNITUDE);
                        }
                    }
                }
                Err(err) => prop_assert!(err.pos <= src.len()),
            }
        }
    }

    #[test]
    fn constants_are_shared_and_bounded() {
        // The same number twice takes one place.
        let same = "1+1+1+1+1+1+1+1+1+1+1+1+1+1+1+1+1+1+1+1+1+1+1+1+1+1+x";
        assert_eq!(parse(same).unwrap().eval(2.0), Ok(28.0));
        let distinct: std::string::String =
            (1..=EXPR_MAX_CONSTS + 1).map(|k| std::format!("{k}")).collect::<std::vec::Vec<_>>().join("+");
        let err = parse(&distinct).unwrap_err();
        assert_eq!(err.kind, ParseErrorKind::TooComplex);
        assert!(core::mem::size_of::<Expr>() <= 2 * EXPR_MAX_OPS + 8 * EXPR_MAX_CONSTS + 32);
    }
}

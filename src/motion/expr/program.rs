//! The program an expression compiles to: its operations, on a stack of values, and the
//! functions and operators they apply. The parser emits them, the evaluator runs them.

/// Functions of one argument.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub(super) enum Func1 {
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
pub(super) enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Min,
    Max,
}

/// The operators of `expr` and `term`, as the parser fuses them with a constant operand.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Arith {
    Add,
    Sub,
    Mul,
    Div,
}

/// One operation of the reverse-Polish program.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub(super) enum Op {
    /// Push the number at this index of the constants.
    Num(u8),
    /// Push the argument `x`.
    X,
    /// The program's first operand, the number at this index or `x`: nothing is under it to
    /// push.
    FirstNum(u8),
    FirstX,
    /// The top with the number at this index as the right operand: `top + c`, `top - c`,
    /// `top * c`, `top / c`; where the source had a number there, one operation instead of two
    /// and nothing pushed.
    AddConst(u8),
    SubConst(u8),
    MulConst(u8),
    DivConst(u8),
    /// The number at this index with the top as the right operand: `c - top`, `c / top` (for
    /// `+` and `*` the order makes no difference: [`Op::AddConst`], [`Op::MulConst`]).
    ConstSub(u8),
    ConstDiv(u8),
    /// Negate the top.
    Neg,
    /// Apply a one-argument function to the top.
    Call(Func1),
    /// Replace the two topmost values by their combination.
    Bin(BinOp),
    /// Raise the top to this integer power, of at most
    /// `EXPR_POW_BY_MULTIPLICATION_MAX_EXPONENT` in magnitude: `^` with a literal exponent
    /// such as `x^2`, one operation instead of two.
    PowInt(i8),
}

impl Op {
    /// How the operation changes the stack's depth.
    pub(super) const fn stack_effect(self) -> isize {
        match self {
            Op::Num(_) | Op::X | Op::FirstNum(_) | Op::FirstX => 1,
            Op::Neg
            | Op::Call(_)
            | Op::PowInt(_)
            | Op::AddConst(_)
            | Op::SubConst(_)
            | Op::MulConst(_)
            | Op::DivConst(_)
            | Op::ConstSub(_)
            | Op::ConstDiv(_) => 0,
            Op::Bin(_) => -1,
        }
    }
}

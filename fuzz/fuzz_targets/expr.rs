//! The expression language of function curves (`$F ... Y=<expression>`, the keypad's entry):
//! any text parsed, and what parses evaluated at a few x.
//!
//! Checks, besides that nothing panics: a refusal points inside the text (or at its end), a text
//! over `MAX_EXPR_LEN_CHARS` characters is refused as too long, a program stays within
//! `EXPR_MAX_OPS`; a value is finite and within `EXPR_MAX_MAGNITUDE`; evaluating twice gives the
//! same; and the text wrapped as `(t)`, `-(-(t))`, `0+(t)` and `1*(t)`, where it still parses,
//! gives exactly the same value or the same error.
#![no_main]

use libfuzzer_sys::fuzz_target;
use servoplot::motion::expr::{
    self, EXPR_MAX_MAGNITUDE, EXPR_MAX_OPS, EvalError, Expr, MAX_EXPR_LEN_CHARS, ParseErrorKind,
};

/// x values every expression is evaluated at (millimetres on the curve), besides the input's own.
const XS: [f32; 7] = [0.0, 1.0, -1.0, 0.5, 3.25, 100.0, -250.0];

fn values(expr: &Expr, xs: &[f32]) -> Vec<Result<f32, EvalError>> {
    xs.iter().map(|&x| expr.eval(x)).collect()
}

fn same(a: &[Result<f32, EvalError>], b: &[Result<f32, EvalError>]) -> bool {
    // -0.0 and 0.0 are the same value: `0+(t)` turns one into the other.
    a.len() == b.len() && a.iter().zip(b).all(|(a, b)| a == b)
}

fuzz_target!(|data: &[u8]| {
    // The first four bytes are an x (any f32: NaN and infinities too), the rest is the text.
    let Some((x, text)) = data.split_first_chunk::<4>() else { return };
    let Ok(src) = std::str::from_utf8(text) else { return };
    let mut xs = XS.to_vec();
    xs.push(f32::from_le_bytes(*x));

    let expr = match expr::parse(src) {
        Ok(expr) => expr,
        Err(e) => {
            assert!(e.pos <= src.len(), "{e:?} beyond the text {src:?}");
            if src.chars().count() > MAX_EXPR_LEN_CHARS {
                assert_eq!(e.kind, ParseErrorKind::TooLong, "{src:?}");
            }
            return;
        }
    };
    assert!(src.chars().count() <= MAX_EXPR_LEN_CHARS, "{src:?} accepted");
    assert!(expr.op_count() <= EXPR_MAX_OPS);
    let got = values(&expr, &xs);
    for (value, x) in got.iter().zip(&xs) {
        if let Ok(v) = value {
            assert!(v.is_finite() && v.abs() <= EXPR_MAX_MAGNITUDE, "{src:?} at {x}: {v}");
        }
    }
    assert!(same(&values(&expr, &xs), &got), "{src:?} evaluated twice differs");

    for wrapped in [format!("({src})"), format!("-(-({src}))"), format!("0+({src})"), format!("1*({src})")] {
        // Wrapping may take the text past a limit of length or nesting: then there is nothing to
        // compare.
        if let Ok(other) = expr::parse(&wrapped) {
            assert!(same(&values(&other, &xs), &got), "{wrapped:?} differs from {src:?}");
        }
    }
});

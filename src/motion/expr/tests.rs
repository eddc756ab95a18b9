//! Tests of the expression language: parsing, its errors and limits, and evaluation in `f32`
//! against the host's `f64` functions.

extern crate std;
use super::*;
use core::f32::consts::{E, PI};
use proptest::prelude::*;
use std::string::String;
use std::vec;

fn eval(src: &str, x: f32) -> f32 {
    match parse(src) {
        Ok(e) => match e.eval(x) {
            Ok(v) => v,
            Err(err) => panic!("{src} at x = {x}: {err:?}"),
        },
        Err(err) => panic!("{src}: {err:?}"),
    }
}

/// `a` (computed in `f32`) is within 4 `f32` ulps of `b` (relative 4.8e-7) or, near zero,
/// within as much absolutely: each function is within 3 ulp (see `math`'s tests), plus the
/// rounding of the operations around it.
fn close(a: f32, b: f64) -> bool {
    (f64::from(a) - b).abs() <= 4.0 * f64::from(f32::EPSILON) * (1.0 + b.abs())
}

fn parse_err(src: &str) -> (ParseErrorKind, usize) {
    match parse(src) {
        Ok(e) => panic!("{src} parsed as {e:?}"),
        Err(ParseError { kind, pos }) => (kind, pos),
    }
}

fn eval_err(src: &str, x: f32) -> EvalError {
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
    let x = 0.3f32;
    let xs = f64::from(x);
    let cases: [(&str, f64); 15] = [
        ("sin(x)", xs.sin()),
        ("cos(x)", xs.cos()),
        ("tan(x)", xs.tan()),
        ("asin(x)", xs.asin()),
        ("acos(x)", xs.acos()),
        ("atan(x)", xs.atan()),
        ("sqrt(x)", xs.sqrt()),
        ("abs(-x)", xs),
        ("exp(x)", xs.exp()),
        ("ln(x)", xs.ln()),
        ("log10(x)", xs.log10()),
        ("floor(x - 1)", -1.0),
        ("ceil(x)", 1.0),
        ("min(x, -2)", -2.0),
        ("max(x, -2)", xs),
    ];
    for (src, want) in cases {
        assert!(close(eval(src, x), want), "{src} = {} instead of {want}", eval(src, x));
    }
    assert!(close(eval("ln(e^2)", 0.0), 2.0));
    let x = PI / 3.0;
    assert!(close(eval("max(sin(x), cos(x)) * min(1, 2)", x), f64::from(x).sin()));
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
    // Too small for any f32 but zero: refused rather than silently zero.
    assert_eq!(parse_err("x * 1e-50"), (ParseErrorKind::NumberOutOfRange, 4));
}

#[test]
fn domain_errors_are_reported_not_computed() {
    assert_eq!(eval_err("sqrt(x)", -1.0), EvalError::SqrtOfNegative);
    assert_eq!(eval("sqrt(x)", -0.0), 0.0);
    assert_eq!(eval_err("ln(x)", 0.0), EvalError::LogOfNonPositive);
    assert_eq!(eval_err("log10(x)", -3.0), EvalError::LogOfNonPositive);
    assert_eq!(eval_err("asin(x)", 1.000_001), EvalError::ArcOutOfRange);
    assert_eq!(eval_err("acos(x)", -1.5), EvalError::ArcOutOfRange);
    assert_eq!(eval("acos(x)", -1.0), PI);
    assert_eq!(eval_err("1/x", 0.0), EvalError::DivisionByZero);
    assert_eq!(eval_err("1/(x-x)", 3.0), EvalError::DivisionByZero);
    assert_eq!(eval_err("0^x", -1.0), EvalError::DivisionByZero);
    assert_eq!(eval_err("x^0.5", -4.0), EvalError::PowerOfNegative);
    assert_eq!(eval("x^3", -2.0), -8.0);
    assert_eq!(eval_err("tan(x)", PI / 2.0), EvalError::TanPole);
    assert_eq!(eval_err("tan(x)", -3.0 * PI / 2.0), EvalError::TanPole);
    assert!(close(eval("tan(x)", 1.5), 1.5f64.tan()));
    // Outside the pole guard tan is large but finite and correct (to the precision that the
    // reduction's 1e-10 leaves near a pole: (1 + tan²)·1e-10 relative to tan, 1e-6 here).
    let near = PI / 2.0 - 1e-4;
    for x in [1.57f32, near, -near] {
        let want = f64::from(x).tan();
        let got = eval("tan(x)", x);
        assert!((f64::from(got) - want).abs() <= 1e-5 * want.abs(), "tan({x}) = {got}, not {want}");
    }
    assert!(eval("tan(x)", near) > 9.9e3);
}

#[test]
fn values_beyond_the_limit_overflow() {
    assert_eq!(eval_err("exp(x)", 1000.0), EvalError::Overflow);
    assert_eq!(eval_err("10^x", 16.0), EvalError::Overflow);
    assert!(close(eval("10^x", 14.0), 1e14));
    assert_eq!(eval("x", EXPR_MAX_MAGNITUDE), EXPR_MAX_MAGNITUDE);
    assert_eq!(eval("1e15", 0.0), 1e15);
    assert_eq!(eval_err("x*x*x", 1e6), EvalError::Overflow);
    assert_eq!(eval_err("1/x", 1e-30), EvalError::Overflow);
    assert_eq!(eval_err("x", f32::NAN), EvalError::Overflow);
    assert_eq!(eval_err("0*x", f32::INFINITY), EvalError::Overflow);
    // A power underflowing to zero makes its reciprocal infinite: refused, not a division.
    assert_eq!(eval_err("x^-4", 1e-20), EvalError::Overflow);
    assert_eq!(eval_err("x^-0.5", 1e-45), EvalError::Overflow);
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
    assert_eq!(eval(&fits, 1.0), (EXPR_MAX_OPS / 2) as f32);
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
        2.5 * (2.0 * core::f64::consts::PI * x / 40.0).sin() * (-x / 100.0).exp() + 0.1 * x
            - (x - 50.0).abs().powf(1.5) / 100.0
    };
    for i in 0..=1000 {
        let x = i as f32 / 10.0;
        let (got, want) = (e.eval(x).unwrap(), f(f64::from(x)));
        // The sine's argument (up to 16) is rounded to 1e-6 by the f32 operations before it,
        // times the amplitude 2.5; the other terms are within an ulp of 10 (1e-6).
        assert!((f64::from(got) - want).abs() < 1e-5, "x = {x}: {got} vs {want}");
    }
}

#[test]
fn curves_match_the_host_in_f64() {
    // (expression, the same in f64, largest |value| on [-30, 30] for the error's scale)
    type F = fn(f64) -> f64;
    let cases: [(&str, F, f64); 6] = [
        ("20*exp(-x^2/200)", |x| 20.0 * (-x * x / 200.0).exp(), 20.0),
        ("x^3/400", |x| x * x * x / 400.0, 67.5),
        ("sin(x)*x/10", |x| x.sin() * x / 10.0, 3.0),
        ("3*sqrt(abs(x))", |x| 3.0 * x.abs().sqrt(), 16.5),
        ("20*atan(x/10)", |x| 20.0 * (x / 10.0).atan(), 25.0),
        ("5*log10(x^2 + 1) - cos(x/3)^2", |x| 5.0 * (x * x + 1.0).log10() - (x / 3.0).cos().powi(2), 15.0),
    ];
    for (src, f, scale) in cases {
        let e = parse(src).unwrap();
        for i in -3000..=3000 {
            let x = i as f32 / 100.0;
            let (got, want) = (e.eval(x).unwrap(), f(f64::from(x)));
            // A few ulps of the curve's scale: far below a step (0.01 mm at 100 steps/mm).
            assert!(
                (f64::from(got) - want).abs() <= 8.0 * f64::from(f32::EPSILON) * scale,
                "{src} at {x}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn small_integer_powers_multiply() {
    assert_eq!(eval("x^2", 1.1), 1.1 * 1.1);
    assert_eq!(eval("x^3", 1.1), 1.1 * 1.1 * 1.1);
    assert_eq!(eval("x^4", -3.0), 81.0);
    assert_eq!(eval("x^-2", 4.0), 1.0 / 16.0);
    assert_eq!(eval("x^-3", -2.0), -0.125);
    assert_eq!(eval("x^1", 0.7), 0.7);
    assert_eq!((eval("x^0", 0.0), eval("x^0", -5.0)), (1.0, 1.0));
    assert_eq!(eval("(-x)^4", 1.5), 5.0625);
    // Exact whenever the result is an f32; beyond the fast path the general power.
    assert_eq!(eval("x^3", 255.0), 16_581_375.0);
    assert!(close(eval("x^5", 1.1), 1.1f64.powi(5)));
    assert!(close(eval("x^2.5", 2.0), 2f64.powf(2.5)));
    assert_eq!(eval("x^5", -2.0), -32.0);
    assert_eq!(eval_err("x^-1", 0.0), EvalError::DivisionByZero);
    assert_eq!(eval_err("x^4.5", -1.0), EvalError::PowerOfNegative);
    // A literal small integer exponent is one operation; others stay a power of two values.
    assert_eq!(parse("x^2").map(|e| e.op_count()), Ok(2));
    assert_eq!(parse("x^(-4)").map(|e| e.op_count()), Ok(4));
    assert_eq!(parse("x^5").map(|e| e.op_count()), Ok(3));
    assert_eq!(parse("x^2.5").map(|e| e.op_count()), Ok(3));
    assert_eq!(eval("x^(3)", -2.0), -8.0);
    assert_eq!(eval("-x^2", 3.0), -9.0);
    assert_eq!(eval_err("x^(-4)", 0.0), EvalError::DivisionByZero);
    assert_eq!(eval_err("0^-1", 0.0), EvalError::DivisionByZero);
    // i32 saturation does not make a huge exponent look small.
    assert_eq!(eval("x^-2147483648", 1.0), 1.0);
    assert_eq!(eval("x^1e10", 0.5), 0.0);
}

#[test]
fn tan_refuses_the_float_nearest_every_pole_up_to_256_rad() {
    let mut k = 0.5;
    while k * core::f64::consts::PI < 256.0 {
        for pole in [k * core::f64::consts::PI, -k * core::f64::consts::PI] {
            assert_eq!(eval_err("tan(x)", pole as f32), EvalError::TanPole, "pole {pole}");
        }
        k += 1.0;
    }
    // And no more than 1e-5 rad around it.
    for x in [PI / 2.0 - 2e-5, PI / 2.0 + 2e-5, 1.57, 3.0 * PI / 2.0 + 1e-4] {
        assert!(eval("tan(x)", x).abs() > 1e3, "{x}");
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
        x in -1e3f32..1e3,
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
    assert!(core::mem::size_of::<Expr>() <= 2 * EXPR_MAX_OPS + 4 * EXPR_MAX_CONSTS + 32);
}

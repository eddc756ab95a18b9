//! The builder's cost per step: the firmware's own [`Builder`] walking curves of every kind in
//! the slices the front ends walk ([`BUILD_SLICE_STEPS`]), and how a function's cost grows with
//! its expression's size, for the builder and for the motion task.
//!
//! Each slice of a build case is measured and reported with its steps (`result slice ...`); once
//! the case is walked, a line of its own says what the runner fits the model with: the curve's
//! kind, its X steps (a sine or a function evaluates its curve once per X step) and its
//! expression's size (`walked ...`).

use cortex_m_semihosting::hprintln;
use servoplot::geom::Point;
use servoplot::motion::drawing::{BUILD_SLICE_STEPS, Builder, EllipseParams, Request, SineParams};
use servoplot::motion::interp::{Method, Shape};
use servoplot::motion::job::Job;
use servoplot::settings::Settings;

use crate::{FEED, cost_mark, method_name, report, task};

/// `x/8` plus two chains of 15 and 10 powers of a constant (the nesting allows 16 levels): 84
/// characters, a 95-byte `$F` line over x −30..30.
const HEAVY: &str = "x/8+.5^.5^.5^.5^.5^.5^.5^.5^.5^.5^.5^.5^.5^.5^.5^.5+.5^.5^.5^.5^.5^.5^.5^.5^.5^.5^.5";

fn function(src: &str, x0_mm: f32, x1_mm: f32) -> Request {
    match servoplot::motion::expr::parse(src) {
        Ok(expr) => Request::Function { expr, x0_mm, x1_mm },
        Err(_) => panic!("expression"),
    }
}

fn sine(amplitude_mm: f32, omega_rad_per_mm: f32, length_mm: f32) -> Request {
    Request::Sine(SineParams { amplitude_mm, omega_rad_per_mm, phase_deg: 0.0, length_mm })
}

/// The build cases: every kind the builder walks; sines and functions both flat (about a step
/// per X step) and steep (many steps per X step), and functions of growing size, so that the
/// runner can tell the cost of a step from that of an evaluation and of an operation. The last
/// is about the costliest step a G-code line can ask for: a flat function whose every step
/// evaluates 25 general powers (57 operations; the line's 96 bytes allow few more).
fn cases() -> [(&'static str, Request); 13] {
    [
        ("b-circle", Request::Ellipse(EllipseParams::circle(20.0, 0.0, 360.0))),
        ("b-arc", Request::Ellipse(EllipseParams::circle(20.0, 30.0, -120.0))),
        ("b-ellipse", Request::Ellipse(EllipseParams { a_mm: 30.0, b_mm: 15.0, start_deg: 0.0, sweep_deg: 360.0 })),
        ("b-sine-flat", sine(1.0, 0.3, 60.0)),
        ("b-sine", sine(10.0, 0.3, 60.0)),
        ("b-sine-steep", sine(100.0, 0.3, 60.0)),
        ("b-fn3", function("x/8", -30.0, 30.0)),
        ("b-fn6", function("sin(x)*x/10", -30.0, 30.0)),
        ("b-fn9", function("20*exp(-x^2/200)", -30.0, 30.0)),
        ("b-fn-steep", function("sin(x/2)*100", -30.0, 30.0)),
        ("b-fn18", function("x/9+sin(x/2)*2+cos(x/3)*3+x^2/900", -30.0, 30.0)),
        ("b-fn30", function("x/9+sin(x/2)*2+cos(x/3)*3+x^2/900+exp(-x^2/99)+sqrt(x+31)/4", -30.0, 30.0)),
        ("b-fn-heavy", function(HEAVY, -30.0, 30.0)),
    ]
}

/// Functions of growing size through the motion task: how its cost per step grows with the
/// expression. Flat, so each step is about one evaluation.
fn motion_functions() -> [(&'static str, Request); 4] {
    [
        ("m-fn3", function("x/8", -30.0, 30.0)),
        ("m-fn10", function("x/8+sin(x/3)/3", -30.0, 30.0)),
        ("m-fn18", function("x/8+sin(x/3)/3+cos(x/4)/2+x^2/2000", -30.0, 30.0)),
        ("m-fn30", function("x/8+sin(x/3)/3+cos(x/4)/2+x^2/2000+exp(-x^2/99)+sqrt(x+31)/4", -30.0, 30.0)),
    ]
}

fn builder(request: &Request, settings: &Settings) -> Builder {
    match Builder::new(request, Point::ORIGIN, settings) {
        Ok(Some(b)) => b,
        _ => panic!("build case refused"),
    }
}

/// Walks `b` to its end in slices, as the front ends do, each slice measured on its own; its X
/// steps and expression size.
fn walk(name: &str, method: Method, mut b: Builder) -> (u64, u8) {
    let mut x_steps = 0u64;
    loop {
        cost_mark();
        let slice = advance(&mut b);
        cost_mark();
        report("slice", name, method, u64::from(slice.steps));
        x_steps += u64::from(slice.x_steps);
        if slice.done {
            if b.finish().is_err() {
                panic!("build case refused when walked");
            }
            return (x_steps, slice.expr_ops);
        }
    }
}

/// One slice, as the front ends walk it.
#[inline(never)]
fn advance(b: &mut Builder) -> servoplot::motion::drawing::Slice {
    b.advance(BUILD_SLICE_STEPS)
}

/// Every case whose name contains `only`, with both methods.
pub fn runs(only: &str) {
    for (name, request) in cases() {
        if !name.contains(only) {
            continue;
        }
        for method in [Method::Classic, Method::Diagonal] {
            let settings = Settings { method, ..Settings::default() };
            let b = builder(&request, &settings);
            let kind = b.kind().name();
            let (x_steps, ops) = walk(name, method, b);
            hprintln!("walked {} {} {} {} {}", name, method_name(method), kind, x_steps, ops);
        }
    }
    for (name, request) in motion_functions() {
        if !name.contains(only) {
            continue;
        }
        for method in [Method::Classic, Method::Diagonal] {
            let settings = Settings { method, ..Settings::default() };
            let drawing = match servoplot::motion::drawing::build(&request, Point::ORIGIN, &settings) {
                Ok(Some(d)) => d,
                _ => panic!("motion case refused"),
            };
            let shape = drawing.shape().clone();
            task::measure(name, method_name(method), Job::draw(drawing, FEED), &settings);
            motion_facts(name, method, &shape, &settings);
        }
    }
    // The motion benchmark's functions too (`main.rs`), measured there.
    for (name, shape) in crate::cases() {
        if name.contains(only) {
            for method in [Method::Classic, Method::Diagonal] {
                motion_facts(name, method, &shape, &Settings { method, ..Settings::default() });
            }
        }
    }
}

/// For a function's case through the motion task: its X steps (one evaluation each) and its
/// expression's size (`motion ...`).
fn motion_facts(name: &str, method: Method, shape: &Shape, settings: &Settings) {
    if let Shape::Function { expr, x0_mm, x1_mm } = shape {
        let x_steps = settings.mm_to_steps(servoplot::geom::Axis::X, x1_mm - x0_mm).unsigned_abs();
        hprintln!("motion {} {} {} {}", name, method_name(method), x_steps, expr.op_count());
    }
}

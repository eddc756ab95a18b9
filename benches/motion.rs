//! Motion benchmark: accuracy, plot time and host CPU cost of the interpolators and the planner.
//!
//! `cargo bench --target host-tuple --bench motion` prints, as Markdown tables:
//!
//! 1. For every curve the machine draws and both interpolation methods: the largest deviation of
//!    a visited lattice point from the ideal curve (computed here from the geometry, not taken
//!    from the interpolators), the number of steps, the plot time through the real planner at the
//!    default settings, and the host CPU time per step of the interpolator alone and of
//!    interpolator + planner. Then the seed's method (classic steps at the constant start rate
//!    `$201`, no speed profile) side by side with diagonal steps + speed profile, and both methods
//!    where the pulse rate `$205` binds.
//! 2. A deterministic polyline drawing (an Archimedean spiral of 2,000 short segments, stroke
//!    letters and a zig-zag hatch) pushed segment by segment as the motion task does: plot time
//!    with look-ahead, without (every segment alone, stopping at every joint), the seed's time,
//!    and `plot_time_lower_bound`.
//!
//! 3. For one large drawing of each kind, the highest max pulse rate (`$205`) at which the
//!    STM32F407 keeps up, with its processor modelled in the simulator (`-- --rates` runs this
//!    table alone).
//!
//! What the motion path costs on the target's own instruction set is counted by the cost
//! harness (`cost/`), not here: these host timings are only an indication.

#[path = "motion/polyline.rs"]
mod polyline;
#[path = "motion/rates.rs"]
mod rates;

use std::hint::black_box;
use std::time::Instant;

use servoplot::geom::{Point, Rotation, TICK_HZ};
use servoplot::motion::expr;
use servoplot::motion::interp::{Curve, Interpolator, Method, Shape};
use servoplot::motion::job::Feed;

use servoplot::motion::planner::{Limits, PLANNER_SEGMENTS, Planner, plot_time_lower_bound};
use servoplot::settings::Settings;

/// Feed of every drawing in the benchmark, mm/min (the default `$203`).
const DRAW_FEED_MM_PER_MIN: f32 = 3_000.0;
const DRAW_FEED: Feed = Feed::MmPerMin(DRAW_FEED_MM_PER_MIN);

/// Where the pulse rate binds: a feed at the axes' max rate and a lower `$205`, as for
/// optocouplers that only manage 10 kHz.
const FAST_FEED: Feed = Feed::MmPerMin(6_000.0);
const SLOW_PULSE_RATE_HZ: f32 = 10_000.0;

/// Steps per millimetre assumed when the benchmark's shapes are written in steps (the default
/// `$100`/`$101`); checked against the settings at start.
const SPM: f64 = 100.0;

/// Busy time before the first measurement, ms.
const WARM_UP_MS: u128 = 300;
/// Timed samples per measurement; the median is reported.
const SAMPLES: usize = 7;
/// Each sample repeats its workload until at least this many steps are timed.
const MIN_STEPS_PER_SAMPLE: u64 = 60_000;

/// Search window around a point for the nearest point of an explicit curve, in steps along X
/// (a visited point lies within about one step of the curve).
const EXPLICIT_WINDOW_STEPS: f64 = 3.0;
/// Samples across that window before the local minimisation.
const EXPLICIT_SAMPLES: usize = 121;
/// Search window around the parametric angle of a point for the nearest ellipse point, rad.
const ELLIPSE_WINDOW_RAD: f64 = 0.02;
const ELLIPSE_SAMPLES: usize = 81;
/// Relative precision of an explicit curve's values, computed in `f32` on the target (2⁻²¹:
/// a few `f32` roundings).
const F32_VALUE_PRECISION: f64 = 1.0 / (1u64 << 21) as f64;
/// Golden-section rounds of the local minimisation (the bracket shrinks by 0.618 each round).
const GOLDEN_ROUNDS: usize = 80;

/// The ideal curve a case should follow, in steps, relative to the pen's start at the origin.
#[derive(Clone, Copy)]
enum Ideal {
    /// The segment from the origin to `(dx, dy)`.
    Line { dx: f64, dy: f64 },
    /// A circle (full or arc) around `(cx, cy)`.
    Circle { cx: f64, cy: f64, r: f64 },
    /// An axis-aligned ellipse around `(cx, cy)`.
    Ellipse { cx: f64, cy: f64, a: f64, b: f64 },
    /// `y = g(x) − g(0)` for x from 0 to `len` (steps).
    Explicit { g: fn(f64) -> f64, len: f64 },
}

/// One curve of the benchmark.
struct CurveCase {
    what: &'static str,
    shape: fn() -> Shape,
    ideal: Ideal,
}

fn gauss_mm(x: f64) -> f64 {
    20.0 * (-x * x / 200.0).exp()
}
fn cubic_mm(x: f64) -> f64 {
    x * x * x / 400.0
}
/// The function curves in steps: x in steps from the start at x0 = −30 mm.
fn gauss_steps(xs: f64) -> f64 {
    SPM * gauss_mm(-30.0 + xs / SPM)
}
fn cubic_steps(xs: f64) -> f64 {
    SPM * cubic_mm(-30.0 + xs / SPM)
}
/// Sine of A = 10 mm, ω = 0.3 rad/mm, in steps.
fn sine_steps(xs: f64) -> f64 {
    1_000.0 * (0.003 * xs).sin()
}

fn cases() -> Vec<CurveCase> {
    // Lines are 50 mm long; the end is the nearest lattice point.
    let line = |deg: f64| {
        let r = deg.to_radians();
        ((5_000.0 * r.cos()).round(), (5_000.0 * r.sin()).round())
    };
    let (l30x, l30y) = line(30.0);
    let (l45x, l45y) = line(45.0);
    vec![
        CurveCase {
            what: "line 0°, 50 mm",
            shape: || Shape::Straight { to: Point::new(5_000, 0) },
            ideal: Ideal::Line { dx: 5_000.0, dy: 0.0 },
        },
        CurveCase {
            what: "line 30°, 50 mm",
            shape: || Shape::Straight { to: Point::new(4_330, 2_500) },
            ideal: Ideal::Line { dx: l30x, dy: l30y },
        },
        CurveCase {
            what: "line 45°, 50 mm",
            shape: || Shape::Straight { to: Point::new(3_536, 3_536) },
            ideal: Ideal::Line { dx: l45x, dy: l45y },
        },
        CurveCase {
            what: "circle r 20 mm",
            shape: || Shape::Arc {
                center: Point::new(-2_000, 0),
                to: Point::ORIGIN,
                rotation: Rotation::CounterClockwise,
            },
            ideal: Ideal::Circle { cx: -2_000.0, cy: 0.0, r: 2_000.0 },
        },
        CurveCase {
            what: "arc r 20 mm, 120° cw",
            // From angle 0 clockwise to −120°: the end (−3000, −1732) is 0.02 step off the circle.
            shape: || Shape::Arc {
                center: Point::new(-2_000, 0),
                to: Point::new(-3_000, -1_732),
                rotation: Rotation::Clockwise,
            },
            ideal: Ideal::Circle { cx: -2_000.0, cy: 0.0, r: 2_000.0 },
        },
        CurveCase {
            what: "ellipse a 30, b 15 mm",
            shape: || Shape::Ellipse {
                center: Point::new(-3_000, 0),
                a_steps: 3_000,
                b_steps: 1_500,
                to: Point::ORIGIN,
                rotation: Rotation::CounterClockwise,
            },
            ideal: Ideal::Ellipse { cx: -3_000.0, cy: 0.0, a: 3_000.0, b: 1_500.0 },
        },
        CurveCase {
            what: "sine A 10 mm, ω 0.3/mm, 60 mm",
            shape: || Shape::Sine {
                amplitude_steps: 1_000.0,
                omega_rad_per_step: 0.003,
                phase_rad: 0.0,
                length_steps: 6_000,
            },
            ideal: Ideal::Explicit { g: sine_steps, len: 6_000.0 },
        },
        CurveCase {
            what: "y = 20·exp(−x²/200), x −30..30",
            shape: || Shape::Function { expr: parse("20*exp(-x^2/200)"), x0_mm: -30.0, x1_mm: 30.0 },
            ideal: Ideal::Explicit { g: gauss_steps, len: 6_000.0 },
        },
        CurveCase {
            what: "y = x³/400, x −30..30",
            shape: || Shape::Function { expr: parse("x^3/400"), x0_mm: -30.0, x1_mm: 30.0 },
            ideal: Ideal::Explicit { g: cubic_steps, len: 6_000.0 },
        },
    ]
}

fn parse(src: &str) -> expr::Expr {
    match expr::parse(src) {
        Ok(e) => e,
        Err(e) => panic!("benchmark expression {src:?} does not parse: {e:?}"),
    }
}

fn method_name(m: Method) -> &'static str {
    match m {
        Method::Classic => "classic",
        Method::Diagonal => "diagonal",
    }
}

fn settings_for(method: Method) -> Settings {
    Settings { method, ..Settings::default() }
}

fn build(case: &CurveCase, method: Method) -> Result<Curve, String> {
    Curve::new(&(case.shape)(), Point::ORIGIN, &settings_for(method)).map_err(|e| format!("{e:?}"))
}

/// Where the builder says the curve ends: its last lattice point.
fn built_end(case: &CurveCase, method: Method) -> Result<Point, String> {
    let drawing = servoplot::motion::drawing::from_shape((case.shape)(), Point::ORIGIN, &settings_for(method));
    drawing.map(|d| d.end()).map_err(|e| format!("{e:?}"))
}

// ---------------------------------------------------------------------------------------------
// Ideal geometry

/// Minimum of `f` over `[lo, hi]`: the best of `samples` evenly spaced values, refined by golden
/// section between its neighbours.
fn minimise(f: impl Fn(f64) -> f64, lo: f64, hi: f64, samples: usize) -> f64 {
    let h = (hi - lo) / (samples - 1) as f64;
    let (mut best_t, mut best) = (lo, f(lo));
    for i in 1..samples {
        let t = lo + h * i as f64;
        let v = f(t);
        if v < best {
            (best_t, best) = (t, v);
        }
    }
    let (mut a, mut b) = ((best_t - h).max(lo), (best_t + h).min(hi));
    let phi = (5f64.sqrt() - 1.0) / 2.0;
    let (mut c, mut d) = (b - phi * (b - a), a + phi * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..GOLDEN_ROUNDS {
        if fc < fd {
            (b, d, fd) = (d, c, fc);
            c = b - phi * (b - a);
            fc = f(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + phi * (b - a);
            fd = f(d);
        }
    }
    best.min(fc).min(fd)
}

/// Distance from lattice point `(px, py)` to the ideal curve, in steps.
fn distance(ideal: Ideal, px: f64, py: f64) -> f64 {
    match ideal {
        Ideal::Line { dx, dy } => (px * dy - py * dx).abs() / dx.hypot(dy),
        Ideal::Circle { cx, cy, r } => ((px - cx).hypot(py - cy) - r).abs(),
        Ideal::Ellipse { cx, cy, a, b } => {
            let (x, y) = (px - cx, py - cy);
            let t0 = (y / b).atan2(x / a);
            let d2 = |t: f64| (a * t.cos() - x).powi(2) + (b * t.sin() - y).powi(2);
            minimise(d2, t0 - ELLIPSE_WINDOW_RAD, t0 + ELLIPSE_WINDOW_RAD, ELLIPSE_SAMPLES).sqrt()
        }
        Ideal::Explicit { g, len } => {
            let g0 = g(0.0);
            let d2 = |x: f64| (x - px).powi(2) + (g(x) - g0 - py).powi(2);
            let (lo, hi) = ((px - EXPLICIT_WINDOW_STEPS).max(0.0), (px + EXPLICIT_WINDOW_STEPS).min(len));
            minimise(d2, lo, hi, EXPLICIT_SAMPLES).sqrt()
        }
    }
}

/// What one walk of a curve visits.
struct Walk {
    steps: u64,
    diagonal_steps: u64,
    /// Steps per axis, for the seed's constant-rate time.
    axis_steps: [u64; 2],
    max_deviation: f64,
    /// The first visited point with the largest deviation, relative to the start.
    worst_at: Point,
    end: Point,
    /// Largest |y| visited, steps: an explicit curve's values are `f32`, exact to 2⁻²¹ of it.
    largest_y: f64,
}

fn walk(mut curve: Curve, ideal: Ideal) -> Walk {
    let mut at = Point::ORIGIN;
    let mut w = Walk {
        steps: 0,
        diagonal_steps: 0,
        axis_steps: [0, 0],
        max_deviation: distance(ideal, 0.0, 0.0),
        worst_at: at,
        end: at,
        largest_y: 0.0,
    };
    loop {
        match curve.next_step() {
            Ok(Some(s)) => {
                at = at.stepped(s);
                w.steps += 1;
                w.diagonal_steps += u64::from(s.is_diagonal());
                w.axis_steps[0] += u64::from(s.x != 0);
                w.axis_steps[1] += u64::from(s.y != 0);
                w.largest_y = w.largest_y.max(f64::from(at.y.unsigned_abs()));
                let d = distance(ideal, f64::from(at.x), f64::from(at.y));
                if d > w.max_deviation {
                    (w.max_deviation, w.worst_at) = (d, at);
                }
            }
            Ok(None) => break,
            Err(e) => panic!("benchmark curve failed part way: {e:?}"),
        }
    }
    w.end = at;
    w
}

/// The seed's plot time: every step at the constant start rate `$201`, no profile, seconds.
fn seed_seconds(settings: &Settings, axis_steps: [u64; 2]) -> f64 {
    let start_mm_per_s = f64::from(settings.start_rate_mm_per_min) / 60.0;
    (0..2).map(|i| axis_steps[i] as f64 / (start_mm_per_s * f64::from(settings.steps_per_mm[i]))).sum()
}

// ---------------------------------------------------------------------------------------------
// Workloads (what is timed)

/// Steps a curve to its end; returns the steps and a checksum.
#[inline(never)]
fn step_all(mut curve: Curve) -> (u64, i64) {
    let (mut n, mut sum) = (0u64, 0i64);
    while let Ok(Some(s)) = curve.next_step() {
        n += 1;
        sum += i64::from(s.x) * 3 + i64::from(s.y);
    }
    (n, sum)
}

/// Plans a curve alone at the drawing feed, from rest to rest, as the pulse task would receive
/// it; returns the steps and the sum of their intervals in ticks.
#[inline(never)]
fn plan_all(curve: Curve, method: Method, limits: Limits) -> (u64, u64) {
    plan_at(curve, DRAW_FEED, method, limits)
}

fn plan_at(curve: Curve, feed: Feed, method: Method, limits: Limits) -> (u64, u64) {
    let mut p = Planner::<Curve, PLANNER_SEGMENTS>::new(limits);
    if p.push(curve, feed, method).is_err() {
        panic!("an empty planner refused a segment");
    }
    drain(&mut p)
}

/// Takes every command the planner has; returns the steps and their ticks.
fn drain(p: &mut Planner<Curve, PLANNER_SEGMENTS>) -> (u64, u64) {
    let (mut n, mut ticks) = (0u64, 0u64);
    while let Some(cmd) = p.next_cmd() {
        match cmd {
            Ok(c) => {
                n += 1;
                ticks += u64::from(c.interval_ticks);
            }
            Err(e) => panic!("benchmark curve failed in the planner: {e:?}"),
        }
    }
    (n, ticks)
}

/// Median host time per step of `run` over [`SAMPLES`] samples, ns. `run` gets a fresh input
/// made by `make` (outside the timed region) and returns the number of steps it took.
fn ns_per_step<T>(make: impl Fn() -> T, run: impl Fn(T) -> u64) -> f64 {
    let steps = run(make()).max(1); // warm-up, and the size of one run
    let reps = MIN_STEPS_PER_SAMPLE.div_ceil(steps) as usize;
    let mut per_step: Vec<f64> = (0..SAMPLES)
        .map(|_| {
            let inputs: Vec<T> = (0..reps).map(|_| make()).collect();
            let t = Instant::now();
            let mut n = 0;
            for input in inputs {
                n += run(black_box(input));
            }
            let elapsed = t.elapsed();
            elapsed.as_nanos() as f64 / n.max(1) as f64
        })
        .collect();
    per_step.sort_by(f64::total_cmp);
    per_step[SAMPLES / 2]
}

// ---------------------------------------------------------------------------------------------
// Part 1: curves

struct CurveRow {
    walk: Walk,
    plot_s: f64,
    interp_ns: f64,
    planned_ns: f64,
    seed_s: f64,
    /// Plot time at [`FAST_FEED`] with `$205` at [`SLOW_PULSE_RATE_HZ`], s.
    fast_slow_pulses_s: f64,
}

fn measure_curve(case: &CurveCase, method: Method) -> Result<CurveRow, String> {
    let settings = settings_for(method);
    let limits = Limits::from_settings(&settings);
    let curve = build(case, method)?;
    let walk = walk(curve.clone(), case.ideal);
    let end = built_end(case, method)?;
    if walk.end != end {
        return Err(format!("ends at {:?}, not at its end {:?}", walk.end, end));
    }
    let (planned_steps, ticks) = plan_all(curve.clone(), method, limits);
    if planned_steps != walk.steps {
        return Err(format!("planner emitted {planned_steps} steps, the curve has {}", walk.steps));
    }
    let interp_ns = ns_per_step(|| curve.clone(), |c| black_box(step_all(c)).0);
    let planned_ns = ns_per_step(|| curve.clone(), |c| black_box(plan_all(c, method, limits)).0);
    let seed_s = seed_seconds(&settings, walk.axis_steps);
    let slow = Limits::from_settings(&Settings { max_pulse_rate_hz: SLOW_PULSE_RATE_HZ, ..settings });
    let fast_slow_pulses_s = plan_at(curve, FAST_FEED, method, slow).1 as f64 / f64::from(TICK_HZ);
    let plot_s = ticks as f64 / f64::from(TICK_HZ);
    Ok(CurveRow { walk, plot_s, interp_ns, planned_ns, seed_s, fast_slow_pulses_s })
}

fn curve_tables() {
    let cases = cases();
    let methods = [Method::Classic, Method::Diagonal];
    let mut rows: Vec<(usize, Method, Result<CurveRow, String>)> = Vec::new();
    for (i, case) in cases.iter().enumerate() {
        for method in methods {
            rows.push((i, method, measure_curve(case, method)));
        }
    }

    println!("### Curves: accuracy, steps, plot time and CPU cost");
    println!();
    println!(
        "Feed F{DRAW_FEED_MM_PER_MIN} mm/min, `Settings::default()`. Deviation: largest distance of a visited \
         lattice point from the ideal curve; (!) marks one beyond the method's bound (1 step classic, 0.5 \
         diagonal), plus for the sine and the functions the f32 precision of their values (2⁻²¹ of the \
         largest |y|)."
    );
    println!();
    println!(
        "| curve | method | max deviation (steps) | at (x, y) (steps from start) | steps | diagonal steps | plot time F3000 (s) | interp (ns/step) | interp + planner (ns/step) |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|");
    for (i, method, row) in &rows {
        let case = &cases[*i];
        match row {
            Ok(r) => {
                let bound = match method {
                    Method::Classic => 1.0,
                    Method::Diagonal => 0.5,
                };
                // Explicit curves compute their values in f32: a row chosen at an exact half step
                // may fall either side by the value's own rounding.
                let slack = match case.ideal {
                    Ideal::Explicit { .. } => r.walk.largest_y * F32_VALUE_PRECISION,
                    _ => 0.0,
                };
                let flag = if r.walk.max_deviation > bound + slack + 1e-9 { " (!)" } else { "" };
                println!(
                    "| {} | {} | {:.4}{} | ({}, {}) | {} | {} | {:.3} | {:.1} | {:.1} |",
                    case.what,
                    method_name(*method),
                    r.walk.max_deviation,
                    flag,
                    r.walk.worst_at.x,
                    r.walk.worst_at.y,
                    r.walk.steps,
                    r.walk.diagonal_steps,
                    r.plot_s,
                    r.interp_ns,
                    r.planned_ns
                );
            }
            Err(e) => println!("| {} | {} | n/a: {e} | | | | | | |", case.what, method_name(*method)),
        }
    }
    println!();

    println!("### Seed method vs diagonal + speed profile");
    println!();
    println!(
        "Seed: classic steps at the constant start rate `$201` = 300 mm/min (500 steps/s), no profile. \
         Profiled: the planner at F3000 mm/min from rest to rest."
    );
    println!();
    println!(
        "| curve | seed: classic, constant 500 steps/s (s) | classic + profile (s) | diagonal + profile (s) | speed-up seed → diagonal + profile |"
    );
    println!("|---|---:|---:|---:|---:|");
    for (i, case) in cases.iter().enumerate() {
        let find = |m: Method| rows.iter().find(|(j, mm, _)| *j == i && *mm == m).and_then(|(_, _, r)| r.as_ref().ok());
        match (find(Method::Classic), find(Method::Diagonal)) {
            (Some(c), Some(d)) => println!(
                "| {} | {:.2} | {:.3} | {:.3} | {:.1}× |",
                case.what,
                c.seed_s,
                c.plot_s,
                d.plot_s,
                c.seed_s / d.plot_s
            ),
            _ => println!("| {} | n/a | n/a | n/a | n/a |", case.what),
        }
    }
    println!();

    println!("### Where diagonal steps pay: when the pulse rate binds");
    println!();
    println!(
        "F6000 mm/min (the axes' max rate) with `$205` = {SLOW_PULSE_RATE_HZ} Hz instead of 20000. Classic \
         moves one axis per step, so a slanted path takes up to √2 times the steps per mm and meets the \
         pulse-rate cap first."
    );
    println!();
    println!("| curve | classic (s) | diagonal (s) | classic / diagonal |");
    println!("|---|---:|---:|---:|");
    for (i, case) in cases.iter().enumerate() {
        let find = |m: Method| rows.iter().find(|(j, mm, _)| *j == i && *mm == m).and_then(|(_, _, r)| r.as_ref().ok());
        if let (Some(c), Some(d)) = (find(Method::Classic), find(Method::Diagonal)) {
            println!(
                "| {} | {:.3} | {:.3} | {:.2} |",
                case.what,
                c.fast_slow_pulses_s,
                d.fast_slow_pulses_s,
                c.fast_slow_pulses_s / d.fast_slow_pulses_s
            );
        }
    }
    println!();
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "--rates") {
        rates::table();
        return;
    }
    let s = Settings::default();
    assert_eq!(s.steps_per_mm, [SPM as f32; 2], "the benchmark's shapes assume the default steps/mm");
    let started = Instant::now();
    // Wakes the CPU up to its working clock before anything is timed.
    let warm = build(&cases()[0], Method::Diagonal).unwrap_or_else(|e| panic!("warm-up line: {e}"));
    while started.elapsed().as_millis() < WARM_UP_MS {
        black_box(plan_all(warm.clone(), Method::Diagonal, Limits::from_settings(&s)));
    }
    println!(
        "Settings: {} steps/mm, start rate {} mm/min, max rate {} mm/min, acceleration {} mm/s², \
         max pulse rate {} Hz, junction deviation {} mm; ticks at {} Hz.",
        s.steps_per_mm[0],
        s.start_rate_mm_per_min,
        s.max_rate_mm_per_min[0],
        s.accel_mm_per_s2[0],
        s.max_pulse_rate_hz,
        s.junction_deviation_mm,
        TICK_HZ
    );
    println!();
    curve_tables();
    polyline::table();
    rates::table();
    eprintln!("benchmark took {:.1} s", started.elapsed().as_secs_f64());
}

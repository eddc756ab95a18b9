//! Where the pen is, who says so, and where it may go, on the simulated board:
//!
//! - the position the G-code parser plans from is the position the pulses reach, whatever the
//!   commands, holds, resets and jog cancels: at the end of a session the parser plans from the
//!   pen (read back through `G92` and `$#`), and a last `G90 G0 X0 Y0` ends at machine (0, 0),
//!   exactly;
//! - a drawing typed on the keypad emits the very steps of the same drawing sent from the PC;
//! - no curve takes the pen outside the travel limits, however flat, large, small or steep.

use std::f32::consts::TAU;

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use servoplot::decimal::{Syntax, parse_prefix};
use servoplot::geom::Point;
use servoplot::panel::FunctionPreset;
use servoplot::sim::{self, SimConfig, SimReport, serial::SimSerial};

// ----- helpers ------------------------------------------------------------------------------

/// A length or angle given in thousandths, as G-code text: `-0.005`, `39`, `12.34`.
fn num(thousandths: i32) -> String {
    let sign = if thousandths < 0 { "-" } else { "" };
    let a = thousandths.unsigned_abs();
    let (int, frac) = (a / 1000, a % 1000);
    if frac == 0 {
        format!("{sign}{int}")
    } else {
        let frac = format!("{frac:03}");
        format!("{sign}{int}.{}", frac.trim_end_matches('0'))
    }
}

/// A value in thousandths from a float (mm, degrees).
fn thousandths(v: f64) -> i32 {
    (v * 1000.0).round() as i32
}

/// Deterministic property runs: a fixed seed, nothing written to disk, bounded shrinking.
fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(0x5e7f_0b1e),
        max_shrink_iters: 48,
        ..ProptestConfig::default()
    }
}

/// The answers without the banner's blank line, one per line.
fn answer_lines(report: &SimReport) -> Vec<String> {
    report.answers().lines().map(str::to_owned).filter(|l| !l.is_empty()).collect()
}

/// The smallest and largest X and Y the pen passed through, in steps.
fn bounds(path: &[Point]) -> (i32, i32, i32, i32) {
    path.iter().fold((i32::MAX, i32::MIN, i32::MAX, i32::MIN), |(x0, x1, y0, y1), p| {
        (x0.min(p.x), x1.max(p.x), y0.min(p.y), y1.max(p.y))
    })
}

// ----- 1. the parser's planned position is the pulses' position -----------------------------

/// A realtime byte sent while the session runs, at a virtual time.
#[derive(Clone, Debug)]
enum Realtime {
    /// Ctrl-X: decelerate, drop everything, answer with the banner.
    Reset { at_ms: u64 },
    /// `!`, then `~` after `for_ms`.
    Hold { at_ms: u64, for_ms: u64 },
    /// 0x85: stops a jog in progress.
    JogCancel { at_ms: u64 },
}

/// What follows every session: the parser is asked where it plans the pen (`G92 X0 Y0` makes
/// its planned position the work offset, which `$#` reports, and `G92.1` clears it again), the
/// machine comes to rest and waits, then goes home to machine (0, 0).
const TAIL: [&str; 5] = ["G92 X0 Y0", "$#", "G92.1", "G4 P2.5", "G90 G0 X0 Y0"];
/// The dwell of the tail, less a margin: a pause this long in the pulses is that dwell.
const TAIL_DWELL_US: u64 = 2_000_000;
/// The home lines are sent once more, by hand, long after the session is over: after a reset
/// the sender stops streaming, a line arriving while a jog runs is refused (`error:9`), and a
/// jog cancel drops what was queued behind the jog. Sessions are far shorter than this.
const HOME_AGAIN: [&str; 2] = ["G92.1", "G90 G0 X0 Y0"];
const HOME_AGAIN_US: u64 = 60_000_000;

fn run_session(lines: &[String], realtime: &[Realtime]) -> SimReport {
    let text: String = lines.iter().map(String::as_str).chain(TAIL).map(|l| format!("{l}\n")).collect();
    let mut serial = SimSerial::with_input(text.as_bytes());
    for event in realtime {
        serial = match *event {
            Realtime::Reset { at_ms } => serial.with_byte_at(at_ms * 1000, 0x18),
            Realtime::Hold { at_ms, for_ms } => {
                serial.with_byte_at(at_ms * 1000, b'!').with_byte_at((at_ms + for_ms) * 1000, b'~')
            }
            Realtime::JogCancel { at_ms } => serial.with_byte_at(at_ms * 1000, 0x85),
        };
    }
    // All at one instant: the lines arrive whole and in order.
    for line in HOME_AGAIN {
        for b in line.bytes().chain([b'\n']) {
            serial = serial.with_byte_at(HOME_AGAIN_US, b);
        }
    }
    sim::run(SimConfig { serial, ..SimConfig::default() })
}

/// Where the pulses emitted before `t_us` took the pen.
fn position_before(report: &SimReport, t_us: u64) -> Point {
    report
        .trace
        .steps(report.settings.dir_invert_mask)
        .iter()
        .take_while(|(t, _)| *t < t_us)
        .fold(Point::ORIGIN, |p, (_, s)| p.stepped(*s))
}

/// Where the pen was when the tail's dwell began: before the last pause of at least
/// [`TAIL_DWELL_US`] in the pulses (none: the home line did not move the pen).
fn position_at_dwell(report: &SimReport) -> Point {
    let times: Vec<u64> = report.trace.pulses.iter().map(|p| p.t_us).filter(|&t| t < HOME_AGAIN_US).collect();
    let end = times.windows(2).rposition(|w| w[1] - w[0] >= TAIL_DWELL_US).map_or(HOME_AGAIN_US, |i| times[i] + 1);
    position_before(report, end)
}

/// The work offset `$#` reported (`[G92:x,y,z]`), in mm.
fn reported_offset(answers: &[String]) -> Option<[f64; 2]> {
    let line = answers.iter().find_map(|a| a.strip_prefix("[G92:"))?;
    let mut v = line.trim_end_matches(']').split(',').map(|n| n.parse::<f64>().ok());
    Some([v.next()??, v.next()??])
}

/// A length in thousandths of a mm: often tiny (a few hundredths of a step up to a few steps),
/// otherwise up to `max` mm either way.
fn length(max_mm: i32) -> impl Strategy<Value = i32> {
    prop_oneof![1 => -30..=30i32, 3 => -max_mm * 1000..=max_mm * 1000]
}

fn feed_word() -> impl Strategy<Value = String> {
    prop_oneof![Just(String::new()), (1000..=4000u32).prop_map(|f| format!(" F{f}"))]
}

/// `G90`/`G91` with `G0`/`G1`, X and/or Y.
fn straight_line() -> impl Strategy<Value = String> {
    (any::<bool>(), any::<bool>(), length(20), length(20), 0..3u8, feed_word()).prop_map(
        |(incremental, feed_move, x, y, which, feed)| {
            let (x, y) = if incremental { (x / 2, y / 2) } else { (x, y) };
            let axes = match which {
                0 => format!("X{}", num(x)),
                1 => format!("Y{}", num(y)),
                _ => format!("X{} Y{}", num(x), num(y)),
            };
            let mode = if incremental { "G91" } else { "G90" };
            if feed_move { format!("{mode} G1 {axes}{feed}") } else { format!("{mode} G0 {axes}") }
        },
    )
}

/// `G2`/`G3` with I, J: the pen is on the circle at angle `from_deg` seen from the centre, the
/// end at `to_deg` (or the start: a full circle). Written incremental, so it holds wherever
/// the pen is.
fn arc_ij() -> impl Strategy<Value = String> {
    (any::<bool>(), 500..=10_000i32, 0..360i32, 0..360i32, any::<bool>()).prop_map(|(cw, r, from_deg, to_deg, full)| {
        let r = r as f64 / 1000.0;
        let (from, to) = ((from_deg as f64).to_radians(), (to_deg as f64).to_radians());
        let (i, j) = (-r * from.cos(), -r * from.sin());
        let (x, y) = if full { (0.0, 0.0) } else { (i + r * to.cos(), j + r * to.sin()) };
        format!(
            "G91 G{} X{} Y{} I{} J{}",
            if cw { 2 } else { 3 },
            num(thousandths(x)),
            num(thousandths(y)),
            num(thousandths(i)),
            num(thousandths(j))
        )
    })
}

/// `G2`/`G3` with R (negative: the arc longer than half a circle).
fn arc_r() -> impl Strategy<Value = String> {
    (any::<bool>(), 500..=10_000i32, 0..360i32, 10..=5000i32, any::<bool>()).prop_map(
        |(cw, chord, dir_deg, extra, long)| {
            let d = chord as f64 / 1000.0;
            let dir = (dir_deg as f64).to_radians();
            let (x, y) = (thousandths(d * dir.cos()), thousandths(d * dir.sin()));
            let chord = ((x as f64).hypot(y as f64)) / 1000.0;
            // Rounded up, and a little more: never shorter than half the chord as written.
            let r = ((chord / 2.0) * 1000.0).ceil() as i32 + 10 + extra;
            format!("G91 G{} X{} Y{} R{}", if cw { 2 } else { 3 }, num(x), num(y), num(if long { -r } else { r }))
        },
    )
}

fn circle_command() -> impl Strategy<Value = String> {
    (500..=10_000i32, -360_000..=360_000i32, -360_000..=360_000i32, any::<bool>(), feed_word()).prop_map(
        |(r, s, w, full, feed)| {
            let sweep = if full { String::new() } else { format!(" W{}", num(w)) };
            format!("$O R{} S{}{sweep}{feed}", num(r), num(s))
        },
    )
}

fn ellipse_command() -> impl Strategy<Value = String> {
    (200..=10_000i32, prop_oneof![10..=200i32, 200..=10_000i32], -360_000..=360_000i32, -360_000..=360_000i32)
        .prop_map(|(a, b, s, w)| format!("$E A{} B{} S{} W{}", num(a), num(b), num(s), num(w)))
}

fn sine_command() -> impl Strategy<Value = String> {
    let nonzero_length = prop_oneof![5..=10_000i32, -10_000..=-5i32];
    (-4000..=4000i32, 50..=1500i32, nonzero_length, -90_000..=90_000i32)
        .prop_map(|(a, w, l, p)| format!("$S A{} W{} L{} P{}", num(a), num(w), num(l), num(p)))
}

/// `$F` with an expression defined over the whole range drawn: (expression, domain in mm).
const FUNCTIONS: [(&str, f64, f64); 4] =
    [("sqrt(x)", 0.0, 15.0), ("acos(x/20)*5", -20.0, 20.0), ("x^2/40", -20.0, 20.0), ("sin(x)*3", -20.0, 20.0)];

fn function_command() -> impl Strategy<Value = String> {
    let span = prop_oneof![1 => prop_oneof![Just(5), Just(10), Just(15), Just(10_005)], 3 => 5..=10_000i32];
    (0..FUNCTIONS.len(), 0.0..1.0f64, span, any::<bool>(), 0..4u8).prop_map(|(k, at, span, leftwards, edge)| {
        let (expr, lo, hi) = FUNCTIONS[k];
        let (lo, hi) = (thousandths(lo), thousandths(hi));
        let x0 = lo + ((hi - lo) as f64 * at) as i32;
        let x1 = match (edge, leftwards) {
            // Now and then right up to the edge of the domain, where the curve is steepest.
            (0, true) => lo,
            (0, false) => hi,
            (_, true) => (x0 - span).max(lo),
            (_, false) => (x0 + span).min(hi),
        };
        let x1 = if x1 == x0 { if x0 > lo { x0 - 5 } else { x0 + 5 } } else { x1 };
        format!("$F X{} U{} Y={expr}", num(x0), num(x1))
    })
}

fn jog_command() -> impl Strategy<Value = String> {
    (length(10), length(10)).prop_map(|(x, y)| format!("$J=G91 X{} Y{} F1000", num(x), num(y)))
}

fn command() -> impl Strategy<Value = String> {
    prop_oneof![
        3 => straight_line(),
        1 => arc_ij(),
        1 => arc_r(),
        1 => circle_command(),
        1 => ellipse_command(),
        1 => sine_command(),
        3 => function_command(),
        1 => jog_command(),
    ]
}

fn realtime() -> impl Strategy<Value = Realtime> {
    prop_oneof![
        (50..4000u64).prop_map(|at_ms| Realtime::Reset { at_ms }),
        (50..4000u64, 100..1500u64).prop_map(|(at_ms, for_ms)| Realtime::Hold { at_ms, for_ms }),
        (50..4000u64).prop_map(|at_ms| Realtime::JogCancel { at_ms }),
    ]
}

fn session_text(lines: &[String], events: &[Realtime], report: &SimReport) -> String {
    let mut s = String::from("lines:\n");
    for l in lines.iter().map(String::as_str).chain(TAIL) {
        s += &format!("    {l}\n");
    }
    s += &format!("realtime: {events:?}\n");
    s += &format!("pen when the tail's dwell began: {:?}\n", position_at_dwell(report));
    s += &format!("pen before the home lines were sent again: {:?}\n", position_before(report, HOME_AGAIN_US));
    s += &format!("final position (steps): {:?}\n", report.position);
    s += &format!("answers: {:?}\n", answer_lines(report));
    s
}

proptest! {
    #![proptest_config(config(40))]

    /// Whatever was drawn, held, reset or cancelled, the parser plans from where the pulses
    /// take the pen, and nothing else keeps its own idea of the position: the parser's planned
    /// position at the end of a session is the pen's (within the half step a millimetre
    /// position rounds by), a streamed `G90 G0 X0 Y0` ends exactly at machine (0, 0), and so does
    /// one sent at the very end.
    #[test]
    fn position_has_one_owner(
        lines in prop::collection::vec(command(), 3..=8),
        events in prop::collection::vec(realtime(), 0..=2),
    ) {
        let report = run_session(&lines, &events);
        let context = || session_text(&lines, &events, &report);
        prop_assert!(!report.timed_out, "did not come to rest\n{}", context());
        // The harness's own assumption: the session was over well before the home lines were
        // sent again.
        let last_before = report.trace.pulses.iter().map(|p| p.t_us).rfind(|&t| t < HOME_AGAIN_US);
        prop_assume!(last_before.is_none_or(|t| t + 10_000_000 < HOME_AGAIN_US));
        let path = report.path();
        prop_assert_eq!(report.position, *path.last().unwrap(), "position counted and pulses differ\n{}", context());

        // Without a reset or a jog cancel (which drop what is queued and cut the stream), with
        // at most one hold (shorter than the tail's dwell), and no curve stopped part way (which
        // drops the moves queued behind it, as documented), every line was answered in order.
        let answers = answer_lines(&report);
        let verdicts: Vec<&String> = answers.iter().filter(|a| *a == "ok" || a.starts_with("error:")).collect();
        let holds = events.iter().filter(|e| matches!(e, Realtime::Hold { .. })).count();
        let undisturbed = holds == events.len()
            && holds <= 1
            && !answers.iter().any(|a| a.starts_with("[MSG:Curve stopped"));
        if undisturbed {
            let n = lines.len();
            prop_assert_eq!(verdicts.len(), n + TAIL.len() + HOME_AGAIN.len(), "one answer per line\n{}", context());
            if verdicts[n] == "ok" {
                // `G92 X0 Y0` was taken: the offset `$#` reported is the planned position.
                let planned = reported_offset(&answers);
                prop_assert!(planned.is_some(), "no [G92:] in the answers\n{}", context());
                let planned = planned.unwrap();
                let pen = position_at_dwell(&report);
                let off = [planned[0] * 100.0 - pen.x as f64, planned[1] * 100.0 - pen.y as f64];
                prop_assert!(
                    off[0].abs() <= 0.501 && off[1].abs() <= 0.501,
                    "the parser plans from ({:.3}, {:.3}) mm, the pulses left the pen at {:?} steps: {:.1}, {:.1} steps apart\n{}",
                    planned[0],
                    planned[1],
                    pen,
                    off[0],
                    off[1],
                    context()
                );
            }
            if *verdicts[n + TAIL.len() - 1] == "ok" {
                let streamed = position_before(&report, HOME_AGAIN_US);
                prop_assert_eq!(
                    streamed,
                    Point::ORIGIN,
                    "the streamed home line ended at {:?}, not at machine (0, 0)\n{}",
                    streamed,
                    context()
                );
            }
        }
        prop_assert_eq!(report.position, Point::ORIGIN, "the pen did not end at machine (0, 0)\n{}", context());
    }
}

/// Four functions over half a step each from (39, 5.6), then 10 mm to the
/// right, must end at X 49.000 mm.
#[test]
fn position_has_one_owner_after_half_step_functions() {
    let f = "$F X0 U0.005 Y=acos(x/20)*5\n";
    let session = format!("G1 X39 Y5.6\n{f}{f}{f}{f}G91 G1 X10\n");
    let report = sim::run_serial(&session);
    assert!(!report.timed_out);
    assert_eq!(
        report.position.x,
        4900,
        "X must end at 49.000 mm, not {} mm; position {:?}; answers {:?}",
        report.position.x as f64 / 100.0,
        report.position,
        answer_lines(&report)
    );
}

/// The same session going on: back to the origin, a function over 10.005 mm, and home: the
/// pen ends exactly at (0, 0).
#[test]
fn position_has_one_owner_after_a_function_ending_half_way_between_steps() {
    let f = "$F X0 U0.005 Y=acos(x/20)*5\n";
    let session = format!("G1 X39 Y5.6\n{f}{f}{f}{f}G91 G1 X10\nG90 G1 X0 Y0\n$F X0 U10.005 Y=sqrt(x)\nG90 G0 X0 Y0\n");
    let report = sim::run_serial(&session);
    assert!(!report.timed_out);
    assert_eq!(report.position, Point::ORIGIN, "answers {:?}", answer_lines(&report));
    // The same from a fresh start.
    let report = sim::run_serial("G90 G1 X0 Y0\n$F X0 U10.005 Y=sqrt(x)\nG90 G0 X0 Y0\n");
    assert_eq!(report.position, Point::ORIGIN, "answers {:?}", answer_lines(&report));
}

/// A function whose range is not a whole number of X steps (10.003 mm, 1000 columns) ends at
/// its last column, x1: the parser must plan on from that point, so an X-only move afterwards
/// leaves Y where the pen is.
#[test]
fn position_has_one_owner_after_a_function_ending_between_columns() {
    let drawn = sim::run_serial("G1 X20 Y20\n$F X10.005 U0.002 Y=sqrt(x)\n");
    let then = sim::run_serial("G1 X20 Y20\n$F X10.005 U0.002 Y=sqrt(x)\nG1 X1\n");
    assert!(!drawn.timed_out && !then.timed_out);
    assert_eq!(
        then.position,
        Point::new(100, drawn.position.y),
        "the function left the pen at {:?}; G1 X1 must move X only; answers {:?}",
        drawn.position,
        answer_lines(&then)
    );
}

// ----- 2. keypad and G-code draw the same steps ----------------------------------------------

/// The keys that type `value` into a number field: digits, `*` for the point, `A` for the
/// sign; empty for an empty field (its default).
fn typed(value: &str) -> String {
    let mut keys: Vec<String> = Vec::new();
    let digits = match value.strip_prefix('-') {
        Some(rest) => {
            keys.push("A".into());
            rest
        }
        None => value,
    };
    for c in digits.chars() {
        keys.push(if c == '.' { "*".into() } else { c.to_string() });
    }
    keys.join(" ")
}

/// The keys of a form: its mode digit, then every field typed and confirmed with `#`, and `#`
/// to draw what the preview shows.
fn form_keys(mode: u8, fields: &[&str]) -> String {
    let mut keys = mode.to_string();
    for field in fields {
        let t = typed(field);
        if !t.is_empty() {
            keys.push(' ');
            keys.push_str(&t);
        }
        keys.push_str(" #");
    }
    keys.push_str(" #");
    keys
}

/// The value the keypad reads from `text` (as the number entry computes it: the digits as an
/// integer over a power of ten).
fn keypad_value(text: &str) -> f32 {
    let (negative, digits) = match text.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, text),
    };
    let decimals = digits.split_once('.').map_or(0, |(_, f)| f.len());
    let mantissa: u32 = digits.replace('.', "").parse().unwrap();
    let v = mantissa as f32 / 10f32.powi(decimals as i32);
    if negative { -v } else { v }
}

/// `v` with 9 significant digits, in plain decimal notation (G-code words take no exponent).
fn nine_digits(v: f32) -> String {
    let magnitude = (v.abs() as f64).log10().floor() as i32;
    let decimals = (8 - magnitude).max(0) as usize;
    format!("{v:.decimals$}")
}

/// One drawing, typed on the keypad and written as G-code, from the same start point.
struct SameDrawing {
    name: String,
    keys: String,
    gcode: String,
}

/// Moves the pen to `start` (mm from the origin) first, on both sides, unless it is the origin.
fn from_start(start: (&str, &str), name: String, keys: String, gcode: String) -> SameDrawing {
    if start == ("0", "0") {
        return SameDrawing { name, keys, gcode };
    }
    let (x, y) = start;
    SameDrawing {
        name: format!("{name} from ({x}, {y})"),
        // A line from the pen, given time to finish; a key puts the end screen away, D goes back
        // to the mode list.
        keys: format!("{} wait:3000 # D {keys}", form_keys(2, &[x, y])),
        gcode: format!("G1 X{x} Y{y} F3000\n{gcode}"),
    }
}

fn drawings() -> Vec<SameDrawing> {
    let mut all = Vec::new();
    let starts = [("0", "0"), ("12.34", "-5.67"), ("-20.005", "7.5")];
    // Line: dX, dY.
    for (k, (dx, dy)) in [("10", "5"), ("-7.25", "3.005"), ("0.005", "-0.005"), ("-12.345", "-0.5")].iter().enumerate()
    {
        all.push(from_start(
            starts[k % starts.len()],
            format!("line dX {dx} dY {dy}"),
            form_keys(2, &[dx, dy]),
            format!("G91 G1 X{dx} Y{dy} F3000\n"),
        ));
    }
    // Circle/arc: radius, start angle, sweep (empty: full turn).
    for (k, (r, s, w)) in
        [("8", "", ""), ("12.5", "30", "-135"), ("5", "-45", "90"), ("0.5", "", "270"), ("7.777", "200", "-360")]
            .iter()
            .enumerate()
    {
        let g = with_angles(format!("$O R{r}"), s, w);
        all.push(from_start(
            starts[k % starts.len()],
            format!("circle R {r} S {s:?} W {w:?}"),
            form_keys(3, &[r, s, w]),
            format!("{g} F3000\n"),
        ));
    }
    // Ellipse: a, b, start angle, sweep.
    for (k, (a, b, s, w)) in [
        ("15", "8", "90", "-270"),
        ("12", "20", "", ""),
        ("20", "5", "30", "45"),
        ("3", "0.2", "", ""),
        ("9.5", "4.25", "-120", "200"),
    ]
    .iter()
    .enumerate()
    {
        let g = with_angles(format!("$E A{a} B{b}"), s, w);
        all.push(from_start(
            starts[k % starts.len()],
            format!("ellipse A {a} B {b} S {s:?} W {w:?}"),
            form_keys(4, &[a, b, s, w]),
            format!("{g} F3000\n"),
        ));
    }
    // Sine: amplitude, period (ω = 2π/P), phase, length.
    for (k, (a, p, ph, l)) in [
        ("5", "12.5", "30", "30"),
        ("-8", "5", "", "-20"),
        ("3", "7", "-60", "12.345"),
        ("0.5", "1", "", "10"),
        ("10", "33.3", "90", "-25"),
    ]
    .iter()
    .enumerate()
    {
        let omega = TAU / keypad_value(p);
        let omega_text = nine_digits(omega);
        let parsed = parse_prefix(omega_text.as_bytes(), Syntax { sign: true, exponent: false }).unwrap().value;
        let mut g = format!("$S A{a} W{omega_text} L{l}");
        if !ph.is_empty() {
            g += &format!(" P{ph}");
        }
        let note =
            if parsed == omega { String::new() } else { format!(" (W reads back as {parsed:e}, not {omega:e})") };
        all.push(from_start(
            starts[k % starts.len()],
            format!("sine A {a} P {p} phase {ph:?} L {l}{note}"),
            form_keys(5, &[a, p, ph, l]),
            format!("{g} F3000\n"),
        ));
    }
    // Function: preset (1-based), x0, x1.
    for (k, (x0, x1)) in [("-10", "10"), ("0", "20"), ("0", "8"), ("-15", "15"), ("-20", "20")].iter().enumerate() {
        let preset = FunctionPreset::ALL[k];
        let expr = preset.expression();
        all.push(from_start(
            starts[k % starts.len()],
            format!("function {expr} x {x0}..{x1}"),
            format!("6 {} # {} # {} # #", k + 1, typed(x0), typed(x1)),
            format!("$F X{x0} U{x1} F3000 Y={expr}\n"),
        ));
    }
    for (k, (p, x0, x1)) in [(3usize, "2.5", "0.005"), (1, "3.333", "-4.125"), (5, "-0.005", "12.5")].iter().enumerate()
    {
        let expr = FunctionPreset::ALL[p - 1].expression();
        all.push(from_start(
            starts[(k + 1) % starts.len()],
            format!("function {expr} x {x0}..{x1}"),
            format!("6 {p} # {} # {} # #", typed(x0), typed(x1)),
            format!("$F X{x0} U{x1} F3000 Y={expr}\n"),
        ));
    }
    all
}

/// Every curve the keypad offers, typed on the keypad and sent as G-code from the same point:
/// the same steps in the same order (timing aside).
/// A `$O`/`$E` command with its S and W words, where typed (an empty field is the default).
fn with_angles(command: String, start: &str, sweep: &str) -> String {
    let mut g = command;
    if !start.is_empty() {
        g += &format!(" S{start}");
    }
    if !sweep.is_empty() {
        g += &format!(" W{sweep}");
    }
    g
}

#[test]
fn keypad_and_gcode_draw_the_same_steps() {
    let mut failures = Vec::new();
    let drawings = drawings();
    for d in &drawings {
        let keys = sim::run_keys(&d.keys).expect("a valid key script");
        let gcode = sim::run_serial(&d.gcode);
        assert!(!keys.timed_out && !gcode.timed_out, "{}", d.name);
        let (kp, gp) = (keys.path(), gcode.path());
        let answers = answer_lines(&gcode);
        if gp.len() < 3 || answers.iter().any(|a| a.starts_with("error")) {
            failures.push(format!(
                "{}: the G-code side drew nothing or was refused: {:?}\n    gcode {:?}",
                d.name, answers, d.gcode
            ));
            continue;
        }
        if kp.len() <= 2 {
            failures.push(format!("{}: the keypad side drew nothing\n    keys {:?}", d.name, d.keys));
            continue;
        }
        if kp != gp {
            let first = kp.iter().zip(&gp).position(|(a, b)| a != b).unwrap_or(kp.len().min(gp.len()));
            failures.push(format!(
                "{}: keypad {} steps ending at {:?}, G-code {} steps ending at {:?}; first difference at step {}: \
                 keypad {:?}, G-code {:?}\n    keys  {:?}\n    gcode {:?}",
                d.name,
                kp.len() - 1,
                kp.last().unwrap(),
                gp.len() - 1,
                gp.last().unwrap(),
                first,
                kp.get(first),
                gp.get(first),
                d.keys,
                d.gcode
            ));
        }
    }
    assert!(failures.is_empty(), "{} of {} drawings differ:\n{}", failures.len(), drawings.len(), failures.join("\n"));
}

// ----- 3. no curve leaves the travel ---------------------------------------------------------

/// Travel limit of these runs, mm either side of the origin ($130, $131), and in steps.
const TRAVEL_MM: i32 = 30;
const TRAVEL_STEPS: i32 = TRAVEL_MM * 100;

/// A size in thousandths of a mm, spread over several decades from `min` to `max`.
fn size(min: i32, max: i32) -> impl Strategy<Value = i32> {
    let decades: Vec<(i32, i32)> =
        [10, 100, 1000, 10_000, 100_000, 1_000_000].windows(2).map(|w| (w[0], w[1])).collect();
    let ranges: Vec<(i32, i32)> =
        decades.into_iter().map(|(lo, hi)| (lo.max(min), hi.min(max))).filter(|(lo, hi)| lo < hi).collect();
    (0..ranges.len()).prop_flat_map(move |k| ranges[k].0..=ranges[k].1)
}

/// A sweep in thousandths of a degree: often small (for huge radii), either way.
fn sweep() -> impl Strategy<Value = i32> {
    (size(100, 360_000), any::<bool>()).prop_map(|(w, neg)| if neg { -w } else { w })
}

fn any_curve() -> impl Strategy<Value = String> {
    let ellipse = (size(10, 400_000), prop_oneof![5..=50i32, size(10, 400_000)], -360_000..=360_000i32, sweep())
        .prop_map(|(a, b, s, w)| format!("$E A{} B{} S{} W{}", num(a), num(b), num(s), num(w)));
    let flat = (size(1000, 200_000), 5..=20i32, -360_000..=360_000i32, sweep())
        .prop_map(|(a, b, s, w)| format!("$E A{} B{} S{} W{}", num(a), num(b), num(s), num(w)));
    let circle = (size(10, 400_000), -360_000..=360_000i32, sweep())
        .prop_map(|(r, s, w)| format!("$O R{} S{} W{}", num(r), num(s), num(w)));
    let arc = (any::<bool>(), size(10, 400_000), 0..360i32, 0..360i32).prop_map(|(cw, r, from, to)| {
        let r = r as f64 / 1000.0;
        let (from, to) = ((from as f64).to_radians(), (to as f64).to_radians());
        let (i, j) = (-r * from.cos(), -r * from.sin());
        let (x, y) = (i + r * to.cos(), j + r * to.sin());
        format!(
            "G91 G{} X{} Y{} I{} J{}",
            if cw { 2 } else { 3 },
            num(thousandths(x)),
            num(thousandths(y)),
            num(thousandths(i)),
            num(thousandths(j))
        )
    });
    let sine = (
        (size(10, 300_000), any::<bool>()).prop_map(|(a, neg)| if neg { -a } else { a }),
        size(10, 200_000),
        (size(10, 60_000), any::<bool>()).prop_map(|(l, neg)| if neg { -l } else { l }),
        -180_000..=180_000i32,
    )
        .prop_map(|(a, w, l, p)| format!("$S A{} W{} L{} P{}", num(a), num(w), num(l), num(p)));
    let exprs = ["x^2/40", "sin(x)*3", "20*exp(-x^2/200)", "30*sin(pi*x/2)^2", "x^3/400", "sqrt(x)", "10*tan(x/10)"];
    let function = (0..exprs.len(), -40_000..=40_000i32, size(5, 60_000), any::<bool>()).prop_map(
        move |(k, x0, span, leftwards)| {
            let x1 = if leftwards { x0 - span } else { x0 + span };
            format!("$F X{} U{} Y={}", num(x0), num(x1), exprs[k])
        },
    );
    prop_oneof![2 => ellipse, 2 => flat, 2 => circle, 1 => arc, 2 => sine, 2 => function]
}

/// What a run of curve commands answered and where its pulses went, checked: every line
/// answered `ok` or `error:N`, and no step outside ±`TRAVEL_STEPS` on either axis.
fn check_inside(lines: &[String], report: &SimReport) -> Result<(), String> {
    let context = || format!("lines: {lines:#?}\nanswers: {:?}", answer_lines(report));
    if report.timed_out {
        return Err(format!("did not come to rest\n{}", context()));
    }
    let answers = answer_lines(report);
    let verdicts: Vec<&String> =
        answers.iter().filter(|a| !a.starts_with("Grbl ") && !a.starts_with("[MSG:")).collect();
    if let Some(odd) = verdicts.iter().find(|a| a.as_str() != "ok" && !a.starts_with("error:")) {
        return Err(format!("answer {odd:?} is neither ok nor error:N\n{}", context()));
    }
    if verdicts.len() != lines.len() {
        return Err(format!("{} answers to {} lines\n{}", verdicts.len(), lines.len(), context()));
    }
    let path = report.path();
    let (x0, x1, y0, y1) = bounds(&path);
    if let Some(p) = path.iter().find(|p| p.x.abs() > TRAVEL_STEPS || p.y.abs() > TRAVEL_STEPS) {
        return Err(format!(
            "a step outside ±{TRAVEL_MM} mm: first at {p:?} steps; the pen went over X {x0}..{x1}, Y {y0}..{y1} steps\n{}",
            context()
        ));
    }
    if report.position != *path.last().unwrap() {
        return Err(format!("position {:?} is not where the pulses went\n{}", report.position, context()));
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(24))]

    /// Flat ellipses, tiny and huge radii, steep sines and functions from anywhere inside a
    /// ±30 mm travel: each is drawn inside it, stopped at its edge or refused, never outside.
    #[test]
    fn no_curve_leaves_the_travel(
        method in 0..=1u8,
        start in (-28_000..=28_000i32, -28_000..=28_000i32),
        curves in prop::collection::vec(any_curve(), 1..=3),
    ) {
        let mut lines = vec![
            format!("$130={TRAVEL_MM}"),
            format!("$131={TRAVEL_MM}"),
            format!("$202={method}"),
            format!("G0 X{} Y{}", num(start.0), num(start.1)),
        ];
        lines.extend(curves);
        let text: String = lines.iter().map(|l| format!("{l}\n")).collect();
        let report = sim::run_serial(&text);
        if let Err(e) = check_inside(&lines, &report) {
            prop_assert!(false, "{}", e);
        }
    }
}

/// A flat 30° elliptic arc, a = 150 mm, at the default ±200 mm travel: its ideal path stays
/// within 20.1 mm of the pen, so the pen never gets near X −200 mm.
#[test]
fn a_flat_ellipse_arc_never_drives_past_the_travel() {
    let report = sim::run_serial("$E A150 B0.009 W-30\n");
    assert!(!report.timed_out);
    let (x0, x1, y0, y1) = bounds(&report.path());
    assert!(
        x0 >= -20_000 && x1 <= 20_000 && y0 >= -20_000 && y1 <= 20_000,
        "the pen went over X {x0}..{x1}, Y {y0}..{y1} steps (travel ±20000); answers {:?}",
        answer_lines(&report)
    );
}

/// A flat 30° elliptic arc, a = 20 mm: the ideal arc spans 20·(1 − cos 30°) ≈ 2.68 mm in X. It
/// is drawn within that box (plus 2 steps), or refused before anything moves; never as a 40 mm
/// stroke there and back.
#[test]
fn a_flat_ellipse_arc_stays_within_its_own_box() {
    let report = sim::run_serial("$E A20 B0.009 W-30\n");
    assert!(!report.timed_out);
    let answers = answer_lines(&report);
    if answers.iter().any(|a| a == "error:33" || a == "error:15") {
        assert!(report.trace.pulses.is_empty(), "refused, yet it moved; answers {answers:?}");
        return;
    }
    let ideal = 2000.0 * (1.0 - 30f64.to_radians().cos());
    let (x0, x1, y0, y1) = bounds(&report.path());
    assert!(
        x0 as f64 >= -ideal - 2.0 && x1 <= 2,
        "the pen went over X {x0}..{x1} steps (ideal arc: {:.1}..0), Y {y0}..{y1}; answers {answers:?}",
        -ideal
    );
}

/// A sine far steeper than the jump limit (A·ω = 500 mm per mm) is refused with an error, and
/// nothing moves.
#[test]
fn a_sine_too_steep_to_draw_is_refused_before_anything_moves() {
    let report = sim::run_serial("$S A5 W100 L10\n");
    let answers = answer_lines(&report);
    assert!(answers.iter().any(|a| a.starts_with("error:")), "{answers:?}");
    assert!(report.trace.pulses.is_empty(), "{answers:?}");
    assert_eq!(report.position, Point::ORIGIN);
}

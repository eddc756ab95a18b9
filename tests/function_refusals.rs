//! `$F` refuses what it would not draw, on the simulated board: a function too far from zero for
//! single precision, and one that changes faster than its X steps sample it, are answered with
//! a reason and `error:33`, nothing moves and the next line starts where the pen is; the near
//! misses draw. The keypad's function mode shows the same refusal on the LCD.

use servoplot::geom::Point;
use servoplot::host::{Command, GcodeState};
use servoplot::panel::FunctionPreset;
use servoplot::panel::expr_entry::{EXPR_TOKENS, ExprEntry};
use servoplot::panel::keypad::Key;
use servoplot::settings::Settings;
use servoplot::sim;
use servoplot::status::RunState;

mod support;

/// Where the parser plans the pen after `line`, from the origin.
fn planned_end(line: &str) -> Point {
    let mut g = GcodeState::new();
    let commands = g.execute(line, &Settings::default(), RunState::Idle).expect("a valid line");
    assert!(commands.into_iter().any(|c| matches!(c, Command::Job(_))));
    g.planned_position()
}

/// What the board answered after its banner.
fn answers(report: &sim::SimReport) -> String {
    let all = report.answers();
    let (_, after) = all.split_once("['$' for help]\r\n").expect("the banner");
    after.to_string()
}

/// Sends `line`, then a move to X1 Y0, and checks that `line` alone was refused with `reason`:
/// no pulse before the move, and the move planned from the origin.
fn assert_refused(line: &str, reason: &str) {
    let report = sim::run_serial(&format!("{line}\nG1 X1 Y0 F3000\n"));
    assert_eq!(answers(&report), format!("[MSG:{reason}]\r\nerror:33\r\nok\r\n"), "{line}");
    assert_eq!(report.position, Point::new(100, 0), "{line}: only the move moved");
    assert!(report.path().iter().all(|p| p.y == 0 && (0..=100).contains(&p.x)), "{line}: a step off the move");
}

const IMPRECISE: &str = "Function too far from 0 for single precision";
const TOO_FINE: &str = "Curve finer than the step lattice can draw";

#[test]
fn the_reported_lines_are_refused_and_move_nothing() {
    // At x = 10,000,000 mm f32 numbers are 1 mm apart: it would draw 4 mm stairs.
    assert_refused("$F X10000000 U10000020 Y=(x-10000000)*4", IMPRECISE);
    // A wave of 0.01 mm, one step: its X steps see it nearly flat.
    assert_refused("$F X0 U5 Y=sin(x*628.3)*3", TOO_FINE);
    // As `$S` refuses the same wave.
    assert_refused("$S A3 W628.3 L5", TOO_FINE);
}

#[test]
fn values_too_far_from_zero_and_waves_between_the_steps_are_refused_too() {
    assert_refused("$F X0 U5 Y=10000000+sin(x)", IMPRECISE);
    // Two waves a step; a wave on a slope whose X steps rise evenly; 1.25 waves a step, which
    // the X steps see as a wave four steps long.
    assert_refused("$F X0 U5 Y=sin(x*1256.6)*3", TOO_FINE);
    assert_refused("$F X0 U5 Y=x*10+sin(x*628.3)*3", TOO_FINE);
    assert_refused("$F X0 U5 Y=sin(x*785.4)*3", TOO_FINE);
}

#[test]
fn the_near_misses_draw() {
    for line in [
        // At x = 1000 mm f32 numbers are 0.00006 mm apart: a line of slope 4.
        "$F X1000 U1020 F3000 Y=(x-1000)*4",
        // Ten steps per wave, as `$S A3 W62.83 L5` draws it, and a value of 1000 mm.
        "$F X0 U5 F3000 Y=sin(x*62.83)*3",
        "$F X0 U5 F3000 Y=1000+sin(x)",
    ] {
        let report = sim::run_serial(&format!("{line}\n"));
        assert_eq!(answers(&report), "ok\r\n", "{line}");
        assert_eq!(report.position, planned_end(line), "{line}");
    }
    let slope = sim::run_serial("$F X1000 U1020 F3000 Y=(x-1000)*4\n");
    assert_eq!(slope.position, Point::new(2000, 8000));
    // Every point within a step of the line y = 4x.
    assert!(slope.path().iter().all(|p| (4.0 * p.x as f64 - p.y as f64).abs() / 17f64.sqrt() <= 1.0));
    // The function and the sine take the same steps.
    let function = sim::run_serial("$F X0 U5 F3000 Y=sin(x*62.83)*3\n");
    let sine = sim::run_serial("$S A3 W62.83 L5 F3000\n");
    assert_eq!(answers(&sine), "ok\r\n");
    let (f, s) = (function.path(), sine.path());
    assert_eq!(f.len(), s.len());
    assert!(f.iter().zip(&s).all(|(a, b)| (a.x - b.x).abs() + (a.y - b.y).abs() <= 2), "within a step or two");
}

/// The keys that type `tokens` on the keypad's function editor once it holds `preset`: the
/// keys that clear it, then digits and `*` (the decimal point) as themselves and every other
/// token from the wheel, turned on from where it stands and put with C. Which key deletes and
/// which turns the wheel on are the editor's own, found by pressing them on it.
fn typing_keys(preset: &str, tokens: &[&str]) -> String {
    let key_name = |k: Key| match k {
        Key::A => "A",
        Key::B => "B",
        _ => "D",
    };
    let deletes = [Key::B, Key::D]
        .into_iter()
        .find(|&k| {
            let mut e = ExprEntry::new("x");
            e.press(k).is_ok() && e.text().is_empty()
        })
        .expect("a key deletes");
    let turns_on = [Key::A, Key::B]
        .into_iter()
        .find(|&k| {
            let mut e = ExprEntry::new("");
            e.press(k).is_ok() && e.token() == EXPR_TOKENS[1]
        })
        .expect("a key turns the wheel on");
    let mut entry = ExprEntry::new(preset);
    let mut keys = String::new();
    while !entry.text().is_empty() {
        entry.press(deletes).unwrap();
        keys += key_name(deletes);
        keys += " ";
    }
    for token in tokens {
        if token.chars().all(|c| c.is_ascii_digit() || c == '.') {
            for c in token.chars() {
                let key = if c == '.' { Key::Star } else { Key::Digit(c as u8 - b'0') };
                entry.press(key).unwrap();
                keys.push(if c == '.' { '*' } else { c });
                keys += " ";
            }
            continue;
        }
        while entry.token() != *token {
            entry.press(turns_on).unwrap();
            keys += key_name(turns_on);
            keys += " ";
        }
        entry.press(Key::C).unwrap();
        keys += "C ";
    }
    assert_eq!(entry.text(), tokens.concat(), "typed as asked");
    keys
}

#[test]
fn the_keypad_shows_the_refusal_and_moves_nothing() {
    // Function mode (6), C to type from the first preset, then sin(x*628.3)*3, from x0 = 0 to
    // x1 = 5 mm: the last # builds it for the preview, and it is refused.
    let preset = FunctionPreset::ALL[0].expression();
    let typing = typing_keys(preset, &["sin(", "x", "*", "628.3", ")", "*", "3"]);
    let report = sim::run_keys(&format!("6 C {typing}# 0 # 5 # wait:500")).unwrap();
    let frame = &report.frames.last().expect("the LCD was drawn").1;
    assert_eq!(support::text(frame, 3, 21), "Finer than a step");
    assert!(report.trace.pulses.is_empty());
    assert_eq!(report.position, Point::ORIGIN);
}

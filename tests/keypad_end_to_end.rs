//! The machine driven from its own keypad, on the simulated board: keys in, pulses and LCD
//! frames out.

use servoplot::geom::Point;
use servoplot::sim;

mod support;

#[test]
fn the_line_mode_draws_the_same_line_as_g1_x10_y5() {
    // Mode 2 (line), dX 10 mm #, dY 5 mm #, and # to draw what the preview shows.
    let keys = sim::run_keys("2 1 0 # 5 # #").unwrap();
    let serial = sim::run_serial("G1 X10 Y5\n");
    assert_eq!(keys.trace.counts(), [1000, 0, 500, 0]);
    assert_eq!(keys.position, Point::new(1000, 500));
    assert_eq!(keys.path(), serial.path(), "same steps in the same order");
}

#[test]
fn a_negative_offset_typed_with_the_sign_key_draws_back_to_the_origin() {
    // A toggles the sign, * is the decimal point: (+12.5, +4) then, in the same form, (-12.5, -4).
    // The first # after the wait puts the end screen away.
    let report = sim::run_keys("2 1 2 * 5 # 4 # # wait:3000 # A 1 2 * 5 # A 4 # #").unwrap();
    assert_eq!(report.trace.counts(), [1250, 1250, 400, 400]);
    assert_eq!(report.position, Point::ORIGIN);
}

#[test]
fn the_lcd_shows_the_position_reached_without_stale_digits() {
    let report = sim::run_keys("2 1 0 # 5 # #").unwrap();
    let (_, last) = report.frames.last().expect("the LCD was drawn");
    let (_, first) = report.frames.first().unwrap();
    assert!(first.lit() > 50, "the first frame shows the menu");
    assert_ne!(first, last, "the screen changed with the position");
    // Redraw the final state from scratch: identical to what the glass shows.
    let again = sim::run_keys("2 1 0 # 5 # # wait:1000").unwrap();
    assert_eq!(again.frames.last().unwrap().1, *last);
}

#[test]
fn holding_a_jog_key_moves_until_release_and_stops_on_a_step() {
    // Mode 1 (jog), hold 6 (+X) for 1 s.
    let report = sim::run_keys("1 6:1000").unwrap();
    let [xf, xb, yf, yb] = report.trace.counts();
    assert!(xf > 100, "moved +X: {xf}");
    assert_eq!((xb, yf, yb), (0, 0, 0));
    assert_eq!(report.position, Point::new(xf as i32, 0), "position is the pulses emitted");
}

#[test]
fn the_circle_mode_draws_a_closed_circle_around_the_centre_left_of_the_pen() {
    // Mode 3 (circle): radius 8 mm #, start angle 0 # (default), sweep # (default: full turn),
    // # to draw it.
    let report = sim::run_keys("3 8 # # # #").unwrap();
    assert_eq!(report.position, Point::ORIGIN, "closed");
    let path = report.path();
    // Centre 8 mm left of the pen: (-800, 0) steps. Diagonal method: within half a step.
    let off = path.iter().map(|p| ((p.x as f64 + 800.0).hypot(p.y as f64) - 800.0).abs()).fold(0.0, f64::max);
    assert!(off <= 0.5 + 1e-9, "{off} steps off the circle");
    assert!(path.iter().any(|p| p.x == -1600), "the far side was reached");
}

#[test]
fn c_holds_and_resumes_a_keypad_curve_and_d_aborts_it_on_its_path() {
    let reference = sim::run_keys("3 8 # # # #").unwrap();
    let full = reference.path();
    // The circle starts at about 1.1 s (after the keys); C at 1.6 s holds, C at 3.2 s resumes.
    let held = sim::run_keys("3 8 # # # # wait:300 C wait:1400 C").unwrap();
    assert_eq!(held.path(), full, "the same steps after a hold and a resume");
    assert!(held.last_pulse_us() > reference.last_pulse_us() + 1_000_000, "it stood still while held");
    let aborted = sim::run_keys("3 8 # # # # wait:300 D").unwrap();
    let cut = aborted.path();
    assert!(cut.len() < full.len() / 2, "D stopped it");
    assert_eq!(cut[..], full[..cut.len()], "on the circle's path");
    assert_eq!(aborted.position, *cut.last().unwrap());
}

#[test]
fn the_lcd_redraws_at_most_ten_times_a_second_and_only_on_change() {
    // A long line (moving for seconds) and a burst of key presses.
    let report = sim::run_keys("2 8 0 # 0 # # wait:3000 1 2 3 4 5 6").unwrap();
    let times: Vec<u64> = report.frames.iter().map(|(t, _)| *t).collect();
    assert!(times.windows(2).all(|w| w[1] - w[0] >= 100_000), "frames closer than 100 ms: {times:?}");
    assert!(report.frames.windows(2).all(|w| w[0].1 != w[1].1), "a frame was sent that changed nothing");
    assert!(report.frames.len() > 10, "the position was redrawn while moving");
}

#[test]
fn a_function_typed_on_the_keypad_draws_what_the_host_link_draws() {
    // Function mode (6), C to type from the first preset (x^2/20), D D D leaves x^2, then B
    // turns the wheel on to ^, A one back to /, C puts it, 4 0 divides by 40: x^2/40 from
    // x0 = 0 to x1 = 20 mm.
    let keys = sim::run_keys("6 C D D D B B B B B B B A C 4 0 # 0 # 2 0 # #").unwrap();
    let serial = sim::run_serial("$F X0 U20 Y=x^2/40\n");
    assert!(serial.answers().contains("ok"), "{}", serial.answers());
    assert_eq!(keys.path(), serial.path(), "same steps in the same order");
    assert_eq!(keys.position, Point::new(2000, 1000));
}

#[test]
fn a_function_undefined_at_the_pen_says_why_as_the_host_link_does() {
    // Function mode (6), the third preset (5*sqrt(x)), from x0 = -4 to 9 mm: nothing moves.
    let keys = sim::run_keys("6 3 # A 4 # 9 # wait:300").unwrap();
    let serial = sim::run_serial("$F X-4 U9 Y=5*sqrt(x)\n");
    assert!(serial.answers().contains("sqrt of a negative number"), "{}", serial.answers());
    assert_eq!((keys.trace.counts(), serial.trace.counts()), ([0; 4], [0; 4]));
    let (_, last) = keys.frames.last().unwrap();
    assert_eq!(support::text(last, 3, 24), "x0: sqrt of a negative");
}

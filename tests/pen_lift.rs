//! The pen lift on the simulated plotter: an RC servo on its 50 Hz PWM, whose pulse width the
//! tests read back with its time. A file as vpype writes it (M3 before each stroke, M5 and G0 to
//! the next) plots its strokes with the pen down and travels with the pen up; no pulse goes out
//! before the pen has settled; `$213=2` lifts the pen by itself; a keypad drawing lowers it and
//! raises it at the end.

use servoplot::geom::Point;
use servoplot::sim::picture::write_plot_svg;
use servoplot::sim::{self, SimConfig, SimReport, keys::KeyScript, serial::SimSerial};

/// The default pen pulses ($210, $211), µs, and settle time ($212).
const UP_US: u16 = 1_000;
const DOWN_US: u16 = 2_000;
const SETTLE_US: u64 = 200_000;

fn run(lines: &str) -> SimReport {
    let report = sim::run(SimConfig { serial: SimSerial::with_input(lines.as_bytes()), ..SimConfig::default() });
    assert!(!report.timed_out);
    report
}

/// Where the pen servo was sent at `t_us` (`None`: no pulse yet).
fn pen_at(report: &SimReport, t_us: u64) -> Option<u16> {
    report.pen.iter().take_while(|c| c.0 <= t_us).last().map(|c| c.1)
}

/// Every step pulse checked against the pen: `(pulses with the pen down, pulses with it up)`, and
/// whether each came at least the settle time after the pen's last move.
fn pulses_by_pen(report: &SimReport) -> (usize, usize, bool) {
    let (mut down, mut up, mut settled) = (0, 0, true);
    for p in &report.trace.pulses {
        match pen_at(report, p.t_us) {
            Some(DOWN_US) => down += 1,
            _ => up += 1,
        }
        let moved = report.pen.iter().take_while(|c| c.0 <= p.t_us).last().map_or(0, |c| c.0);
        settled &= p.t_us >= moved + SETTLE_US;
    }
    (down, up, settled)
}

#[test]
fn a_vpype_style_file_draws_its_strokes_pen_down_and_travels_pen_up() {
    let file = "$213=1\nG0 X10 Y10\nM3\nG1 X30 F3000\nG1 Y30\nM5\nG0 X50 Y10\nM3\nG1 X60\nM5\nG0 X0 Y0\n";
    let report = run(file);
    assert!(report.answers().ends_with(&"ok\r\n".repeat(11)), "{}", report.answers());
    // Up at once, then down and up around each stroke.
    let widths: Vec<u16> = report.pen.iter().map(|c| c.1).collect();
    assert_eq!(widths, [UP_US, DOWN_US, UP_US, DOWN_US, UP_US]);
    // Strokes: 20 + 20 + 10 mm at 100 steps/mm; travel: the G0 moves, both axes stepping.
    let (down, up, settled) = pulses_by_pen(&report);
    assert_eq!(down, 5_000, "every drawing pulse with the pen down");
    assert_eq!(up, (1_000 + 1_000) + (2_000 + 2_000) + (6_000 + 1_000), "every travel pulse with the pen up");
    assert!(settled, "no pulse within the settle time of a pen move");
    assert_eq!(report.position, Point::ORIGIN);

    // The SVG draws the three strokes in black, the four travels dashed.
    let strokes = report.strokes();
    let drawn: Vec<_> = strokes.iter().filter(|s| s.0).map(|s| (s.1[0], *s.1.last().unwrap())).collect();
    assert_eq!(
        drawn,
        [(Point::new(1_000, 1_000), Point::new(3_000, 3_000)), (Point::new(5_000, 1_000), Point::new(6_000, 1_000))]
    );
    let mut svg = Vec::new();
    write_plot_svg(&strokes, report.settings.steps_per_mm, &mut svg).unwrap();
    let svg = String::from_utf8(svg).unwrap();
    assert_eq!(svg.matches("stroke-dasharray").count(), 3, "travels: to the first stroke, between, home");
    assert_eq!(svg.matches(r#"stroke="black""#).count(), 2);
}

#[test]
fn with_213_2_rapids_lift_the_pen_and_drawing_moves_lower_it() {
    let report = run("$213=2\nG0 X10\nG1 X20 F3000\n$O R5 S0\nG0 X0\n");
    let widths: Vec<u16> = report.pen.iter().map(|c| c.1).collect();
    assert_eq!(widths, [UP_US, DOWN_US, UP_US], "the circle follows the line with the pen down");
    let (down, up, settled) = pulses_by_pen(&report);
    assert_eq!(up, 1_000 + 2_000, "the rapids, out and back from the end of the full circle");
    assert!(down > 1_000, "the line and the circle");
    assert!(settled);
}

#[test]
fn m3_s_sets_the_pen_between_the_up_and_down_pulses_as_31_and_30_say() {
    // Servo-angle G-code: $31=20 holds the pen up, $30=90 puts it fully down; S between goes in
    // proportion. An S word under M3 moves the pen once the motion before it has ended.
    let report = run("$213=1\n$31=20\n$30=90\nM3 S55\nG1 X10 F3000\nS90\nG1 X20\nM3 S20\nM5\n");
    let widths: Vec<u16> = report.pen.iter().map(|c| c.1).collect();
    assert_eq!(widths, [UP_US, 1_500, DOWN_US, UP_US], "{:?}", report.pen);
    // The first line drawn at the S55 pulse, the second at the full one; each after settling.
    let at = |x_steps: i32| {
        let p =
            report.trace.pulses.iter().filter(|p| p.axis == servoplot::geom::Axis::X).nth(x_steps as usize).unwrap();
        pen_at(&report, p.t_us)
    };
    assert_eq!((at(500), at(1_500)), (Some(1_500), Some(DOWN_US)));
    assert!(pulses_by_pen(&report).2, "no pulse before the pen settled");
    // M3 with no S word yet goes fully down, as before.
    let plain = run("$213=1\nM3\nG1 X10 F3000\n");
    assert_eq!(plain.pen.iter().map(|c| c.1).collect::<Vec<_>>(), [UP_US, DOWN_US]);
}

#[test]
fn laser_mode_lifts_the_pen_for_rapids_under_m3() {
    // $32=1: as a laser is off in rapids, the pen travels up and draws down while M3 is on.
    let report = run("$213=1\n$32=1\nM3 S1000\nG0 X10\nG1 X20 F3000\nG0 X30\nM5\nG1 X40\n");
    let (down, up, settled) = pulses_by_pen(&report);
    assert_eq!((down, up), (1_000, 3_000), "only G1 X20 under M3 draws");
    assert!(settled);
}

#[test]
fn without_a_pen_lift_nothing_drives_the_pen_servo_and_m3_changes_nothing() {
    let report = run("M3\nG0 X10\nM5\nG1 X0 F3000\n");
    assert!(report.pen.is_empty(), "{:?}", report.pen);
    assert_eq!(report.strokes().len(), 1, "one stroke, all drawn");
    assert!(report.strokes()[0].0);
}

#[test]
fn program_end_raises_the_pen() {
    let report = run("$213=1\nM3\nG1 X10 F3000\nM2\n");
    assert!(report.answers().contains("[MSG:Pgm End]"), "{}", report.answers());
    assert_eq!(report.pen.last().map(|c| c.1), Some(UP_US));
    let last_pulse = report.last_pulse_us();
    assert!(report.pen.last().unwrap().0 > last_pulse, "raised after the line was drawn");
}

#[test]
fn a_keypad_drawing_lowers_the_pen_first_and_raises_it_at_the_end() {
    let setup = run("$213=2\n");
    let keys = KeyScript::parse("2 1 0 # 5 # #").unwrap();
    let report = sim::run(SimConfig { flash: setup.flash, keys, ..SimConfig::default() });
    assert!(!report.timed_out);
    let widths: Vec<u16> = report.pen.iter().map(|c| c.1).collect();
    assert_eq!(widths, [UP_US, DOWN_US, UP_US]);
    let (down, up, settled) = pulses_by_pen(&report);
    assert_eq!((down, up), (1_500, 0));
    assert!(settled);
    assert!(report.pen[2].0 >= report.last_pulse_us(), "up once drawn");
}

#[test]
fn a_reset_while_the_pen_settles_sends_no_pulse_and_a_long_settle_keeps_the_watchdog_fed() {
    let lines = "$213=2\n$212=2000\nG1 X10 F3000\n";
    let reference = run(lines);
    assert!(reference.watchdog_unfed_us <= 20_000, "unfed {} µs", reference.watchdog_unfed_us);
    let down = reference.pen.iter().find(|c| c.1 == DOWN_US).unwrap().0;
    let reset = down + 1_000_000;
    let serial = SimSerial::with_input(lines.as_bytes()).with_byte_at(reset, 0x18);
    let report = sim::run(SimConfig { serial, ..SimConfig::default() });
    assert!(
        report.trace.pulses.is_empty(),
        "{} pulses after a reset before the pen settled",
        report.trace.pulses.len()
    );
}

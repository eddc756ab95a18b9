//! Every curve the host can ask for, drawn on the simulated board: the pen ends exactly where
//! the G-code parser planned it, stays on the ideal curve, and closed curves close.

use servoplot::geom::Point;
use servoplot::host::{Command, GcodeState};
use servoplot::settings::Settings;
use servoplot::sim;
use servoplot::status::RunState;

/// Where the parser plans the pen after `line`, from the origin.
fn planned_end(line: &str) -> Point {
    let mut g = GcodeState::new();
    let commands = g.execute(line, &Settings::default(), RunState::Idle).expect("a valid line");
    assert!(commands.into_iter().any(|c| matches!(c, Command::Job(_))));
    g.planned_position()
}

/// Largest distance from the ideal curve, in steps, over every point the pen passed.
fn deviation(path: &[Point], distance: impl Fn(f64, f64) -> f64) -> f64 {
    path.iter().map(|p| distance(p.x as f64, p.y as f64)).fold(0.0, f64::max)
}

#[test]
fn every_curve_ends_where_the_parser_planned_it() {
    for method in [0, 1] {
        for line in [
            "G2 X20 Y0 I10 J0 F2000",
            "G3 X-5 Y5 R5 F2000",
            "$O R10 S30 F2000",
            "$O R8 S45 W-135 F2000",
            "$E A15 B8 S90 W-270 F2000",
            "$E A12 B20 F2000",
            "$S A5 W0.5 L30 P30 F2000",
            "$S A8 W1.2 L-20 F2000",
            "$F X-10 U10 F2000 Y=x^2/20",
            "$F X0 U8 F1500 Y=3*sqrt(x)",
            "$F X-3 U3 F1500 Y=10*sin(2*x)+min(x,1)",
        ] {
            let report = sim::run_serial(&format!("$202={method}\n{line}\n"));
            assert!(report.answers().lines().filter(|l| *l == "ok").count() == 2, "{line}: {}", report.answers());
            assert_eq!(report.position, planned_end(line), "method {method}: {line}");
            assert_eq!(*report.path().last().unwrap(), report.position);
        }
    }
}

#[test]
fn a_circle_closes_and_stays_within_a_step_of_its_radius() {
    for (method, bound) in [(0, 1.0), (1, 0.5)] {
        // Centre 10 mm left of the pen: (-1000, 0) steps, radius 1000 steps.
        let report = sim::run_serial(&format!("$202={method}\n$O R10 F3000\n"));
        let path = report.path();
        assert_eq!(report.position, Point::ORIGIN, "closed");
        let d = deviation(&path, |x, y| ((x + 1000.0).hypot(y) - 1000.0).abs());
        assert!(d <= bound + 1e-9, "method {method}: {d} steps off the circle");
        if method == 0 {
            assert_eq!(path.len() - 1, 8 * 1000, "a classic full circle takes 8R steps");
        }
    }
}

#[test]
fn a_sine_follows_its_curve_from_the_pen() {
    // y = 5·(sin(0.5·x + 30°) − sin 30°) mm for x in [0, 30] mm, at 100 steps/mm.
    let report = sim::run_serial("$S A5 W0.5 L30 P30 F2000\n");
    let phase = 30f64.to_radians();
    let y = |x_steps: f64| 500.0 * ((0.5 * x_steps / 100.0 + phase).sin() - phase.sin());
    // True distance: the nearest of finely spaced curve points within a few steps.
    let distance = |px: f64, py: f64| {
        (-400..=400).map(|k| px + k as f64 / 100.0).map(|x| (x - px).hypot(y(x) - py)).fold(f64::MAX, f64::min)
    };
    let d = deviation(&report.path(), distance);
    // Diagonal (the default): half a step, plus the sampling above and the chord's sag.
    assert!(d <= 0.5 + 0.02, "{d} steps off the sine");
    assert_eq!(report.position.x, 3000);
}

#[test]
fn a_function_undefined_part_way_stops_there_and_says_so() {
    // sqrt(4 - x) is undefined past x = 4: the pen stops at the last defined column.
    let report = sim::run_serial("$F X0 U3.99 F1500 Y=sqrt(4-x)\n$F X0 U6 F1500 Y=sqrt(4-x)\n");
    let answers = report.answers();
    // The parser already refuses the second line: it samples the range before anything moves.
    assert!(answers.contains("error:33"), "{answers}");
    assert_eq!(report.position.x, 399);
}

#[test]
fn an_expression_syntax_error_names_its_column_and_moves_nothing() {
    let report = sim::run_serial("$F X0 U5 Y=3*sin(x))\n");
    let answers = report.answers();
    assert!(answers.contains("column"), "{answers}");
    assert!(answers.contains("error:2"), "{answers}");
    assert!(report.trace.pulses.is_empty());
}

#[test]
fn a_function_with_a_hole_is_refused_with_where_before_anything_moves() {
    // Undefined only for |x - 2| < 0.0001 mm, where a column of the interpolator (every
    // 0.01 mm) falls: the builder walks the whole curve before it moves and finds the hole.
    let report = sim::run_serial("$F X0 U4.1 F1500 Y=sqrt(abs(x-2)-0.0001)\nG1 X1 Y0\n");
    let answers = report.answers();
    assert!(answers.contains("[MSG:Function is undefined after x=1.990]\r\nerror:33"), "{answers}");
    // Nothing of the curve was drawn; the next line is planned from where the pen is.
    assert_eq!(report.position, Point::new(100, 0), "{answers}");
    assert_eq!(report.path().iter().map(|p| p.y).max(), Some(0));
}

#[test]
fn a_function_leaving_the_travel_anywhere_is_refused_before_anything_moves() {
    // 250·sin²(πx/2) is 0 at every even x; the humps between reach 250 mm, beyond the ±200 mm
    // travel. The builder's box is the lattice path's own, so the first hump is seen.
    let report = sim::run_serial("$F X0 U128 F3000 Y=250*sin(pi*x/2)^2\nG1 X1 Y0\n");
    let answers = report.answers();
    assert!(answers.contains("error:15\r\nok"), "{answers}");
    assert_eq!(report.position, Point::new(100, 0));
}

#[test]
fn no_curve_steps_outside_the_travel() {
    // From 10 mm inside the top and the bottom edge, functions whose humps (30 and 20 mm) pass
    // the edge between their zeros: refused, with either method, and nothing moves past the
    // edge.
    for method in [0, 1] {
        for (start, line) in [(190, "$F X0 U128 F3000 Y=30*sin(pi*x/2)^2"), (-190, "$F X0 U64 F3000 Y=-20*sin(pi*x)^2")]
        {
            let report = sim::run_serial(&format!("$202={method}\nG0 Y{start}\n{line}\n"));
            let answers = report.answers();
            assert!(answers.ends_with("ok\r\nok\r\nerror:15\r\n"), "{line}: {answers}");
            assert!(report.path().iter().all(|p| p.y.abs() <= 20_000), "{line}: a step outside the travel");
            assert_eq!(report.position, Point::new(0, start * 100), "{line}");
        }
    }
}

#[test]
fn a_sine_steeper_than_the_jump_limit_is_refused_before_anything_moves() {
    let report = sim::run_serial("$S A200 W1000 L100\n");
    let answers = report.answers();
    assert!(answers.contains("error:33"), "{answers}");
    assert!(report.trace.pulses.is_empty());
}

#[test]
fn arcs_too_small_to_draw_are_refused_by_the_parser() {
    let report = sim::run_serial("G2 X0.01 Y0 R0.005\nG2 X0.01 Y0 I0.005\n$O R0.005 S45 W360\n");
    let answers = report.answers();
    assert_eq!(answers.lines().filter(|l| *l == "error:33").count(), 3, "{answers}");
    assert!(!answers.contains("Curve refused"), "{answers}");
    assert!(report.trace.pulses.is_empty());
    assert_eq!(report.position, Point::ORIGIN);
}

//! A program checked whole before it runs (`servoplot::program`): the plot time the check gives
//! by the planner's own model is the time the simulated plotter then takes to plot the same
//! file over the host link, within 2 %, for a polyline file as vpype writes it and for a file of
//! arcs; and the check's box is the box of the pulses the plot emits.

use std::fmt::Write;

use servoplot::geom::Point;
use servoplot::host::GcodeState;
use servoplot::machine_io::pen::Pen;
use servoplot::motion::planner::Limits;
use servoplot::program::{CheckPlanner, ProgramCheck, Progress, Summary};
use servoplot::settings::Settings;
use servoplot::sim::{self, SimReport};

/// How far the check's plot time may be from the simulator's, as a share of it.
const PLOT_TIME_TOLERANCE: f64 = 0.02;

/// Checks `program` as a card would feed it, a line at a time, with the settings the simulator
/// starts with, from machine zero with the pen up.
fn check(program: &str) -> Summary {
    let settings = Settings::default();
    let mut planner = Box::new(CheckPlanner::new(Limits::from_settings(&settings)));
    let mut check = Box::new(ProgramCheck::new(GcodeState::new(), &settings, Pen::Up));
    check.start(GcodeState::new(), &settings, Pen::Up, &mut planner);
    for line in program.lines() {
        assert!(check.push_line(line));
        loop {
            match check.work(&mut planner) {
                Progress::Working => {}
                Progress::Ready => break,
                other => panic!("line {line:?}: {other:?}"),
            }
        }
    }
    assert!(check.end());
    while check.work(&mut planner) == Progress::Working {}
    assert_eq!(check.work(&mut planner), Progress::Done);
    check.summary()
}

/// Plots `program` over the simulator's host link: the report and the time from the first
/// pulse to the last, µs.
fn plot(program: &str) -> (SimReport, u64) {
    let report = sim::run_serial(program);
    assert!(!report.timed_out);
    assert!(!report.answers().contains("error"), "{}", report.answers());
    let first = report.trace.pulses.first().expect("pulses").t_us;
    let time = report.last_pulse_us() - first;
    (report, time)
}

/// Checks and plots `program`: the check's estimate within the tolerance of the plot's time,
/// and its box that of the pulses.
fn estimate_matches_plot(program: &str) {
    let summary = check(program);
    let (report, plotted_us) = plot(program);
    let estimate_us = summary.plot_time_us;
    let error = (estimate_us as f64 - plotted_us as f64).abs() / plotted_us as f64;
    assert!(error <= PLOT_TIME_TOLERANCE, "check {estimate_us} µs, plot {plotted_us} µs: {:.2} % apart", error * 100.0);
    let path = report.path();
    let (mut min, mut max) = (Point::ORIGIN, Point::ORIGIN);
    for p in &path {
        (min.x, min.y, max.x, max.y) = (min.x.min(p.x), min.y.min(p.y), max.x.max(p.x), max.y.max(p.y));
    }
    let motion = summary.motion.expect("motion");
    assert_eq!((motion.min, motion.max), (min, max), "the box of every move is the box of the pulses");
    assert!(summary.within_travel);
}

/// A file as vpype writes it for a pen lifted by M3/M5: closed polylines (polygons of many short
/// segments, on circles of different sizes) drawn pen down, with pen-up travel between them.
fn polyline_file() -> String {
    let mut out = String::from("$213=1\nG21\nG90\n");
    for (k, (cx, cy, r, sides)) in
        [(0.0, 0.0, 30.0, 90), (60.0, 20.0, 15.0, 48), (-50.0, 40.0, 20.0, 64), (20.0, -60.0, 40.0, 120)]
            .into_iter()
            .enumerate()
    {
        let at = |i: usize| {
            let t = std::f64::consts::TAU * i as f64 / sides as f64;
            (cx + r * t.cos(), cy + r * t.sin())
        };
        let (x, y) = at(0);
        writeln!(out, "G0 X{x:.3} Y{y:.3}\nM3").unwrap();
        for i in 1..=sides {
            let (x, y) = at(i);
            let feed = if i == 1 { format!(" F{}", 2000 + 500 * k) } else { String::new() };
            writeln!(out, "G1 X{x:.3} Y{y:.3}{feed}").unwrap();
        }
        out.push_str("M5\n");
    }
    out.push_str("G0 X0 Y0\nM2\n");
    out
}

/// A file of arcs: a chain of half circles of different radii turning both ways (a scalloped
/// line), full circles, an R-word arc and lines between.
fn arc_file() -> String {
    let mut out = String::from("G21\nG90\nG0 X-150 Y0\nF2400\n");
    let mut x = -150.0;
    let radii = [5.0, 10.0, 3.0, 8.0, 12.0, 6.0, 1.5, 4.0];
    for (i, r) in radii.iter().chain(&radii).chain(&radii).map(|r| r / 2.0).enumerate() {
        let g = if i % 2 == 0 { "G2" } else { "G3" };
        writeln!(out, "{g} X{:.3} Y0 I{r:.3} J0", x + 2.0 * r).unwrap();
        x += 2.0 * r;
    }
    out.push_str("G1 X10 Y0\nG2 X10 Y0 I15 J0\nG3 X40 Y30 R30\nG1 X40 Y50\n");
    out.push_str("G91\nG2 X20 Y20 I20 J0\nG3 X-10 Y10 I-10 J0\nG2 X0 Y0 I0 J-25 F3600\nG90\nG0 X0 Y0\n");
    out
}

#[test]
fn a_vpype_polyline_files_plot_time_is_the_checks_within_2_percent() {
    estimate_matches_plot(&polyline_file());
}

#[test]
fn an_arc_files_plot_time_is_the_checks_within_2_percent() {
    estimate_matches_plot(&arc_file());
}

#[test]
fn the_demo_pen_files_plot_time_is_the_checks_within_2_percent() {
    estimate_matches_plot(include_str!("../demo/pen.gcode"));
}

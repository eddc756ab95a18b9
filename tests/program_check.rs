//! A program checked whole before it runs (`servoplot::program`): the plot time the check gives
//! by the planner's own model is the time the simulated plotter then takes to plot the same
//! file over the host link, within 2 %, for a polyline file as vpype writes it and for a file of
//! arcs; and the check's box is the box of the pulses the plot emits.

use servoplot::geom::Point;
use servoplot::host::GcodeState;
use servoplot::machine_io::pen::Pen;
use servoplot::motion::planner::Limits;
use servoplot::program::{CheckPlanner, ProgramCheck, Progress, Summary};
use servoplot::settings::Settings;
use servoplot::sim::{self, SimReport};

mod support;

use support::files::{arc_file, polyline_file};

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

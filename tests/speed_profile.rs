//! The speed profile as the servo drivers see it: measured on the simulated board's pulse
//! trace, not on the planner's commands.

use servoplot::geom::Point;
use servoplot::sim::{self, SimReport};

/// Speed along the straight line from the origin to `end`, in mm/min, between the pulses at
/// 30% and 70% of the path (the cruise), from the projection of each pulse's point on the line.
fn cruise_speed_mm_per_min(report: &SimReport, end: Point) -> f64 {
    let steps = report.trace.steps(0);
    let path = report.path();
    let (i, j) = (steps.len() * 3 / 10, steps.len() * 7 / 10);
    let len = ((end.x as f64).powi(2) + (end.y as f64).powi(2)).sqrt();
    let along = |p: Point| (p.x as f64 * end.x as f64 + p.y as f64 * end.y as f64) / len;
    let mm = (along(path[j + 1]) - along(path[i + 1])) / 100.0; // 100 steps/mm
    let s = (steps[j].0 - steps[i].0) as f64 / 1e6;
    mm / s * 60.0
}

#[test]
fn the_feed_rate_is_the_tangential_speed_in_every_direction_for_both_methods() {
    for method in [0, 1] {
        for deg in (0..360).step_by(30).chain([45, 135, 200, 315]) {
            let a = (deg as f64).to_radians();
            let (x, y) = (80.0 * a.cos(), 80.0 * a.sin());
            let report = sim::run_serial(&format!("$202={method}\nG1 X{x:.3} Y{y:.3} F2400\n"));
            let end = Point::new((x * 100.0).round() as i32, (y * 100.0).round() as i32);
            assert_eq!(report.position, end);
            let v = cruise_speed_mm_per_min(&report, end);
            assert!((v - 2400.0).abs() / 2400.0 < 0.01, "method {method}, {deg}°: {v:.1} mm/min");
        }
    }
}

#[test]
fn motion_starts_and_stops_at_the_start_rate_and_never_exceeds_an_axis_rate() {
    let report = sim::run_serial("G0 X150 Y-40\n");
    let s = &report.settings;
    // The path advances δ per (diagonal-method) step; from the start rate v0, one step at the
    // acceleration a reaches at most v1 = √(v0² + 2aδ): the first two intervals are no shorter
    // than δ/v0 and δ/v1, and the last two mirror them.
    let delta_mm = (150f64.hypot(40.0)) / 15_000.0;
    let (v0, a) = (s.start_rate_mm_per_min as f64 / 60.0, s.accel_mm_per_s2[0] as f64);
    let v1 = (v0 * v0 + 2.0 * a * delta_mm).sqrt();
    let steps = report.trace.steps(0);
    let n = steps.len();
    let interval = |i: usize| (steps[i + 1].0 - steps[i].0) as f64 / 1e6;
    for (i, what) in [(0, "first"), (n - 2, "last")] {
        assert!(interval(i) >= delta_mm / v1 * 0.99, "{what} interval {} s", interval(i));
    }
    // Per axis: pulses never closer than the axis' max rate allows (100 mm/s = 10 kHz).
    for axis in [servoplot::geom::Axis::X, servoplot::geom::Axis::Y] {
        let times: Vec<u64> = report.trace.pulses.iter().filter(|p| p.axis == axis).map(|p| p.t_us).collect();
        let min_gap = times.windows(2).map(|w| w[1] - w[0]).min().unwrap();
        let rate = s.max_rate_mm_per_min[axis.index()] as f64 / 60.0 * 100.0;
        assert!(min_gap as f64 >= 1e6 / rate - 1.0, "{axis:?}: {min_gap} µs between pulses");
    }
    // The rapid reached the X axis' max rate, the limiting one.
    let x_times: Vec<u64> =
        report.trace.pulses.iter().filter(|p| p.axis == servoplot::geom::Axis::X).map(|p| p.t_us).collect();
    let mid = x_times.len() / 2;
    let rate = 100.0 * 1e6 / (x_times[mid + 50] - x_times[mid - 50]) as f64;
    assert!((rate - 10_000.0).abs() < 100.0, "X cruises at {rate:.0} Hz");
}

#[test]
fn a_polyline_does_not_stop_at_every_joint() {
    // 200 segments of 0.5 mm around a circle of 16 mm radius: gentle 1.8° turns.
    let mut g = String::from("G1 X0 Y0 F3000\n");
    for k in 1..=200 {
        let a = k as f64 * std::f64::consts::TAU / 200.0;
        g += &format!("G1 X{:.3} Y{:.3}\n", 16.0 * a.sin(), 16.0 - 16.0 * a.cos());
    }
    let report = sim::run_serial(&g);
    assert_eq!(report.position, Point::ORIGIN);
    let steps = report.trace.steps(0);
    // Away from the ends, no interval is as slow as the start rate: no stop at a joint.
    let start_interval_us = 1e6 / (report.settings.start_rate_mm_per_min as f64 / 60.0 * 100.0);
    let n = steps.len();
    let slowest = steps[n / 10..n * 9 / 10].windows(2).map(|w| w[1].0 - w[0].0).max().unwrap();
    assert!((slowest as f64) < start_interval_us / 3.0, "slowest interior interval {slowest} µs");
}

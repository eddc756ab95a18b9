//! Speed profile of single curves: the feed along the path, the axes' rates and
//! accelerations, starts and stops at the start rate, exact timing over long runs.

use super::*;

#[test]
fn tangential_speed_is_the_feed_in_every_direction_for_both_methods() {
    for spm in [[100.0, 100.0], [80.0, 50.0]] {
        // Near-instant ramps, so the time is the length over the feed.
        let limits = limits_with(|s| {
            s.steps_per_mm = spm;
            s.accel_mm_per_s2 = [10_000.0; 2];
        });
        for method in [Method::Classic, Method::Diagonal] {
            for deg in (0..360).step_by(15) {
                let a = (deg as f64).to_radians();
                let (dx, dy) = ((8_000.0 * a.cos()).round() as i32, (8_000.0 * a.sin()).round() as i32);
                let job = Chords::line(dx, dy, method);
                let lens = job.step_lengths_mm(&limits);
                let ideal_mm = ((dx as f64 / spm[0] as f64).powi(2) + (dy as f64 / spm[1] as f64).powi(2)).sqrt();
                let mut p = TestPlanner::new(limits);
                let trace = run(&mut p, Vec::from([job]), method, DEFAULT_FEED);
                assert_eq!(trace.position(), Point::new(dx, dy));
                let expected_s = ideal_mm / 50.0;
                let err = (trace.seconds() - expected_s).abs() / expected_s;
                assert!(err < 0.01, "{method:?} {deg}° at {spm:?}: {} s for {expected_s} s", trace.seconds());
                // Cruise: every step in the middle half at the feed.
                let v = trace.speeds(&lens);
                let n = v.len();
                for s in &v[n / 4..3 * n / 4] {
                    assert!((s - 50.0).abs() < 0.5, "{method:?} {deg}°: cruise at {s} mm/s");
                }
                assert!(p.is_idle());
            }
        }
    }
}

#[test]
fn a_circle_is_drawn_at_the_feed_with_both_methods() {
    let limits = limits_with(|s| s.accel_mm_per_s2 = [10_000.0; 2]);
    for method in [Method::Classic, Method::Diagonal] {
        // 50 mm radius as one curve of 720 chords.
        let points = circle_points(5_000.0, 720);
        let job = Chords::circle(5_000.0, 720, method);
        let lens = job.step_lengths_mm(&limits);
        let perimeter_mm: f64 = lens.iter().sum();
        let mut p = TestPlanner::new(limits);
        let trace = run(&mut p, Vec::from([job]), method, DEFAULT_FEED);
        assert_eq!(trace.position(), end_of(&points));
        let err = (trace.seconds() - perimeter_mm / 50.0).abs() / (perimeter_mm / 50.0);
        assert!(err < 0.01, "{method:?}: {} s for {perimeter_mm} mm", trace.seconds());
        // No axis faster than its max rate (6000 mm/min = 10_000 steps/s).
        assert_axis_rates_within(&trace, &limits);
    }
}

#[test]
fn a_small_circle_slows_so_that_no_axis_exceeds_its_acceleration() {
    // 3 mm radius at 3000 mm/min would need 833 mm/s² of centripetal acceleration; the axes
    // take 500, of which the curve may use 80 %: √(400 · 3) = 34.6 mm/s.
    let limits = Limits::default();
    let curve_speed = (CENTRIPETAL_SHARE as f64 * 500.0 * 3.0).sqrt();
    for method in [Method::Classic, Method::Diagonal] {
        let job = Chords::circle(300.0, 120, method);
        let lens = job.step_lengths_mm(&limits);
        let mut p = TestPlanner::new(limits);
        let trace = run(&mut p, Vec::from([job]), method, DEFAULT_FEED);
        assert_eq!(trace.position(), Point::ORIGIN);
        let axis = max_axis_accel(&trace, &limits, 20_000);
        assert!(axis[0] <= 500.0 * 1.05 && axis[1] <= 500.0 * 1.05, "{method:?}: axes at {axis:?} mm/s²");
        // Mean speeds over 10 ms (about 35 steps) in the middle third of the circle.
        let w = trace.windowed_speeds(&lens, 10_000);
        let n = w.len();
        let (slowest, fastest) =
            w[n / 3..2 * n / 3].iter().fold((f64::MAX, 0.0f64), |(lo, hi), &(_, s)| (lo.min(s), hi.max(s)));
        assert!(slowest > 0.9 * curve_speed && fastest < curve_speed * 1.01, "{method:?}: {slowest}..{fastest} mm/s");
    }
}

#[test]
fn a_kink_inside_a_curve_is_passed_at_the_start_rate() {
    let limits = Limits::default();
    for method in [Method::Classic, Method::Diagonal] {
        // One curve whose tangent jumps by 90° at (3000, 0).
        let job = Chords::through(&[Point::ORIGIN, Point::new(3_000, 0), Point::new(3_000, 3_000)], method);
        let lens = job.step_lengths_mm(&limits);
        let mut p = TestPlanner::new(limits);
        let trace = run(&mut p, Vec::from([job]), method, DEFAULT_FEED);
        assert_eq!(trace.position(), Point::new(3_000, 3_000));
        let v = trace.speeds(&lens);
        assert!(v[1_500] > 49.5 && v[4_500] > 49.5);
        assert!(v[2_999] <= 5.0 * 1.001 && v[3_000] <= 5.0 * 1.001, "kink at {} / {}", v[2_999], v[3_000]);
        assert!(trace.max_accel(&lens) <= 500.0 * 1.05);
    }
}

#[test]
fn a_rapid_circle_keeps_every_axis_within_its_rate() {
    // At rapid the cap depends on the direction: 100 mm/s along an axis, 141 mm/s at 45°.
    let limits = Limits::default();
    for method in [Method::Classic, Method::Diagonal] {
        let job = Chords::circle(5_000.0, 720, method);
        let lens = job.step_lengths_mm(&limits);
        let mut p = TestPlanner::new(limits);
        let trace = run(&mut p, Vec::from([job]), method, Feed::Rapid);
        assert_eq!(trace.position(), Point::ORIGIN);
        assert_axis_rates_within(&trace, &limits);
        let v = trace.speeds(&lens);
        let top = v.iter().cloned().fold(0.0, f64::max);
        assert!(top > 130.0, "{method:?}: never faster than {top} mm/s");
        let axis = max_axis_accel(&trace, &limits, 20_000);
        assert!(axis[0] <= 500.0 * 1.05 && axis[1] <= 500.0 * 1.05, "{method:?}: axes at {axis:?} mm/s²");
    }
}

#[test]
fn a_zigzag_curve_with_more_kinks_than_blocks_reaches_its_end() {
    let limits = Limits::default();
    let method = Method::Diagonal;
    let mut points = Vec::from([Point::ORIGIN]);
    for i in 1..=200 {
        points.push(Point::new(i * 20, if i % 2 == 0 { 0 } else { 20 }));
    }
    let job = Chords::through(&points, method);
    let lens = job.step_lengths_mm(&limits);
    let mut p = TestPlanner::new(limits);
    let trace = run(&mut p, Vec::from([job]), method, DEFAULT_FEED);
    assert_eq!(trace.position(), end_of(&points));
    let v = trace.speeds(&lens);
    // Every kink (a right angle between 45° chords, every 20 steps) at the junction speed:
    // 707 mm/s² along 45°, 0.02 mm deviation.
    let s = core::f64::consts::FRAC_1_SQRT_2;
    let rule = (500.0 * core::f64::consts::SQRT_2 * 0.02 * s / (1.0 - s)).sqrt();
    for k in (20..v.len()).step_by(20) {
        assert!(v[k] <= rule * 1.001 && v[k - 1] <= rule * 1.001, "kink at step {k}: {} mm/s", v[k]);
    }
    assert!(v[10] > rule * 1.5, "no faster than {} between kinks", v[10]);
    assert!(trace.max_accel(&lens) <= 500.0 * core::f64::consts::SQRT_2 * 1.05);
}

#[test]
fn motion_starts_and_ends_at_the_start_rate() {
    let limits = Limits::default(); // start rate 300 mm/min = 5 mm/s
    for method in [Method::Classic, Method::Diagonal] {
        for (dx, dy) in [(3_000, 0), (2_000, 2_000), (-500, 1_700), (7, 3)] {
            let job = Chords::line(dx, dy, method);
            let lens = job.step_lengths_mm(&limits);
            let mut p = TestPlanner::new(limits);
            let trace = run(&mut p, Vec::from([job]), method, DEFAULT_FEED);
            let v = trace.speeds(&lens);
            assert!(v[0] <= 5.0 * 1.001, "{method:?} ({dx}, {dy}) starts at {} mm/s", v[0]);
            assert!(*v.last().unwrap() <= 5.0 * 1.001, "ends at {} mm/s", v.last().unwrap());
            if dx.abs() > 1_000 {
                assert!(v.iter().cloned().fold(0.0, f64::max) > 49.5, "never reached the feed");
            }
        }
    }
}

#[test]
fn acceleration_stays_within_each_axis_limit() {
    let limits = limits_with(|s| s.accel_mm_per_s2 = [400.0, 200.0]);
    for method in [Method::Classic, Method::Diagonal] {
        for deg in [0.0f64, 30.0, 45.0, 70.0, 90.0, 200.0] {
            let a = deg.to_radians();
            let (dx, dy) = ((6_000.0 * a.cos()).round() as i32, (6_000.0 * a.sin()).round() as i32);
            let job = Chords::line(dx, dy, method);
            let lens = job.step_lengths_mm(&limits);
            let mut p = TestPlanner::new(limits);
            let trace = run(&mut p, Vec::from([job]), method, Feed::Rapid);
            // Tangential limit: a·|cos| ≤ 400 and a·|sin| ≤ 200 (steps/mm equal on both axes).
            let (c, s) = (a.cos().abs(), a.sin().abs());
            let allowed =
                f64::min(if c > 1e-6 { 400.0 / c } else { f64::MAX }, if s > 1e-6 { 200.0 / s } else { f64::MAX });
            let seen = trace.max_accel(&lens);
            assert!(seen <= allowed * 1.05, "{method:?} {deg}°: {seen} mm/s² > {allowed}");
            assert!(seen >= allowed * 0.8, "{method:?} {deg}°: ramps at only {seen} mm/s² of {allowed}");
        }
    }
}

#[test]
fn rapid_runs_each_axis_at_its_max_rate_and_no_interval_is_too_short() {
    // Slow drivers: 4 kHz max pulse rate caps the steps; fast drivers: the axis max rates cap.
    for pulse_hz in [4_000.0, MAX_PULSE_RATE_HZ] {
        let limits = limits_with(|s| {
            s.max_pulse_rate_hz = pulse_hz;
            s.max_rate_mm_per_min = [6_000.0, 3_000.0];
        });
        for method in [Method::Classic, Method::Diagonal] {
            for (dx, dy) in [(20_000, 0), (0, 20_000), (15_000, 15_000), (-20_000, 7_000)] {
                let job = Chords::line(dx, dy, method);
                let lens = job.step_lengths_mm(&limits);
                let mut p = TestPlanner::new(limits);
                let trace = run(&mut p, Vec::from([job]), method, Feed::Rapid);
                assert_axis_rates_within(&trace, &limits);
                // Cruise is as fast as the tighter of the two rules allows.
                let (fx, fy) = (dx as f64 / 100.0, dy as f64 / 100.0);
                let len = (fx * fx + fy * fy).sqrt();
                let axis_cap = f64::min(
                    if fx != 0.0 { 100.0 * len / fx.abs() } else { f64::MAX },
                    if fy != 0.0 { 50.0 * len / fy.abs() } else { f64::MAX },
                );
                let pulse_cap = pulse_hz as f64 * lens[0];
                let expected = axis_cap.min(pulse_cap);
                let top = trace.speeds(&lens).into_iter().fold(0.0, f64::max);
                assert!(
                    (top - expected).abs() / expected < 0.01,
                    "{method:?} ({dx},{dy}) {pulse_hz} Hz: {top} vs {expected}"
                );
            }
        }
    }
}

#[test]
fn long_runs_have_no_rounding_drift() {
    // 1800 mm/min at 100 steps/mm along X: 333.33 µs per step, 1333.33 ticks.
    let limits = limits_with(|s| s.accel_mm_per_s2 = [10_000.0; 2]);
    let mut p = TestPlanner::new(limits);
    let trace =
        run(&mut p, Vec::from([Chords::line(60_000, 0, Method::Diagonal)]), Method::Diagonal, Feed::MmPerMin(1_800.0));
    let cruise: Vec<u64> = trace.cmds[1_000..31_000].iter().map(|c| c.interval_ticks as u64).collect();
    assert!(cruise.iter().all(|&t| t == 1_333 || t == 1_334));
    let total: u64 = cruise.iter().sum();
    assert!(total.abs_diff(40_000_000) <= 1, "30,000 steps took {total} ticks");
}

#[test]
fn the_longest_line_in_the_machine_runs_to_its_end() {
    let limits = limits_with(|s| s.steps_per_mm = [200.0, 200.0]);
    for method in [Method::Classic, Method::Diagonal] {
        let mut p = TestPlanner::new(limits);
        let trace = run(&mut p, Vec::from([Chords::line(200_000, -199_999, method)]), method, Feed::Rapid);
        assert_eq!(trace.position(), Point::new(200_000, -199_999));
        assert!(p.is_idle());
    }
}

#[test]
fn a_long_curve_is_scanned_while_it_runs_without_slowing_down() {
    // One 100 mm line: only a little of it is scanned when it starts.
    let limits = Limits::default();
    let method = Method::Diagonal;
    let job = Chords::line(10_000, 0, method);
    let lens = job.step_lengths_mm(&limits);
    let mut p = TestPlanner::new(limits);
    p.push(job, DEFAULT_FEED, method).unwrap();
    let mut trace = Trace::default();
    while let Some(c) = p.next_cmd() {
        trace.cmds.push(c.unwrap());
    }
    let v = trace.speeds(&lens);
    // Accelerates at 500 mm/s² from the start rate: 50 mm/s after 2.5 mm (250 steps).
    assert!(v[260] > 49.5, "at 2.6 mm: {} mm/s", v[260]);
    assert!(trace.max_accel(&lens) <= 500.0 * 1.05);
    assert_eq!(trace.position(), Point::new(10_000, 0));
}

#[test]
fn a_line_longer_than_the_look_ahead_horizon_brakes_for_its_end_not_for_the_horizon() {
    // 200 steps/mm and 10 mm/s²: braking from the feed (50 mm/s) takes 125 mm, 25,000 steps,
    // beyond the steps scanned ahead; the line is 300 mm.
    let limits = limits_with(|s| {
        s.steps_per_mm = [200.0; 2];
        s.accel_mm_per_s2 = [10.0; 2];
    });
    assert!(125.0 * 200.0 > STEP_RING_LEN as f64);
    for method in [Method::Classic, Method::Diagonal] {
        let job = Chords::line(60_000, 0, method);
        let lens = job.step_lengths_mm(&limits);
        let trace = run(&mut TestPlanner::new(limits), Vec::from([job]), method, DEFAULT_FEED);
        assert_eq!(trace.position(), Point::new(60_000, 0));
        let top = trace.speeds(&lens).into_iter().fold(0.0, f64::max);
        assert!(top > 49.9 && top < 50.1, "{method:?}: top speed {top} mm/s");
        let accel = trace.max_accel_over(&lens, 100_000);
        assert!(accel <= 10.0 * 1.05, "{method:?}: {accel} mm/s²");
        // From the start rate (5 mm/s) up in 4.5 s over 123.75 mm, 52.5 mm at the feed, down in
        // 4.5 s: 10.05 s.
        assert!((trace.seconds() - 10.05).abs() < 0.03, "{method:?}: {} s", trace.seconds());
    }
}

#[test]
fn the_lower_bound_is_below_every_plot_and_close_for_long_lines() {
    let limits = Limits::default();
    for method in [Method::Classic, Method::Diagonal] {
        for points in [
            Vec::from([Point::ORIGIN, Point::new(10_000, 3_000)]),
            Vec::from([Point::ORIGIN, Point::new(20, 0)]),
            Vec::from([Point::ORIGIN, Point::new(3_000, 0), Point::new(3_000, 3_000), Point::new(0, 0)]),
        ] {
            for feed in [DEFAULT_FEED, Feed::Rapid] {
                let jobs = segments(&points, method);
                let trace = run(&mut TestPlanner::new(limits), jobs, method, feed);
                let bound = plot_time_lower_bound(&limits, method, feed, &points) as f64;
                assert!(
                    bound > 0.0 && bound <= trace.seconds(),
                    "{method:?} {points:?}: {} s < bound {bound}",
                    trace.seconds()
                );
                if points.len() == 2 && points[1].x > 1_000 {
                    assert!(trace.seconds() < bound * 1.01, "{} s, bound {bound}", trace.seconds());
                }
            }
        }
    }
    assert_eq!(plot_time_lower_bound(&limits, Method::Classic, DEFAULT_FEED, &[Point::ORIGIN]), 0.0);
}

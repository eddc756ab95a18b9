//! Look-ahead across segments: joints passed without stopping where the junction rule
//! allows, and slowed where it does not.

use super::*;

/// Speed near each vertex of a polyline run: the slowest step within `steps` steps of it.
fn speed_at_junctions(trace: &Trace, jobs: &[Chords], lens: &[f64], steps: usize) -> Vec<f64> {
    let v = trace.speeds(lens);
    let mut at = 0;
    let mut out = Vec::new();
    for job in &jobs[..jobs.len() - 1] {
        at += job.step_lengths_mm(&Limits::default()).len();
        let lo = at.saturating_sub(steps);
        out.push(v[lo..(at + steps).min(v.len())].iter().cloned().fold(f64::MAX, f64::min));
    }
    out
}

#[test]
fn a_polyline_circle_does_not_stop_at_its_joints() {
    let limits = Limits::default();
    for method in [Method::Classic, Method::Diagonal] {
        let points = circle_points(5_000.0, 2_000);
        let jobs = segments(&points, method);
        let lens = lengths(&jobs, &limits);
        let mut p = TestPlanner::new(limits);
        let trace = run(&mut p, jobs.clone(), method, DEFAULT_FEED);
        assert_eq!(trace.position(), end_of(&points));
        let v = trace.speeds(&lens);
        let n = v.len();
        // Away from the start and end ramps (3 mm each) the speed stays near the feed.
        let interior = &v[n / 20..n - n / 20];
        let slowest = interior.iter().cloned().fold(f64::MAX, f64::min);
        assert!(slowest > 40.0, "{method:?}: slows to {slowest} mm/s (start rate 5)");
        assert!(trace.max_accel(&lens) <= 500.0 * core::f64::consts::SQRT_2 * 1.05);
        assert_axis_rates_within(&trace, &limits);
        // Honest lower bound, and close to it.
        let bound = plot_time_lower_bound(&limits, method, DEFAULT_FEED, &points) as f64;
        assert!(bound <= trace.seconds() && trace.seconds() < bound * 1.05, "{} s, bound {bound} s", trace.seconds());
    }
}

#[test]
fn gentle_junctions_keep_the_feed_and_a_right_angle_slows_by_the_junction_rule() {
    for jd_mm in [0.02f32, 1.0] {
        let limits = limits_with(|s| s.junction_deviation_mm = jd_mm);
        let method = Method::Diagonal;
        // 3° turn, then a right angle, each after 30 mm.
        let points = [Point::ORIGIN, Point::new(3_000, 0), Point::new(6_000, 157), Point::new(6_000 - 157, 3_157)];
        let jobs = segments(&points, method);
        let lens = lengths(&jobs, &limits);
        let mut p = TestPlanner::new(limits);
        let trace = run(&mut p, jobs.clone(), method, DEFAULT_FEED);
        assert_eq!(trace.position(), end_of(&points));
        let at = speed_at_junctions(&trace, &jobs, &lens, 3);
        assert!(at[0] > 49.5, "3° turn taken at {} mm/s", at[0]);
        // Right angle: sin(θ/2) = √½; at 0.02 mm the rule gives 4.9 mm/s, below the start rate.
        let s = core::f64::consts::FRAC_1_SQRT_2;
        let rule = (500.0 * jd_mm as f64 * s / (1.0 - s)).sqrt().max(5.0);
        assert!((at[1] - rule).abs() / rule < 0.03, "jd {jd_mm}: corner at {} mm/s, rule {rule}", at[1]);
        assert!(trace.max_accel(&lens) <= 500.0 * core::f64::consts::SQRT_2 * 1.05);
    }
}

#[test]
fn a_reversal_passes_at_the_start_rate_and_a_slower_feed_is_met_before_its_segment() {
    let limits = Limits::default();
    let method = Method::Classic;
    let jobs = segments(&[Point::ORIGIN, Point::new(3_000, 0), Point::new(0, 0)], method);
    let lens = lengths(&jobs, &limits);
    let mut p = TestPlanner::new(limits);
    let trace = run(&mut p, jobs.clone(), method, DEFAULT_FEED);
    let v = trace.speeds(&lens);
    // The last step before the joint at the start rate, the first after it one acceleration
    // step above.
    let next = (25.0f64 + 2.0 * 500.0 * 0.01).sqrt();
    assert!(v[2_999] <= 5.0 * 1.001 && v[3_000] <= next * 1.001, "reversal at {} / {}", v[2_999], v[3_000]);

    // Collinear, 3000 then 600 mm/min: the first segment brakes to 10 mm/s before the joint.
    let mut p = TestPlanner::new(limits);
    p.push(Chords::line(3_000, 0, method), DEFAULT_FEED, method).unwrap();
    p.push(Chords::line(3_000, 0, method), Feed::MmPerMin(600.0), method).unwrap();
    let mut trace = Trace::default();
    while let Some(Ok(c)) = p.next_cmd() {
        trace.cmds.push(c);
    }
    let lens = [0.01f64; 6_000];
    let v = trace.speeds(&lens);
    assert!(v[..3_000].iter().cloned().fold(0.0, f64::max) > 49.5);
    assert!(v[2_999] <= 10.0 * 1.001 && v[3_000] <= 10.0 * 1.001, "joint at {} / {}", v[2_999], v[3_000]);
    assert!((v[4_500] - 10.0).abs() < 0.05);
    assert!(trace.max_accel(&lens) <= 500.0 * 1.05);
}

#[test]
fn a_segment_pushed_while_the_last_one_runs_joins_it_without_a_stop() {
    let limits = Limits::default();
    let method = Method::Diagonal;
    let mut p = TestPlanner::new(limits);
    p.push(Chords::line(3_000, 0, method), DEFAULT_FEED, method).unwrap();
    let mut trace = Trace::default();
    for _ in 0..2_000 {
        trace.cmds.push(p.next_cmd().unwrap().unwrap());
    }
    // Pushed 10 mm before the end: enough to keep cruising (braking takes 2.5 mm).
    p.push(Chords::line(3_000, 100, method), DEFAULT_FEED, method).unwrap();
    while let Some(c) = p.next_cmd() {
        trace.cmds.push(c.unwrap());
    }
    let mut lens = Vec::from([0.01f64; 3_000]);
    lens.extend(Chords::line(3_000, 100, method).step_lengths_mm(&limits));
    let v = trace.speeds(&lens);
    let slowest = v[2_000..4_000].iter().cloned().fold(f64::MAX, f64::min);
    assert!(slowest > 49.5, "slowed to {slowest} mm/s at the joint");
    assert_eq!(trace.position(), Point::new(6_000, 100));
}

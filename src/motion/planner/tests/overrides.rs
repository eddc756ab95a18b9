//! The feed and rapid overrides acting on motion already queued: the speed changes at the
//! acceleration limit, never beyond what the machine allows, and the path stays the same steps.

use super::*;
use crate::motion::overrides::Overrides;

fn overrides(feed_percent: u8, rapid_percent: u8) -> Overrides {
    Overrides { feed_percent, rapid_percent, ..Overrides::NONE }
}

/// The mean speed of steps `from..to`, and the slowest and fastest of them, mm/s.
fn speeds_over(v: &[f64], from: usize, to: usize) -> (f64, f64, f64) {
    let part = &v[from..to];
    let mean = part.iter().sum::<f64>() / part.len() as f64;
    (mean, part.iter().cloned().fold(f64::MAX, f64::min), part.iter().cloned().fold(0.0, f64::max))
}

fn steps(trace: &Trace) -> Vec<Step> {
    trace.cmds.iter().map(|c| c.step).collect()
}

#[test]
fn a_feed_override_of_half_mid_line_brakes_at_the_acceleration_limit_to_half_the_feed() {
    let limits = Limits::default();
    for method in [Method::Classic, Method::Diagonal] {
        // 200 mm along X at 3000 mm/min (50 mm/s); the override comes at 50 mm, cruising.
        let job = Chords::line(20_000, 0, method);
        let lens = job.step_lengths_mm(&limits);
        let plain = run(&mut TestPlanner::new(limits), Vec::from([job.clone()]), method, DEFAULT_FEED);
        let mut p = TestPlanner::new(limits);
        let trace = run_with(&mut p, Vec::from([job]), method, DEFAULT_FEED, |n, p| {
            if n == 5_000 {
                p.set_overrides(overrides(50, 100));
            }
        });
        // The same path, to its very end, stopping at the start rate.
        assert_eq!(steps(&trace), steps(&plain));
        assert_eq!(trace.position(), Point::new(20_000, 0));
        assert!(p.is_idle());
        let v = trace.speeds(&lens);
        assert!(v[19_999] <= 5.0 * 1.001, "{method:?}: stops from {} mm/s", v[19_999]);
        // Braking from 50 to 25 mm/s at 500 mm/s² takes (50² − 25²) / 1000 = 1.875 mm: 188 steps.
        let (before, ..) = speeds_over(&v, 4_000, 5_000);
        assert!((before - 50.0).abs() < 0.5, "{method:?}: {before} mm/s before");
        assert!(v[5_000] > 49.5 && v[5_050] > 40.0, "{method:?}: no drop at once ({} / {})", v[5_000], v[5_050]);
        let (half, slowest, fastest) = speeds_over(&v, 5_200, 17_000);
        assert!((half - 25.0).abs() < 0.25 && slowest > 24.5 && fastest < 25.5, "{method:?}: {slowest}..{fastest}");
        // Never faster than the acceleration limit allows, braking or not.
        let accel = trace.max_accel_over(&lens, 2_000);
        assert!(accel <= 500.0 * 1.05, "{method:?}: {accel} mm/s²");
        // And at 25 mm/s the rest takes about twice as long.
        assert!(trace.seconds() > plain.seconds() * 1.6, "{} s vs {} s", trace.seconds(), plain.seconds());
    }
}

#[test]
fn raising_the_override_ramps_up_at_the_acceleration_limit() {
    let limits = Limits::default();
    let method = Method::Diagonal;
    let job = Chords::line(20_000, 0, method);
    let lens = job.step_lengths_mm(&limits);
    let mut p = TestPlanner::new(limits);
    p.set_overrides(overrides(50, 100));
    let trace = run_with(&mut p, Vec::from([job]), method, DEFAULT_FEED, |n, p| {
        if n == 5_000 {
            p.set_overrides(overrides(120, 100));
        }
    });
    assert_eq!(trace.position(), Point::new(20_000, 0));
    let v = trace.speeds(&lens);
    let (before, ..) = speeds_over(&v, 4_000, 5_000);
    assert!((before - 25.0).abs() < 0.25, "set at rest, it applies from the start: {before} mm/s");
    let (after, ..) = speeds_over(&v, 6_000, 15_000);
    assert!((after - 60.0).abs() < 0.6, "{after} mm/s");
    assert!(trace.max_accel_over(&lens, 2_000) <= 500.0 * 1.05);
}

#[test]
fn twice_the_feed_never_exceeds_an_axis_max_rate_or_the_pulse_rate() {
    // 4000 mm/min twice over is 8000, beyond the axes' 6000.
    let limits = Limits::default();
    let fast = Feed::MmPerMin(4_000.0);
    for method in [Method::Classic, Method::Diagonal] {
        for (dx, dy) in [(20_000, 0), (17_320, 10_000), (-3_000, 15_000)] {
            let job = Chords::line(dx, dy, method);
            let mut p = TestPlanner::new(limits);
            let trace = run_with(&mut p, Vec::from([job]), method, fast, |n, p| {
                if n == 100 {
                    p.set_overrides(overrides(200, 100));
                }
            });
            assert_eq!(trace.position(), Point::new(dx, dy));
            assert_axis_rates_within(&trace, &limits);
        }
    }
    // Where the drivers' pulse rate binds (5 kHz at 100 steps/mm: 50 mm/s along X).
    let slow_drivers = limits_with(|s| s.max_pulse_rate_hz = 5_000.0);
    let job = Chords::line(10_000, 0, Method::Diagonal);
    let lens = job.step_lengths_mm(&slow_drivers);
    let mut p = TestPlanner::new(slow_drivers);
    p.set_overrides(overrides(200, 100));
    let trace = run(&mut p, Vec::from([job]), Method::Diagonal, Feed::MmPerMin(2_000.0));
    assert_axis_rates_within(&trace, &slow_drivers);
    let top = trace.speeds(&lens).into_iter().fold(0.0, f64::max);
    assert!(top <= 50.0 * 1.001 && top > 49.0, "{top} mm/s");
}

#[test]
fn a_rapid_override_of_a_quarter_slows_a_rapid_and_no_feed_motion() {
    let limits = Limits::default();
    let method = Method::Diagonal;
    // A rapid along X runs at the axis' max rate, 100 mm/s.
    let job = Chords::line(20_000, 0, method);
    let lens = job.step_lengths_mm(&limits);
    let mut p = TestPlanner::new(limits);
    let trace = run_with(&mut p, Vec::from([job.clone()]), method, Feed::Rapid, |n, p| {
        if n == 8_000 {
            // The feed override leaves a rapid alone; the rapid override takes it to 25 %.
            p.set_overrides(overrides(50, 25));
        }
    });
    assert_eq!(trace.position(), Point::new(20_000, 0));
    let v = trace.speeds(&lens);
    let (full, ..) = speeds_over(&v, 7_000, 8_000);
    assert!((full - 100.0).abs() < 1.0, "{full} mm/s");
    // 100 to 25 mm/s at 500 mm/s²: 9.4 mm.
    let (quarter, slowest, fastest) = speeds_over(&v, 9_000, 18_000);
    assert!((quarter - 25.0).abs() < 0.25 && slowest > 24.5 && fastest < 25.5, "{slowest}..{fastest} mm/s");
    assert!(trace.max_accel_over(&lens, 2_000) <= 500.0 * 1.05);

    // Feed motion does not take the rapid override.
    let mut p = TestPlanner::new(limits);
    p.set_overrides(overrides(100, 25));
    let trace = run(&mut p, Vec::from([job]), method, DEFAULT_FEED);
    let (feed, ..) = speeds_over(&trace.speeds(&lens), 5_000, 15_000);
    assert!((feed - 50.0).abs() < 0.5, "{feed} mm/s");
}

#[test]
fn a_jog_takes_no_override() {
    let limits = Limits::default();
    let method = Method::Classic;
    let job = Chords::line(10_000, 0, method);
    let lens = job.step_lengths_mm(&limits);
    let mut p = TestPlanner::new(limits);
    p.set_overrides(overrides(10, 25));
    p.push_jog(job, DEFAULT_FEED, method).unwrap();
    let mut trace = Trace::default();
    while let Some(c) = p.next_cmd() {
        trace.cmds.push(c.unwrap());
        if trace.cmds.len() == 4_000 {
            p.set_overrides(overrides(200, 50));
        }
    }
    assert_eq!(trace.position(), Point::new(10_000, 0));
    let (jog, slowest, fastest) = speeds_over(&trace.speeds(&lens), 1_000, 9_000);
    assert!((jog - 50.0).abs() < 0.5 && slowest > 49.5 && fastest < 50.5, "{slowest}..{fastest} mm/s");
}

#[test]
fn a_lower_override_just_before_a_corner_brakes_at_the_limit_and_never_passes_it_faster() {
    let limits = Limits::default();
    for method in [Method::Classic, Method::Diagonal] {
        // A right angle after 50 mm; 5 mm of braking from the feed down to the override's 5 mm/s
        // would be needed, the override comes 1 mm before it.
        let points = [Point::ORIGIN, Point::new(5_000, 0), Point::new(5_000, 5_000)];
        let jobs = segments(&points, method);
        let lens = lengths(&jobs, &limits);
        let plain = run(&mut TestPlanner::new(limits), jobs.clone(), method, DEFAULT_FEED);
        for at in [4_700, 4_900, 4_990, 5_010, 9_900] {
            let mut p = TestPlanner::new(limits);
            let trace = run_with(&mut p, jobs.clone(), method, DEFAULT_FEED, |n, p| {
                if n == at {
                    p.set_overrides(overrides(10, 100));
                }
            });
            assert_eq!(steps(&trace), steps(&plain), "{method:?} at {at}");
            assert!(p.is_idle());
            let (v, v_plain) = (trace.speeds(&lens), plain.speeds(&lens));
            assert!(trace.max_accel_over(&lens, 2_000) <= 500.0 * 1.05, "{method:?} at {at}");
            for i in 4_990..5_010 {
                assert!(v[i] <= v_plain[i] * 1.001, "{method:?} at {at}: corner at {} mm/s", v[i]);
            }
            assert!(v[v.len() - 1] <= 5.0 * 1.001, "{method:?} at {at}: stops from {} mm/s", v[v.len() - 1]);
        }
    }
}

#[test]
fn on_a_tight_circle_twice_the_feed_keeps_within_its_curvature_and_the_axes_acceleration() {
    // 3 mm radius: the curve allows √(0.8 · 500 · 3) = 34.6 mm/s; 3000 mm/min at 60 % is 30.
    let limits = Limits::default();
    let curve_speed = (CENTRIPETAL_SHARE as f64 * 500.0 * 3.0).sqrt();
    for method in [Method::Classic, Method::Diagonal] {
        let job = Chords::circle(300.0, 120, method);
        let lens = job.step_lengths_mm(&limits);
        for (from, to) in [(60, 200), (200, 60), (60, 100)] {
            let mut p = TestPlanner::new(limits);
            p.set_overrides(overrides(from, 100));
            let trace = run_with(&mut p, Vec::from([job.clone()]), method, DEFAULT_FEED, |n, p| {
                if n == 400 {
                    p.set_overrides(overrides(to, 100));
                }
            });
            assert_eq!(trace.position(), Point::ORIGIN);
            let axis = max_axis_accel(&trace, &limits, 20_000);
            assert!(axis[0] <= 500.0 * 1.05 && axis[1] <= 500.0 * 1.05, "{method:?} {from}→{to}: {axis:?} mm/s²");
            // Mean speeds over 20 ms (about 70 steps, two or three chords).
            let w = trace.windowed_speeds(&lens, 20_000);
            let fastest = w.iter().fold(0.0f64, |hi, &(_, s)| hi.max(s));
            assert!(fastest < curve_speed * 1.01, "{method:?} {from}→{to}: {fastest} mm/s");
            if to == 200 {
                let n = w.len();
                let slowest = w[n / 2..3 * n / 4].iter().fold(f64::MAX, |lo, &(_, s)| lo.min(s));
                assert!(slowest > 0.9 * curve_speed, "{method:?}: the raise takes it to the curve's cap: {slowest}");
            }
        }
    }
}

#[test]
fn overrides_applied_while_held_act_from_the_resume() {
    let limits = Limits::default();
    let method = Method::Diagonal;
    let job = Chords::line(20_000, 0, method);
    let lens = job.step_lengths_mm(&limits);
    let mut p = TestPlanner::new(limits);
    let mut trace = run_with(&mut p, Vec::from([job]), method, DEFAULT_FEED, |n, p| {
        if n == 5_000 {
            p.hold();
        }
    });
    assert_eq!(p.state(), PlannerState::Held);
    p.set_overrides(overrides(30, 100));
    p.resume();
    while let Some(c) = p.next_cmd() {
        trace.cmds.push(c.unwrap());
    }
    assert_eq!(trace.position(), Point::new(20_000, 0));
    let (v, ..) = speeds_over(&trace.speeds(&lens), 10_000, 18_000);
    assert!((v - 15.0).abs() < 0.15, "{v} mm/s");
}

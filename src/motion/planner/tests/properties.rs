//! Random settings, curves, feeds, holds, aborts and overrides: the steps emitted are the path's
//! own, and overrides keep the motion within its limits.

use super::*;
use crate::motion::overrides::Overrides;
use proptest::prelude::*;

/// Settings anywhere in their ranges.
fn any_settings() -> impl Strategy<Value = Settings> {
    (
        (1.0f32..200.0, 1.0f32..200.0),
        (60.0f32..60_000.0, 60.0f32..60_000.0),
        (1.0f32..10_000.0, 1.0f32..10_000.0),
        0.0f32..1.0,
        100.0f32..MAX_PULSE_RATE_HZ,
        0.0f32..5.0,
    )
        .prop_map(|(spm, rate, accel, start, pulse, jd)| Settings {
            steps_per_mm: [spm.0, spm.1],
            max_rate_mm_per_min: [rate.0, rate.1],
            accel_mm_per_s2: [accel.0, accel.1],
            start_rate_mm_per_min: 1.0 + start * (rate.0.min(rate.1) - 1.0),
            max_pulse_rate_hz: pulse,
            junction_deviation_mm: jd,
            ..Settings::default()
        })
}

/// A change of the feed and rapid overrides (percent) after a number of steps.
fn any_override_change() -> impl Strategy<Value = (usize, u8, u8)> {
    (0usize..2_000, 10u8..=200, prop_oneof![Just(25u8), Just(50), Just(100)])
}

/// A job: a chain of chords (kinks between them), maybe failing after some steps.
fn any_job() -> impl Strategy<Value = (Vec<(i32, i32)>, Option<u64>)> {
    (proptest::collection::vec((-300i32..300, -300i32..300), 1..4), proptest::option::of(0u64..400))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    /// Random settings, curves with kinks and errors, feeds, holds, aborts and overrides: the steps
    /// emitted are exactly the path's own (a prefix of them after an abort), errors come
    /// where the curves fail, no interval is below the pulse period, and the planner ends
    /// idle.
    #[test]
    fn steps_are_the_paths_own_whatever_happens(
        settings in any_settings(),
        job_specs in proptest::collection::vec(any_job(), 1..6),
        feed in prop_oneof![Just(Feed::Rapid), any::<f32>().prop_map(Feed::MmPerMin)],
        diagonal in any::<bool>(),
        hold_at in proptest::option::of(0usize..2_000),
        abort_at in proptest::option::of(0usize..2_000),
        overrides in proptest::collection::vec(any_override_change(), 0..4),
    ) {
        let limits = Limits::try_from_settings(&settings).unwrap();
        let method = if diagonal { Method::Diagonal } else { Method::Classic };
        let jobs: Vec<Chords> = job_specs
            .iter()
            .map(|(offsets, fail)| {
                let mut points = Vec::from([Point::ORIGIN]);
                for (dx, dy) in offsets {
                    let last = *points.last().unwrap();
                    points.push(Point::new(last.x + dx, last.y + dy));
                }
                let job = Chords::through(&points, method);
                match fail { Some(k) => job.failing_after(*k), None => job }
            })
            .collect();
        // What the path is: each job's steps, and the step count before each error.
        let (mut path, mut errors) = (Vec::new(), Vec::new());
        for job in &jobs {
            let mut walk = job.clone();
            loop {
                match walk.next_step() {
                    Ok(Some(step)) => path.push(step),
                    Ok(None) => break,
                    Err(e) => {
                        errors.push((path.len(), e));
                        break;
                    }
                }
            }
        }
        let mut p = TestPlanner::new(limits);
        let mut trace = run_with(&mut p, jobs, method, feed, |n, p| {
            if Some(n) == hold_at { p.hold(); }
            if Some(n) == abort_at { p.abort(); }
            for &(at, feed_percent, rapid_percent) in &overrides {
                if at == n {
                    p.set_overrides(Overrides { feed_percent, rapid_percent, ..Overrides::NONE });
                }
            }
        });
        if p.state() == PlannerState::Held {
            p.resume();
            while let Some(c) = p.next_cmd() {
                match c {
                    Ok(cmd) => trace.cmds.push(cmd),
                    Err(e) => trace.errors.push((trace.cmds.len(), e)),
                }
            }
        }
        prop_assert!(p.is_idle());
        let steps: Vec<Step> = trace.cmds.iter().map(|c| c.step).collect();
        if abort_at.is_some_and(|n| n <= path.len()) {
            prop_assert!(steps.len() <= path.len());
            prop_assert_eq!(&steps[..], &path[..steps.len()]);
            prop_assert_eq!(&trace.errors[..], &errors[..trace.errors.len()]);
        } else {
            prop_assert_eq!(&steps, &path);
            prop_assert_eq!(&trace.errors, &errors);
        }
        prop_assert!(trace.cmds.iter().all(|c| c.interval_ticks >= limits.min_interval_ticks()));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Overrides changing at random points of a polyline or a circle, at the default limits: the
    /// same steps as without them, no axis beyond its max rate, the speed changing at the
    /// acceleration limit at most, and a stop at the start rate at the end.
    #[test]
    fn overrides_keep_the_motion_within_its_limits(
        circle in any::<bool>(),
        offsets in proptest::collection::vec((-3_000i32..3_000, -3_000i32..3_000), 1..5),
        feed in prop_oneof![Just(Feed::Rapid), (600.0f32..6_000.0).prop_map(Feed::MmPerMin)],
        diagonal in any::<bool>(),
        changes in proptest::collection::vec((0usize..12_000, 10u8..=200, prop_oneof![Just(25u8), Just(50), Just(100)]), 1..6),
    ) {
        let limits = Limits::default();
        let method = if diagonal { Method::Diagonal } else { Method::Classic };
        let jobs = if circle {
            Vec::from([Chords::circle(1_000.0, 180, method)])
        } else {
            let mut points = Vec::from([Point::ORIGIN]);
            for (dx, dy) in &offsets {
                let last = *points.last().unwrap();
                points.push(Point::new(last.x + dx, last.y + dy));
            }
            segments(&points, method)
        };
        let lens = lengths(&jobs, &limits);
        let plain = run(&mut TestPlanner::new(limits), jobs.clone(), method, feed);
        let mut p = TestPlanner::new(limits);
        let trace = run_with(&mut p, jobs, method, feed, |n, p| {
            for &(at, feed_percent, rapid_percent) in &changes {
                if at == n {
                    p.set_overrides(Overrides { feed_percent, rapid_percent, ..Overrides::NONE });
                }
            }
        });
        prop_assert!(p.is_idle());
        let steps = |t: &Trace| t.cmds.iter().map(|c| c.step).collect::<Vec<_>>();
        prop_assert_eq!(steps(&trace), steps(&plain));
        assert_axis_rates_within(&trace, &limits);
        let v = trace.speeds(&lens);
        prop_assert!(v[v.len() - 1] <= 5.0 * 1.001, "stops from {} mm/s", v[v.len() - 1]);
        // Speeds within the start rate may jump (an override's cap below it is met that way).
        let accel = trace.max_accel_above(&lens, 5_000, 5.0 * 1.05);
        prop_assert!(accel <= 500.0 * core::f64::consts::SQRT_2 * 1.05, "{} mm/s²", accel);
        if circle {
            let axis = max_axis_accel(&trace, &limits, 20_000);
            prop_assert!(axis[0] <= 500.0 * 1.05 && axis[1] <= 500.0 * 1.05, "{:?} mm/s²", axis);
        }
    }
}

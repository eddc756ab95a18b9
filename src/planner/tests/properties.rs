//! Random settings, curves, feeds, holds and aborts: the steps emitted are the path's own.

use super::*;
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

/// A job: a chain of chords (kinks between them), maybe failing after some steps.
fn any_job() -> impl Strategy<Value = (Vec<(i32, i32)>, Option<u64>)> {
    (proptest::collection::vec((-300i32..300, -300i32..300), 1..4), proptest::option::of(0u64..400))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    /// Random settings, curves with kinks and errors, feeds, holds and aborts: the steps
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

//! Hold, abort and curve errors on the path; limits, feeds and the queue's capacity.

use super::*;

#[test]
fn hold_stops_on_the_path_and_resume_reaches_the_end() {
    let limits = Limits::default();
    for method in [Method::Classic, Method::Diagonal] {
        let points = [Point::ORIGIN, Point::new(4_000, 1_000), Point::new(4_500, 3_000), Point::new(0, 5_000)];
        let jobs = segments(&points, method);
        let lens = lengths(&jobs, &limits);
        let mut p = TestPlanner::new(limits);
        let mut trace = run_with(&mut p, jobs.clone(), method, DEFAULT_FEED, |n, p| {
            if n == 3_000 {
                p.hold();
                assert_eq!(p.state(), PlannerState::Holding);
            }
        });
        assert_eq!(p.state(), PlannerState::Held);
        assert_eq!(p.next_cmd(), None);
        let held_at = trace.cmds.len();
        assert!(held_at > 3_000 && held_at < 3_300, "stopped after {held_at} steps");
        let v = trace.speeds(&lens[..held_at]);
        assert!(v[held_at - 1] <= 5.0 * 1.001, "stopped from {} mm/s", v[held_at - 1]);
        assert!(trace.max_accel(&lens[..held_at]) <= 500.0 * core::f64::consts::SQRT_2 * 1.05);
        // The queued segments are still there; resume runs them from the start rate.
        p.resume();
        while let Some(r) = p.next_cmd() {
            trace.cmds.push(r.unwrap());
        }
        let v = trace.speeds(&lens);
        assert!(v[held_at] <= 5.0 * 1.001, "resumed at {} mm/s", v[held_at]);
        assert_eq!(trace.position(), end_of(&points));
        assert!(p.is_idle());
        assert_eq!(p.state(), PlannerState::Idle);
    }
}

#[test]
fn abort_stops_on_the_path_and_drops_the_rest() {
    let limits = Limits::default();
    let method = Method::Diagonal;
    let points = [Point::ORIGIN, Point::new(3_000, 0), Point::new(3_000, 3_000), Point::new(0, 3_000), Point::ORIGIN];
    let jobs = segments(&points, method);
    let full = run(&mut TestPlanner::new(limits), jobs.clone(), method, DEFAULT_FEED);
    let mut p = TestPlanner::new(limits);
    let trace = run_with(&mut p, jobs.clone(), method, DEFAULT_FEED, |n, p| {
        if n == 4_500 {
            p.abort();
            assert!(p.is_full(), "takes no segment while aborting");
        }
    });
    assert_eq!(p.state(), PlannerState::Idle);
    assert!(p.is_idle());
    assert_eq!(p.next_cmd(), None);
    let n = trace.cmds.len();
    assert!(n > 4_500 && n < 4_800, "stopped after {n} steps");
    // Exactly the path's own steps: the position is the path's point after n steps.
    let steps = |t: &Trace| t.cmds[..n].iter().map(|c| c.step).collect::<Vec<_>>();
    assert_eq!(steps(&trace), steps(&full));
    assert_eq!(trace.position(), Point::new(3_000, 1_500 + (n as i32 - 4_500)));
    let v = trace.speeds(&lengths(&jobs, &limits)[..n]);
    assert!(v[n - 1] <= 5.0 * 1.001);

    // A new job starts from rest at the start rate.
    p.push(Chords::line(100, 0, method), DEFAULT_FEED, method).unwrap();
    let first = p.next_cmd().unwrap().unwrap();
    assert_eq!(first.interval_ticks, 2_000 * TICKS_PER_US);
}

#[test]
fn hold_and_abort_at_rest_act_at_once() {
    let method = Method::Diagonal;
    let mut p = TestPlanner::new(Limits::default());
    p.hold();
    assert_eq!(p.state(), PlannerState::Held);
    p.push(Chords::line(500, 0, method), DEFAULT_FEED, method).unwrap();
    assert_eq!(p.next_cmd(), None, "a hold keeps new jobs from starting");
    p.abort();
    assert_eq!(p.state(), PlannerState::Idle);
    assert_eq!(p.next_cmd(), None);
    p.push(Chords::line(500, 0, method), DEFAULT_FEED, method).unwrap();
    assert_eq!(p.state(), PlannerState::Running);
    let trace = run(&mut p, Vec::new(), method, DEFAULT_FEED);
    assert_eq!(trace.position(), Point::new(500, 0));
}

#[test]
fn a_curve_error_stops_at_the_failing_point_and_the_next_job_starts_from_rest() {
    let limits = Limits::default();
    for method in [Method::Classic, Method::Diagonal] {
        let jobs = Vec::from([
            Chords::line(2_000, 0, method),
            Chords::line(0, 4_000, method).failing_after(2_500),
            Chords::line(-1_000, 0, method).failing_after(0),
            Chords::line(-1_000, 0, method),
        ]);
        let lens = lengths(&jobs, &limits);
        let mut p = TestPlanner::new(limits);
        let trace = run(&mut p, jobs, method, DEFAULT_FEED);
        assert_eq!(trace.errors, [(4_500, CurveError::Domain), (4_500, CurveError::Domain)]);
        assert_eq!(trace.position(), Point::new(1_000, 2_500));
        let v = trace.speeds(&lens);
        // Full speed on the failing segment, then a stop at its error, then a fresh start.
        assert!(v[2_000..4_500].iter().cloned().fold(0.0, f64::max) > 49.5);
        assert!(v[4_499] <= 5.0 * 1.001 && v[4_500] <= 5.0 * 1.001, "{} / {}", v[4_499], v[4_500]);
        assert!(trace.max_accel(&lens[..4_500]) <= 500.0 * 1.05);
        assert!(p.is_idle());
    }
}

#[test]
fn limits_come_only_from_settings_in_range() {
    let bad = |change: fn(&mut Settings)| {
        let mut s = Settings::default();
        change(&mut s);
        Limits::try_from_settings(&s)
    };
    assert_eq!(bad(|s| s.steps_per_mm[0] = f32::NAN), Err(LimitsError::OutOfRange(100)));
    assert_eq!(bad(|s| s.accel_mm_per_s2[1] = 0.0), Err(LimitsError::OutOfRange(121)));
    assert_eq!(bad(|s| s.max_rate_mm_per_min[0] = f32::INFINITY), Err(LimitsError::OutOfRange(110)));
    assert_eq!(bad(|s| s.junction_deviation_mm = -1.0), Err(LimitsError::OutOfRange(11)));
    assert_eq!(bad(|s| s.start_rate_mm_per_min = 5_000.0), Ok(limits_with(|s| s.start_rate_mm_per_min = 5_000.0)));
    assert_eq!(bad(|s| s.start_rate_mm_per_min = 7_000.0), Err(LimitsError::OutOfRange(201)));
    assert!(bad(|s| s.junction_deviation_mm = 0.0).is_ok());
    // The infallible form repairs what the strict one refuses.
    let s = Settings {
        steps_per_mm: [f32::NAN, 500.0],
        accel_mm_per_s2: [0.0, 500.0],
        start_rate_mm_per_min: 7_000.0,
        ..Settings::default()
    };
    let l = Limits::from_settings(&s);
    assert_eq!(l.steps_per_mm(), [100.0, 200.0]);
    assert_eq!(l.accel_mm_per_s2(), [1.0, 500.0]);
    assert_eq!(l.start_speed_mm_per_s(), 100.0);
    assert_eq!(Limits::from_settings(&Settings::default()), Limits::default());
    // 30 kHz is not a whole number of ticks: the period is rounded up, never down.
    let l = limits_with(|s| s.max_pulse_rate_hz = 30_000.0);
    assert_eq!(l.min_interval_ticks(), 134);
    assert!(l.max_pulse_rate_hz() <= 30_000.0);
}

#[test]
fn odd_feeds_fall_back_to_the_default_or_the_minimum() {
    let limits = Limits::default(); // default feed 3000 mm/min = 50 mm/s
    let method = Method::Diagonal;
    for (feed, expected_ticks) in [
        (Feed::MmPerMin(0.0), 200 * TICKS_PER_US),
        (Feed::MmPerMin(-5.0), 200 * TICKS_PER_US),
        (Feed::MmPerMin(f32::NAN), 200 * TICKS_PER_US),
        (Feed::MmPerMin(f32::INFINITY), 200 * TICKS_PER_US),
        // Below the 1 mm/min floor: one 0.01 mm step per 0.6 s.
        (Feed::MmPerMin(1e-6), 600_000 * TICKS_PER_US),
    ] {
        let mut p = TestPlanner::new(limits);
        p.push(Chords::line(3_000, 0, method), feed, method).unwrap();
        let mut intervals = Vec::new();
        while let Some(c) = p.next_cmd() {
            intervals.push(c.unwrap().interval_ticks);
        }
        assert_eq!(intervals.len(), 3_000);
        assert_eq!(intervals[1_500], expected_ticks, "{feed:?}");
    }
}

#[test]
fn new_limits_wait_until_the_planner_is_idle() {
    let method = Method::Diagonal;
    let mut p = TestPlanner::new(Limits::default());
    p.push(Chords::line(2_000, 0, method), DEFAULT_FEED, method).unwrap();
    let first = p.next_cmd().unwrap().unwrap();
    assert_eq!(first.interval_ticks, 2_000 * TICKS_PER_US, "5 mm/s start rate");
    // Double the start rate while moving: the running job keeps its own.
    p.set_limits(limits_with(|s| s.start_rate_mm_per_min = 600.0));
    let mut last = first;
    while let Some(c) = p.next_cmd() {
        last = c.unwrap();
    }
    assert!(last.interval_ticks >= 1_998 * TICKS_PER_US, "ended at {} ticks", last.interval_ticks);
    p.push(Chords::line(2_000, 0, method), DEFAULT_FEED, method).unwrap();
    assert_eq!(p.next_cmd().unwrap().unwrap().interval_ticks, 1_000 * TICKS_PER_US, "10 mm/s start rate");
}

#[test]
fn empty_curves_and_a_zero_depth_planner_do_nothing() {
    let method = Method::Classic;
    let mut p = TestPlanner::new(Limits::default());
    p.push(Chords::line(0, 0, method), DEFAULT_FEED, method).unwrap();
    assert!(p.is_idle());
    assert_eq!(p.next_cmd(), None);
    let mut tiny: Planner<Chords, 0> = Planner::new(Limits::default());
    assert!(tiny.is_full());
    assert_eq!(tiny.push(Chords::line(5, 5, method), DEFAULT_FEED, method), Err(PlannerFull));
    assert_eq!(tiny.next_cmd(), None);
    tiny.hold();
    tiny.abort();
    assert_eq!(tiny.state(), PlannerState::Idle);
}

#[test]
fn a_full_queue_refuses_and_takes_again_after_a_segment_ends() {
    let method = Method::Diagonal;
    let mut p: Planner<Chords, 2> = Planner::new(Limits::default());
    p.push(Chords::line(3, 0, method), DEFAULT_FEED, method).unwrap();
    p.push(Chords::line(3, 0, method), DEFAULT_FEED, method).unwrap();
    assert!(p.is_full());
    assert_eq!(p.push(Chords::line(3, 0, method), DEFAULT_FEED, method), Err(PlannerFull));
    for _ in 0..3 {
        p.next_cmd().unwrap().unwrap();
    }
    assert!(!p.is_full());
    p.push(Chords::line(0, 3, method), DEFAULT_FEED, method).unwrap();
    let mut n = 3;
    let mut at = Point::new(3, 0);
    while let Some(c) = p.next_cmd() {
        at = at.stepped(c.unwrap().step);
        n += 1;
    }
    assert_eq!((n, at), (9, Point::new(6, 3)));
}

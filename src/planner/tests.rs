//! Behaviour of the planner as the pulse task sees it: step commands, their timing, and the
//! position they add up to.

extern crate std;

use super::*;
use crate::geom::{Point, Step, StepCmd, TICK_HZ};
use crate::interp::{CurveError, Interpolator, Method};
use crate::interp::{LineInterp, Tangent};
use crate::job::Feed;
use crate::settings::{MAX_PULSE_RATE_HZ, Settings};
use std::vec::Vec;

const DEFAULT_FEED: Feed = Feed::MmPerMin(3_000.0);

fn limits_with(change: impl FnOnce(&mut Settings)) -> Limits {
    let mut s = Settings::default();
    change(&mut s);
    Limits::try_from_settings(&s).unwrap()
}

/// A test curve: a chain of straight chords, optionally failing after a number of steps. Its
/// tangent is the current chord's (so each vertex is a kink), or for a circle the tangent of the
/// circle through the current point.
#[derive(Clone, Debug)]
struct Chords {
    /// Each chord with the steps it has left.
    chords: Vec<(LineInterp, u64)>,
    index: usize,
    fail_after_steps: Option<u64>,
    taken: u64,
    ended: bool,
    /// Centre of a counter-clockwise circle, relative to the start, in steps.
    centre: Option<(f64, f64)>,
    at: (i64, i64),
}

impl Chords {
    fn through(points: &[Point], method: Method) -> Self {
        let chords = points
            .windows(2)
            .map(|p| {
                let line = LineInterp::new(p[1].x - p[0].x, p[1].y - p[0].y, method);
                let n = line.total_steps();
                (line, n)
            })
            .collect();
        Chords { chords, index: 0, fail_after_steps: None, taken: 0, ended: false, centre: None, at: (0, 0) }
    }

    /// A counter-clockwise circle of `radius_steps` through `sides` lattice chords, starting at
    /// its rightmost point, with the circle's own smooth tangent.
    fn circle(radius_steps: f64, sides: usize, method: Method) -> Self {
        let mut c = Self::through(&circle_points(radius_steps, sides), method);
        c.centre = Some((-radius_steps.round(), 0.0));
        c
    }

    fn line(dx: i32, dy: i32, method: Method) -> Self {
        Self::through(&[Point::ORIGIN, Point::new(dx, dy)], method)
    }

    fn failing_after(mut self, steps: u64) -> Self {
        self.fail_after_steps = Some(steps);
        self
    }

    /// Ideal length of each step the curve takes, in mm: a chord's length over its steps.
    fn step_lengths_mm(&self, limits: &Limits) -> Vec<f64> {
        let spm = limits.steps_per_mm();
        let mut out = Vec::new();
        for (line, n) in &self.chords {
            let (dx, dy) = chord_offset(line);
            let len = ((dx / spm[0] as f64).powi(2) + (dy / spm[1] as f64).powi(2)).sqrt();
            out.extend(core::iter::repeat_n(len / *n as f64, *n as usize));
        }
        if let Some(k) = self.fail_after_steps {
            out.truncate(k as usize);
        }
        out
    }
}

/// The offset a line covers, by walking a copy of it.
fn chord_offset(line: &LineInterp) -> (f64, f64) {
    let mut copy = line.clone();
    let (mut x, mut y) = (0i64, 0i64);
    while let Ok(Some(s)) = copy.next_step() {
        x += s.x as i64;
        y += s.y as i64;
    }
    (x as f64, y as f64)
}

impl Interpolator for Chords {
    fn next_step(&mut self) -> Result<Option<Step>, CurveError> {
        if self.ended {
            return Ok(None);
        }
        if self.fail_after_steps == Some(self.taken) {
            self.ended = true;
            return Err(CurveError::Domain);
        }
        while let Some((line, left)) = self.chords.get_mut(self.index) {
            if *left > 0 {
                *left -= 1;
                self.taken += 1;
                let step = line.next_step();
                if let Ok(Some(s)) = step {
                    self.at = (self.at.0 + s.x as i64, self.at.1 + s.y as i64);
                }
                return step;
            }
            self.index += 1;
        }
        self.ended = true;
        Ok(None)
    }

    fn tangent(&self) -> Tangent {
        if let Some((cx, cy)) = self.centre {
            let (rx, ry) = (self.at.0 as f64 - cx, self.at.1 as f64 - cy);
            return Tangent::along(-ry as f32, rx as f32);
        }
        let mut current = self.chords[self.index.min(self.chords.len() - 1)..].iter().filter(|(_, left)| *left > 0);
        match current.next() {
            Some((line, _)) => line.tangent(),
            None => self.chords.last().map_or(Tangent::default(), |(l, _)| l.tangent()),
        }
    }
}

type TestPlanner = Planner<Chords, PLANNER_SEGMENTS>;

/// What the pulse task received.
#[derive(Default, Debug)]
struct Trace {
    cmds: Vec<StepCmd>,
    /// Errors, with the number of steps emitted before each.
    errors: Vec<(usize, CurveError)>,
}

impl Trace {
    fn position(&self) -> Point {
        self.cmds.iter().fold(Point::ORIGIN, |p, c| p.stepped(c.step))
    }

    fn seconds(&self) -> f64 {
        self.cmds.iter().map(|c| c.interval_ticks as f64).sum::<f64>() / TICK_HZ as f64
    }

    /// Speed of each step, mm/s, given each step's ideal length.
    fn speeds(&self, lengths_mm: &[f64]) -> Vec<f64> {
        assert_eq!(lengths_mm.len(), self.cmds.len(), "trace and path differ in length");
        self.cmds.iter().zip(lengths_mm).map(|(c, len)| len / (c.interval_ticks as f64 / TICK_HZ as f64)).collect()
    }

    /// Mean speeds over windows of at least `window_ticks`: (mid time s, speed mm/s).
    fn windowed_speeds(&self, lengths_mm: &[f64], window_ticks: u64) -> Vec<(f64, f64)> {
        let mut out = Vec::new();
        let (mut t, mut w_ticks, mut w_mm) = (0u64, 0u64, 0.0f64);
        for (c, len) in self.cmds.iter().zip(lengths_mm) {
            w_ticks += c.interval_ticks as u64;
            w_mm += len;
            if w_ticks >= window_ticks {
                let mid = (t as f64 + w_ticks as f64 / 2.0) / TICK_HZ as f64;
                out.push((mid, w_mm / (w_ticks as f64 / TICK_HZ as f64)));
                t += w_ticks;
                w_ticks = 0;
                w_mm = 0.0;
            }
        }
        out
    }

    /// Largest tangential acceleration between 5 ms windows, mm/s².
    fn max_accel(&self, lengths_mm: &[f64]) -> f64 {
        self.max_accel_over(lengths_mm, 5_000)
    }

    /// Largest tangential acceleration between windows of at least `window_ticks`, mm/s².
    fn max_accel_over(&self, lengths_mm: &[f64], window_ticks: u64) -> f64 {
        let w = self.windowed_speeds(lengths_mm, window_ticks);
        w.windows(2).map(|p| ((p[1].1 - p[0].1) / (p[1].0 - p[0].0)).abs()).fold(0.0, f64::max)
    }
}

/// Feeds `jobs` to the planner and collects everything it emits until it has nothing more.
fn run(planner: &mut TestPlanner, jobs: Vec<Chords>, method: Method, feed: Feed) -> Trace {
    run_with(planner, jobs, method, feed, |_, _| {})
}

/// As [`run`], calling `hook` after every emitted step with the number emitted so far. Stops
/// feeding jobs once an abort is under way, and stops when the planner returns `None` with no
/// job left or while held.
fn run_with(
    planner: &mut TestPlanner,
    jobs: Vec<Chords>,
    method: Method,
    feed: Feed,
    mut hook: impl FnMut(usize, &mut TestPlanner),
) -> Trace {
    let mut trace = Trace::default();
    let mut jobs = jobs.into_iter();
    let mut aborted = false;
    let mut idle_calls = 0;
    loop {
        while !aborted && !planner.is_full() {
            match jobs.next() {
                Some(job) => planner.push(job, feed, method).unwrap(),
                None => break,
            }
        }
        match planner.next_cmd() {
            Some(Ok(cmd)) => {
                trace.cmds.push(cmd);
                hook(trace.cmds.len(), planner);
                aborted |= planner.state() == PlannerState::Aborting;
            }
            Some(Err(e)) => trace.errors.push((trace.cmds.len(), e)),
            None => {
                idle_calls += 1;
                if planner.state() == PlannerState::Held || jobs.len() == 0 || aborted || idle_calls > 10 {
                    return trace;
                }
            }
        }
    }
}

fn end_of(points: &[Point]) -> Point {
    *points.last().unwrap()
}

/// Vertices of a regular polygon around the origin, starting and ending at (r, 0), as lattice
/// points relative to the start.
fn circle_points(radius_steps: f64, sides: usize) -> Vec<Point> {
    (0..=sides)
        .map(|i| {
            let a = i as f64 / sides as f64 * core::f64::consts::TAU;
            Point::new(
                (radius_steps * a.cos()).round() as i32 - radius_steps.round() as i32,
                (radius_steps * a.sin()).round() as i32,
            )
        })
        .collect()
}

/// Single-chord jobs along a polyline.
fn segments(points: &[Point], method: Method) -> Vec<Chords> {
    points.windows(2).map(|p| Chords::through(&[Point::ORIGIN, p[1].offset_from(p[0])], method)).collect()
}

fn lengths(jobs: &[Chords], limits: &Limits) -> Vec<f64> {
    jobs.iter().flat_map(|j| j.step_lengths_mm(limits)).collect()
}

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

/// Mean pulse rate of each axis over 20 ms windows within its max rate, and every interval at
/// least one period of the max pulse rate.
fn assert_axis_rates_within(trace: &Trace, limits: &Limits) {
    let min_ticks = limits.min_interval_ticks();
    assert_eq!(min_ticks as f32, (TICK_HZ as f32 / limits.max_pulse_rate_hz()).round());
    assert!(trace.cmds.iter().all(|c| c.interval_ticks >= min_ticks), "interval below {min_ticks} ticks");
    let spm = limits.steps_per_mm();
    let vmax = limits.max_speed_mm_per_s();
    let (mut ticks, mut counts) = (0u64, [0u64; 2]);
    for c in &trace.cmds {
        ticks += c.interval_ticks as u64;
        counts[0] += c.step.x.unsigned_abs() as u64;
        counts[1] += c.step.y.unsigned_abs() as u64;
        if ticks >= 20_000 {
            for axis in 0..2 {
                // One step more than the max rate allows in the window is the pattern's grain.
                let allowed = (vmax[axis] * spm[axis]) as f64 * ticks as f64 / TICK_HZ as f64 * 1.001 + 1.0;
                assert!(counts[axis] as f64 <= allowed, "axis {axis}: {} steps in {ticks} ticks", counts[axis]);
            }
            ticks = 0;
            counts = [0; 2];
        }
    }
}

/// Largest acceleration of each axis, mm/s², from its mean velocity over windows of at least
/// `window_ticks` (so that single steps do not show as spikes).
fn max_axis_accel(trace: &Trace, limits: &Limits, window_ticks: u64) -> [f64; 2] {
    let spm = limits.steps_per_mm();
    let mut windows = Vec::new(); // (mid time s, velocity mm/s per axis)
    let (mut t, mut w_ticks, mut moved) = (0u64, 0u64, [0i64; 2]);
    for c in &trace.cmds {
        w_ticks += c.interval_ticks as u64;
        moved[0] += c.step.x as i64;
        moved[1] += c.step.y as i64;
        if w_ticks >= window_ticks {
            let dt = w_ticks as f64 / TICK_HZ as f64;
            let mid = (t as f64 + w_ticks as f64 / 2.0) / TICK_HZ as f64;
            windows.push((mid, [moved[0] as f64 / spm[0] as f64 / dt, moved[1] as f64 / spm[1] as f64 / dt]));
            t += w_ticks;
            w_ticks = 0;
            moved = [0; 2];
        }
    }
    let mut most = [0.0f64; 2];
    for p in windows.windows(2) {
        for (axis, most) in most.iter_mut().enumerate() {
            *most = most.max(((p[1].1[axis] - p[0].1[axis]) / (p[1].0 - p[0].0)).abs());
        }
    }
    most
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
    // 1800 mm/min at 100 steps/mm along X: 333.33 µs per step.
    let limits = limits_with(|s| s.accel_mm_per_s2 = [10_000.0; 2]);
    let mut p = TestPlanner::new(limits);
    let trace =
        run(&mut p, Vec::from([Chords::line(60_000, 0, Method::Diagonal)]), Method::Diagonal, Feed::MmPerMin(1_800.0));
    let cruise: Vec<u64> = trace.cmds[1_000..31_000].iter().map(|c| c.interval_ticks as u64).collect();
    assert!(cruise.iter().all(|&t| t == 333 || t == 334));
    let total: u64 = cruise.iter().sum();
    assert!(total.abs_diff(10_000_000) <= 1, "30,000 steps took {total} ticks");
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
    assert_eq!(first.interval_ticks, 2_000);
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
    assert_eq!(l.min_interval_ticks(), 34);
    assert!(l.max_pulse_rate_hz() <= 30_000.0);
}

#[test]
fn odd_feeds_fall_back_to_the_default_or_the_minimum() {
    let limits = Limits::default(); // default feed 3000 mm/min = 50 mm/s
    let method = Method::Diagonal;
    for (feed, expected_ticks) in [
        (Feed::MmPerMin(0.0), 200),
        (Feed::MmPerMin(-5.0), 200),
        (Feed::MmPerMin(f32::NAN), 200),
        (Feed::MmPerMin(f32::INFINITY), 200),
        // Below the 1 mm/min floor: one 0.01 mm step per 0.6 s.
        (Feed::MmPerMin(1e-6), 600_000),
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
    assert_eq!(first.interval_ticks, 2_000, "5 mm/s start rate");
    // Double the start rate while moving: the running job keeps its own.
    p.set_limits(limits_with(|s| s.start_rate_mm_per_min = 600.0));
    let mut last = first;
    while let Some(c) = p.next_cmd() {
        last = c.unwrap();
    }
    assert!(last.interval_ticks >= 1_998, "ended at {} ticks", last.interval_ticks);
    p.push(Chords::line(2_000, 0, method), DEFAULT_FEED, method).unwrap();
    assert_eq!(p.next_cmd().unwrap().unwrap().interval_ticks, 1_000, "10 mm/s start rate");
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

mod properties {
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
}

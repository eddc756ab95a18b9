//! Behaviour of the planner as the pulse task sees it: step commands, their timing, and the
//! position they add up to.

extern crate std;

use super::*;
use crate::geom::{Point, Step, StepCmd, TICK_HZ, TICKS_PER_US};
use crate::motion::interp::{CurveError, Interpolator, Method};
use crate::motion::interp::{StraightInterp, Tangent};
use crate::motion::job::Feed;
use crate::settings::{MAX_PULSE_RATE_HZ, Settings};
use std::vec::Vec;

mod control;
mod lookahead;
mod overrides;
mod profile;
mod properties;

const DEFAULT_FEED: Feed = Feed::MmPerMin(3_000.0);

/// Steps a line of `(dx, dy)` takes with `method`: one axis per step, or both at once.
fn line_steps(dx: i32, dy: i32, method: Method) -> u64 {
    let (x, y) = (dx.unsigned_abs() as u64, dy.unsigned_abs() as u64);
    match method {
        Method::Classic => x + y,
        Method::Diagonal => x.max(y),
    }
}

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
    chords: Vec<(StraightInterp, u64)>,
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
                let (dx, dy) = (p[1].x - p[0].x, p[1].y - p[0].y);
                (StraightInterp::new(dx, dy, method), line_steps(dx, dy, method))
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
fn chord_offset(line: &StraightInterp) -> (f64, f64) {
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

    /// A single chord that cannot fail is a straight line, as [`StraightInterp`] is.
    fn straight_steps_left(&self) -> Option<u64> {
        match self.chords[..] {
            [(_, left)] if self.fail_after_steps.is_none() && self.centre.is_none() => Some(left),
            _ => None,
        }
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

    /// Mean speeds over windows of at least `window_us`: (mid time s, speed mm/s).
    fn windowed_speeds(&self, lengths_mm: &[f64], window_us: u64) -> Vec<(f64, f64)> {
        let window_ticks = window_us * u64::from(TICKS_PER_US);
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

    /// Largest tangential acceleration between windows of at least `window_us`, mm/s².
    fn max_accel_over(&self, lengths_mm: &[f64], window_us: u64) -> f64 {
        self.max_accel_above(lengths_mm, window_us, 0.0)
    }

    /// As [`Self::max_accel_over`], between windows both faster than `floor_mm_per_s` (the start
    /// rate: below it the servos take a jump in speed, as when they start and stop).
    fn max_accel_above(&self, lengths_mm: &[f64], window_us: u64, floor_mm_per_s: f64) -> f64 {
        let w = self.windowed_speeds(lengths_mm, window_us);
        w.windows(2)
            .filter(|p| p[0].1.min(p[1].1) > floor_mm_per_s)
            .map(|p| ((p[1].1 - p[0].1) / (p[1].0 - p[0].0)).abs())
            .fold(0.0, f64::max)
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
/// `window_us` (so that single steps do not show as spikes). Each axis' windows begin and end
/// at its own steps, so that a window's distance and duration are exact.
fn max_axis_accel(trace: &Trace, limits: &Limits, window_us: u64) -> [f64; 2] {
    let window_ticks = window_us * u64::from(TICKS_PER_US);
    let spm = limits.steps_per_mm();
    let mut most = [0.0f64; 2];
    for (axis, most) in most.iter_mut().enumerate() {
        let mut windows = Vec::new(); // (mid time s, velocity mm/s)
        let (mut now, mut start, mut moved) = (0u64, None::<u64>, 0i64);
        for c in &trace.cmds {
            now += c.interval_ticks as u64;
            let step = if axis == 0 { c.step.x } else { c.step.y };
            if step == 0 {
                continue;
            }
            match start {
                None => start = Some(now),
                Some(t0) => {
                    moved += step as i64;
                    if now - t0 >= window_ticks {
                        let dt = (now - t0) as f64 / TICK_HZ as f64;
                        let mid = (t0 + now) as f64 / 2.0 / TICK_HZ as f64;
                        windows.push((mid, moved as f64 / spm[axis] as f64 / dt));
                        start = Some(now);
                        moved = 0;
                    }
                }
            }
        }
        for p in windows.windows(2) {
            *most = most.max(((p[1].1 - p[0].1) / (p[1].0 - p[0].0)).abs());
        }
    }
    most
}

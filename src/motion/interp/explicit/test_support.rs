//! Checks shared by the tests of every explicit curve: walking a curve, its deviation from the
//! chords through the ideal column values, every column met, the same steps in batches, and
//! the float slack all of them allow.

extern crate std;
use crate::geom::{Point, Step};
use crate::motion::interp::{CurveError, Filled, Interpolator, Method, Tangent};
use std::vec::Vec;

/// Deviation bound of `Diagonal` from the chord polyline, in steps.
pub const DIAGONAL_MAX_DEVIATION_STEPS: f64 = 0.5;
/// Deviation bound of `Classic` from the chord polyline, in steps (√2/2).
pub const CLASSIC_MAX_DEVIATION_STEPS: f64 = core::f64::consts::FRAC_1_SQRT_2;
/// Float slack on every bound, in steps, however small the curve.
pub const FLOAT_SLACK_MIN_STEPS: f64 = 1e-5;
/// Float slack on every bound per step of the curve's magnitude (2⁻²¹: the `f32` values' own
/// error, see `crate::motion::interp::explicit`'s Arithmetic).
pub const FLOAT_SLACK_PER_STEP: f64 = 1.0 / (1u32 << 21) as f64;

/// Float slack on every bound for a curve whose values (g in steps, from zero, not from its
/// start) reach `magnitude_steps`.
pub fn float_slack_steps(magnitude_steps: f64) -> f64 {
    FLOAT_SLACK_MIN_STEPS + magnitude_steps.abs() * FLOAT_SLACK_PER_STEP
}

pub fn max_deviation_for(method: Method) -> f64 {
    match method {
        Method::Classic => CLASSIC_MAX_DEVIATION_STEPS,
        Method::Diagonal => DIAGONAL_MAX_DEVIATION_STEPS,
    }
}

/// The lattice points an interpolator visits, from the start, and how it ended.
pub struct Walk {
    pub path: Vec<Point>,
    pub end: Result<(), CurveError>,
}

impl Walk {
    pub fn last(&self) -> Point {
        self.path.last().copied().unwrap_or(Point::ORIGIN)
    }

    pub fn steps(&self) -> usize {
        self.path.len() - 1
    }
}

/// Runs `interp` to its end, checking every step (a neighbour; one axis for `Classic`), that
/// it ends within `max_steps` and that it stays ended.
pub fn walk(interp: &mut impl Interpolator, method: Method, max_steps: usize) -> Walk {
    let mut p = Point::ORIGIN;
    let mut path = Vec::from([p]);
    let end = loop {
        match interp.next_step() {
            Ok(Some(s)) => {
                assert!(s.is_neighbour(), "{s:?} after {p:?} is not a step to a neighbour");
                assert!(method != Method::Classic || !s.is_diagonal(), "classic moved both axes after {p:?}");
                p = p.stepped(s);
                path.push(p);
                assert!(path.len() <= max_steps + 1, "more than {max_steps} steps");
            }
            Ok(None) => break Ok(()),
            Err(e) => break Err(e),
        }
    };
    for _ in 0..2 {
        assert_eq!(interp.next_step(), Ok(None), "a finished curve moved again");
    }
    Walk { path, end }
}

fn segment_distance(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let t = (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    let (ex, ey) = (p.0 - a.0 - t * dx, p.1 - a.1 - t * dy);
    (ex * ex + ey * ey).sqrt()
}

/// Largest distance from a path point to the polyline through `(dir·k, h[k])` (measured to
/// the chords on either side of the point's column), checking that no point leaves the
/// columns `0..h.len()`.
pub fn max_deviation(path: &[Point], dir: i32, h: &[f64]) -> f64 {
    let mut worst = 0.0f64;
    for p in path {
        let k = p.x * dir;
        assert!(k >= 0 && (k as usize) < h.len(), "{p:?} is outside the curve's columns");
        let k = k as usize;
        let at = |c: usize| ((dir * c as i32) as f64, h[c]);
        let pt = (p.x as f64, p.y as f64);
        let mut d = if h.len() == 1 { segment_distance(pt, at(0), (at(0).0 + 1.0, h[0])) } else { f64::INFINITY };
        if k > 0 {
            d = d.min(segment_distance(pt, at(k - 1), at(k)));
        }
        if k + 1 < h.len() {
            d = d.min(segment_distance(pt, at(k), at(k + 1)));
        }
        worst = worst.max(d);
    }
    worst
}

/// Checks that the path stands, in every column `k` of `h`, at a row within half a step (and
/// `slack`) of `h[k]`.
pub fn assert_meets_every_column(path: &[Point], dir: i32, h: &[f64], slack: f64) {
    let mut met = std::vec![false; h.len()];
    for p in path {
        let k = (p.x * dir) as usize;
        if k < h.len() && (p.y as f64 - h[k]).abs() <= 0.5 + slack {
            met[k] = true;
        }
    }
    if let Some(k) = met.iter().position(|m| !m) {
        panic!("column {k} (ideal {}) is not met", h[k]);
    }
}

/// What a curve hands out, in order: steps, kinks (after the step that reaches them, with the
/// tangent before) and its end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    Step(Step),
    Kink(Tangent),
    End(Result<(), CurveError>),
}

/// In a list of batch sizes: one step through `next_step` instead of `fill`.
pub const ONE_BY_NEXT_STEP: usize = usize::MAX;

/// The events of `curve` taken through `fill` in batches of the sizes `sizes` gives in turn (0
/// included), one step through `next_step` wherever it says [`ONE_BY_NEXT_STEP`]; `next_step`
/// reports no kinks, so with `kinks` false none are recorded. Checks the tangent after every
/// batch against `tangent_at` (by steps taken), when given.
pub fn in_batches<I: Interpolator>(
    mut curve: I,
    sizes: &[usize],
    kinks: bool,
    cap: usize,
    tangent_at: Option<&[Tangent]>,
) -> Vec<Event> {
    assert!(sizes.iter().any(|&n| n > 0), "batches of no steps never end");
    let mut buf = [Step::NONE; 64];
    let mut events = Vec::new();
    let mut steps = 0;
    for k in 0.. {
        if let Some(t) = tangent_at {
            assert_eq!(curve.tangent(), t[steps.min(t.len() - 1)], "tangent after {steps} steps");
        }
        assert!(steps <= cap, "no end after {cap} steps");
        let size = sizes[k % sizes.len()];
        if size == ONE_BY_NEXT_STEP {
            match curve.next_step() {
                Ok(Some(s)) => {
                    events.push(Event::Step(s));
                    steps += 1;
                }
                Ok(None) => {
                    events.push(Event::End(Ok(())));
                    break;
                }
                Err(e) => {
                    events.push(Event::End(Err(e)));
                    break;
                }
            }
            continue;
        }
        let n = size.min(buf.len());
        let filled = curve.fill(&mut buf[..n]);
        assert!(filled.steps <= n);
        events.extend(buf[..filled.steps].iter().map(|&s| Event::Step(s)));
        steps += filled.steps;
        if let (Some(before), true) = (filled.kink, kinks) {
            events.push(Event::Kink(before));
        }
        match filled.end {
            None => assert!(filled.steps == n || filled.kink.is_some(), "a batch short of its end"),
            Some(end) => {
                assert!(filled.kink.is_none(), "a kink and an end at once");
                events.push(Event::End(end));
                break;
            }
        }
    }
    // Ended for good.
    assert_eq!(curve.fill(&mut buf[..4]), Filled::ended(0, Ok(())));
    assert_eq!(curve.next_step(), Ok(None));
    events
}

/// The curve stepped by `next_step` alone, with the unit tangent after every step (the first
/// before any), and its kinks as [`Interpolator`]'s own `fill` finds them: the reference
/// every batched run must reproduce.
pub fn reference<I: Interpolator>(mut curve: I, cap: usize) -> (Vec<Event>, Vec<Tangent>) {
    let mut events = Vec::new();
    let mut tangents = Vec::from([curve.tangent()]);
    loop {
        let before = curve.tangent();
        match curve.next_step() {
            Ok(Some(s)) => events.push(Event::Step(s)),
            Ok(None) => break events.push(Event::End(Ok(()))),
            Err(e) => break events.push(Event::End(Err(e))),
        }
        let now = curve.tangent();
        tangents.push(now);
        if before.kinks_to(now) {
            events.push(Event::Kink(before));
        }
        assert!(tangents.len() <= cap + 1, "no end after {cap} steps");
    }
    (events, tangents)
}

/// Random batch sizes: up to 40 steps, or one step by `next_step`, never all empty.
pub fn batch_sizes() -> impl proptest::strategy::Strategy<Value = Vec<usize>> {
    use proptest::prelude::*;
    let size = prop_oneof![0usize..40, Just(ONE_BY_NEXT_STEP)];
    (1usize..40, proptest::collection::vec(size, 0..12)).prop_map(|(first, mut rest)| {
        rest.insert(0, first);
        rest
    })
}

/// Batch sizes the batched runs are checked with.
pub const BATCH_SIZES: [&[usize]; 5] =
    [&[16], &[1], &[64], &[ONE_BY_NEXT_STEP], &[3, 0, 7, ONE_BY_NEXT_STEP, 16, 5, 2, 64, ONE_BY_NEXT_STEP, 13]];

/// `fill` in every mix of [`BATCH_SIZES`] and `next_step` hands out the steps, kinks and end of
/// [`reference`], with the same tangent between them; returns the number of steps.
pub fn assert_same_in_batches<I: Interpolator + Clone>(curve: &I, cap: usize) -> usize {
    let (events, tangents) = reference(curve.clone(), cap);
    let without_kinks: Vec<Event> = events.iter().copied().filter(|e| !matches!(e, Event::Kink(_))).collect();
    for sizes in BATCH_SIZES {
        let kinks = !sizes.contains(&ONE_BY_NEXT_STEP);
        let batched = in_batches(curve.clone(), sizes, kinks, cap, Some(&tangents));
        let want = if kinks { &events } else { &without_kinks };
        if let Some(i) = (0..want.len().min(batched.len())).find(|&i| want[i] != batched[i]) {
            panic!("event {i}: alone {:?}, in batches {:?} ({sizes:?})", want[i], batched[i]);
        }
        assert_eq!(batched.len(), want.len(), "different lengths ({sizes:?})");
    }
    tangents.len() - 1
}

/// Runs `curve` through `fill` in batches of the sizes `sizes` gives (mixed with `next_step`
/// where it says [`ONE_BY_NEXT_STEP`]) and checks the steps and end against `next_step` alone.
pub fn assert_same_steps_in_batches<I: Interpolator + Clone>(curve: &I, sizes: &[usize], cap: usize) {
    let (events, _) = reference(curve.clone(), cap);
    let alone: Vec<Event> = events.into_iter().filter(|e| !matches!(e, Event::Kink(_))).collect();
    let batched: Vec<Event> = in_batches(curve.clone(), sizes, false, cap, None)
        .into_iter()
        .filter(|e| !matches!(e, Event::Kink(_)))
        .collect();
    assert_eq!(batched, alone, "batches {sizes:?}");
}

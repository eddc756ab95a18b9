//! Checks shared by the tests of every explicit curve: walking a curve, its deviation from the
//! chords through the ideal column values, every column met, and the float slack they allow.

extern crate std;
use crate::geom::Point;
use crate::interp::{CurveError, Interpolator, Method};
use std::vec::Vec;

/// Deviation bound of `Diagonal` from the chord polyline, in steps.
pub const DIAGONAL_MAX_DEVIATION_STEPS: f64 = 0.5;
/// Deviation bound of `Classic` from the chord polyline, in steps (√2/2).
pub const CLASSIC_MAX_DEVIATION_STEPS: f64 = core::f64::consts::FRAC_1_SQRT_2;
/// Floating-point slack on every bound, in steps.
pub const FLOAT_SLACK_STEPS: f64 = 1e-6;

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

/// Checks that the path stands, in every column `k` of `h`, at a row within half a step of
/// `h[k]`.
pub fn assert_meets_every_column(path: &[Point], dir: i32, h: &[f64]) {
    let mut met = std::vec![false; h.len()];
    for p in path {
        let k = (p.x * dir) as usize;
        if k < h.len() && (p.y as f64 - h[k]).abs() <= 0.5 + FLOAT_SLACK_STEPS {
            met[k] = true;
        }
    }
    if let Some(k) = met.iter().position(|m| !m) {
        panic!("column {k} (ideal {}) is not met", h[k]);
    }
}

//! Straight line from the start point to an end point given as an offset in steps.
//!
//! `classic` is the original controller's point-by-point comparison: with the discriminant
//! `F = x·ye − y·xe` (on absolute values) it steps X while `F >= 0` and Y otherwise, one axis per
//! step, |dx| + |dy| steps in all. `diagonal` is the same comparison on the major axis
//! (Bresenham's rule): every step moves the major axis and, when the error says so, the minor one
//! too; max(|dx|, |dy|) steps, error <= 0.5 step.

use crate::geom::Step;
use crate::motion::interp::interpolator::{CurveError, Filled, Interpolator, Tangent};
use crate::motion::method::Method;

/// Interpolates a straight line; see the module documentation.
#[derive(Clone, Debug)]
pub struct StraightInterp {
    /// Absolute end offsets.
    xe: i64,
    ye: i64,
    /// Step directions.
    sx: i8,
    sy: i8,
    /// Steps still to take on each axis.
    left_x: i64,
    left_y: i64,
    /// Discriminant (classic) or Bresenham error (diagonal).
    f: i64,
    method: Method,
    tangent: Tangent,
}

impl StraightInterp {
    /// A line from the current point to the point `(dx, dy)` steps away.
    pub fn new(dx: i32, dy: i32, method: Method) -> Self {
        let (xe, ye) = ((dx as i64).abs(), (dy as i64).abs());
        let f = match method {
            Method::Classic => 0,
            // Bresenham: error term of the minor axis, scaled by 2.
            Method::Diagonal => 2 * xe.min(ye) - xe.max(ye),
        };
        StraightInterp {
            xe,
            ye,
            sx: Step::sign(dx),
            sy: Step::sign(dy),
            left_x: xe,
            left_y: ye,
            f,
            method,
            tangent: Tangent::along(dx as f32, dy as f32),
        }
    }

    /// Steps still to take with its method.
    fn steps_left(&self) -> u64 {
        let left = match self.method {
            Method::Classic => self.left_x + self.left_y,
            Method::Diagonal => self.left_x.max(self.left_y),
        };
        left as u64
    }

    fn classic(&mut self) -> Step {
        // Exhausted axes first: the comparison alone would overshoot a zero-length axis.
        let along_x = if self.left_y == 0 {
            true
        } else if self.left_x == 0 {
            false
        } else {
            self.f >= 0
        };
        if along_x {
            self.f -= self.ye;
            self.left_x -= 1;
            Step::new(self.sx, 0)
        } else {
            self.f += self.xe;
            self.left_y -= 1;
            Step::new(0, self.sy)
        }
    }

    fn diagonal(&mut self) -> Step {
        let x_major = self.xe >= self.ye;
        let (major, minor) = if x_major { (self.xe, self.ye) } else { (self.ye, self.xe) };
        let minor_moves = self.f > 0;
        if minor_moves {
            self.f -= 2 * major;
        }
        self.f += 2 * minor;
        let (mx, my) = if x_major { (true, minor_moves) } else { (minor_moves, true) };
        if mx {
            self.left_x -= 1;
        }
        if my {
            self.left_y -= 1;
        }
        Step::new(if mx { self.sx } else { 0 }, if my { self.sy } else { 0 })
    }
}

impl Interpolator for StraightInterp {
    fn next_step(&mut self) -> Result<Option<Step>, CurveError> {
        if self.left_x == 0 && self.left_y == 0 {
            return Ok(None);
        }
        Ok(Some(match self.method {
            Method::Classic => self.classic(),
            Method::Diagonal => self.diagonal(),
        }))
    }

    fn tangent(&self) -> Tangent {
        self.tangent
    }

    fn straight_steps_left(&self) -> Option<u64> {
        Some(self.steps_left())
    }

    /// A line never kinks: a tight loop of the same comparisons as `next_step`.
    fn fill(&mut self, out: &mut [Step]) -> Filled {
        let left = self.steps_left();
        let n = out.len().min(usize::try_from(left).unwrap_or(usize::MAX));
        let Some(out) = out.get_mut(..n) else { return Filled::more(0) };
        match self.method {
            Method::Classic => self.fill_classic(out),
            Method::Diagonal => self.fill_diagonal(out),
        }
        if n as u64 == left { Filled::ended(n, Ok(())) } else { Filled::more(n) }
    }
}

impl StraightInterp {
    /// `out.len()` classic steps (no more than are left), with the state in registers: the
    /// steps of [`classic`](Self::classic).
    fn fill_classic(&mut self, out: &mut [Step]) {
        let (along_x, along_y) = (Step::new(self.sx, 0), Step::new(0, self.sy));
        let (xe, ye) = (self.xe, self.ye);
        let (mut f, mut left_x, mut left_y) = (self.f, self.left_x, self.left_y);
        for slot in out.iter_mut() {
            // Exhausted axes first: the comparison alone would overshoot a zero-length axis.
            if left_y == 0 || (left_x != 0 && f >= 0) {
                f -= ye;
                left_x -= 1;
                *slot = along_x;
            } else {
                f += xe;
                left_y -= 1;
                *slot = along_y;
            }
        }
        (self.f, self.left_x, self.left_y) = (f, left_x, left_y);
    }

    /// `out.len()` diagonal steps (no more than are left), with the state in registers.
    fn fill_diagonal(&mut self, out: &mut [Step]) {
        let x_major = self.xe >= self.ye;
        let (major, minor) = if x_major { (self.xe, self.ye) } else { (self.ye, self.xe) };
        let (straight, both) = if x_major {
            (Step::new(self.sx, 0), Step::new(self.sx, self.sy))
        } else {
            (Step::new(0, self.sy), Step::new(self.sx, self.sy))
        };
        let mut f = self.f;
        let mut minor_steps = 0i64;
        for slot in out.iter_mut() {
            if f > 0 {
                f -= 2 * major;
                minor_steps += 1;
                *slot = both;
            } else {
                *slot = straight;
            }
            f += 2 * minor;
        }
        self.f = f;
        let n = out.len() as i64;
        if x_major {
            self.left_x -= n;
            self.left_y -= minor_steps;
        } else {
            self.left_y -= n;
            self.left_x -= minor_steps;
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::geom::Point;
    use std::vec::Vec;

    fn walk(dx: i32, dy: i32, method: Method) -> Vec<Point> {
        let mut line = StraightInterp::new(dx, dy, method);
        let mut p = Point::ORIGIN;
        let mut path = Vec::from([p]);
        while let Some(s) = line.next_step().unwrap() {
            assert!(s.is_neighbour(), "{s:?} is not a step to a neighbour");
            if method == Method::Classic {
                assert!(!s.is_diagonal(), "classic moved both axes");
            }
            p = p.stepped(s);
            path.push(p);
        }
        path
    }

    /// Steps a line of `(dx, dy)` takes with `method`: one axis per step, or both at once.
    fn line_steps(dx: i32, dy: i32, method: Method) -> u64 {
        let (x, y) = (dx.unsigned_abs() as u64, dy.unsigned_abs() as u64);
        match method {
            Method::Classic => x + y,
            Method::Diagonal => x.max(y),
        }
    }

    /// Perpendicular distance of `p` from the infinite line through the origin and (dx, dy).
    fn distance(p: Point, dx: i32, dy: i32) -> f64 {
        let (dx, dy) = (dx as f64, dy as f64);
        ((p.x as f64) * dy - (p.y as f64) * dx).abs() / (dx * dx + dy * dy).sqrt()
    }

    #[test]
    fn classic_reaches_every_quadrant_with_dx_plus_dy_steps() {
        for (dx, dy) in [(7, 3), (-7, 3), (-7, -3), (7, -3), (3, 7), (-3, -7), (0, 5), (0, -5), (5, 0), (-5, 0), (4, 4)]
        {
            let path = walk(dx, dy, Method::Classic);
            assert_eq!(*path.last().unwrap(), Point::new(dx, dy));
            assert_eq!(path.len() - 1, (dx.abs() + dy.abs()) as usize, "steps for ({dx}, {dy})");
            for p in &path {
                assert!(distance(*p, dx, dy) < 1.0, "({dx}, {dy}): {p:?} strays");
            }
        }
    }

    #[test]
    fn classic_follows_the_textbook_table_in_the_first_quadrant() {
        // End (4, 3): F starts at 0 → +X, F=-3 → +Y, F=1 → +X, F=-2 → +Y, F=2 → +X, F=-1 → +Y, F=3 → +X.
        let mut line = StraightInterp::new(4, 3, Method::Classic);
        let mut steps = Vec::new();
        while let Some(s) = line.next_step().unwrap() {
            steps.push(s);
        }
        use Step as S;
        assert_eq!(steps, [S::XP, S::YP, S::XP, S::YP, S::XP, S::YP, S::XP]);
    }

    #[test]
    fn diagonal_takes_the_major_axis_count_and_stays_within_half_a_step() {
        for (dx, dy) in
            [(7, 3), (-7, 3), (-7, -3), (7, -3), (3, 7), (-3, -7), (0, 5), (5, 0), (4, 4), (-4, 4), (1000, 999)]
        {
            let path = walk(dx, dy, Method::Diagonal);
            assert_eq!(*path.last().unwrap(), Point::new(dx, dy));
            assert_eq!(path.len() - 1, dx.abs().max(dy.abs()) as usize);
            for p in &path {
                assert!(distance(*p, dx, dy) <= 0.5 + 1e-9, "({dx}, {dy}): {p:?} strays");
            }
        }
    }

    #[test]
    fn fill_hands_out_exactly_the_steps_of_next_step() {
        for (dx, dy) in [(7, 3), (-7, 3), (3, -7), (0, 5), (-5, 0), (4, 4), (1000, 999), (-999, -1000), (0, 0)] {
            for method in [Method::Classic, Method::Diagonal] {
                let mut one = StraightInterp::new(dx, dy, method);
                let mut expected = Vec::new();
                while let Some(s) = one.next_step().unwrap() {
                    expected.push(s);
                }
                for batch in [1, 3, 16, 4096] {
                    let mut line = StraightInterp::new(dx, dy, method);
                    let (mut got, mut buf) = (Vec::new(), std::vec![Step::NONE; batch]);
                    loop {
                        let filled = line.fill(&mut buf);
                        assert_eq!(filled.kink, None);
                        got.extend_from_slice(&buf[..filled.steps]);
                        if let Some(end) = filled.end {
                            assert_eq!(end, Ok(()));
                            break;
                        }
                        assert_eq!(filled.steps, batch, "a short fill must say why");
                    }
                    assert_eq!(got, expected, "({dx}, {dy}) {method:?} in batches of {batch}");
                    assert_eq!(line.next_step(), Ok(None));
                }
            }
        }
    }

    #[test]
    fn a_zero_line_takes_no_step() {
        for m in [Method::Classic, Method::Diagonal] {
            assert_eq!(StraightInterp::new(0, 0, m).next_step(), Ok(None));
        }
    }

    #[test]
    fn the_longest_line_in_the_machine_does_not_overflow() {
        // ±500 mm at 200 steps/mm, corner to corner.
        let (dx, dy) = (200_000, -199_999);
        for m in [Method::Classic, Method::Diagonal] {
            let mut line = StraightInterp::new(dx, dy, m);
            let mut p = Point::ORIGIN;
            let mut n = 0u64;
            while let Some(s) = line.next_step().unwrap() {
                p = p.stepped(s);
                n += 1;
            }
            assert_eq!(p, Point::new(dx, dy));
            assert_eq!(n, line_steps(dx, dy, m));
        }
    }
}

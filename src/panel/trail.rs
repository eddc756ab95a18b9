//! A pen path kept for the LCD's preview: a bounded polyline of lattice points, and drawing it
//! scaled to fit a box of the screen.
//!
//! A [`Trail`] holds at most [`TRAIL_POINTS`] points. When it is full it keeps every other
//! point and from then on takes every other sample offered ([`Trail::sample`]): a path of any
//! length keeps its whole shape, at a resolution that halves each time, which on a 122x32 panel
//! stays finer than a pixel for long. Each point remembers whether the pen drew the way to it or
//! travelled with the pen up. [`draw`] scales the trails to the box they share (the same scale on
//! both axes, Y up), draws the planned path dotted and the path drawn solid, and marks the pen.

use embedded_graphics::Pixel;
use embedded_graphics::draw_target::DrawTarget;
use embedded_graphics::geometry::Point as Px;
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_graphics::primitives::{Line, PointsIter, Rectangle};
use heapless::Vec;

use crate::geom::Point;
use crate::motion::drawing::Bounds;

/// Most points a trail keeps.
pub const TRAIL_POINTS: usize = 128;

/// Half the width of the mark at the pen's point: a 5x5 cross.
const PEN_MARK_HALF_PX: i32 = 2;

/// A bounded polyline of lattice points; see the module documentation.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Trail {
    points: Vec<Point, TRAIL_POINTS>,
    /// Bit `i` set: the way to point `i` was travelled with the pen up.
    pen_up: [u32; TRAIL_POINTS / 32],
    /// Samples taken per point kept: 2 to this power.
    stride_log2: u32,
    /// Samples the last point stands for.
    since: u32,
}

impl Trail {
    pub const fn new() -> Self {
        Trail { points: Vec::new(), pen_up: [0; TRAIL_POINTS / 32], stride_log2: 0, since: 0 }
    }

    fn set_pen_up(&mut self, i: usize) {
        self.pen_up[i / 32] |= 1 << (i % 32);
    }

    pub fn clear(&mut self) {
        *self = Trail::new();
    }

    pub fn points(&self) -> &[Point] {
        &self.points
    }

    pub fn last(&self) -> Option<Point> {
        self.points.last().copied()
    }

    /// True when the pen drew the way to point `i` (the first point is where the path starts).
    pub fn drawn_to(&self, i: usize) -> bool {
        self.pen_up.get(i / 32).is_none_or(|w| w & (1 << (i % 32)) == 0)
    }

    /// Offers the pen's point, `drawn` when the pen drew the way here; returns true when the
    /// trail changed. The last point is always the latest one offered; the points before it are
    /// one every `stride` samples, and every point where the pen went up or down.
    pub fn sample(&mut self, at: Point, drawn: bool) -> bool {
        let Some(last) = self.last() else {
            self.push(at, drawn);
            return true;
        };
        if last == at {
            return false;
        }
        let n = self.points.len();
        let pen_changed = self.drawn_to(n - 1) != drawn;
        if n < 2 || self.since >= 1 << self.stride_log2 || pen_changed {
            self.push(at, drawn);
            self.since = 1;
        } else {
            self.points[n - 1] = at;
            self.since += 1;
        }
        true
    }

    /// Appends `at` whatever the stride; when full, every other point is dropped first.
    pub fn push(&mut self, at: Point, drawn: bool) {
        if self.points.is_full() {
            self.halve();
        }
        let i = self.points.len();
        if self.points.push(at).is_ok() && !drawn {
            self.set_pen_up(i);
        }
    }

    /// Keeps the first and last points, every even one, and every point where the pen changes;
    /// doubles the stride. A point is dropped only where the way to it and the way on from it
    /// were travelled alike, so the merged way keeps the next point's mark.
    fn halve(&mut self) {
        let old = core::mem::take(self);
        let last = old.points.len() - 1;
        for (i, &p) in old.points.iter().enumerate() {
            if i % 2 == 0 || i == last || old.drawn_to(i) != old.drawn_to(i + 1) {
                self.push(p, old.drawn_to(i));
            }
        }
        self.stride_log2 = (old.stride_log2 + 1).min(31);
    }

    /// The box around every point; `None` while empty.
    pub fn bounds(&self) -> Option<Bounds> {
        let (&first, rest) = self.points.split_first()?;
        let mut b = Bounds::at(first);
        rest.iter().for_each(|&p| b.add(p));
        Some(b)
    }
}

/// How a path in steps maps into a box of pixels: the same scale on both axes, centred, Y up,
/// one pixel in from the box's edges.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// The pixel of the bounds' lower left corner (fractional).
    origin: [f32; 2],
    /// The bounds' lower left corner, steps.
    min: Point,
    /// Pixels per step.
    scale: f32,
}

impl Fit {
    /// The fit of `bounds` into `area`.
    pub fn new(bounds: Bounds, area: Rectangle) -> Fit {
        let span = |lo: i32, hi: i32| (hi as f32 - lo as f32).max(1.0);
        let (room_x, room_y) = (area.size.width.saturating_sub(3) as f32, area.size.height.saturating_sub(3) as f32);
        let (span_x, span_y) = (span(bounds.min.x, bounds.max.x), span(bounds.min.y, bounds.max.y));
        let scale = (room_x / span_x).min(room_y / span_y);
        let left = area.top_left.x as f32 + 1.0 + (room_x - span_x * scale) / 2.0;
        let bottom = (area.top_left.y + area.size.height as i32) as f32 - 2.0 - (room_y - span_y * scale) / 2.0;
        Fit { origin: [left, bottom], min: bounds.min, scale }
    }

    /// The pixel of step point `p`.
    pub fn pixel(&self, p: Point) -> Px {
        let dx = (p.x as f32 - self.min.x as f32) * self.scale;
        let dy = (p.y as f32 - self.min.y as f32) * self.scale;
        Px::new(round(self.origin[0] + dx), round(self.origin[1] - dy))
    }
}

fn round(v: f32) -> i32 {
    (v + if v < 0.0 { -0.5 } else { 0.5 }) as i32
}

/// Draws into `area` (cleared first): `plan` dotted, the way `drawn` solid (its pen-up travel
/// left out), and a cross at `pen`, all at the one [`Fit`] of everything shown. Nothing is drawn
/// outside `area`.
pub fn draw<D>(
    target: &mut D,
    area: Rectangle,
    plan: Option<&Trail>,
    drawn: Option<&Trail>,
    pen: Option<Point>,
) -> Result<(), D::Error>
where
    D: DrawTarget<Color = BinaryColor>,
{
    target.fill_solid(&area, BinaryColor::Off)?;
    let mut bounds: Option<Bounds> = None;
    let boxes = [plan.and_then(Trail::bounds), drawn.and_then(Trail::bounds), pen.map(Bounds::at)];
    for b in boxes.into_iter().flatten() {
        let all = bounds.get_or_insert(b);
        all.add(b.min);
        all.add(b.max);
    }
    let Some(bounds) = bounds else { return Ok(()) };
    let fit = Fit::new(bounds, area);
    let put = |p: Px, target: &mut D| target.draw_iter(area.contains(p).then_some(Pixel(p, BinaryColor::On)));
    for (trail, dotted) in [(plan, true), (drawn, false)] {
        let Some(trail) = trail else { continue };
        for (i, pair) in trail.points().windows(2).enumerate() {
            if !trail.drawn_to(i + 1) {
                continue;
            }
            for p in Line::new(fit.pixel(pair[0]), fit.pixel(pair[1])).points() {
                if !dotted || (p.x + p.y) % 2 == 0 {
                    put(p, target)?;
                }
            }
        }
        // A path of one point (a dot) still shows.
        if let [only] = trail.points() {
            put(fit.pixel(*only), target)?;
        }
    }
    if let Some(pen) = pen {
        let c = fit.pixel(pen);
        for d in -PEN_MARK_HALF_PX..=PEN_MARK_HALF_PX {
            put(Px::new(c.x + d, c.y), target)?;
            put(Px::new(c.x, c.y + d), target)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use core::convert::Infallible;
    use embedded_graphics::geometry::{OriginDimensions, Size};
    use std::collections::BTreeSet;

    /// Lit pixels, and how many were drawn outside 122x32.
    #[derive(Default)]
    struct Canvas {
        lit: BTreeSet<(i32, i32)>,
        outside: usize,
    }

    impl OriginDimensions for Canvas {
        fn size(&self) -> Size {
            Size::new(122, 32)
        }
    }

    impl DrawTarget for Canvas {
        type Color = BinaryColor;
        type Error = Infallible;
        fn draw_iter<I: IntoIterator<Item = Pixel<BinaryColor>>>(&mut self, pixels: I) -> Result<(), Infallible> {
            for Pixel(p, c) in pixels {
                if !(0..122).contains(&p.x) || !(0..32).contains(&p.y) {
                    self.outside += 1;
                } else if c.is_on() {
                    self.lit.insert((p.x, p.y));
                } else {
                    self.lit.remove(&(p.x, p.y));
                }
            }
            Ok(())
        }
    }

    fn area() -> Rectangle {
        Rectangle::new(Px::new(90, 0), Size::new(32, 32))
    }

    #[test]
    fn a_full_trail_halves_and_keeps_its_ends_and_shape() {
        let mut t = Trail::new();
        let n = 1000;
        for i in 0..=n {
            t.sample(Point::new(i, i * i / 100), true);
        }
        assert!(t.points().len() <= TRAIL_POINTS && t.points().len() > TRAIL_POINTS / 4, "{}", t.points().len());
        assert_eq!(t.points()[0], Point::new(0, 0));
        assert_eq!(t.last(), Some(Point::new(n, n * n / 100)), "the pen's latest point is always kept");
        // Every kept point is on the path, in order.
        assert!(t.points().windows(2).all(|w| w[0].x < w[1].x && w[1].y == w[1].x * w[1].x / 100));
    }

    #[test]
    fn a_point_where_the_pen_stands_still_is_not_kept_twice() {
        let mut t = Trail::new();
        assert!(t.sample(Point::new(1, 1), true));
        assert!(!t.sample(Point::new(1, 1), true));
        assert_eq!(t.points().len(), 1);
    }

    #[test]
    fn pen_up_travel_survives_halving() {
        let mut t = Trail::new();
        // Strokes of 10 points joined by travel moves.
        for i in 0..600 {
            t.sample(Point::new(i, (i / 10) % 2), i % 10 != 0);
        }
        let ups = (1..t.points().len()).filter(|&i| !t.drawn_to(i)).count();
        assert!(ups > 0, "travel is still marked after halving");
        assert!(t.drawn_to(t.points().len() - 1));
    }

    #[test]
    fn a_line_fills_the_box_with_the_same_scale_on_both_axes() {
        let plan = Trail::new();
        let mut drawn = Trail::new();
        drawn.push(Point::new(-1000, 0), true);
        drawn.push(Point::new(1000, 0), true);
        let mut c = Canvas::default();
        draw(&mut c, area(), Some(&plan), Some(&drawn), None).unwrap();
        let xs: BTreeSet<i32> = c.lit.iter().map(|p| p.0).collect();
        let ys: BTreeSet<i32> = c.lit.iter().map(|p| p.1).collect();
        assert_eq!(ys.len(), 1, "a horizontal line stays one row: {ys:?}");
        assert_eq!((*xs.first().unwrap(), *xs.last().unwrap()), (91, 120), "one pixel in from the box");
        assert_eq!(c.outside, 0);
    }

    #[test]
    fn y_is_up_and_the_pen_is_marked() {
        let mut drawn = Trail::new();
        drawn.push(Point::new(0, 0), true);
        drawn.push(Point::new(0, 100), true);
        let mut c = Canvas::default();
        draw(&mut c, area(), None, Some(&drawn), Some(Point::new(0, 100))).unwrap();
        // The pen at the top: a cross around the top end, the line going down from it.
        let row = |y: i32| c.lit.iter().filter(|p| p.1 == y).count();
        assert_eq!(row(1), 2 * PEN_MARK_HALF_PX as usize + 1, "the cross's bar on the top row: {:?}", c.lit);
        assert!(c.lit.iter().any(|p| p.1 > 28), "the line reaches the bottom");
    }

    #[test]
    fn the_plan_is_dotted_and_travel_is_left_out() {
        let mut plan = Trail::new();
        plan.push(Point::new(0, 0), true);
        plan.push(Point::new(100, 0), true);
        let mut c = Canvas::default();
        draw(&mut c, area(), Some(&plan), None, None).unwrap();
        let dotted = c.lit.len();
        assert!((14..=16).contains(&dotted), "every other pixel of 30: {dotted}");

        let mut drawn = Trail::new();
        drawn.push(Point::new(0, 0), true);
        drawn.push(Point::new(50, 0), false);
        drawn.push(Point::new(100, 0), true);
        let mut c = Canvas::default();
        draw(&mut c, area(), None, Some(&drawn), None).unwrap();
        assert!(c.lit.iter().all(|p| p.0 >= 105), "only the second half is drawn: {:?}", c.lit);
    }

    #[test]
    fn the_box_is_cleared_and_nothing_lands_outside_it() {
        let mut c = Canvas::default();
        c.lit.insert((100, 10));
        c.lit.insert((10, 10));
        let mut drawn = Trail::new();
        drawn.push(Point::new(i32::MIN / 2, i32::MAX / 2), true);
        drawn.push(Point::new(i32::MAX / 2, i32::MIN / 2), true);
        draw(&mut c, area(), None, Some(&drawn), Some(Point::new(i32::MAX / 2, i32::MIN / 2))).unwrap();
        assert!(c.lit.contains(&(10, 10)), "outside the box stays");
        assert!(c.lit.iter().filter(|p| p.0 < 90).count() == 1);
        assert_eq!(c.outside, 0);
    }
}

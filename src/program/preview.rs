//! The drawing's picture for the 122x32 LCD: the travel's outline with the program's pen-down
//! strokes in it, and during a plot the part drawn so far.
//!
//! The picture never holds the path: the strokes are a bitmap of the screen's size
//! ([`StrokeMap`], [`STROKE_MAP_BYTES`]), set pixel by pixel as the check walks the program, and
//! a plot's progress is a second one ([`PlotProgress`]) set as the pen moves. The travel
//! (`±$130` by `±$131`) is scaled to the largest rectangle the map holds with its aspect kept
//! ([`MapScale`]), so a stroke lands where it lies in the travel whatever comes after it, and
//! the map is right as soon as the last line is checked. [`draw`] puts the picture on any
//! embedded-graphics target: the outline and the strokes; during a plot the drawn part solid,
//! the rest dotted, and the pen's place a small hollow square.

use embedded_graphics::Pixel;
use embedded_graphics::draw_target::DrawTarget;
use embedded_graphics::geometry::Point as ScreenPoint;
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_graphics::primitives::{Line, PointsIter};

use crate::geom::Point;
use crate::settings::Settings;

/// The picture's width and height, pixels: the whole visible LCD.
pub const PREVIEW_WIDTH_PX: u8 = 122;
pub const PREVIEW_HEIGHT_PX: u8 = 32;

/// The width of the part of the picture the travel is fitted to, pixels: the right of the
/// screen, text to its left (as a keypad drawing's preview).
pub const PICTURE_WIDTH_PX: u8 = 40;

/// Bytes of one bitmap of the picture: a bit per pixel.
pub const STROKE_MAP_BYTES: usize = PREVIEW_WIDTH_PX as usize * PREVIEW_HEIGHT_PX as usize / 8;

/// A pixel of the picture, column and row from its top left.
pub type Pixel8 = (u8, u8);

/// Where the travel lies on the picture: machine steps to pixels, X to the right and Y up, the
/// travel's rectangle centred in the picture's right [`PICTURE_WIDTH_PX`], its aspect kept (in
/// millimetres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapScale {
    /// Pixels per step, per axis.
    px_per_step: [f32; 2],
    /// The pixel of machine zero (fractional), per axis.
    zero_px: [f32; 2],
    /// The travel's rectangle: top-left and bottom-right pixels.
    top_left: Pixel8,
    bottom_right: Pixel8,
}

impl MapScale {
    /// The travel of `settings` (`$130`, `$131`, around machine zero), fitted to the picture.
    pub fn for_travel(settings: &Settings) -> MapScale {
        let travel_mm = settings.max_travel_mm.map(|t| 2.0 * t.max(f32::MIN_POSITIVE));
        let room = [f32::from(PICTURE_WIDTH_PX - 1), f32::from(PREVIEW_HEIGHT_PX - 1)];
        let beside = [f32::from(PREVIEW_WIDTH_PX - PICTURE_WIDTH_PX), 0.0];
        let px_per_mm = (room[0] / travel_mm[0]).min(room[1] / travel_mm[1]);
        let size = [0, 1].map(|i| crate::math::floor(travel_mm[i] * px_per_mm));
        let left = [0, 1].map(|i| beside[i] + crate::math::floor((room[i] - size[i]) / 2.0));
        let px_per_step = [0, 1].map(|i| px_per_mm / settings.steps_per_mm[i]);
        MapScale {
            px_per_step,
            zero_px: [left[0] + size[0] / 2.0, left[1] + size[1] / 2.0],
            top_left: (left[0] as u8, left[1] as u8),
            bottom_right: ((left[0] + size[0]) as u8, (left[1] + size[1]) as u8),
        }
    }

    /// The pixel of the machine point `p` (steps), clamped to the picture.
    pub fn pixel(&self, p: Point) -> Pixel8 {
        let x = self.zero_px[0] + p.x as f32 * self.px_per_step[0];
        let y = self.zero_px[1] - p.y as f32 * self.px_per_step[1];
        let clamp = |v: f32, max: u8| crate::math::round(v).clamp(0.0, f32::from(max - 1)) as u8;
        (clamp(x, PREVIEW_WIDTH_PX), clamp(y, PREVIEW_HEIGHT_PX))
    }

    /// The travel's outline: its top-left and bottom-right pixels.
    pub fn outline(&self) -> (Pixel8, Pixel8) {
        (self.top_left, self.bottom_right)
    }
}

/// One bit per pixel of the picture.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StrokeMap {
    bits: [u8; STROKE_MAP_BYTES],
}

impl Default for StrokeMap {
    fn default() -> Self {
        Self::new()
    }
}

impl StrokeMap {
    /// No pixel set.
    pub const fn new() -> StrokeMap {
        StrokeMap { bits: [0; STROKE_MAP_BYTES] }
    }

    pub fn clear(&mut self) {
        self.bits = [0; STROKE_MAP_BYTES];
    }

    fn index((x, y): Pixel8) -> Option<usize> {
        (x < PREVIEW_WIDTH_PX && y < PREVIEW_HEIGHT_PX)
            .then(|| usize::from(y) * usize::from(PREVIEW_WIDTH_PX) + usize::from(x))
    }

    /// Sets a pixel; one outside the picture is ignored.
    pub fn set(&mut self, p: Pixel8) {
        if let Some(i) = Self::index(p) {
            self.bits[i / 8] |= 1 << (i % 8);
        }
    }

    /// True when the pixel is set.
    pub fn get(&self, p: Pixel8) -> bool {
        Self::index(p).is_some_and(|i| self.bits[i / 8] & (1 << (i % 8)) != 0)
    }

    /// True when no pixel is set.
    pub fn is_empty(&self) -> bool {
        self.bits.iter().all(|b| *b == 0)
    }

    /// Sets the pixels of the straight line from `a` to `b`, both included (embedded-graphics'
    /// Bresenham, as the LCD's other pictures draw theirs).
    pub fn line(&mut self, a: Pixel8, b: Pixel8) {
        let px = |(x, y): Pixel8| ScreenPoint::new(i32::from(x), i32::from(y));
        for p in Line::new(px(a), px(b)).points() {
            // Both ends lie on the picture, so every point between them does.
            self.set((p.x as u8, p.y as u8));
        }
    }
}

/// A pen's trail on a map: each place the pen is seen at joined to the last by a line while it
/// draws.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PenStrokes {
    map: StrokeMap,
    last: Option<Pixel8>,
}

impl PenStrokes {
    pub const fn new() -> PenStrokes {
        PenStrokes { map: StrokeMap::new(), last: None }
    }

    /// The pen is at the pixel `at`, drawing or not since it was last seen.
    pub fn pen_at(&mut self, at: Pixel8, draws: bool) {
        if draws {
            match self.last {
                Some(last) if last != at => self.map.line(last, at),
                _ => self.map.set(at),
            }
        }
        self.last = Some(at);
    }

    /// Where the pen was last seen.
    pub fn pen(&self) -> Option<Pixel8> {
        self.last
    }

    /// The pixels drawn.
    pub fn map(&self) -> &StrokeMap {
        &self.map
    }
}

/// A plot under way on the picture: the part drawn so far, and the pen's place. The plot's
/// owner hands it the machine's position as it reads it ([`pen_at`](Self::pen_at)); a pen-down
/// move between two readings is drawn as the straight line between them.
#[derive(Clone, Debug, PartialEq)]
pub struct PlotProgress {
    scale: MapScale,
    drawn: PenStrokes,
}

impl PlotProgress {
    /// A plot about to start, on the picture of `scale`.
    pub fn new(scale: MapScale) -> PlotProgress {
        PlotProgress { scale, drawn: PenStrokes::new() }
    }

    /// The pen is at `p` (machine steps), drawing or not since the last reading.
    pub fn pen_at(&mut self, p: Point, draws: bool) {
        self.drawn.pen_at(self.scale.pixel(p), draws);
    }

    /// The pixels drawn so far.
    pub fn drawn(&self) -> &StrokeMap {
        self.drawn.map()
    }

    /// The pen's pixel, once it has been seen.
    pub fn pen(&self) -> Option<Pixel8> {
        self.drawn.pen()
    }
}

/// Draws the picture onto `target` with its top left at `origin`: the travel's outline and the
/// program's `strokes`; with `progress`, the strokes drawn so far solid, the rest dotted (every
/// other pixel), and the pen's place a hollow 3x3 square. Only lit pixels are written: clear the
/// area first.
pub fn draw<D: DrawTarget<Color = BinaryColor>>(
    target: &mut D,
    origin: ScreenPoint,
    scale: &MapScale,
    strokes: &StrokeMap,
    progress: Option<&PlotProgress>,
) -> Result<(), D::Error> {
    let at = |(x, y): Pixel8| Pixel(origin + ScreenPoint::new(i32::from(x), i32::from(y)), BinaryColor::On);
    let ((x0, y0), (x1, y1)) = scale.outline();
    let horizontal = (x0..=x1).flat_map(|x| [(x, y0), (x, y1)]);
    let vertical = (y0..=y1).flat_map(|y| [(x0, y), (x1, y)]);
    target.draw_iter(horizontal.chain(vertical).map(at))?;
    let pixels = (0..PREVIEW_HEIGHT_PX).flat_map(|y| (0..PREVIEW_WIDTH_PX).map(move |x| (x, y)));
    let lit = pixels.filter(|&p| {
        strokes.get(p)
            && match progress {
                None => true,
                Some(progress) => progress.drawn().get(p) || (p.0 + p.1) % 2 == 0,
            }
    });
    target.draw_iter(lit.map(at))?;
    if let Some((px, py)) = progress.and_then(PlotProgress::pen) {
        let (px, py) = (i32::from(px), i32::from(py));
        let ring = [(-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)];
        let mark = ring.into_iter().map(|(dx, dy)| ScreenPoint::new(px + dx, py + dy));
        target.draw_iter(mark.map(|p| Pixel(origin + p, BinaryColor::On)))?;
        target.draw_iter(core::iter::once(Pixel(origin + ScreenPoint::new(px, py), BinaryColor::Off)))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wide_travel_fills_the_pictures_width_and_is_centred_in_the_height() {
        // 400 x 100 mm in the right 40 pixels: 39 pixels wide, so 9 high (aspect kept), 11 rows
        // above and 12 below.
        let settings = Settings { max_travel_mm: [200.0, 50.0], ..Settings::default() };
        let scale = MapScale::for_travel(&settings);
        assert_eq!(scale.outline(), ((82, 11), (121, 20)));
        let spm = settings.steps_per_mm;
        let at = |x: f32, y: f32| Point::new((x * spm[0]) as i32, (y * spm[1]) as i32);
        assert_eq!(scale.pixel(at(-200.0, 50.0)), (82, 11), "top left of the travel");
        assert_eq!(scale.pixel(at(200.0, -50.0)), (121, 20), "bottom right");
        assert_eq!(scale.pixel(at(500.0, -500.0)), (121, 31), "beyond the picture: clamped to it");
    }

    #[test]
    fn a_tall_travel_fills_the_height_and_is_centred_in_the_pictures_width() {
        // 100 x 200 mm: 31 pixels high, so 15 wide, centred in the right 40.
        let settings = Settings { max_travel_mm: [50.0, 100.0], ..Settings::default() };
        let ((x0, y0), (x1, y1)) = MapScale::for_travel(&settings).outline();
        assert_eq!((y0, y1, x1 - x0), (0, 31, 15));
        assert_eq!(x0, 82 + 12, "centred in the picture's width");
    }

    #[test]
    fn a_line_sets_every_pixel_between_its_ends_and_no_other() {
        let lit = |map: &StrokeMap| -> std::vec::Vec<Pixel8> {
            let all = (0..PREVIEW_HEIGHT_PX).flat_map(|y| (0..PREVIEW_WIDTH_PX).map(move |x| (x, y)));
            all.filter(|&p| map.get(p)).collect()
        };
        let mut map = StrokeMap::new();
        map.line((2, 3), (10, 7));
        assert_eq!(lit(&map).len(), 9, "one pixel per column: {:?}", lit(&map));
        assert!(map.get((2, 3)) && map.get((10, 7)) && map.get((6, 5)));
        map.set((200, 200));
        assert_eq!(lit(&map).len(), 9, "a pixel off the picture is ignored");
        map.clear();
        assert!(map.is_empty());
    }
}

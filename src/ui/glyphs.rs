//! Text on the LCD: each character's glyph copied from the 5x7 font's image, its ink in one
//! colour, the rest of its cell left as it is. Owns no state.
//!
//! The screen's lines are one font, one size and no decorations: copying glyphs is all the
//! text rendering they need.

use embedded_graphics::Drawable;
use embedded_graphics::Pixel;
use embedded_graphics::draw_target::DrawTarget;
use embedded_graphics::geometry::{Dimensions, OriginDimensions, Point};
use embedded_graphics::image::{Image, ImageDrawableExt};
use embedded_graphics::mono_font::MonoFont;
use embedded_graphics::mono_font::ascii::FONT_5X7;
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_graphics::primitives::Rectangle;

/// The screen's font: 5x7 pixels, a pixel apart.
pub const FONT: MonoFont<'static> = FONT_5X7;

/// Draws `text` with its cells' top-left corner at `at`, ink in `ink`.
pub fn draw<D>(target: &mut D, text: &str, at: Point, ink: BinaryColor) -> Result<(), D::Error>
where
    D: DrawTarget<Color = BinaryColor>,
{
    let size = FONT.character_size;
    let per_row = FONT.image.size().width / size.width;
    let advance = (size.width + FONT.character_spacing) as i32;
    let mut ink_only = Ink { target, ink };
    for (i, c) in text.chars().enumerate() {
        let index = FONT.glyph_mapping.index(c) as u32;
        let corner = Point::new(((index % per_row) * size.width) as i32, ((index / per_row) * size.height) as i32);
        let glyph = FONT.image.sub_image(&Rectangle::new(corner, size));
        Image::new(&glyph, at + Point::new(i as i32 * advance, 0)).draw(&mut ink_only)?;
    }
    Ok(())
}

/// Passes a glyph's set pixels on to `target` in `ink` and drops the others.
struct Ink<'a, D> {
    target: &'a mut D,
    ink: BinaryColor,
}

impl<D: DrawTarget<Color = BinaryColor>> Dimensions for Ink<'_, D> {
    fn bounding_box(&self) -> Rectangle {
        self.target.bounding_box()
    }
}

impl<D: DrawTarget<Color = BinaryColor>> DrawTarget for Ink<'_, D> {
    type Color = BinaryColor;
    type Error = D::Error;

    fn draw_iter<I: IntoIterator<Item = Pixel<BinaryColor>>>(&mut self, pixels: I) -> Result<(), D::Error> {
        let ink = self.ink;
        self.target.draw_iter(pixels.into_iter().filter(|p| p.1.is_on()).map(|Pixel(at, _)| Pixel(at, ink)))
    }
}

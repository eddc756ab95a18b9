//! Text on the LCD: each character's glyph from a 5x7 table, its ink in one colour, the rest of
//! its cell left as it is. Owns no state.
//!
//! The screen's lines are one font, one size and no decorations: setting glyphs' pixels is all
//! the text rendering they need.

use embedded_graphics::Pixel;
use embedded_graphics::draw_target::DrawTarget;
use embedded_graphics::geometry::Point;
use embedded_graphics::pixelcolor::BinaryColor;

// `GLYPHS_5X7`, 35 bits a character: embedded-graphics' `FONT_5X7` (the version this crate
// depends on), each character rendered by build.rs with embedded-graphics' own text renderer, so
// the pixels are the ones it draws. The tests below hold the two to each other.
include!(concat!(env!("OUT_DIR"), "/font5x7.rs"));

/// From one cell to the next: the font's glyphs are 5 pixels wide, their spacing included.
const ADVANCE: i32 = 5;

/// Draws `text` with its cells' top-left corner at `at`, ink in `ink`. A character outside
/// the table (' '..='~') is drawn as '?', as embedded-graphics' ASCII fonts draw it (DEL, the
/// one other glyph they hold, is a copy of '?').
pub fn draw<D>(target: &mut D, text: &str, at: Point, ink: BinaryColor) -> Result<(), D::Error>
where
    D: DrawTarget<Color = BinaryColor>,
{
    let pixels = text.chars().zip((at.x..).step_by(ADVANCE as usize)).flat_map(move |(c, left)| {
        let index = match c {
            ' '..='~' => c as usize - ' ' as usize,
            _ => usize::from(b'?' - b' '),
        };
        // Bit 7 * x + y of the character's 35 is the pixel x from the left, y from the top.
        let first = index * 35;
        (0..35i32)
            .filter(move |&k| {
                let bit = first + k as usize;
                GLYPHS_5X7[bit / 8] >> (bit % 8) & 1 != 0
            })
            .map(move |k| Pixel(Point::new(left + k / 7, at.y + k % 7), ink))
    });
    target.draw_iter(pixels)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use embedded_graphics::Drawable;
    use embedded_graphics::geometry::{OriginDimensions, Size};
    use embedded_graphics::mono_font::MonoTextStyle;
    use embedded_graphics::mono_font::ascii::FONT_5X7;
    use embedded_graphics::text::{Baseline, Text};
    use std::string::String;
    use std::vec;
    use std::vec::Vec;

    /// A canvas that records every pixel drawn, none drawn twice.
    struct Canvas {
        pixels: Vec<Option<BinaryColor>>,
    }

    const W: usize = 40;
    const H: usize = 12;

    impl Canvas {
        fn new() -> Self {
            Canvas { pixels: vec![None; W * H] }
        }
    }

    impl OriginDimensions for Canvas {
        fn size(&self) -> Size {
            Size::new(W as u32, H as u32)
        }
    }

    impl DrawTarget for Canvas {
        type Color = BinaryColor;
        type Error = core::convert::Infallible;

        fn draw_iter<I: IntoIterator<Item = Pixel<BinaryColor>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
            for Pixel(p, c) in pixels {
                assert!((0..W as i32).contains(&p.x) && (0..H as i32).contains(&p.y), "{p:?} off the canvas");
                let cell = &mut self.pixels[p.y as usize * W + p.x as usize];
                assert!(cell.is_none(), "{p:?} drawn twice");
                *cell = Some(c);
            }
            Ok(())
        }
    }

    /// Every printable ASCII character and DEL, alone and in a run, in both inks: the same pixels as
    /// embedded-graphics' text renderer with no background, and nothing else drawn.
    #[test]
    fn every_printable_character_matches_embedded_graphics() {
        let mut runs: Vec<String> = (' '..='\u{7f}').map(String::from).collect();
        runs.push("Ab~ 0|".into());
        for text in &runs {
            for ink in [BinaryColor::On, BinaryColor::Off] {
                let at = Point::new(3, 2);
                let mut ours = Canvas::new();
                draw(&mut ours, text, at, ink).unwrap();
                let mut theirs = Canvas::new();
                Text::with_baseline(text, at, MonoTextStyle::new(&FONT_5X7, ink), Baseline::Top)
                    .draw(&mut theirs)
                    .unwrap();
                assert_eq!(ours.pixels, theirs.pixels, "{text:?} in {ink:?}");
            }
        }
    }

    /// A character the table lacks is drawn as embedded-graphics draws it: as '?'.
    #[test]
    fn other_characters_are_drawn_as_embedded_graphics_draws_them() {
        for text in ["\u{e9}", "\t", "\u{80}", "\0", "x\u{b0}y"] {
            let mut ours = Canvas::new();
            draw(&mut ours, text, Point::new(1, 1), BinaryColor::On).unwrap();
            let mut theirs = Canvas::new();
            Text::with_baseline(text, Point::new(1, 1), MonoTextStyle::new(&FONT_5X7, BinaryColor::On), Baseline::Top)
                .draw(&mut theirs)
                .unwrap();
            assert_eq!(ours.pixels, theirs.pixels, "{text:?}");
        }
        let mut question = Canvas::new();
        draw(&mut question, "?", Point::new(1, 1), BinaryColor::On).unwrap();
        let mut other = Canvas::new();
        draw(&mut other, "\u{e9}", Point::new(1, 1), BinaryColor::On).unwrap();
        assert_eq!(question.pixels, other.pixels);
    }
}

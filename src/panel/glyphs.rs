//! Text on the LCD: each character's glyph from a 5x7 table, or for a Chinese character from the
//! 7x7 table of [`texts`](crate::panel::texts), its ink in one colour, the rest of its cell left as
//! it is. Owns no state.
//!
//! The screen's lines are one font a script, one size and no decorations: setting glyphs'
//! pixels is all the text rendering they need. A Chinese character's cell is two 5x7 cells
//! wide, as its text is two bytes long: a line's width in columns is its length in bytes.

use embedded_graphics::Pixel;
use embedded_graphics::draw_target::DrawTarget;
use embedded_graphics::geometry::Point;
use embedded_graphics::pixelcolor::BinaryColor;

use crate::panel::texts::{GLYPHS_7X7, HANZI_COUNT, HANZI_FIRST};

// `GLYPHS_5X7`, 35 bits a character: embedded-graphics' `FONT_5X7` (the version this crate
// depends on), each character rendered by build.rs with embedded-graphics' own text renderer, so
// the pixels are the ones it draws; but `*`, a multiplication sign (the font's asterisk reads as
// `%`), as the expressions on the screen multiply with it. The tests below hold them to that.
include!(concat!(env!("OUT_DIR"), "/font5x7.rs"));

/// From one cell to the next: the font's glyphs are 5 pixels wide, their spacing included.
const ADVANCE: i32 = 5;
/// A Chinese glyph's cell: two columns; the 7-pixel glyph one pixel in from its left.
const HANZI_ADVANCE: i32 = 2 * ADVANCE;

/// Draws `text` with its cells' top-left corner at `at`, ink in `ink`. A character outside
/// the tables (' '..='~' and the Chinese glyphs) is drawn as '?', as embedded-graphics' ASCII
/// fonts draw it (DEL, the one other glyph they hold, is a copy of '?').
pub fn draw<D>(target: &mut D, text: &str, at: Point, ink: BinaryColor) -> Result<(), D::Error>
where
    D: DrawTarget<Color = BinaryColor>,
{
    let mut left = at.x;
    for c in text.chars() {
        let hanzi = (c as u32).wrapping_sub(HANZI_FIRST as u32) as usize;
        let (table, first, size, x0, advance) = match c {
            _ if hanzi < HANZI_COUNT => (&GLYPHS_7X7[..], hanzi * 49, 49, left + 1, HANZI_ADVANCE),
            ' '..='~' => (&GLYPHS_5X7[..], (c as usize - ' ' as usize) * 35, 35, left, ADVANCE),
            _ => (&GLYPHS_5X7[..], usize::from(b'?' - b' ') * 35, 35, left, ADVANCE),
        };
        // Bit 7 * x + y of the glyph's bits is the pixel x from the left, y from the top.
        let lit = (0..size).filter(move |&k| {
            let bit = first + k as usize;
            table.get(bit / 8).is_some_and(|byte| byte >> (bit % 8) & 1 != 0)
        });
        target.draw_iter(lit.map(move |k| Pixel(Point::new(x0 + k / 7, at.y + k % 7), ink)))?;
        left += advance;
    }
    Ok(())
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

    /// Every printable ASCII character but `*`, and DEL, alone and in a run, in both inks: the
    /// same pixels as embedded-graphics' text renderer with no background, and nothing else drawn.
    #[test]
    fn every_printable_character_matches_embedded_graphics() {
        let mut runs: Vec<String> = (' '..='\u{7f}').filter(|&c| c != '*').map(String::from).collect();
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

    /// `*` is a multiplication sign: a small diagonal cross centred where `+` crosses, nothing
    /// like the font's asterisk (a star of dots that reads as `%`).
    #[test]
    fn the_asterisk_is_a_multiplication_sign() {
        let mut star = Canvas::new();
        draw(&mut star, "*", Point::zero(), BinaryColor::On).unwrap();
        let lit: Vec<(usize, usize)> = (0..7)
            .flat_map(|y| (0..5).map(move |x| (x, y)))
            .filter(|&(x, y)| star.pixels[y * W + x].is_some())
            .collect();
        assert_eq!(lit, [(1, 2), (3, 2), (2, 3), (1, 4), (3, 4)]);
        let mut plus = Canvas::new();
        draw(&mut plus, "+", Point::zero(), BinaryColor::On).unwrap();
        assert!(plus.pixels[3 * W + 2].is_some() && plus.pixels[2 * W + 2].is_some(), "+ crosses at (2, 3)");
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

    /// Every Chinese character the texts use, alone and among ASCII characters: the pixels u8g2's
    /// own renderer draws, one pixel in from the left of a cell two columns wide.
    #[test]
    fn chinese_characters_match_u8g2() {
        use crate::panel::texts::{HANZI, readable};
        use u8g2_fonts::FontRenderer;
        use u8g2_fonts::fonts::u8g2_font_boutique_bitmap_7x7_t_gb2312;
        use u8g2_fonts::types::{FontColor, VerticalPosition};
        let font = FontRenderer::new::<u8g2_font_boutique_bitmap_7x7_t_gb2312>();
        for (k, hanzi) in HANZI.chars().enumerate() {
            let stand_in = char::from_u32(HANZI_FIRST as u32 + k as u32).unwrap();
            let text: String = ['a', stand_in, 'b'].into_iter().collect();
            assert_eq!(readable(&text), std::format!("a{hanzi}b"));
            let at = Point::new(3, 2);
            let mut ours = Canvas::new();
            draw(&mut ours, &text, at, BinaryColor::On).unwrap();
            let mut theirs = Canvas::new();
            let style = MonoTextStyle::new(&FONT_5X7, BinaryColor::On);
            Text::with_baseline("a", at, style, Baseline::Top).draw(&mut theirs).unwrap();
            // The font's glyphs stand one row below the top of its line.
            let cell = at + Point::new(ADVANCE + 1, -1);
            font.render(hanzi, cell, VerticalPosition::Top, FontColor::Transparent(BinaryColor::On), &mut theirs)
                .unwrap();
            Text::with_baseline("b", at + Point::new(ADVANCE + HANZI_ADVANCE, 0), style, Baseline::Top)
                .draw(&mut theirs)
                .unwrap();
            assert_eq!(ours.pixels, theirs.pixels, "{hanzi}");
        }
    }
}

//! What several end-to-end tests share: reading the simulated LCD's frames back as text, glyph
//! by glyph in the 5x7 font, and a canvas to draw expected pictures on.

#![allow(dead_code)]

use embedded_graphics::Drawable;
use embedded_graphics::mono_font::MonoTextStyle;
use embedded_graphics::mono_font::ascii::FONT_5X7;
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_graphics::prelude::{DrawTarget, OriginDimensions, Point as Px, Size};
use embedded_graphics::text::{Baseline, Text};
use servoplot::sim::lcd::Frame;

pub const W: usize = 122;
pub const H: usize = 32;

/// A 122x32 canvas.
pub struct Canvas(pub [[bool; W]; H]);

impl OriginDimensions for Canvas {
    fn size(&self) -> Size {
        Size::new(W as u32, H as u32)
    }
}

impl DrawTarget for Canvas {
    type Color = BinaryColor;
    type Error = core::convert::Infallible;
    fn draw_iter<I: IntoIterator<Item = embedded_graphics::Pixel<BinaryColor>>>(
        &mut self,
        it: I,
    ) -> Result<(), Self::Error> {
        for embedded_graphics::Pixel(p, c) in it {
            if (0..W as i32).contains(&p.x) && (0..H as i32).contains(&p.y) {
                self.0[p.y as usize][p.x as usize] = c.is_on();
            }
        }
        Ok(())
    }
}

/// The 5x7 glyphs of the printable ASCII characters.
pub fn glyphs() -> Vec<(char, [[bool; 5]; 7])> {
    (' '..='~')
        .map(|c| {
            let mut canvas = Canvas([[false; W]; H]);
            let style = MonoTextStyle::new(&FONT_5X7, BinaryColor::On);
            Text::with_baseline(&c.to_string(), Px::zero(), style, Baseline::Top).draw(&mut canvas).unwrap();
            let mut g = [[false; 5]; 7];
            for (y, row) in g.iter_mut().enumerate() {
                row.copy_from_slice(&canvas.0[y][..5]);
            }
            (c, g)
        })
        .collect()
}

/// Text line `line` of `frame`, read up to `columns` characters (`?` where no glyph matches),
/// trailing spaces cut; inverted lines are read as well.
pub fn text(frame: &Frame, line: usize, columns: usize) -> String {
    let glyphs = glyphs();
    let top = line * 8 + 1;
    let inverted = frame.pixels[top - 1][0];
    let mut s = String::new();
    for c in 0..columns {
        let x0 = 1 + 5 * c;
        let cell: Vec<Vec<bool>> =
            (0..7).map(|y| (0..5).map(|x| frame.pixels[top + y][x0 + x] != inverted).collect()).collect();
        let found = glyphs.iter().find(|(_, g)| (0..7).all(|y| (0..5).all(|x| g[y][x] == cell[y][x])));
        s.push(found.map_or('?', |(ch, _)| *ch));
    }
    s.trim_end().to_string()
}

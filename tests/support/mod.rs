//! What several end-to-end tests share: reading the simulated LCD's frames back as text, glyph
//! by glyph in the 5x7 font and u8g2's 7x7 Chinese font, and a canvas to draw expected pictures
//! on.

#![allow(dead_code)]

pub mod files;
pub mod links;

use embedded_graphics::Drawable;
use embedded_graphics::mono_font::MonoTextStyle;
use embedded_graphics::mono_font::ascii::FONT_5X7;
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_graphics::prelude::{DrawTarget, OriginDimensions, Point as Px, Size};
use embedded_graphics::text::{Baseline, Text};
use servoplot::sim::lcd::Frame;
use u8g2_fonts::FontRenderer;
use u8g2_fonts::fonts::u8g2_font_boutique_bitmap_7x7_t_gb2312;
use u8g2_fonts::types::{FontColor, VerticalPosition};

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

/// The LCD's `*`: a multiplication sign, 3x3 pixels centred where `+` crosses.
const MULTIPLICATION_SIGN: [[bool; 5]; 7] = {
    let (o, x) = (false, true);
    [[o; 5], [o; 5], [o, x, o, x, o], [o, o, x, o, o], [o, x, o, x, o], [o; 5], [o; 5]]
};

/// The 5x7 glyphs of the printable ASCII characters: embedded-graphics' font, and `*` as a
/// multiplication sign.
pub fn glyphs() -> Vec<(char, [[bool; 5]; 7])> {
    (' '..='~')
        .map(|c| {
            if c == '*' {
                return (c, MULTIPLICATION_SIGN);
            }
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

/// The Chinese characters the firmware's texts use, each as u8g2's 7x7 font draws it, one
/// pixel in from the left of a cell two columns (10 pixels) wide.
pub fn chinese_glyphs() -> Vec<(char, [[bool; 10]; 7])> {
    let font = FontRenderer::new::<u8g2_font_boutique_bitmap_7x7_t_gb2312>();
    servoplot::panel::texts::HANZI
        .chars()
        .map(|c| {
            let mut canvas = Canvas([[false; W]; H]);
            // The font's glyphs stand one row below the top of its line.
            font.render(c, Px::new(1, -1), VerticalPosition::Top, FontColor::Transparent(BinaryColor::On), &mut canvas)
                .unwrap();
            let mut g = [[false; 10]; 7];
            for (y, row) in g.iter_mut().enumerate() {
                row.copy_from_slice(&canvas.0[y][..10]);
            }
            (c, g)
        })
        .collect()
}

/// Text line `line` of `frame`, read up to `columns` columns (`?` where no glyph matches; a
/// Chinese character takes two), trailing spaces cut; inverted lines are read as well.
pub fn text(frame: &Frame, line: usize, columns: usize) -> String {
    let glyphs = glyphs();
    let chinese = chinese_glyphs();
    let top = line * 8 + 1;
    let inverted = frame.pixels[top - 1][0];
    let lit = |x: usize, y: usize| x < W && frame.pixels[top + y][x] != inverted;
    let mut s = String::new();
    let mut c = 0;
    while c < columns {
        let x0 = 1 + 5 * c;
        if let Some((ch, _)) = chinese.iter().find(|(_, g)| (0..7).all(|y| (0..10).all(|x| g[y][x] == lit(x0 + x, y))))
        {
            s.push(*ch);
            c += 2;
            continue;
        }
        let found = glyphs.iter().find(|(_, g)| (0..7).all(|y| (0..5).all(|x| g[y][x] == lit(x0 + x, y))));
        s.push(found.map_or('?', |(ch, _)| *ch));
        c += 1;
    }
    s.trim_end().to_string()
}

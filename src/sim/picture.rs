//! Pictures the simulator writes: the pen path as SVG, LCD frames as PNG, and the whole
//! session's LCD as an animated GIF.

use std::io::{self, Write};
use std::path::Path;
use std::vec::Vec;

use crate::geom::Point;
use crate::sim::lcd::Frame;

/// Each LCD pixel becomes a square of this many image pixels.
pub const LCD_PNG_SCALE: usize = 4;
/// Border around the LCD picture, in LCD pixels.
pub const LCD_PNG_BORDER: usize = 2;
/// Pixel colours of a yellow-green STN panel, lit and unlit, RGB.
const LCD_ON_RGB: [u8; 3] = [0x20, 0x30, 0x20];
const LCD_OFF_RGB: [u8; 3] = [0x9a, 0xc8, 0x3c];

/// Shortest and longest time a frame of the session GIF is shown, centiseconds: viewers show
/// shorter delays slower, and a long wait is shown shortened.
pub const GIF_MIN_DELAY_CS: u64 = 2;
pub const GIF_MAX_DELAY_CS: u64 = 300;

/// `frame` scaled up with its border, one byte per image pixel: 1 lit, 0 not.
fn scaled(frame: &Frame) -> (usize, usize, Vec<u8>) {
    let w = (frame.pixels[0].len() + 2 * LCD_PNG_BORDER) * LCD_PNG_SCALE;
    let h = (frame.pixels.len() + 2 * LCD_PNG_BORDER) * LCD_PNG_SCALE;
    let mut lit = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let (fx, fy) =
                ((x / LCD_PNG_SCALE).wrapping_sub(LCD_PNG_BORDER), (y / LCD_PNG_SCALE).wrapping_sub(LCD_PNG_BORDER));
            lit.push(u8::from(frame.pixels.get(fy).and_then(|row| row.get(fx)).copied().unwrap_or(false)));
        }
    }
    (w, h, lit)
}

/// Writes the LCD of a whole session as an animated GIF, scaled as the PNGs: each of `frames`
/// (with the virtual time it was sent, µs) is shown until the next one came, within
/// [`GIF_MIN_DELAY_CS`]..=[`GIF_MAX_DELAY_CS`]; the last for the longest.
pub fn write_session_gif(frames: &[(u64, Frame)], path: &Path) -> io::Result<()> {
    let Some((_, first)) = frames.first() else { return Ok(()) };
    let (w, h, _) = scaled(first);
    let file = io::BufWriter::new(std::fs::File::create(path)?);
    let palette: Vec<u8> = [LCD_OFF_RGB, LCD_ON_RGB].concat();
    let mut enc = gif::Encoder::new(file, w as u16, h as u16, &palette).map_err(io::Error::other)?;
    enc.set_repeat(gif::Repeat::Infinite).map_err(io::Error::other)?;
    for (i, (t_us, frame)) in frames.iter().enumerate() {
        let shown_us = frames.get(i + 1).map_or(u64::MAX, |next| next.0 - t_us);
        let delay_cs = (shown_us / 10_000).clamp(GIF_MIN_DELAY_CS, GIF_MAX_DELAY_CS);
        let (_, _, lit) = scaled(frame);
        let mut image = gif::Frame::from_indexed_pixels(w as u16, h as u16, lit, None);
        image.delay = delay_cs as u16;
        enc.write_frame(&image).map_err(io::Error::other)?;
    }
    Ok(())
}

/// Writes `frame` as a PNG, scaled up so a person can read it.
pub fn write_frame_png(frame: &Frame, path: &Path) -> io::Result<()> {
    let (w, h, lit) = scaled(frame);
    let rgb: Vec<u8> = lit.iter().flat_map(|&on| if on != 0 { LCD_ON_RGB } else { LCD_OFF_RGB }).collect();
    let file = std::fs::File::create(path)?;
    let mut enc = png::Encoder::new(io::BufWriter::new(file), w as u32, h as u32);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut writer = enc.write_header().map_err(io::Error::other)?;
    writer.write_image_data(&rgb).map_err(io::Error::other)?;
    writer.finish().map_err(io::Error::other)
}

/// Writes the pen path as an SVG drawing in millimetres, Y up, with a 5 mm margin and the origin
/// marked: the strokes drawn with the pen down in black, the travel with the pen up dashed in
/// grey (see [`SimReport::strokes`](super::SimReport::strokes)).
pub fn write_plot_svg(strokes: &[(bool, Vec<Point>)], steps_per_mm: [f32; 2], out: &mut impl Write) -> io::Result<()> {
    const MARGIN_MM: f32 = 5.0;
    let mm = |p: &Point| (p.x as f32 / steps_per_mm[0], p.y as f32 / steps_per_mm[1]);
    let (mut x0, mut y0, mut x1, mut y1) = (0.0f32, 0.0f32, 0.0f32, 0.0f32);
    for p in strokes.iter().flat_map(|s| &s.1) {
        let (x, y) = mm(p);
        x0 = x0.min(x);
        y0 = y0.min(y);
        x1 = x1.max(x);
        y1 = y1.max(y);
    }
    let (w, h) = (x1 - x0 + 2.0 * MARGIN_MM, y1 - y0 + 2.0 * MARGIN_MM);
    writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.2}mm" height="{h:.2}mm" viewBox="{:.3} {:.3} {w:.3} {h:.3}">"#,
        x0 - MARGIN_MM,
        -y1 - MARGIN_MM
    )?;
    writeln!(
        out,
        r#"<rect x="{:.3}" y="{:.3}" width="{w:.3}" height="{h:.3}" fill="white"/>"#,
        x0 - MARGIN_MM,
        -y1 - MARGIN_MM
    )?;
    writeln!(out, r##"<path d="M -2 0 H 2 M 0 -2 V 2" stroke="#c00" stroke-width="0.1" fill="none"/>"##)?;
    for (down, path) in strokes {
        let style = if *down {
            r#"stroke="black" stroke-width="0.25""#
        } else {
            r##"stroke="#999" stroke-width="0.15" stroke-dasharray="1 1""##
        };
        write!(out, r#"<polyline fill="none" {style} stroke-linejoin="round" points=""#)?;
        // Collinear runs are merged so the file stays small; the path itself is exact.
        let mut last_dir = None;
        for (i, p) in path.iter().enumerate() {
            let dir = path.get(i + 1).map(|n| (n.x - p.x, n.y - p.y));
            if i == 0 || dir != last_dir || i + 1 == path.len() {
                let (x, y) = mm(p);
                write!(out, "{x:.3},{:.3} ", -y)?;
            }
            last_dir = dir;
        }
        writeln!(out, r#""/>"#)?;
    }
    writeln!(out, "</svg>")
}

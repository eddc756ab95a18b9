//! Link scripts for the firmware image (the host build, the simulator, needs none), and the
//! LCD's glyph table for every build.

use embedded_graphics::Drawable;
use embedded_graphics::Pixel;
use embedded_graphics::draw_target::DrawTarget;
use embedded_graphics::geometry::{OriginDimensions, Point, Size};
use embedded_graphics::mono_font::MonoTextStyle;
use embedded_graphics::mono_font::ascii::FONT_5X7;
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_graphics::text::{Baseline, Text};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    write_font(&out);
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("none") {
        // memory.x sits in the package root, which is on the linker's search path as the
        // build script's output directory is not: copy it there for link.x to include.
        std::fs::copy("memory.x", out.join("memory.x")).expect("memory.x is readable");
        println!("cargo:rustc-link-search={}", out.display());
        println!("cargo:rustc-link-arg-bins=--nmagic");
        // Identical functions (generic copies that compile to the same code) are kept once. No
        // code here compares function addresses.
        println!("cargo:rustc-link-arg-bins=--icf=all");
        println!("cargo:rustc-link-arg-bins=-Tlink.x");
        println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
    }
}

/// One glyph's pixels as embedded-graphics draws them: bit `7 * x + y` set where the pixel x
/// from the left, y from the top, is lit.
#[derive(Default)]
struct Cell(u64);

impl OriginDimensions for Cell {
    fn size(&self) -> Size {
        Size::new(5, 7)
    }
}

impl DrawTarget for Cell {
    type Color = BinaryColor;
    type Error = core::convert::Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<BinaryColor>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
        for Pixel(p, c) in pixels {
            assert!((0..5).contains(&p.x) && (0..7).contains(&p.y), "a 5x7 glyph's pixel outside its cell");
            if c.is_on() {
                self.0 |= 1 << (7 * p.x + p.y);
            }
        }
        Ok(())
    }
}

/// `$OUT_DIR/font5x7.rs`: embedded-graphics' 5x7 font, the printable ASCII characters ' '..='~'
/// each rendered by its own text renderer, as one run of bits (see the table's comment). Its
/// ASCII fonts' one other glyph, DEL's, is a copy of '?', which the firmware draws for any
/// character outside the table.
fn write_font(out: &Path) {
    let style = MonoTextStyle::new(&FONT_5X7, BinaryColor::On);
    let mut bits = Vec::new();
    for c in ' '..='~' {
        let mut cell = Cell::default();
        let mut buf = [0; 4];
        Text::with_baseline(c.encode_utf8(&mut buf), Point::zero(), style, Baseline::Top)
            .draw(&mut cell)
            .expect("drawing into memory cannot fail");
        bits.extend((0..35).map(|k| cell.0 >> k & 1 != 0));
    }
    let bytes: Vec<u8> =
        bits.chunks(8).map(|byte| byte.iter().rev().fold(0, |acc, &on| acc << 1 | u8::from(on))).collect();
    let mut src = format!(
        "/// embedded-graphics' `FONT_5X7`, ' '..='~', written by build.rs: 35 bits per character, bit\n\
         /// `35 * (c - ' ') + 7 * x + y` (bit n is bit n % 8 of byte n / 8) set where the pixel x from\n\
         /// the left, y from the top of c's 5x7 cell is lit.\n\
         pub const GLYPHS_5X7: [u8; {}] = [\n",
        bytes.len()
    );
    for line in bytes.chunks(16) {
        src.push_str("   ");
        for b in line {
            write!(src, " {b:#04x},").expect("writing to a String");
        }
        src.push('\n');
    }
    src.push_str("];\n");
    std::fs::write(out.join("font5x7.rs"), src).expect("OUT_DIR is writable");
}

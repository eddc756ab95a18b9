//! Link scripts for the firmware images (each board's memory map; the host build, the simulator,
//! needs none), and for every build the LCD's glyph table and its texts in both languages, with
//! the glyphs of the Chinese characters they use.

use embedded_graphics::Drawable;
use embedded_graphics::Pixel;
use embedded_graphics::draw_target::DrawTarget;
use embedded_graphics::geometry::{OriginDimensions, Point, Size};
use embedded_graphics::mono_font::MonoTextStyle;
use embedded_graphics::mono_font::ascii::FONT_5X7;
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_graphics::text::{Baseline, Text};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use u8g2_fonts::FontRenderer;
use u8g2_fonts::fonts::u8g2_font_boutique_bitmap_7x7_t_gb2312;
use u8g2_fonts::types::{FontColor, VerticalPosition};

/// Each firmware image and its board's memory map.
const IMAGES: [(&str, &str); 2] =
    [("servoplot", "src/board/stm32f407/memory.x"), ("servoplot-mps2-an386", "src/board/mps2_an386/memory.x")];

/// The LCD's texts, `name | English | 中文` a line.
const TEXTS: &str = "src/panel/texts.txt";
/// The first of the characters that stand for Chinese glyphs on the screen's lines: the k-th
/// glyph is `HANZI_FIRST + k`, two bytes in UTF-8 up to U+07FF, as it is two columns wide on the
/// screen.
const HANZI_FIRST: u32 = 0x100;
const HANZI_LAST: u32 = 0x7ff;
/// In the texts' tables, the first [`HANZI_ONE_BYTE`] glyphs (the most used) are one byte,
/// `0x80 + k`; the others two, [`HANZI_ESCAPE`] then `k - HANZI_ONE_BYTE`.
const HANZI_ONE_BYTE: usize = 128;
const HANZI_ESCAPE: u8 = 0x01;
/// Byte values no text uses, each made to stand for the pair of bytes used most often in the
/// texts (either of which may be such a code again): the texts' own compression.
const PAIR_CODES: std::ops::RangeInclusive<u8> = 0x02..=0x1f;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed={TEXTS}");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    write_font(&out);
    write_texts(&out);
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("none") {
        // Each image links with its board's memory map: cortex-m-rt's link.x includes
        // memory.x (the linker finds it in the package root), which includes board-memory.x,
        // found in a directory of its own on that image's search path.
        println!("cargo:rerun-if-changed=memory.x");
        for (bin, map) in IMAGES {
            println!("cargo:rerun-if-changed={map}");
            let dir = out.join(bin);
            std::fs::create_dir_all(&dir).expect("OUT_DIR is writable");
            std::fs::copy(map, dir.join("board-memory.x")).expect("the memory map is readable");
            // Two arguments: flip-link reads `-L DIR` written apart.
            println!("cargo:rustc-link-arg-bin={bin}=-L");
            println!("cargo:rustc-link-arg-bin={bin}={}", dir.display());
        }
        println!("cargo:rustc-link-arg-bins=--nmagic");
        // Identical functions (generic copies that compile to the same code) are kept once. No
        // code here compares function addresses.
        println!("cargo:rustc-link-arg-bins=--icf=all");
        println!("cargo:rustc-link-arg-bins=-Tlink.x");
        println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
    }
}

/// One glyph's pixels as a font draws them: bit `7 * x + y` set where the pixel x from the
/// left, y from the top, is lit; `width` pixels wide, 7 high.
struct Cell {
    bits: u64,
    width: i32,
}

impl Cell {
    fn new(width: i32) -> Self {
        Cell { bits: 0, width }
    }
}

impl OriginDimensions for Cell {
    fn size(&self) -> Size {
        Size::new(self.width as u32, 7)
    }
}

impl DrawTarget for Cell {
    type Color = BinaryColor;
    type Error = core::convert::Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<BinaryColor>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
        for Pixel(p, c) in pixels {
            assert!((0..self.width).contains(&p.x) && (0..7).contains(&p.y), "a glyph's pixel outside its cell");
            if c.is_on() {
                self.bits |= 1 << (7 * p.x + p.y);
            }
        }
        Ok(())
    }
}

/// The glyph drawn for `*`, rows from the top, `#` lit: a multiplication sign centred where
/// `+` crosses, as the expressions on the screen use `*` (the font's own asterisk, a star of
/// dots, reads as `%` at this size).
const MULTIPLICATION_SIGN: [&str; 7] = [".....", ".....", ".#.#.", "..#..", ".#.#.", ".....", "....."];

/// `$OUT_DIR/font5x7.rs`: embedded-graphics' 5x7 font, the printable ASCII characters ' '..='~'
/// each rendered by its own text renderer (but `*`, drawn as [`MULTIPLICATION_SIGN`]), as one
/// run of bits (see the table's comment). Its ASCII fonts' one other glyph, DEL's, is a copy
/// of '?', which the firmware draws for any character outside the table.
fn write_font(out: &Path) {
    let style = MonoTextStyle::new(&FONT_5X7, BinaryColor::On);
    let mut bits = Vec::new();
    for c in ' '..='~' {
        let mut cell = Cell::new(5);
        if c == '*' {
            for (y, row) in MULTIPLICATION_SIGN.iter().enumerate() {
                for (x, _) in row.bytes().enumerate().filter(|&(_, b)| b == b'#') {
                    cell.bits |= 1 << (7 * x + y);
                }
            }
        } else {
            let mut buf = [0; 4];
            Text::with_baseline(c.encode_utf8(&mut buf), Point::zero(), style, Baseline::Top)
                .draw(&mut cell)
                .expect("drawing into memory cannot fail");
        }
        bits.extend((0..35).map(|k| cell.bits >> k & 1 != 0));
    }
    let mut src = format!(
        "/// embedded-graphics' `FONT_5X7`, ' '..='~' (`*` a multiplication sign), written by build.rs:\n\
         /// 35 bits per character, bit `35 * (c - ' ') + 7 * x + y` (bit n is bit n % 8 of byte n / 8)\n\
         /// set where the pixel x from the left, y from the top of c's 5x7 cell is lit.\n\
         pub const GLYPHS_5X7: [u8; {}] = [\n",
        bits.len().div_ceil(8)
    );
    write_bytes(&mut src, &bits);
    std::fs::write(out.join("font5x7.rs"), src).expect("OUT_DIR is writable");
}

/// `bits` as the elements of a byte array (bit n is bit n % 8 of byte n / 8), and its end.
fn write_bytes(src: &mut String, bits: &[bool]) {
    let bytes: Vec<u8> =
        bits.chunks(8).map(|byte| byte.iter().rev().fold(0, |acc, &on| acc << 1 | u8::from(on))).collect();
    for line in bytes.chunks(16) {
        src.push_str("   ");
        for b in line {
            write!(src, " {b:#04x},").expect("writing to a String");
        }
        src.push('\n');
    }
    src.push_str("];\n");
}

/// A text's bytes as symbols: a byte, or (above 0xff) an escaped glyph with its number byte,
/// which no pair may split.
fn symbols(bytes: &[u8]) -> Vec<u16> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == HANZI_ESCAPE {
            out.push(0x100 | u16::from(bytes[i + 1]));
            i += 2;
        } else {
            assert!(!PAIR_CODES.contains(&bytes[i]), "a text uses a pair code's byte");
            out.push(u16::from(bytes[i]));
            i += 1;
        }
    }
    out
}

fn unsymbols(symbols: &[u16]) -> Vec<u8> {
    symbols
        .iter()
        .flat_map(|&s| match u8::try_from(s) {
            Ok(b) => vec![b],
            Err(_) => vec![HANZI_ESCAPE, s as u8],
        })
        .collect()
}

/// Gives each of [`PAIR_CODES`] in turn to the pair of bytes most used in `texts` (while one
/// saves bytes), replacing it there; returns the codes and their pairs.
fn pair_codes(texts: &mut [Vec<u16>]) -> Vec<(u8, [u8; 2])> {
    let mut pairs = Vec::new();
    for code in PAIR_CODES {
        let mut counts: BTreeMap<(u16, u16), usize> = BTreeMap::new();
        for text in texts.iter() {
            for w in text.windows(2) {
                if w[0] < 0x100 && w[1] < 0x100 {
                    *counts.entry((w[0], w[1])).or_default() += 1;
                }
            }
        }
        // Each use saves a byte; the pair's entry costs two.
        let Some((&(first, second), _)) =
            counts.iter().filter(|&(_, &n)| n > 3).max_by_key(|&(pair, &n)| (n, std::cmp::Reverse(*pair)))
        else {
            break;
        };
        for text in texts.iter_mut() {
            let mut out = Vec::with_capacity(text.len());
            let mut i = 0;
            while i < text.len() {
                if i + 1 < text.len() && (text[i], text[i + 1]) == (first, second) {
                    out.push(u16::from(code));
                    i += 2;
                } else {
                    out.push(text[i]);
                    i += 1;
                }
            }
            *text = out;
        }
        pairs.push((code, [first as u8, second as u8]));
    }
    pairs
}

/// How deep the pairs nest under `code`: 1 for a pair of plain bytes.
fn pair_depth(code: u8, pairs: &[(u8, [u8; 2])]) -> usize {
    match pairs.iter().find(|(c, _)| *c == code) {
        Some((_, pair)) => 1 + pair.iter().map(|&b| pair_depth(b, pairs)).max().unwrap_or(0),
        None => 0,
    }
}

/// One line of [`TEXTS`].
struct Entry {
    name: String,
    english: String,
    chinese: String,
}

/// `$OUT_DIR/texts.rs`: from [`TEXTS`], the `Msg` enum, each language's texts as one run of
/// bytes and their lengths in it, ASCII as it is and a Chinese character as the number of its
/// glyph (one byte, or two for the least used), and those glyphs: the Chinese characters used, each rendered from u8g2's 7x7 GB2312 font
/// by its own renderer, 49 bits a glyph in the 5x7 table's order.
fn write_texts(out: &Path) {
    let source = std::fs::read_to_string(TEXTS).expect("the texts file is readable");
    let mut entries = Vec::new();
    for (n, line) in source.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let parts: Vec<&str> = line.split(" | ").map(str::trim).collect();
        let [name, english, chinese] = parts[..] else {
            panic!("{TEXTS}:{}: not `name | English | 中文`", n + 1);
        };
        assert!(
            name.chars().all(|c| c.is_ascii_alphanumeric()) && !english.is_empty() && !chinese.is_empty(),
            "{TEXTS}:{}: a name of letters and digits, and two texts",
            n + 1
        );
        entries.push(Entry { name: name.into(), english: english.into(), chinese: chinese.into() });
    }
    // The Chinese characters, the most used first.
    let mut uses: BTreeMap<char, usize> = BTreeMap::new();
    for c in entries.iter().flat_map(|e| e.english.chars().chain(e.chinese.chars())) {
        if !(' '..='~').contains(&c) {
            *uses.entry(c).or_default() += 1;
        }
    }
    let mut hanzi: Vec<char> = uses.keys().copied().collect();
    hanzi.sort_by_key(|c| (std::cmp::Reverse(uses[c]), *c));
    assert!(HANZI_FIRST + hanzi.len() as u32 <= HANZI_LAST + 1, "too many Chinese characters");
    assert!(hanzi.len() <= HANZI_ONE_BYTE + 256, "too many Chinese characters for the escape byte");
    let encode = |text: &str| -> Vec<u8> {
        let mut bytes = Vec::new();
        for c in text.chars() {
            match hanzi.iter().position(|&h| h == c) {
                Some(k) if k < HANZI_ONE_BYTE => bytes.push(0x80 + k as u8),
                Some(k) => bytes.extend([HANZI_ESCAPE, (k - HANZI_ONE_BYTE) as u8]),
                None => bytes.push(u8::try_from(c).expect("ASCII")),
            }
        }
        bytes
    };

    let mut src = String::from(
        "/// A text of the LCD, in either language: see `src/panel/texts.txt`.\n\
         #[derive(Clone, Copy, Debug, PartialEq, Eq)]\n\
         #[cfg_attr(target_os = \"none\", derive(defmt::Format))]\n\
         pub enum Msg {\n",
    );
    for e in &entries {
        writeln!(src, "    /// {}", e.english).expect("writing to a String");
        writeln!(src, "    {},", e.name).expect("writing to a String");
    }
    src.push_str("}\n\n");
    let mut texts: Vec<Vec<u16>> =
        entries.iter().flat_map(|e| [&e.english, &e.chinese]).map(|text| symbols(&encode(text))).collect();
    let pairs = pair_codes(&mut texts);
    let depth = pairs.iter().map(|&(code, _)| pair_depth(code, &pairs)).max().unwrap_or(0);
    let bytes: Vec<Vec<u8>> = texts.iter().map(|t| unsymbols(t)).collect();
    writeln!(
        src,
        "/// Each byte of `PAIR_CODES` stands for a pair of bytes (which may be such codes again,\n\
         /// at most `PAIR_DEPTH` deep), written by build.rs.\n\
         const PAIR_CODES: core::ops::RangeInclusive<u8> = {:#04x}..={:#04x};\n\
         const PAIRS: [[u8; 2]; {}] = {:?};\nconst PAIR_DEPTH: usize = {depth};",
        PAIR_CODES.start(),
        PAIR_CODES.start() + pairs.len() as u8 - 1,
        pairs.len(),
        pairs.iter().map(|(_, pair)| *pair).collect::<Vec<_>>()
    )
    .expect("writing to a String");
    for (table, texts) in [
        ("ENGLISH", bytes.iter().step_by(2).cloned().collect::<Vec<_>>()),
        ("CHINESE", bytes.iter().skip(1).step_by(2).cloned().collect()),
    ] {
        let lengths: Vec<u8> = texts.iter().map(|t| u8::try_from(t.len()).expect("a text fits a line")).collect();
        writeln!(
            src,
            "const {table}: [u8; {}] = {:?};",
            lengths.iter().map(|&n| usize::from(n)).sum::<usize>(),
            texts.concat()
        )
        .expect("writing to a String");
        writeln!(src, "const {table}_LENGTHS: [u8; {}] = {lengths:?};", lengths.len()).expect("writing to a String");
    }
    let settings: Vec<(&str, &str)> =
        entries.iter().filter_map(|e| Some((e.name.strip_prefix("Setting")?, e.name.as_str()))).collect();
    writeln!(
        src,
        "\n/// The settings' names, in the file's order, which is `SETTING_INFO`'s (a test holds the\n\
         /// two to each other).\npub const SETTING_NAMES: [Msg; {}] = [{}];",
        settings.len(),
        settings.iter().map(|(_, name)| format!("Msg::{name}")).collect::<Vec<_>>().join(", ")
    )
    .expect("writing to a String");
    writeln!(
        src,
        "/// The `$` number each of [`SETTING_NAMES`] names.\n#[cfg(not(target_os = \"none\"))]\n\
         pub const SETTING_NAME_IDS: [u16; {}] = [{}];\n",
        settings.len(),
        settings.iter().map(|(id, _)| *id).collect::<Vec<_>>().join(", ")
    )
    .expect("writing to a String");
    writeln!(
        src,
        "#[cfg(not(target_os = \"none\"))]\nimpl Msg {{\n    /// Every text, in the file's order.\n    pub const ALL: [Msg; {}] = [{}];\n}}\n",
        entries.len(),
        entries.iter().map(|e| format!("Msg::{}", e.name)).collect::<Vec<_>>().join(", ")
    )
    .expect("writing to a String");

    let renderer = FontRenderer::new::<u8g2_font_boutique_bitmap_7x7_t_gb2312>();
    let mut bits = Vec::new();
    for &c in &hanzi {
        let mut cell = Cell::new(7);
        // The font's glyphs stand one row below the top of its line.
        renderer
            .render(c, Point::new(0, -1), VerticalPosition::Top, FontColor::Transparent(BinaryColor::On), &mut cell)
            .unwrap_or_else(|e| panic!("{c:?} is not in the font: {e:?}"));
        bits.extend((0..49).map(|k| cell.bits >> k & 1 != 0));
    }
    writeln!(
        src,
        "/// The first character standing for a Chinese glyph.\npub const HANZI_FIRST: char = {:?};",
        char::from_u32(HANZI_FIRST).unwrap()
    )
    .expect("writing to a String");
    writeln!(src, "/// How many Chinese glyphs there are.\npub const HANZI_COUNT: usize = {};", hanzi.len())
        .expect("writing to a String");
    writeln!(
        src,
        "/// The glyphs a table byte `0x80 + k` stands for; the others are `{HANZI_ESCAPE:#04x}` and\n\
         /// `k - HANZI_ONE_BYTE`.\nconst HANZI_ONE_BYTE: usize = {HANZI_ONE_BYTE};\nconst HANZI_ESCAPE: u8 = {HANZI_ESCAPE:#04x};"
    )
    .expect("writing to a String");
    writeln!(
        src,
        "/// The Chinese characters, in glyph order (the most used first).\n#[cfg(not(target_os = \"none\"))]\npub const HANZI: &str = {:?};",
        hanzi.iter().collect::<String>()
    )
    .expect("writing to a String");
    write!(
        src,
        "/// u8g2's `boutique_bitmap_7x7` glyph of each Chinese character (glyph order), written by build.rs:\n\
         /// 49 bits per glyph, bit `49 * k + 7 * x + y` set where the pixel x from the left, y from the\n\
         /// top of glyph k's 7x7 cell is lit.\n\
         pub const GLYPHS_7X7: [u8; {}] = [\n",
        bits.len().div_ceil(8)
    )
    .expect("writing to a String");
    write_bytes(&mut src, &bits);
    std::fs::write(out.join("texts.rs"), src).expect("OUT_DIR is writable");
}

//! The lines a user stores on the plotter: GRBL's startup blocks (`$N0=`, `$N1=`), G-code lines
//! the host link runs after every reset to set the modes a user wants by default (`G20 G54`,
//! ...), and the build info line (`$I=`) that `$I` shows. Owns the stored lines; the G-code parser
//! checks a startup block before it is stored, and the serial task runs them.
//!
//! The serial task keeps them in the flash store ([`crate::store`]), with the settings.

use heapless::String;

/// Startup blocks, as in GRBL.
pub const STARTUP_LINES: usize = 2;
/// Longest startup block, in bytes, as stored (compacted: no spaces or comments); GRBL's.
pub const STARTUP_LINE_MAX_BYTES: usize = 80;

/// One stored startup block, or the build info line: as long as GRBL's.
pub type StartupLine = String<STARTUP_LINE_MAX_BYTES>;

/// `bytes` as a line: `None` unless every byte is ASCII and they fit in a line. (Built char by
/// char: ASCII needs no UTF-8 validation.)
pub fn ascii_line(bytes: &[u8]) -> Option<StartupLine> {
    let mut line = StartupLine::new();
    for &byte in bytes {
        if !byte.is_ascii() {
            return None;
        }
        line.push(char::from(byte)).ok()?;
    }
    Some(line)
}

/// The stored startup blocks, empty ones included.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StartupLines {
    lines: [StartupLine; STARTUP_LINES],
    /// `$I=`: shown by `$I` after the version.
    pub build_info: StartupLine,
}

impl StartupLines {
    pub const fn new() -> Self {
        StartupLines { lines: [String::new(), String::new()], build_info: String::new() }
    }

    /// Stores `line` as block `index` (an empty line clears it); the parser has checked both.
    pub fn set(&mut self, index: usize, line: StartupLine) {
        if let Some(slot) = self.lines.get_mut(index) {
            *slot = line;
        }
    }

    /// Every block, in order, empty ones included (`$N` lists them all).
    pub fn all(&self) -> impl Iterator<Item = &str> {
        self.lines.iter().map(String::as_str)
    }

    /// Block `index`, empty when none is stored.
    pub fn line(&self, index: usize) -> &str {
        self.lines.get(index).map_or("", String::as_str)
    }

    /// Forgets every block and the build info line (`$RST=*`).
    pub fn clear(&mut self) {
        *self = StartupLines::new();
    }
}

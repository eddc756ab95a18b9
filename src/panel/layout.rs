//! The LCD's geometry: its visible size, the text grid the 5x7 font makes of it, and where the
//! previews sit in it.

/// Visible width of the LCD.
pub const SCREEN_WIDTH_PX: u32 = 122;
/// Visible height of the LCD.
pub const SCREEN_HEIGHT_PX: u32 = 32;
/// Height of one text line (the 5x7 font and a row between lines).
pub const SCREEN_LINE_HEIGHT_PX: u32 = 8;
/// Width of one character (the 5x7 font).
pub const SCREEN_CHAR_WIDTH_PX: u32 = 5;
/// Left margin, so inverted lines do not start with a glyph at the glass' edge.
pub const SCREEN_MARGIN_PX: u32 = 1;
/// Text lines on the screen.
pub const SCREEN_LINES: usize = (SCREEN_HEIGHT_PX / SCREEN_LINE_HEIGHT_PX) as usize;
/// Characters per line.
pub const SCREEN_COLUMNS: usize = ((SCREEN_WIDTH_PX - SCREEN_MARGIN_PX) / SCREEN_CHAR_WIDTH_PX) as usize;
/// Width of the preview beside the run screen's numbers, at the right edge.
pub const PREVIEW_BESIDE_WIDTH_PX: u32 = 28;
/// Width of the preview of a drawing before it starts, at the right edge.
pub const PREVIEW_CONFIRM_WIDTH_PX: u32 = 56;

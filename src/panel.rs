//! The machine's own panel: its keypad and its LCD, and what the user does with them.
//!
//! Data flow: key scans -> [`keypad`] (decoded key events) -> [`menu`] (jobs, controls, jogs and
//! settings for the machine) -> the machine's state -> [`screen`] -> the LCD, in the [`language`]
//! chosen.
//!
//! [`menu`] turns key events (from [`crate::panel::keypad`]) into jobs, controls, jogs and settings;
//! [`entry`] holds the number being typed; [`presets`] names the functions the keypad offers;
//! [`run`] follows a drawing (its plan, progress and time) and [`trail`] keeps its path as a
//! bounded polyline; [`screen`] draws it all on the 122x32 LCD, whose sizes are in [`layout`],
//! its text glyph by glyph ([`glyphs`]) in either language ([`texts`]). Everything here is pure: no clock, no pins, no
//! waiting.

// 4x4 keypad decoding: raw scans in, debounced key events out.
pub mod keypad;

// The language the menu and the screen speak (`$216`).
pub mod language;

pub mod entry;
pub mod expr_entry;
pub mod glyphs;
pub mod layout;
pub mod menu;
pub mod presets;
pub mod run;
pub mod screen;
pub mod texts;
pub mod trail;

pub use layout::{SCREEN_HEIGHT_PX, SCREEN_WIDTH_PX};
pub use menu::{Menu, MenuAction};
pub use presets::FunctionPreset;
pub use screen::ScreenView;

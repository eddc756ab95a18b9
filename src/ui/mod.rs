//! The machine's own user interface: the keypad menu and the LCD screen.
//!
//! [`menu`] turns key events (from [`crate::keypad`]) into jobs, controls, jogs and settings;
//! [`entry`] holds the number being typed; [`presets`] names the functions the keypad offers;
//! [`run`] follows a drawing (its plan, progress and time) and [`trail`] keeps its path as a
//! bounded polyline; [`screen`] draws it all on the 122x32 LCD, whose sizes are in [`layout`],
//! its text glyph by glyph ([`glyphs`]) in either language ([`texts`]). Everything here is pure: no clock, no pins, no
//! waiting.

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

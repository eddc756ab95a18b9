//! Why the menu refused a key or a job: the [`UiError`] it shows until the next key.

use crate::drawing::DrawError;
use crate::expr::ParseError;
use crate::ui::entry::EntryError;
use crate::unit::Unit;

/// Why the menu refused a key or a job; shown until the next key.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum UiError {
    Entry(EntryError),
    /// The typed function does not parse: why, and where.
    Expression(ParseError),
    /// `#` on an empty field that has no default.
    Empty,
    OutOfRange {
        min: f32,
        max: f32,
        unit: Unit,
    },
    /// Zero where the field needs a length.
    Zero,
    /// A function's x1 equals its x0.
    SameEnds,
    /// The drawing builder refused the drawing (beyond the travel, too steep, too fine, a
    /// function undefined part way...).
    Drawing(DrawError),
    /// The machine is moving or has jobs queued.
    Busy,
    /// An alarm locks motion.
    Alarm,
    /// Homing is switched off (`$22`).
    HomingOff,
    /// `D` aborted the motion.
    Aborted,
    /// A fraction typed for a setting that takes whole numbers.
    NotWhole,
    /// The new settings would disagree with the others (a start rate above a top speed, a
    /// pulse too wide for the pulse rate): nothing changed.
    Clash,
}

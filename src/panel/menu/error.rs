//! Why the menu refused a key or a job: the [`UiError`] it shows until the next key.

use crate::card::CardError;
use crate::host::GrblError;
use crate::motion::drawing::DrawError;
use crate::motion::expr::{EvalError, ParseError};
use crate::panel::entry::EntryError;
use crate::settings::{SETTING_INFO, SettingError, Settings};
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
    /// A function cannot be evaluated at its x0, where the pen is: why, as the host link says.
    UndefinedAtStart(EvalError),
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
    /// Setting `$set` would disagree with setting `$with` (a start rate above a top speed, a
    /// pulse too wide for the pulse rate): nothing changed.
    Clash {
        set: u16,
        with: u16,
    },
    /// Setting `$set` would leave the pen outside the travel: nothing changed.
    StrandsPen {
        set: u16,
    },
    /// The card gave no files, or failed while a file was read: nothing moves (more).
    Card(CardError),
    /// Line `line` of the card file was refused with `error`: by its check (nothing moved), or
    /// as it ran (the plot stopped there).
    CardLine {
        line: u32,
        error: GrblError,
    },
}

impl UiError {
    /// Why `changes` (settings typed, each in its range, or a speed preset's) were refused by
    /// `settings` with `e`.
    pub fn settings_refused(settings: &Settings, changes: &[(u16, f32)], e: SettingError) -> UiError {
        let first = changes.first().map_or(0, |&(id, _)| id);
        match (e, settings.clash(changes)) {
            (SettingError::StrandsPen, _) => UiError::StrandsPen { set: first },
            // The one changed is `set`, the other `with`.
            (_, Some([a, b])) if changes.iter().any(|&(id, _)| id == a) => UiError::Clash { set: a, with: b },
            (_, Some([a, b])) => UiError::Clash { set: b, with: a },
            (_, None) => {
                let info = SETTING_INFO.iter().find(|i| i.id == first).unwrap_or(&SETTING_INFO[0]);
                UiError::OutOfRange { min: info.min, max: info.max, unit: info.unit }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_refused_change_names_the_setting_it_clashes_with() {
        let s = Settings::default();
        let clash = |changes: &[(u16, f32)]| UiError::settings_refused(&s, changes, SettingError::OutOfRange);
        assert_eq!(clash(&[(201, 7_000.0)]), UiError::Clash { set: 201, with: 110 });
        assert_eq!(clash(&[(110, 5.0)]), UiError::Clash { set: 110, with: 201 });
        assert_eq!(clash(&[(0, 100.0)]), UiError::Clash { set: 0, with: 205 });
        assert_eq!(clash(&[(203, 1_000.0), (111, 5.0)]), UiError::Clash { set: 111, with: 201 });
        let strands = UiError::settings_refused(&s, &[(130, 10.0)], SettingError::StrandsPen);
        assert_eq!(strands, UiError::StrandsPen { set: 130 });
    }
}

//! What the 122x32 LCD shows, and drawing it on any monochrome embedded-graphics target.
//!
//! [`view`] turns the menu, the machine status and the settings, with what the LCD task adds
//! ([`Live`]: the clock, the pen's speed, the work offset, the path drawn), into a
//! [`ScreenView`]: four text lines of [`SCREEN_COLUMNS`] characters in the 5x7 font (whose
//! decimal point is a dot; the 5x8 font's is a cross, and "0.000" read "0+000"), the title line
//! inverted, an error (if any) inverted on the bottom line, and where a path is shown, its
//! [`PreviewBox`]. The view is small and compares cheaply, so the LCD task redraws only when it
//! changes. [`render`] draws a whole view: every line's full width is cleared before its text is
//! drawn, and the preview's box before its path, so no pixel of an earlier frame survives (no
//! stale digits), and nothing is drawn outside [`SCREEN_WIDTH_PX`] x
//! [`SCREEN_HEIGHT_PX`](crate::ui::layout::SCREEN_HEIGHT_PX).
//!
//! Layout of the menu's screens (the preview and run screens are in `run`):
//!
//! ```text
//! LINE 1/2            IDLE    title and run state (inverted)
//! X  12.345 Y  -3.000         pen position, work mm (inverted until homed)
//! dX mm: -12.5_               field being typed, with its unit
//! X offset from the pen       help, or the error (inverted)
//! ```

use core::fmt::{self, Write};

use embedded_graphics::draw_target::DrawTarget;
use embedded_graphics::geometry::{Point, Size};
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_graphics::primitives::Rectangle;
use heapless::String;

use crate::decimal::{Int, Num};
use crate::drawing::DrawError;
use crate::geom::Step;
use crate::homing::HomingFail;
use crate::inputs::Trip;
use crate::interp::CurveError;
use crate::overrides::OVERRIDE_NONE_PERCENT;
use crate::settings::SETTING_INFO;
use crate::settings::Settings;
use crate::settings::presets::SpeedPreset;
use crate::status::{MotionFault, RunState, Status};
use crate::text::{Padded, Text};
use crate::ui::entry::{ENTRY_MAX_CHARS, EntryError};
use crate::ui::glyphs;
use crate::ui::layout::{SCREEN_COLUMNS, SCREEN_LINE_HEIGHT_PX, SCREEN_LINES, SCREEN_MARGIN_PX, SCREEN_WIDTH_PX};
use crate::ui::menu::{Field, Menu, Mode, SETTING_EDIT_HINT, Screen, UiError};
use crate::ui::trail::{self, Trail};

mod lines;
mod run;

use lines::{Cut, position_line, state_name};
pub use lines::{Live, PreviewBox, ScreenView, TextLine};

/// The screen for the current menu and machine state.
pub fn view(menu: &Menu, status: &Status, settings: &Settings, live: &Live) -> ScreenView {
    let mut v = match (menu.run(), menu.screen()) {
        (Some(r), _) => run::run_view(menu, r, status, settings, live),
        (None, Screen::Preview { plan, .. }) => run::preview_view(plan, status),
        (None, _) => menu_view(menu, status, settings, live),
    };
    if let Some(error) = menu.message() {
        v.lines[SCREEN_LINES - 1] = TextLine::new(format_args!("{}", ErrorText(error)), true);
    } else if let (RunState::Idle | RunState::Alarm, Some(fault)) = (status.state, status.fault) {
        v.lines[SCREEN_LINES - 1] = TextLine::new(format_args!("{}", FaultText(fault)), true);
    }
    v
}

/// The mode list, the forms, jog and settings.
fn menu_view(menu: &Menu, status: &Status, settings: &Settings, live: &Live) -> ScreenView {
    let mut lines: [TextLine; SCREEN_LINES] = Default::default();
    let [title, l1, l2, l3] = &mut lines;
    let mut title_text: String<SCREEN_COLUMNS> = String::new();
    let _ = match menu.screen() {
        Screen::Modes => Cut(&mut title_text).write_str("SERVOPLOT"),
        Screen::Jog | Screen::Presets(_) | Screen::Preview { .. } => {
            Cut(&mut title_text).write_str(menu.selected().title())
        }
        Screen::Settings(page) => write!(
            Cut(&mut title_text),
            "{} {}/{}",
            Text(Mode::Settings.title()),
            Int::from(page.index() + 1),
            Int::from(SETTING_INFO.len())
        ),
        Screen::Form(form) => {
            write!(
                Cut(&mut title_text),
                "{} {}/{}",
                Text(form.mode().title()),
                Int::from(form.field_index() + 1),
                Int::from(form.mode().fields().len())
            )
        }
    };
    let state = state_name(status);
    let pad = SCREEN_COLUMNS.saturating_sub(state.len());
    *title = TextLine::new(format_args!("{}{}", Padded::left(&title_text, pad), Text(state)), true);
    *l1 = position_line(status, settings, live.work_offset_mm);

    match menu.screen() {
        Screen::Modes => {
            let first = menu.selected().index().min(Mode::ALL.len() - 2);
            for (line, i) in [l2, l3].into_iter().zip(first..) {
                let mode = Mode::ALL[i];
                let marker = Text(if mode == menu.selected() { ">" } else { " " });
                *line = TextLine::new(format_args!("{marker}{} {}", Int::from(i + 1), Text(mode.label())), false);
            }
        }
        Screen::Jog => match menu.jog() {
            Some(jog) => {
                *l2 = TextLine::new(format_args!("Moving {}", Direction(jog.step)), false);
                *l3 = TextLine::plain("Release to stop");
            }
            None => {
                *l2 = TextLine::plain("2 +Y 8 -Y 4 -X 6 +X");
                *l3 = TextLine::plain("7 9 1 3 diagonal D back");
            }
        },
        Screen::Form(form) => match form.field() {
            Some(Field::Number(spec)) => {
                let entry = form.entry();
                let sign = Text(if entry.is_negative() { "-" } else { "" });
                *l2 = TextLine::new(
                    format_args!("{} {}: {sign}{}_", Text(spec.label), Text(spec.unit.symbol()), Text(entry.digits())),
                    false,
                );
                *l3 = TextLine::plain(spec.hint);
            }
            Some(Field::Preset) => match form.typed() {
                Some(typed) => {
                    // The end of the text, where it is typed.
                    let text = typed.text();
                    let shown = text.get(text.len().saturating_sub(SCREEN_COLUMNS - 3)..).unwrap_or(text);
                    *l2 = TextLine::new(format_args!("y={}_", Text(shown)), false);
                    *l3 = TextLine::new(format_args!("A>{} C put B del #", Text(typed.token())), false);
                }
                None => {
                    let p = form.preset();
                    *l2 =
                        TextLine::new(format_args!("f{} y={}", Int::from(p.index() + 1), Text(p.expression())), false);
                    *l3 = TextLine::plain("1-5/AB pick C type # ok");
                }
            },
            None => {}
        },
        Screen::Settings(page) => {
            let info = page.info();
            let unit = Text(info.unit.symbol());
            let gap = Text(if unit.0.is_empty() { "" } else { " " });
            *l1 = TextLine::new(format_args!("${} {}", Int::from(info.id), Text(info.name)), false);
            match page.edit() {
                Some(entry) => {
                    let sign = Text(if entry.is_negative() { "-" } else { "" });
                    *l2 = TextLine::new(format_args!("={sign}{}_{gap}{unit}", Text(entry.digits())), false);
                    *l3 = TextLine::plain(SETTING_EDIT_HINT);
                }
                None => {
                    let value = settings.get(info.id).unwrap_or(0.0);
                    *l2 = TextLine::new(format_args!("{}{gap}{unit}", Num(value)), false);
                    *l3 = TextLine::new(format_args!("{}..{} # edit", Num(info.min), Num(info.max)), false);
                }
            }
        }
        Screen::Presets(selected) => {
            let (feed, rate, accel) = selected.speeds();
            *l1 = TextLine::new(format_args!("F{} R{} A{}", Num(feed), Num(rate), Num(accel)), false);
            let first = selected.index().min(SpeedPreset::ALL.len() - 2);
            for (line, i) in [l2, l3].into_iter().zip(first..) {
                let preset = SpeedPreset::ALL[i];
                let marker = Text(if preset == *selected { ">" } else { " " });
                let set = Text(if preset.is_set(settings) { " *" } else { "" });
                *line = TextLine::new(format_args!("{marker}{} {}{set}", Int::from(i + 1), Text(preset.name())), false);
            }
        }
        Screen::Preview { .. } => {}
    }

    // The settings stay in view while the machine works (their keys wait for it).
    if menu.is_busy(status) && !matches!(menu.screen(), Screen::Settings(_)) {
        let (doing, keys) = match status.state {
            RunState::Hold => ("Held", "C resume  D abort"),
            RunState::Jog => ("Jogging", "D abort"),
            _ => ("Drawing", "C hold  D abort"),
        };
        // A drawing at another feed than programmed says so.
        let feed = status.overrides.feed_percent;
        let mut what: String<SCREEN_COLUMNS> = String::new();
        let _ = match status.state {
            RunState::Run if feed != OVERRIDE_NONE_PERCENT => {
                write!(Cut(&mut what), "{} F{}%", Text(doing), Int::from(feed))
            }
            _ => Cut(&mut what).write_str(doing),
        };
        lines[2] = match status.queued_jobs {
            0 => TextLine::plain(&what),
            n => TextLine::new(format_args!("{}, {} queued", Text(&what), Int::from(n)), false),
        };
        lines[3] = TextLine::plain(keys);
    }
    ScreenView { lines, preview: None }
}

/// Draws `view` over the whole screen; its preview shows `plan` (the menu's, see
/// [`Menu::plan`]) and `drawn`.
pub fn render<D>(view: &ScreenView, plan: Option<&Trail>, drawn: Option<&Trail>, target: &mut D) -> Result<(), D::Error>
where
    D: DrawTarget<Color = BinaryColor>,
{
    for (i, line) in view.lines.iter().enumerate() {
        let (fg, bg) =
            if line.inverted { (BinaryColor::Off, BinaryColor::On) } else { (BinaryColor::On, BinaryColor::Off) };
        let top = (i as u32 * SCREEN_LINE_HEIGHT_PX) as i32;
        let area = Rectangle::new(Point::new(0, top), Size::new(SCREEN_WIDTH_PX, SCREEN_LINE_HEIGHT_PX));
        target.fill_solid(&area, bg)?;
        // The 7-pixel glyphs sit on the line's last row: a row apart from the line above.
        glyphs::draw(target, &line.text, Point::new(SCREEN_MARGIN_PX as i32, top + 1), fg)?;
    }
    if let Some(p) = &view.preview {
        trail::draw(target, p.area, plan.filter(|_| p.plan), drawn, p.pen)?;
    }
    Ok(())
}

/// Draws the screen for the current menu and machine state: [`render`] of [`view`].
pub fn draw<D>(menu: &Menu, status: &Status, settings: &Settings, live: &Live, target: &mut D) -> Result<(), D::Error>
where
    D: DrawTarget<Color = BinaryColor>,
{
    render(&view(menu, status, settings, live), menu.plan().map(|p| &p.path), live.drawn, target)
}

/// A jog direction as `+X`, `-Y`, `+X+Y`, ...
struct Direction(Step);

impl fmt::Display for Direction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (v, axis) in [(self.0.x, 'X'), (self.0.y, 'Y')] {
            let sign = match v {
                1.. => '+',
                ..0 => '-',
                0 => continue,
            };
            f.write_char(sign)?;
            f.write_char(axis)?;
        }
        Ok(())
    }
}

struct ErrorText(UiError);

impl fmt::Display for ErrorText {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let text = match self.0 {
            UiError::Expression(e) => return write!(f, "Col {} {}", Int::from(e.pos + 1), Text(e.kind.message())),
            UiError::Entry(EntryError::TooLong) => return write!(f, "Max {} characters", Int::from(ENTRY_MAX_CHARS)),
            UiError::Entry(EntryError::NotANumber) => "Not a number",
            UiError::Empty => "Type a value",
            UiError::OutOfRange { min, max, unit } => {
                return write!(f, "Range {}..{} {}", Num(min), Num(max), Text(unit.symbol()));
            }
            UiError::Zero => "Must not be 0",
            UiError::SameEnds => "x1 must differ from x0",
            UiError::Drawing(DrawError::Travel) => "Beyond travel limits",
            UiError::Drawing(DrawError::TooSteep) => "too steep: A or 1/P",
            UiError::Drawing(DrawError::TooFine) => "Finer than a step",
            UiError::Drawing(DrawError::BadParameter) => "Bad parameter",
            UiError::Drawing(DrawError::Setup(_)) => "Cannot start here",
            UiError::Drawing(DrawError::Fails { error: CurveError::Jump, .. }) => "f(x) jumps too far",
            UiError::Drawing(DrawError::Fails { .. }) => "f(x) undefined there",
            UiError::Busy => "Busy: wait, or D abort",
            UiError::Alarm => "Alarm: motion locked",
            UiError::HomingOff => "Homing off: $22=1",
            UiError::Aborted => "Aborted",
            UiError::NotWhole => "Whole numbers only",
            UiError::Clash => "Clashes with $201 or $0",
        };
        f.write_str(text)
    }
}

/// Why the last job stopped early, as the screen says it.
struct FaultText(MotionFault);

impl fmt::Display for FaultText {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let why = match self.0 {
            MotionFault::Tripped(Trip::Limit { axis, max }) => {
                return write!(f, "Limit {}{}: $X", Text(axis.name()), Text(if max { "+" } else { "-" }));
            }
            MotionFault::Tripped(Trip::DriverAlarm(axis)) => return write!(f, "{} driver alarm", Text(axis.name())),
            MotionFault::Tripped(Trip::EStop) => "E-stop",
            MotionFault::Homing(HomingFail::Aborted) => return f.write_str("Homing aborted"),
            MotionFault::Homing(HomingFail::PullOff(axis) | HomingFail::Approach(axis)) => {
                return write!(f, "Homing {} failed", Text(axis.name()));
            }
            MotionFault::Curve(CurveError::Domain) => "f(x) undefined",
            MotionFault::Curve(CurveError::DivisionByZero) => "division by 0",
            MotionFault::Curve(CurveError::Overflow) => "value too large",
            MotionFault::Curve(CurveError::Jump) => "jump too large",
            MotionFault::Curve(CurveError::Travel) => "travel limit",
        };
        write!(f, "Stopped: {}", Text(why))
    }
}

#[cfg(test)]
mod tests;

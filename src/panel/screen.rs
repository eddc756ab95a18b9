//! What the 122x32 LCD shows, and drawing it on any monochrome embedded-graphics target.
//!
//! [`view`] turns the menu, the machine status and the settings, with what the LCD task adds
//! ([`Live`]: the clock, the pen's speed, the work offset, the path drawn), into a
//! [`ScreenView`]: four text lines of [`SCREEN_COLUMNS`] columns in the 5x7 font (whose
//! decimal point is a dot; the 5x8 font's is a cross, and "0.000" read "0+000") and, in 中文,
//! 7x7 Chinese glyphs two columns wide, every text in the language of the settings
//! ([`texts`](crate::panel::texts)); a splash at power-up; the title line
//! inverted, an error (if any) inverted on the bottom line, and where a path is shown, its
//! [`PreviewBox`]. The view is small and compares cheaply, so the LCD task redraws only when it
//! changes. [`render`] draws a whole view: every line's full width is cleared before its text is
//! drawn, and the preview's box before its path, so no pixel of an earlier frame survives (no
//! stale digits), and nothing is drawn outside [`SCREEN_WIDTH_PX`] x
//! [`SCREEN_HEIGHT_PX`](crate::panel::layout::SCREEN_HEIGHT_PX).
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

use crate::card::{CardPicture, CardProgress};
use crate::decimal::{Int, Num};
use crate::geom::Step;
use crate::machine_io::homing::HomingFail;
use crate::machine_io::inputs::Trip;
use crate::motion::interp::CurveError;
use crate::motion::overrides::OVERRIDE_NONE_PERCENT;
use crate::panel::entry::{ENTRY_MAX_CHARS, EntryError};
use crate::panel::glyphs;
use crate::panel::language::Language;
use crate::panel::layout::{SCREEN_COLUMNS, SCREEN_LINE_HEIGHT_PX, SCREEN_LINES, SCREEN_MARGIN_PX, SCREEN_WIDTH_PX};
use crate::panel::menu::{Field, Menu, Mode, Screen, UiError};
use crate::panel::texts::{Msg, SETTING_NAMES, Say};
use crate::panel::trail::{self, Trail};
use crate::program::preview;
use crate::settings::SETTING_INFO;
use crate::settings::Settings;
use crate::settings::presets::SpeedPreset;
use crate::status::{MotionFault, RunState, Status};
use crate::text::{Padded, Text};

mod card;
mod lines;
mod run;

pub use lines::{CardMark, Live, PreviewBox, ScreenView, TextLine};
use lines::{Cut, position_line, state_name};

/// The digits of the mode list's first ten modes, in order.
const DIGITS: &str = "1234567890";

/// How long the splash stays at power-up, unless a key is pressed first.
pub const SPLASH_MS: u32 = 2_000;

/// The screen for the current menu and machine state.
pub fn view(menu: &Menu, status: &Status, settings: &Settings, live: &Live) -> ScreenView {
    let language = settings.language;
    let mut v = match (menu.run(), menu.screen()) {
        (Some(r), _) => run::run_view(menu, r, status, settings, live),
        (None, _) if let CardProgress::Offer(offer) = menu.card_progress() => card::offer_view(&offer, language),
        (None, Screen::Splash) if live.now_ms < SPLASH_MS => splash_view(language),
        (None, Screen::Preview { plan, .. }) => run::preview_view(plan, status, language),
        (None, Screen::Card(_)) if let CardProgress::Checked(facts) = menu.card_progress() => {
            let name = menu.card_choice().map(|f| f.name);
            card::checked_view(name.as_ref().map_or("", |n| n.as_str()), &facts, language)
        }
        (None, _) => menu_view(menu, status, settings, live),
    };
    if let Some(refused @ UiError::CardLine { error, .. }) = menu.message() {
        // A card file's line refused: its number and error, and why in words below.
        v.lines[SCREEN_LINES - 2] = TextLine::new(format_args!("{}", ErrorText(refused, language)), true);
        v.lines[SCREEN_LINES - 1] = TextLine::new(format_args!("{}", Say(Msg::from(error), language)), true);
    } else if let Some(error) = menu.message() {
        v.lines[SCREEN_LINES - 1] = TextLine::new(format_args!("{}", ErrorText(error, language)), true);
    } else if let (RunState::Idle | RunState::Alarm, Some(fault)) = (status.state, status.fault) {
        v.lines[SCREEN_LINES - 1] = TextLine::new(format_args!("{}", FaultText(fault, language)), true);
    } else if status.state == RunState::Alarm {
        // Locked with no fault to tell (at power-on with homing on): how to unlock.
        let how = if settings.homing { Msg::LockedHome } else { Msg::LockedUnlock };
        v.lines[SCREEN_LINES - 1] = TextLine::new(format_args!("{}", Say(how, language)), true);
    }
    v
}

/// At power-up: the name and version, and the key that switches the language.
fn splash_view(language: Language) -> ScreenView {
    ScreenView {
        lines: [
            TextLine { inverted: true, ..TextLine::plain(concat!("SERVOPLOT ", env!("CARGO_PKG_VERSION"))) },
            TextLine::say(Msg::SplashName, language),
            TextLine::say(Msg::SplashLanguage, language),
            TextLine::say(Msg::SplashKeys, language),
        ],
        preview: None,
    }
}

/// The mode list, the forms, jog and settings.
fn menu_view(menu: &Menu, status: &Status, settings: &Settings, live: &Live) -> ScreenView {
    let language = settings.language;
    let say = |msg| Say(msg, language);
    let mut lines: [TextLine; SCREEN_LINES] = Default::default();
    let [title, l1, l2, l3] = &mut lines;
    let mut title_text: String<SCREEN_COLUMNS> = String::new();
    let _ = match menu.screen() {
        Screen::Splash | Screen::Modes => Cut(&mut title_text).write_str("SERVOPLOT"),
        Screen::Jog | Screen::Presets(_) | Screen::Preview { .. } | Screen::Card(_) => {
            write!(Cut(&mut title_text), "{}", say(menu.selected().title()))
        }
        Screen::Settings(page) => write!(
            Cut(&mut title_text),
            "{} {}/{}",
            say(Mode::Settings.title()),
            Int::from(page.index() + 1),
            Int::from(SETTING_INFO.len())
        ),
        Screen::Form(form) => {
            write!(
                Cut(&mut title_text),
                "{} {}/{}",
                say(form.mode().title()),
                Int::from(form.field_index() + 1),
                Int::from(form.mode().fields().len())
            )
        }
    };
    let state = say(state_name(status));
    let pad = SCREEN_COLUMNS.saturating_sub(state.columns());
    *title = TextLine::new(format_args!("{}{state}", Padded::left(&title_text, pad)), true);
    *l1 = position_line(status, settings, live.work_offset_mm);

    match menu.screen() {
        Screen::Splash | Screen::Modes => {
            let first = menu.selected().index().min(Mode::ALL.len() - 2);
            for (line, i) in [l2, l3].into_iter().zip(first..) {
                let mode = Mode::ALL[i];
                let marker = Text(if mode == menu.selected() { ">" } else { " " });
                // Only the first ten have a digit.
                let digit = Text(DIGITS.get(i..=i).unwrap_or(" "));
                *line = TextLine::new(format_args!("{marker}{digit} {}", say(mode.label())), false);
            }
        }
        Screen::Jog => match (menu.jog(), status.state) {
            (Some(jog), _) => {
                *l2 = TextLine::new(format_args!("{} {}", say(Msg::JogMoving), Direction(jog.step)), false);
                *l3 = TextLine::say(Msg::JogRelease, language);
            }
            // Released: the machine slows to a stop, as the title's JOG says.
            (None, RunState::Jog) => {
                *l2 = TextLine::say(Msg::JogStopping, language);
                *l3 = TextLine::say(Msg::KeysAbort, language);
            }
            (None, _) => {
                *l2 = TextLine::plain("2 +Y 8 -Y 4 -X 6 +X");
                *l3 = TextLine::say(Msg::JogKeys, language);
            }
        },
        Screen::Form(form) => match form.field() {
            Some(Field::Number(spec)) => {
                let entry = form.entry();
                let sign = Text(if entry.is_negative() { "-" } else { "" });
                *l2 = TextLine::new(
                    format_args!("{} {}: {sign}{}_", say(spec.label), Text(spec.unit.symbol()), Text(entry.digits())),
                    false,
                );
                *l3 = TextLine::say(spec.hint, language);
            }
            Some(Field::Preset) => match form.typed() {
                Some(typed) => {
                    // The end of the text, where it is typed.
                    let text = typed.text();
                    let shown = text.get(text.len().saturating_sub(SCREEN_COLUMNS - 3)..).unwrap_or(text);
                    *l2 = TextLine::new(format_args!("y={}_", Text(shown)), false);
                    *l3 = TextLine::new(format_args!("A<{}>B {}", Text(typed.token()), say(Msg::KeysTyping)), false);
                }
                None => {
                    let p = form.preset();
                    *l2 =
                        TextLine::new(format_args!("f{} y={}", Int::from(p.index() + 1), Text(p.expression())), false);
                    *l3 = TextLine::say(Msg::KeysPreset, language);
                }
            },
            None => {}
        },
        Screen::Settings(page) => {
            let info = page.info();
            let unit = Text(info.unit.symbol());
            let gap = Text(if unit.0.is_empty() { "" } else { " " });
            let name = say(SETTING_NAMES.get(page.index()).copied().unwrap_or(Msg::TitleSettings));
            *l1 = TextLine::new(format_args!("${} {name}", Int::from(info.id)), false);
            match page.edit() {
                Some(entry) => {
                    let sign = Text(if entry.is_negative() { "-" } else { "" });
                    *l2 = TextLine::new(format_args!("={sign}{}_{gap}{unit}", Text(entry.digits())), false);
                    *l3 = TextLine::say(Msg::KeysSet, language);
                }
                None => {
                    let value = settings.get(info.id).unwrap_or(0.0);
                    *l2 = TextLine::new(format_args!("{}{gap}{unit}", Num(value)), false);
                    *l3 = TextLine::new(
                        format_args!("{}..{} {}", Num(info.min), Num(info.max), say(Msg::KeysEdit)),
                        false,
                    );
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
                let name = say(preset_name(preset));
                *line = TextLine::new(format_args!("{marker}{} {name}{set}", Int::from(i + 1)), false);
            }
        }
        Screen::Preview { .. } => {}
        Screen::Card(list) => {
            let [said, keys] = match menu.card_progress() {
                CardProgress::Checking { lines } => card::checking_lines(lines, language),
                _ => card::card_lines(list, language),
            };
            (*l2, *l3) = (said, keys);
        }
    }

    // The settings stay in view while the machine works (their keys wait for it).
    if menu.is_busy(status) && !matches!(menu.screen(), Screen::Settings(_)) {
        let (doing, keys) = match status.state {
            RunState::Hold => (Msg::BusyHeld, Msg::KeysHeld),
            RunState::Jog => (Msg::BusyJogging, Msg::KeysAbort),
            RunState::Home => (Msg::BusyHoming, Msg::KeysAbort),
            _ => (Msg::BusyDrawing, Msg::KeysDrawing),
        };
        // A drawing at another feed than programmed says so.
        let feed = status.overrides.feed_percent;
        let mut what: String<SCREEN_COLUMNS> = String::new();
        let _ = match status.state {
            RunState::Run if feed != OVERRIDE_NONE_PERCENT => {
                write!(Cut(&mut what), "{} F{}%", say(doing), Int::from(feed))
            }
            _ => write!(Cut(&mut what), "{}", say(doing)),
        };
        lines[2] = match status.queued_jobs {
            0 => TextLine::plain(&what),
            n => TextLine::new(format_args!("{}, {} {}", Text(&what), Int::from(n), say(Msg::Queued)), false),
        };
        lines[3] = TextLine::say(keys, language);
    }
    ScreenView { lines, preview: None }
}

/// A speed preset's name on the presets screen.
const fn preset_name(preset: SpeedPreset) -> Msg {
    match preset {
        SpeedPreset::FinePen => Msg::PresetFinePen,
        SpeedPreset::FeltTip => Msg::PresetFeltTip,
        SpeedPreset::FastDraft => Msg::PresetFastDraft,
    }
}

/// Draws `view` over the whole screen; its preview shows `plan` (the menu's, see
/// [`Menu::plan`]) and `drawn`.
pub fn render<D>(
    view: &ScreenView,
    plan: Option<&Trail>,
    drawn: Option<&Trail>,
    picture: Option<&CardPicture>,
    target: &mut D,
) -> Result<(), D::Error>
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
    match (&view.preview, picture) {
        // The picture's pixels are the screen's: the lines above cleared them.
        (Some(PreviewBox { card: Some(_), .. }), Some(picture)) => {
            let (strokes, progress) = (&picture.strokes, picture.progress.as_ref());
            preview::draw(target, Point::zero(), &picture.scale, strokes, progress)?;
        }
        (Some(p), _) => trail::draw(target, p.area, plan.filter(|_| p.plan), drawn, p.pen)?,
        (None, _) => {}
    }
    Ok(())
}

/// Draws the screen for the current menu and machine state: [`render`] of [`view`].
pub fn draw<D>(menu: &Menu, status: &Status, settings: &Settings, live: &Live, target: &mut D) -> Result<(), D::Error>
where
    D: DrawTarget<Color = BinaryColor>,
{
    render(&view(menu, status, settings, live), menu.plan().map(|p| &p.path), live.drawn, live.picture, target)
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

struct ErrorText(UiError, Language);

impl fmt::Display for ErrorText {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let say = |msg| Say(msg, self.1);
        let msg = match self.0 {
            UiError::Expression(e) => {
                let why = say(Msg::from(e.kind));
                return write!(f, "{} {} {why}", say(Msg::ErrColumn), Int::from(e.pos + 1));
            }
            UiError::Entry(EntryError::TooLong) => {
                return write!(f, "{} {} {}", say(Msg::ErrMax), Int::from(ENTRY_MAX_CHARS), say(Msg::ErrCharacters));
            }
            UiError::Entry(EntryError::NotANumber) => Msg::ErrNotNumber,
            UiError::Empty => Msg::ErrEmpty,
            UiError::OutOfRange { min, max, unit } => {
                return write!(f, "{} {}..{} {}", say(Msg::ErrRange), Num(min), Num(max), Text(unit.symbol()));
            }
            UiError::Zero => Msg::ErrZero,
            UiError::SameEnds => Msg::ErrSameEnds,
            UiError::Drawing(e) => Msg::from(e),
            UiError::Busy => Msg::ErrBusy,
            UiError::Alarm => Msg::ErrAlarm,
            UiError::HomingOff => Msg::ErrHomingOff,
            UiError::Aborted => Msg::ErrAborted,
            UiError::NotWhole => Msg::ErrWhole,
            UiError::Clash { with, .. } => return write!(f, "{} ${}", say(Msg::ErrClash), Int::from(with)),
            UiError::StrandsPen { .. } => Msg::ErrStrands,
            UiError::UndefinedAtStart(e) => return write!(f, "{} {}", say(Msg::ErrAtX0), say(Msg::from(e))),
            UiError::Card(e) => card::card_error_text(e),
            UiError::CardLine { line, error } => {
                return write!(f, "{} {}: error:{}", say(Msg::CardLine), Int::from(line), Int::from(error.code()));
            }
        };
        write!(f, "{}", say(msg))
    }
}

/// Why the last job stopped early, as the screen says it.
struct FaultText(MotionFault, Language);

impl fmt::Display for FaultText {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let say = |msg| Say(msg, self.1);
        let why = match self.0 {
            MotionFault::Tripped(Trip::Limit { axis, max }) => {
                let end = Text(if max { "+" } else { "-" });
                return write!(f, "{} {}{end}: $X", say(Msg::FaultLimit), Text(axis.name()));
            }
            MotionFault::Tripped(Trip::DriverAlarm(axis)) => {
                return write!(f, "{} {}", Text(axis.name()), say(Msg::FaultDriver));
            }
            MotionFault::Tripped(Trip::EStop) => Msg::FaultEstop,
            MotionFault::Tripped(Trip::MissedUpdate) => Msg::FaultMissedUpdate,
            MotionFault::Homing(HomingFail::Aborted) => return write!(f, "{}", say(Msg::FaultHomingAborted)),
            MotionFault::Homing(HomingFail::PullOff(axis) | HomingFail::Approach(axis)) => {
                return write!(f, "{} {} {}", say(Msg::FaultHoming), Text(axis.name()), say(Msg::FaultFailed));
            }
            MotionFault::Curve(CurveError::Domain) => Msg::FaultUndefined,
            MotionFault::Curve(CurveError::DivisionByZero) => Msg::FaultDivision,
            MotionFault::Curve(CurveError::Overflow) => Msg::FaultOverflow,
            MotionFault::Curve(CurveError::Jump) => Msg::FaultJump,
            MotionFault::Curve(CurveError::Aliased) => Msg::ErrFine,
            MotionFault::Curve(CurveError::Travel) => Msg::FaultTravel,
            MotionFault::CardLost => return write!(f, "{}", say(Msg::FaultCardLost)),
        };
        write!(f, "{}: {}", say(Msg::FaultStopped), say(why))
    }
}

#[cfg(test)]
mod tests;

//! What the 122x32 LCD shows, and drawing it on any monochrome embedded-graphics target.
//!
//! [`view`] turns the menu, the machine status and the settings into a [`ScreenView`]: four
//! text lines of [`SCREEN_COLUMNS`] characters in the 5x7 font (whose decimal point is a dot; the
//! 5x8 font's is a cross, and "0.000" read "0+000"), the title line inverted, an
//! error (if any) inverted on the bottom line. The view is small and compares cheaply, so the LCD
//! task redraws only when it changes. [`render`] draws a whole view: every line's full width is
//! cleared before its text is drawn, so no pixel of an earlier frame survives (no stale digits),
//! and nothing is drawn outside [`SCREEN_WIDTH_PX`] x
//! [`SCREEN_HEIGHT_PX`](crate::ui::layout::SCREEN_HEIGHT_PX).
//!
//! Layout:
//!
//! ```text
//! LINE 1/2            IDLE    title and run state (inverted)
//! X  12.345 Y  -3.000         pen position, mm (inverted until homed)
//! dX mm: -12.5_               field being typed, with its unit
//! X offset from the pen       help, or the error (inverted)
//! ```

use core::fmt::{self, Write};

use embedded_graphics::Drawable;
use embedded_graphics::draw_target::DrawTarget;
use embedded_graphics::geometry::{Point, Size};
use embedded_graphics::mono_font::MonoTextStyle;
use embedded_graphics::mono_font::ascii::FONT_5X7;
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_graphics::primitives::Rectangle;
use embedded_graphics::text::{Baseline, Text};
use heapless::String;

use crate::decimal::Int;
use crate::drawing::DrawError;
use crate::geom::{Axis, Step};
use crate::homing::HomingFail;
use crate::inputs::Trip;
use crate::interp::{CurveError, Method};
use crate::job::JOG_FEED_MM_PER_MIN;
use crate::overrides::OVERRIDE_NONE_PERCENT;
use crate::settings::Settings;
use crate::status::{MotionFault, RunState, Status};
use crate::ui::entry::{ENTRY_MAX_CHARS, EntryError};
use crate::ui::layout::{SCREEN_COLUMNS, SCREEN_LINE_HEIGHT_PX, SCREEN_LINES, SCREEN_MARGIN_PX, SCREEN_WIDTH_PX};
use crate::ui::menu::{Field, Menu, Mode, Screen, UiError};

/// Widest position value shown (`-500.000`, or fewer decimals for larger values).
const POSITION_CHARS: usize = 9;

/// One line of text; longer text is cut at [`SCREEN_COLUMNS`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct TextLine {
    pub text: String<SCREEN_COLUMNS>,
    /// Light text on a dark bar.
    pub inverted: bool,
}

impl TextLine {
    fn new(args: fmt::Arguments, inverted: bool) -> Self {
        let mut line = TextLine { text: String::new(), inverted };
        let _ = Cut(&mut line.text).write_fmt(args);
        line
    }
}

/// Everything the screen shows; equal views draw identical frames.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ScreenView {
    pub lines: [TextLine; SCREEN_LINES],
}

/// Writes into a fixed string, silently cutting what does not fit.
struct Cut<'a, const N: usize>(&'a mut String<N>);

impl<const N: usize> Write for Cut<'_, N> {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        for c in s.chars() {
            if self.0.push(c).is_err() {
                break;
            }
        }
        Ok(())
    }
}

/// The screen for the current menu and machine state.
pub fn view(menu: &Menu, status: &Status, settings: &Settings) -> ScreenView {
    let mut lines: [TextLine; SCREEN_LINES] = Default::default();
    let [title, l1, l2, l3] = &mut lines;
    let mut title_text: String<SCREEN_COLUMNS> = String::new();
    let _ = match menu.screen() {
        Screen::Modes => Cut(&mut title_text).write_str("SERVOPLOT"),
        Screen::Jog | Screen::Settings { .. } => Cut(&mut title_text).write_str(menu.selected().title()),
        Screen::Form(form) => {
            write!(
                Cut(&mut title_text),
                "{} {}/{}",
                form.mode().title(),
                Int::from(form.field_index() + 1),
                Int::from(form.mode().fields().len())
            )
        }
    };
    let state = state_name(status);
    let pad = SCREEN_COLUMNS.saturating_sub(state.len());
    *title = TextLine::new(format_args!("{:<pad$}{}", title_text.as_str(), state), true);
    *l1 = position_line(status, settings);

    match menu.screen() {
        Screen::Modes => {
            let first = menu.selected().index().min(Mode::ALL.len() - 2);
            for (line, i) in [l2, l3].into_iter().zip(first..) {
                let mode = Mode::ALL[i];
                let marker = if mode == menu.selected() { ">" } else { " " };
                *line = TextLine::new(format_args!("{marker}{} {}", Int::from(i + 1), mode.label()), false);
            }
        }
        Screen::Jog => match menu.jog() {
            Some(jog) => {
                *l2 = TextLine::new(format_args!("Moving {}", Direction(jog.step)), false);
                *l3 = TextLine::new(format_args!("Release to stop"), false);
            }
            None => {
                *l2 = TextLine::new(format_args!("2 +Y 8 -Y 4 -X 6 +X"), false);
                *l3 = TextLine::new(format_args!("7 9 1 3 diagonal D back"), false);
            }
        },
        Screen::Form(form) => match form.field() {
            Some(Field::Number(spec)) => {
                let entry = form.entry();
                let sign = if entry.is_negative() { "-" } else { "" };
                *l2 = TextLine::new(
                    format_args!("{} {}: {sign}{}_", spec.label, spec.unit.symbol(), entry.digits()),
                    false,
                );
                *l3 = TextLine::new(format_args!("{}", spec.hint), false);
            }
            Some(Field::Preset) => {
                let p = form.preset();
                *l2 = TextLine::new(format_args!("f{} y={}", Int::from(p.index() + 1), p.expression()), false);
                *l3 = TextLine::new(format_args!("1-5 or A/B pick, # ok"), false);
            }
            None => {}
        },
        Screen::Settings { first_line } => {
            for (line, i) in [l1, l2, l3].into_iter().zip(*first_line..) {
                *line = settings_line(i, settings);
            }
        }
    }

    if menu.is_busy(status) && !matches!(menu.screen(), Screen::Settings { .. }) {
        let (doing, keys) = match status.state {
            RunState::Hold => ("Held", "C resume  D abort"),
            RunState::Jog => ("Jogging", "D abort"),
            _ => ("Drawing", "C hold  D abort"),
        };
        // A drawing at another feed than programmed says so.
        let feed = status.overrides.feed_percent;
        let mut what: String<SCREEN_COLUMNS> = String::new();
        let _ = match status.state {
            RunState::Run if feed != OVERRIDE_NONE_PERCENT => write!(Cut(&mut what), "{doing} F{}%", Int::from(feed)),
            _ => Cut(&mut what).write_str(doing),
        };
        lines[2] = match status.queued_jobs {
            0 => TextLine::new(format_args!("{what}"), false),
            n => TextLine::new(format_args!("{what}, {} queued", Int::from(n)), false),
        };
        lines[3] = TextLine::new(format_args!("{keys}"), false);
    }
    if let Some(error) = menu.message() {
        lines[SCREEN_LINES - 1] = TextLine::new(format_args!("{}", ErrorText(error)), true);
    } else if let (RunState::Idle | RunState::Alarm, Some(fault)) = (status.state, status.fault) {
        lines[SCREEN_LINES - 1] = TextLine::new(format_args!("{}", FaultText(fault)), true);
    }
    ScreenView { lines }
}

/// Draws `view` over the whole screen.
pub fn render<D>(view: &ScreenView, target: &mut D) -> Result<(), D::Error>
where
    D: DrawTarget<Color = BinaryColor>,
{
    for (i, line) in view.lines.iter().enumerate() {
        let (fg, bg) =
            if line.inverted { (BinaryColor::Off, BinaryColor::On) } else { (BinaryColor::On, BinaryColor::Off) };
        let top = (i as u32 * SCREEN_LINE_HEIGHT_PX) as i32;
        let area = Rectangle::new(Point::new(0, top), Size::new(SCREEN_WIDTH_PX, SCREEN_LINE_HEIGHT_PX));
        target.fill_solid(&area, bg)?;
        let style = MonoTextStyle::new(&FONT_5X7, fg);
        // The 7-pixel glyphs sit on the line's last row: a row apart from the line above.
        let at = Point::new(SCREEN_MARGIN_PX as i32, top + 1);
        Text::with_baseline(&line.text, at, style, Baseline::Top).draw(target)?;
    }
    Ok(())
}

/// Draws the screen for the current menu and machine state: [`render`] of [`view`].
pub fn draw<D>(menu: &Menu, status: &Status, settings: &Settings, target: &mut D) -> Result<(), D::Error>
where
    D: DrawTarget<Color = BinaryColor>,
{
    render(&view(menu, status, settings), target)
}

fn state_name(status: &Status) -> &'static str {
    match status.state {
        RunState::Idle => "IDLE",
        RunState::Run => "RUN",
        RunState::Hold if status.door => "DOOR",
        RunState::Hold => "HOLD",
        RunState::Jog => "JOG",
        RunState::Alarm => "ALARM",
        RunState::Check => "CHECK",
        RunState::Sleep => "SLEEP",
        RunState::Home => "HOME",
    }
}

fn position_line(status: &Status, settings: &Settings) -> TextLine {
    let x = mm_text(settings.steps_to_mm(Axis::X, status.position.x));
    let y = mm_text(settings.steps_to_mm(Axis::Y, status.position.y));
    // Inverted while the position may be wrong: until homed.
    let line = format_args!("X{:>w$} Y{:>w$}", x.as_str(), y.as_str(), w = POSITION_CHARS);
    TextLine::new(line, status.position_lost)
}

/// `mm` with 3 decimals, or fewer when it would not fit [`POSITION_CHARS`].
fn mm_text(mm: f32) -> String<POSITION_CHARS> {
    let mut s = String::new();
    for decimals in [3, 1, 0] {
        s.clear();
        if crate::decimal::write_fixed(&mut s, mm, decimals).is_ok() {
            return s;
        }
    }
    s.clear();
    let _ = s.push_str("-----");
    s
}

fn settings_line(i: usize, s: &Settings) -> TextLine {
    let line = |args| TextLine::new(args, false);
    match i {
        0 => line(format_args!("Steps/mm X{} Y{}", Num(s.steps_per_mm[0]), Num(s.steps_per_mm[1]))),
        1 => line(format_args!("Travel mm X{} Y{}", Num(s.max_travel_mm[0]), Num(s.max_travel_mm[1]))),
        2 => line(format_args!("Feed {} mm/min", Num(s.default_feed_mm_per_min))),
        3 => line(format_args!("Start {} mm/min", Num(s.start_rate_mm_per_min))),
        4 => line(format_args!("Jog {} mm/min", Num(JOG_FEED_MM_PER_MIN))),
        5 => line(format_args!("Pulse max {} Hz", Num(s.max_pulse_rate_hz))),
        6 => line(format_args!(
            "Interpolation {}",
            match s.method {
                Method::Classic => "classic",
                Method::Diagonal => "diagonal",
            }
        )),
        _ => TextLine::default(),
    }
}

/// A setting's value as the screen shows it: up to three decimals, trailing zeros left off.
struct Num(f32);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        crate::decimal::write_trimmed(f, self.0, 0, 3)
    }
}

/// A jog direction as `+X`, `-Y`, `+X+Y`, ...
struct Direction(Step);

impl fmt::Display for Direction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (v, axis) in [(self.0.x, "X"), (self.0.y, "Y")] {
            match v {
                1.. => write!(f, "+{axis}")?,
                ..0 => write!(f, "-{axis}")?,
                0 => {}
            }
        }
        Ok(())
    }
}

struct ErrorText(UiError);

impl fmt::Display for ErrorText {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            UiError::Entry(EntryError::TooLong) => write!(f, "Max {} characters", Int::from(ENTRY_MAX_CHARS)),
            UiError::Entry(EntryError::NotANumber) => f.write_str("Not a number"),
            UiError::Empty => f.write_str("Type a value"),
            UiError::OutOfRange { min, max, unit } => write!(f, "Range {}..{} {}", Num(min), Num(max), unit.symbol()),
            UiError::Zero => f.write_str("Must not be 0"),
            UiError::SameEnds => f.write_str("x1 must differ from x0"),
            UiError::Drawing(DrawError::Travel) => f.write_str("Beyond travel limits"),
            UiError::Drawing(DrawError::TooSteep) => f.write_str("too steep: A or 1/P"),
            UiError::Drawing(DrawError::TooFine) => f.write_str("Finer than a step"),
            UiError::Drawing(DrawError::BadParameter) => f.write_str("Bad parameter"),
            UiError::Drawing(DrawError::Setup(_)) => f.write_str("Cannot start here"),
            UiError::Drawing(DrawError::Fails { error: CurveError::Jump, .. }) => f.write_str("f(x) jumps too far"),
            UiError::Drawing(DrawError::Fails { .. }) => f.write_str("f(x) undefined there"),
            UiError::Busy => f.write_str("Busy: wait, or D abort"),
            UiError::Alarm => f.write_str("Alarm: motion locked"),
            UiError::HomingOff => f.write_str("Homing off: $22=1"),
            UiError::Aborted => f.write_str("Aborted"),
        }
    }
}

/// Why the last job stopped early, as the screen says it.
struct FaultText(MotionFault);

impl fmt::Display for FaultText {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let why = match self.0 {
            MotionFault::Tripped(Trip::Limit { axis, max }) => {
                return write!(f, "Limit {}{}: $X", axis.name(), if max { "+" } else { "-" });
            }
            MotionFault::Tripped(Trip::DriverAlarm(axis)) => return write!(f, "{} driver alarm", axis.name()),
            MotionFault::Tripped(Trip::EStop) => "E-stop",
            MotionFault::Homing(HomingFail::Aborted) => return f.write_str("Homing aborted"),
            MotionFault::Homing(HomingFail::PullOff(axis) | HomingFail::Approach(axis)) => {
                return write!(f, "Homing {} failed", axis.name());
            }
            MotionFault::Curve(CurveError::Domain) => "f(x) undefined",
            MotionFault::Curve(CurveError::DivisionByZero) => "division by 0",
            MotionFault::Curve(CurveError::Overflow) => "value too large",
            MotionFault::Curve(CurveError::Jump) => "jump too large",
            MotionFault::Curve(CurveError::Travel) => "travel limit",
        };
        write!(f, "Stopped: {why}")
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::keypad::{Key, KeyEvent};
    use crate::overrides::Overrides;
    use crate::ui::layout::SCREEN_HEIGHT_PX;
    use core::convert::Infallible;
    use embedded_graphics::Pixel;
    use embedded_graphics::geometry::OriginDimensions;

    const W: usize = SCREEN_WIDTH_PX as usize;
    const H: usize = SCREEN_HEIGHT_PX as usize;

    /// An in-memory 122x32 frame that counts pixels drawn outside it.
    #[derive(Clone, PartialEq)]
    struct Frame {
        px: [[bool; W]; H],
        outside: usize,
    }

    impl Frame {
        fn filled(on: bool) -> Self {
            Frame { px: [[on; W]; H], outside: 0 }
        }

        fn lit_in_rows(&self, rows: core::ops::Range<usize>) -> usize {
            self.px[rows].iter().flatten().filter(|&&p| p).count()
        }
    }

    impl core::fmt::Debug for Frame {
        fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
            for row in &self.px {
                let s: std::string::String = row.iter().map(|&p| if p { '#' } else { '.' }).collect();
                writeln!(f, "{s}")?;
            }
            write!(f, "outside: {}", self.outside)
        }
    }

    impl OriginDimensions for Frame {
        fn size(&self) -> Size {
            Size::new(SCREEN_WIDTH_PX, SCREEN_HEIGHT_PX)
        }
    }

    impl DrawTarget for Frame {
        type Color = BinaryColor;
        type Error = Infallible;

        fn draw_iter<I: IntoIterator<Item = Pixel<BinaryColor>>>(&mut self, pixels: I) -> Result<(), Infallible> {
            for Pixel(p, c) in pixels {
                match (usize::try_from(p.x), usize::try_from(p.y)) {
                    (Ok(x), Ok(y)) if x < W && y < H => self.px[y][x] = c.is_on(),
                    _ => self.outside += 1,
                }
            }
            Ok(())
        }
    }

    fn press(menu: &mut Menu, keys: &str, status: &Status) {
        for c in keys.chars().filter(|c| !c.is_whitespace()) {
            let key = match c {
                '0'..='9' => Key::Digit(c as u8 - b'0'),
                'A' => Key::A,
                'B' => Key::B,
                'C' => Key::C,
                'D' => Key::D,
                '*' => Key::Star,
                _ => Key::Hash,
            };
            menu.handle(KeyEvent::Press(key), status, &Settings::default());
        }
    }

    fn texts(v: &ScreenView) -> [&str; SCREEN_LINES] {
        [v.lines[0].text.as_str(), v.lines[1].text.as_str(), v.lines[2].text.as_str(), v.lines[3].text.as_str()]
    }

    fn fresh(menu: &Menu, status: &Status) -> Frame {
        let mut f = Frame::filled(false);
        draw(menu, status, &Settings::default(), &mut f).unwrap();
        f
    }

    #[test]
    fn form_screen_shows_title_position_field_and_help() {
        let mut m = Menu::new();
        press(&mut m, "2 A12*5", &Status::default());
        let status = Status { position: crate::geom::Point::new(1234, -300), ..Status::default() };
        let v = view(&m, &status, &Settings::default());
        // The state sits at the right end of the title line.
        let title = std::format!("{:<20}IDLE", "LINE 1/2");
        assert_eq!(texts(&v), [title.as_str(), "X   12.340 Y   -3.000", "dX mm: -12.5_", "X offset from the pen"]);
        assert!(v.lines[0].inverted && !v.lines[3].inverted);
        assert!(!v.lines[1].inverted, "the position is known");
        let lost = Status { position_lost: true, ..status };
        assert!(view(&m, &lost, &Settings::default()).lines[1].inverted, "until homed, the position shows inverted");
    }

    #[test]
    fn errors_replace_the_help_line_until_the_next_key() {
        let mut m = Menu::new();
        press(&mut m, "2 2000#", &Status::default());
        let v = view(&m, &Status::default(), &Settings::default());
        assert_eq!(v.lines[3].text.as_str(), "Range -1000..1000 mm");
        assert!(v.lines[3].inverted);
        assert_eq!(v.lines[2].text.as_str(), "dX mm: 2000_", "the value stays for correction");
        press(&mut m, "B", &Status::default());
        let v = view(&m, &Status::default(), &Settings::default());
        assert_eq!(v.lines[3].text.as_str(), "X offset from the pen");
    }

    #[test]
    fn running_shows_what_c_and_d_do() {
        let mut m = Menu::new();
        press(&mut m, "2", &Status::default());
        let status = Status { state: RunState::Run, queued_jobs: 2, ..Status::default() };
        let v = view(&m, &status, &Settings::default());
        assert_eq!(texts(&v)[0], std::format!("{:<21}RUN", "LINE 1/2"));
        assert_eq!(texts(&v)[2..], ["Drawing, 2 queued", "C hold  D abort"]);
        let v = view(&m, &Status { state: RunState::Hold, ..Status::default() }, &Settings::default());
        assert_eq!(texts(&v)[2..], ["Held", "C resume  D abort"]);
    }

    #[test]
    fn a_drawing_shows_the_feed_override_when_it_is_not_100_percent() {
        let mut m = Menu::new();
        press(&mut m, "2", &Status::default());
        let slower = Overrides { feed_percent: 90, ..Overrides::NONE };
        let status = Status { state: RunState::Run, queued_jobs: 2, overrides: slower, ..Status::default() };
        assert_eq!(texts(&view(&m, &status, &Settings::default()))[2], "Drawing F90%, 2 queued");
        let fastest = Overrides { feed_percent: 200, ..Overrides::NONE };
        let status = Status { state: RunState::Run, queued_jobs: 4, overrides: fastest, ..Status::default() };
        assert_eq!(texts(&view(&m, &status, &Settings::default()))[2], "Drawing F200%, 4 queued");
        let rapid = Overrides { rapid_percent: 25, ..Overrides::NONE };
        let status = Status { state: RunState::Run, overrides: rapid, ..Status::default() };
        assert_eq!(texts(&view(&m, &status, &Settings::default()))[2], "Drawing");
        let jogging = Status { state: RunState::Jog, overrides: slower, ..Status::default() };
        assert_eq!(texts(&view(&m, &jogging, &Settings::default()))[2], "Jogging", "a jog takes no override");
    }

    #[test]
    fn mode_list_jog_and_settings_screens() {
        let mut m = Menu::new();
        let idle = Status::default();
        let s = Settings::default();
        assert_eq!(texts(&view(&m, &idle, &s))[2..], [">1 Jog", " 2 Line"]);
        press(&mut m, "BBBBBB", &idle);
        assert_eq!(texts(&view(&m, &idle, &s))[2..], [">7 Settings", " 8 Home ($H)"]);
        press(&mut m, "#", &idle);
        assert_eq!(texts(&view(&m, &idle, &s))[1..], ["Steps/mm X100 Y100", "Travel mm X200 Y200", "Feed 3000 mm/min"]);
        press(&mut m, "BBBBBBBB", &idle);
        assert_eq!(texts(&view(&m, &idle, &s))[3], "Interpolation diagonal");
        press(&mut m, "D1", &idle);
        m.handle(KeyEvent::Press(Key::Digit(3)), &idle, &s);
        let jog = Status { state: RunState::Jog, ..Status::default() };
        assert_eq!(texts(&view(&m, &jog, &s))[2..], ["Moving +X+Y", "Release to stop"]);
    }

    #[test]
    fn large_positions_fit_with_fewer_decimals() {
        let m = Menu::new();
        let s = Settings { steps_per_mm: [1.0, 1.0], ..Settings::default() };
        let status = Status { position: crate::geom::Point::new(-1_234_567, i32::MAX), ..Status::default() };
        assert_eq!(texts(&view(&m, &status, &s))[1], "X -1234567 Y    -----");
        let status = Status { position: crate::geom::Point::new(-12_345, 500), ..Status::default() };
        assert_eq!(texts(&view(&m, &status, &s))[1], "X -12345.0 Y  500.000");
    }

    #[test]
    fn a_shorter_value_leaves_no_stale_digits() {
        let mut m = Menu::new();
        let idle = Status::default();
        press(&mut m, "2 A8888*888", &idle);
        // The LCD's buffer: start from garbage, draw the long value, then the short one over it.
        let mut lcd = Frame::filled(true);
        draw(&m, &idle, &Settings::default(), &mut lcd).unwrap();
        let long = lcd.clone();
        press(&mut m, "BBBBBBBA", &idle);
        assert_eq!(form_digits(&m), "8");
        draw(&m, &idle, &Settings::default(), &mut lcd).unwrap();
        assert_ne!(lcd, long);
        assert_eq!(lcd, fresh(&m, &idle), "the redrawn frame equals one drawn on a blank screen");
        assert_eq!(lcd.outside, 0);
    }

    fn form_digits(m: &Menu) -> &str {
        match m.screen() {
            Screen::Form(f) => f.entry().digits(),
            _ => "",
        }
    }

    #[test]
    fn title_bar_is_drawn_and_text_lines_have_glyphs() {
        let mut m = Menu::new();
        press(&mut m, "3", &Status::default());
        let f = fresh(&m, &Status::default());
        let title_px = W * SCREEN_LINE_HEIGHT_PX as usize;
        let lit = f.lit_in_rows(0..8);
        // Inverted bar: mostly lit, with the glyphs cut out of it.
        assert!(lit > title_px / 2 && lit < title_px, "title row: {lit} of {title_px} lit\n{f:?}");
        for line in 1..SCREEN_LINES {
            assert!(f.lit_in_rows(line * 8..line * 8 + 8) > 0, "line {line} is blank\n{f:?}");
        }
        // The title's first glyph ('C') is where the 5x7 font puts it.
        let mut reference = Frame::filled(true);
        Text::with_baseline("C", Point::new(1, 1), MonoTextStyle::new(&FONT_5X7, BinaryColor::Off), Baseline::Top)
            .draw(&mut reference)
            .unwrap();
        for y in 0..8 {
            assert_eq!(f.px[y][..6], reference.px[y][..6], "row {y}\n{f:?}");
        }
    }

    #[test]
    fn the_decimal_point_is_a_dot_at_the_foot_of_its_cell() {
        // "X    0.000": the point is the 6th character of the position line's X value.
        let status = Status::default();
        let f = fresh(&Menu::new(), &status);
        let v = view(&Menu::new(), &status, &Settings::default());
        let column = texts(&v)[1].find('.').unwrap();
        let x0 = SCREEN_MARGIN_PX as usize + column * crate::ui::layout::SCREEN_CHAR_WIDTH_PX as usize;
        let line = SCREEN_LINE_HEIGHT_PX as usize;
        let lit: std::vec::Vec<(usize, usize)> =
            (line..2 * line).flat_map(|y| (x0..x0 + 5).map(move |x| (x, y))).filter(|&(x, y)| f.px[y][x]).collect();
        assert!(!lit.is_empty(), "{f:?}");
        // Nothing in the upper half of the cell, nothing beside the dot: no cross.
        assert!(lit.iter().all(|&(_, y)| y >= line + 4), "{lit:?}\n{f:?}");
        let width = lit.iter().map(|p| p.0).max().unwrap() - lit.iter().map(|p| p.0).min().unwrap() + 1;
        assert!(width <= 2, "{lit:?}");
    }

    #[test]
    fn nothing_is_drawn_outside_the_screen() {
        let s = Settings::default();
        let busy = Status {
            state: RunState::Run,
            queued_jobs: 255,
            position: crate::geom::Point::new(-50_000, -50_000),
            position_lost: true,
            fault: None,
            door: false,
            underruns: u32::MAX,
            overrides: Overrides { feed_percent: 200, ..Overrides::NONE },
        };
        for keys in ["", "1", "2 A88888888 #", "6", "7 BBBBBBBB", "4 12345678 9", "5 1# 1# # 0#"] {
            let mut m = Menu::new();
            press(&mut m, keys, &Status::default());
            for status in [Status::default(), busy] {
                let mut f = Frame::filled(false);
                draw(&m, &status, &s, &mut f).unwrap();
                assert_eq!(f.outside, 0, "keys {keys:?}");
            }
        }
    }

    #[test]
    fn the_view_changes_exactly_when_the_screen_does() {
        let mut m = Menu::new();
        let idle = Status::default();
        let s = Settings::default();
        let before = view(&m, &idle, &s);
        assert_eq!(before, view(&m.clone(), &idle, &s));
        press(&mut m, "2", &idle);
        let form = view(&m, &idle, &s);
        assert_ne!(form, before);
        m.handle(KeyEvent::Release(Key::Digit(2)), &idle, &s);
        assert_eq!(view(&m, &idle, &s), form, "a release in a form shows nothing new");
        let moved = Status { position: crate::geom::Point::new(1, 0), ..idle };
        assert_ne!(view(&m, &moved, &s), form, "a step of the pen is visible");
    }

    #[test]
    fn a_curve_stopped_part_way_is_shown_until_the_next_job() {
        let m = Menu::new();
        let s = Settings::default();
        let stopped = Status { fault: Some(MotionFault::Curve(CurveError::Domain)), ..Status::default() };
        let v = view(&m, &stopped, &s);
        assert_eq!(v.lines[3].text.as_str(), "Stopped: f(x) undefined");
        assert!(v.lines[3].inverted);
        let running = Status { state: RunState::Run, ..stopped };
        assert_ne!(view(&m, &running, &s).lines[3].text.as_str(), "Stopped: f(x) undefined");
    }
}

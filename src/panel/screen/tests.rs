//! The screens drawn on an in-memory 122x32 frame: their text, their pixels, and that nothing
//! stale or outside the glass survives a redraw.

extern crate std;
use super::*;
use crate::motion::overrides::Overrides;
use crate::panel::keypad::{Key, KeyEvent};
use crate::panel::layout::SCREEN_HEIGHT_PX;
use core::convert::Infallible;
use embedded_graphics::Drawable;
use embedded_graphics::Pixel;
use embedded_graphics::geometry::OriginDimensions;
use embedded_graphics::mono_font::MonoTextStyle;
use embedded_graphics::mono_font::ascii::FONT_5X7;
use embedded_graphics::text::{Baseline, Text};

/// Past the splash, at rest, nothing drawn, with no work offset.
const LATER: Live = Live { now_ms: SPLASH_MS, ..Live::NONE };

/// The screen at rest, nothing drawn, with no work offset.
fn view(menu: &Menu, status: &Status, settings: &Settings) -> ScreenView {
    super::view(menu, status, settings, &LATER)
}

fn draw<D: DrawTarget<Color = BinaryColor>>(
    menu: &Menu,
    status: &Status,
    settings: &Settings,
    target: &mut D,
) -> Result<(), D::Error> {
    super::draw(menu, status, settings, &LATER, target)
}

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

/// The view's lines as a person reads them.
fn texts(v: &ScreenView) -> [std::string::String; SCREEN_LINES] {
    v.lines.clone().map(|line| crate::panel::texts::readable(&line.text))
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
    assert_eq!(texts(&view(&m, &idle, &s)), ["SETTINGS 1/48       IDLE", "$0 Pulse width", "5 us", "2.5..100 # edit"]);
    press(&mut m, &"B".repeat(33), &idle);
    assert_eq!(texts(&view(&m, &idle, &s))[1..], ["$202 Diagonal steps", "1", "0..1 # edit"]);
    press(&mut m, "BBBB 1*5", &idle);
    assert_eq!(texts(&view(&m, &idle, &s))[1..], ["$206 Input debounce", "=1.5_ ms", "#set Cnext *. Bdel Dback"]);
    press(&mut m, "#", &idle);
    assert_eq!(texts(&view(&m, &idle, &s))[3], "Whole numbers only");
    press(&mut m, "DDBB", &idle);
    assert_eq!(texts(&view(&m, &idle, &s))[2..], [">9 Speed presets", " 0 Language 语言"]);
    // The presets open on the one in force.
    press(&mut m, "#", &idle);
    assert_eq!(texts(&view(&m, &idle, &s))[1..], ["F3000 R6000 A500", ">2 Felt tip *", " 3 Fast draft"]);
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
    // The title's first glyph ('C') is where embedded-graphics' own text renderer puts it.
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
    let x0 = SCREEN_MARGIN_PX as usize + column * crate::panel::layout::SCREEN_CHAR_WIDTH_PX as usize;
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
        missed_updates: u32::MAX,
        overrides: Overrides { feed_percent: 200, ..Overrides::NONE },
        emitted_steps: u32::MAX,
        work_left: true,
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

#[test]
fn a_typed_function_shows_its_end_the_wheel_and_its_error() {
    let mut m = Menu::new();
    let idle = Status::default();
    let s = Settings::default();
    press(&mut m, "6", &idle);
    assert_eq!(texts(&view(&m, &idle, &s))[2..], ["f1 y=x^2/20", "1-5/AB pick C type # ok"]);
    press(&mut m, "C B B", &idle);
    assert_eq!(texts(&view(&m, &idle, &s))[2..], ["y=x^2/20_", "A<)>B C put D del"]);
    press(&mut m, "A A A", &idle);
    assert_eq!(texts(&view(&m, &idle, &s))[3], "A<,>B C put D del", "back past the first token");
    // A long text shows its end, where it is typed.
    press(&mut m, "B B B C C C C C C C C C C C C C C C C C C C C", &idle);
    assert_eq!(texts(&view(&m, &idle, &s))[2], "y=0))))))))))))))))))))_");
    press(&mut m, "#", &idle);
    assert_eq!(texts(&view(&m, &idle, &s))[3], "Col 7 unmatched ( or )");
}

#[test]
fn the_splash_shows_at_power_up_until_a_key_or_its_time() {
    let mut m = Menu::new();
    let (idle, s) = (Status::default(), Settings::default());
    let at = |now_ms| Live { now_ms, ..Live::NONE };
    let splash = texts(&super::view(&m, &idle, &s, &at(0)));
    assert_eq!(splash[1..], ["Servo pen plotter", "0: 中文", "Any key: menu"]);
    assert!(splash[0].starts_with("SERVOPLOT ") && super::view(&m, &idle, &s, &at(0)).lines[0].inverted);
    assert_eq!(texts(&super::view(&m, &idle, &s, &at(SPLASH_MS)))[2..], [">1 Jog", " 2 Line"]);
    // A key puts it away at once, and acts on the mode list.
    press(&mut m, "B", &idle);
    assert_eq!(texts(&super::view(&m, &idle, &s, &at(0)))[2..], [">2 Line", " 3 Circle/arc"]);
}

#[test]
fn every_screen_speaks_chinese_when_set() {
    let mut m = Menu::new();
    let idle = Status::default();
    let s = Settings { language: crate::panel::language::Language::Chinese, ..Settings::default() };
    assert_eq!(texts(&super::view(&m, &idle, &s, &Live::NONE))[1], "伺服绘图机", "the splash");
    assert_eq!(
        texts(&view(&m, &idle, &s)),
        ["SERVOPLOT           空闲", "X    0.000 Y    0.000", ">1 点动", " 2 直线"]
    );
    press(&mut m, "3", &idle);
    assert_eq!(
        texts(&view(&m, &idle, &s)),
        ["圆/圆弧 1/3         空闲", "X    0.000 Y    0.000", "半径 mm: _", "#确定 *. A- B删 D返回"]
    );
    press(&mut m, "#", &idle);
    assert_eq!(texts(&view(&m, &idle, &s))[3], "请输入数值");
    press(&mut m, "9999#", &idle);
    assert_eq!(texts(&view(&m, &idle, &s))[3], "范围 0.1..500 mm");
    press(&mut m, "DD7", &idle);
    assert_eq!(texts(&view(&m, &idle, &s))[1..], ["$0 脉冲宽度", "5 us", "2.5..100 #设定"]);
    let failed = Status { fault: Some(MotionFault::Homing(HomingFail::Approach(crate::geom::Axis::Y))), ..idle };
    assert_eq!(texts(&view(&m, &failed, &s))[3], "回零 Y 失败");
    let stopped = Status { fault: Some(MotionFault::Curve(CurveError::DivisionByZero)), ..Status::default() };
    assert_eq!(texts(&view(&m, &stopped, &s))[3], "停止: 除以 0");
    assert_eq!(texts(&view(&m, &stopped, &Settings::default()))[3], "Stopped: division by 0");
}

#[test]
fn homing_says_homing_and_d_aborts_it() {
    let m = Menu::new();
    let s = Settings { homing: true, ..Settings::default() };
    let homing = Status { state: RunState::Home, ..Status::default() };
    let v = texts(&view(&m, &homing, &s));
    assert_eq!(v, ["SERVOPLOT           HOME", "X    0.000 Y    0.000", "Homing", "D abort"]);
}

#[test]
fn a_lock_with_nothing_to_tell_says_how_to_unlock() {
    let m = Menu::new();
    let locked = Status { state: RunState::Alarm, ..Status::default() };
    let homing = Settings { homing: true, ..Settings::default() };
    let v = view(&m, &locked, &homing);
    assert_eq!((v.lines[3].text.as_str(), v.lines[3].inverted), ("Locked: 8 home, or $X", true));
    assert_eq!(texts(&view(&m, &locked, &Settings::default()))[3], "Locked: $X unlocks");
    let chinese = Settings { language: crate::panel::language::Language::Chinese, ..homing };
    assert_eq!(texts(&view(&m, &locked, &chinese))[3], "已锁定: 8回零, 或$X");
    // A lock with a cause says the cause.
    let tripped = Status { fault: Some(MotionFault::Tripped(Trip::EStop)), ..locked };
    assert_eq!(texts(&view(&m, &tripped, &homing))[3], "Stopped: E-stop");
}

#[test]
fn a_released_jog_says_it_is_stopping_while_the_title_says_jog() {
    let mut m = Menu::new();
    let s = Settings::default();
    press(&mut m, "1", &Status::default());
    m.handle(KeyEvent::Press(Key::Digit(6)), &Status::default(), &s);
    let jogging = Status { state: RunState::Jog, ..Status::default() };
    assert_eq!(texts(&view(&m, &jogging, &s))[2..], ["Moving +X", "Release to stop"]);
    m.handle(KeyEvent::Release(Key::Digit(6)), &jogging, &s);
    let v = texts(&view(&m, &jogging, &s));
    assert_eq!(v, [std::format!("{:<21}JOG", "JOG").as_str(), "X    0.000 Y    0.000", "Stopping", "D abort"]);
    assert_eq!(texts(&view(&m, &Status::default(), &s))[2], "2 +Y 8 -Y 4 -X 6 +X", "at rest");
}

#[test]
fn a_run_stopped_by_an_alarm_says_alarm_not_done() {
    let mut m = Menu::new();
    let s = Settings::default();
    assert!(m.observe(&Status { state: RunState::Run, work_left: true, ..Status::default() }, 0));
    let alarm = Status { state: RunState::Alarm, fault: Some(MotionFault::Tripped(Trip::EStop)), ..Status::default() };
    assert!(m.observe(&alarm, 1_000));
    let v = texts(&view(&m, &alarm, &s));
    assert!(v[0].ends_with(" ALARM"), "{v:?}");
    let mut done = Menu::new();
    done.observe(&Status { state: RunState::Run, work_left: true, ..Status::default() }, 0);
    done.observe(&Status::default(), 1_000);
    assert!(texts(&view(&done, &Status::default(), &s))[0].ends_with(" DONE"));
}

#[test]
fn refusals_say_why_in_either_language() {
    let mut m = Menu::new();
    let idle = Status::default();
    let chinese = Settings { language: crate::panel::language::Language::Chinese, ..Settings::default() };
    let cases = [
        (UiError::Clash { set: 201, with: 110 }, "Clashes with $110", "冲突: $110"),
        (UiError::StrandsPen { set: 130 }, "Pen beyond new travel", "笔将超出行程"),
        (
            UiError::UndefinedAtStart(crate::motion::expr::EvalError::SqrtOfNegative),
            "x0: sqrt of a negative",
            "x0: 负数开方",
        ),
        (UiError::UndefinedAtStart(crate::motion::expr::EvalError::DivisionByZero), "x0: division by 0", "x0: 除以 0"),
    ];
    for (why, english, zh) in cases {
        m.refuse(why);
        assert_eq!(texts(&view(&m, &idle, &Settings::default()))[3], english);
        assert_eq!(texts(&view(&m, &idle, &chinese))[3], zh);
    }
}

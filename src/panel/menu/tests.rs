//! The menu driven key by key as on the keypad: the forms and their checks, starting jobs,
//! run control, jogging and the mode list.

extern crate std;
use super::*;
use crate::geom::{Point, Rotation};
use crate::motion::drawing::{BUILD_SLICE_STEPS, DrawError, Request};
use crate::motion::interp::Shape;
use crate::motion::job::{Feed, Job};
use crate::panel::entry::EntryError;
use crate::panel::expr_entry::ExprEntry;
use crate::panel::presets::FunctionPreset;
use std::vec::Vec;

fn key(ch: char) -> Key {
    match ch {
        '0'..='9' => Key::Digit(ch as u8 - b'0'),
        'A' => Key::A,
        'B' => Key::B,
        'C' => Key::C,
        'D' => Key::D,
        '*' => Key::Star,
        '#' => Key::Hash,
        _ => panic!("no key {ch}"),
    }
}

/// What the keypad task ends up doing after a key: what the menu asked for, or a job it started
/// (the drawing it asked for, built and checked).
#[allow(clippy::large_enum_variant)]
#[derive(Debug, PartialEq)]
enum Did {
    Act(MenuAction),
    Start(Job),
}

/// What the keypad task does with `action`: a drawing asked for is built, in one go (as if
/// between two keys), and handed to the menu; what follows.
fn carried_out(menu: &mut Menu, action: MenuAction, status: &Status) -> Did {
    let MenuAction::Build(request) = action else { return Did::Act(action) };
    let s = Settings::default();
    let mut slot = None;
    if let Err(why) = Building::start(&mut slot, &request, status.position, &s) {
        menu.refuse(why);
        return Did::Act(MenuAction::None);
    }
    let built = slot.as_mut().unwrap();
    while !built.advance(BUILD_SLICE_STEPS).done {}
    match menu.built(built, status, &s) {
        MenuAction::Start(feed) => Did::Start(built.job(feed).expect("a drawing started is checked")),
        other => Did::Act(other),
    }
}

/// Presses each key of `keys` (spaces ignored); returns what was done but nothing. A drawing
/// asked for is built at once, its preview confirmed with `#` at once, and a drawing started is
/// drawn at once, as if between two keys: the machine runs and comes to rest, and a key puts the
/// end screen away.
fn type_keys(menu: &mut Menu, keys: &str, status: &Status) -> Vec<Did> {
    let s = Settings::default();
    let mut done = Vec::new();
    for c in keys.chars().filter(|c| !c.is_whitespace()) {
        let action = menu.handle(KeyEvent::Press(key(c)), status, &s);
        let mut did = carried_out(menu, action, status);
        if matches!(menu.screen(), Screen::Preview { .. }) {
            let action = menu.handle(KeyEvent::Press(Key::Hash), status, &s);
            did = carried_out(menu, action, status);
        }
        if let Did::Start(_) = did {
            draw_to_the_end(menu);
            menu.handle(KeyEvent::Press(Key::Star), &idle(), &s);
        }
        if did != Did::Act(MenuAction::None) {
            done.push(did);
        }
    }
    done
}

/// The machine draws what the menu started and comes to rest: the run ends.
fn draw_to_the_end(menu: &mut Menu) {
    let drawing = Status { state: RunState::Run, work_left: true, ..Status::default() };
    assert!(menu.observe(&drawing, 0));
    assert!(menu.observe(&idle(), 1000));
    assert_eq!(menu.run().and_then(|r| r.ended_ms), Some(1000));
}

fn idle() -> Status {
    Status::default()
}

/// A line started from the pen at `from` to (`x`, `y`) steps.
fn line_from(from: Point, x: i32, y: i32) -> Did {
    let drawing =
        crate::motion::drawing::build(&Request::Straight { to: Point::new(x, y) }, from, &Settings::default());
    Did::Start(Job::draw(drawing.unwrap().unwrap(), Feed::MmPerMin(3_000.0)))
}

fn line(x: i32, y: i32) -> Did {
    line_from(Point::ORIGIN, x, y)
}

fn form(menu: &Menu) -> &Form {
    match menu.screen() {
        Screen::Form(f) => f,
        s => panic!("not a form: {s:?}"),
    }
}

#[test]
fn line_mode_starts_a_line_in_steps() {
    let mut m = Menu::new();
    assert_eq!(type_keys(&mut m, "2 10# 5#", &idle()), [line(1000, 500)]);
    // The form stays as typed until the drawing shows (no empty form flashes up before it)...
    assert_eq!(form(&m).field_index(), 1);
    assert_eq!(form(&m).entry().digits(), "5");
    // ...and the next key starts the next line in an empty form.
    assert_eq!(type_keys(&mut m, "3", &idle()), []);
    assert_eq!(form(&m).field_index(), 0);
    assert_eq!(form(&m).entry().digits(), "3");
}

#[test]
fn line_is_relative_to_the_pen() {
    let mut m = Menu::new();
    let status = Status { position: Point::new(200, -300), ..Status::default() };
    assert_eq!(type_keys(&mut m, "2 10# 5#", &status), [line_from(status.position, 1200, 200)]);
}

#[test]
fn backspace_sign_and_decimal_point() {
    let mut m = Menu::new();
    // "12" then delete the 2, point, 5, minus: -1.5 mm. Then 0.25 mm.
    assert_eq!(type_keys(&mut m, "2 12B*5A# *25#", &idle()), [line(-150, 25)]);
}

#[test]
fn out_of_range_keeps_the_field_for_correction() {
    let mut m = Menu::new();
    assert_eq!(type_keys(&mut m, "2 2000#", &idle()), []);
    assert_eq!(m.message(), Some(UiError::OutOfRange { min: -1000.0, max: 1000.0, unit: Unit::Mm }));
    assert_eq!(form(&m).field_index(), 0);
    assert_eq!(form(&m).entry().digits(), "2000");
    // Any key clears the message; fix the value and go on.
    assert_eq!(type_keys(&mut m, "B#", &idle()), []);
    assert_eq!(m.message(), None);
    assert_eq!(type_keys(&mut m, "0#", &idle()), [line(20_000, 0)]);
}

#[test]
fn empty_and_malformed_fields_are_refused() {
    let mut m = Menu::new();
    assert_eq!(type_keys(&mut m, "2#", &idle()), []);
    assert_eq!(m.message(), Some(UiError::Empty));
    assert_eq!(type_keys(&mut m, "A#", &idle()), []);
    assert_eq!(m.message(), Some(UiError::Entry(EntryError::NotANumber)));
    assert_eq!(type_keys(&mut m, "C12345678 9", &idle()), []);
    assert_eq!(m.message(), Some(UiError::Entry(EntryError::TooLong)));
    assert_eq!(form(&m).entry().digits(), "12345678");
}

#[test]
fn beyond_travel_nothing_starts() {
    let mut m = Menu::new();
    // Pen at X 100 mm; 150 mm further is past the 200 mm travel.
    let status = Status { position: Point::new(10_000, 0), ..Status::default() };
    assert_eq!(type_keys(&mut m, "2 150# 0#", &status), []);
    assert_eq!(m.message(), Some(UiError::Drawing(DrawError::Travel)));
    // The last field keeps its text; delete it, go back to dX and correct that.
    assert_eq!(form(&m).field_index(), 1);
    assert_eq!(form(&m).entry().digits(), "0");
    assert_eq!(type_keys(&mut m, "B B BBB 100# 0#", &status), [line_from(status.position, 20_000, 0)]);
}

#[test]
fn held_backspace_stays_in_its_field() {
    let mut m = Menu::new();
    let s = Settings::default();
    type_keys(&mut m, "2 7# 123", &idle());
    for _ in 0..10 {
        m.handle(KeyEvent::Repeat(Key::B), &idle(), &s);
    }
    assert_eq!(form(&m).field_index(), 1);
    assert!(form(&m).entry().is_empty());
    // A fresh press on the empty field goes back to dX, text intact.
    m.handle(KeyEvent::Press(Key::B), &idle(), &s);
    assert_eq!(form(&m).field_index(), 0);
    assert_eq!(form(&m).entry().digits(), "7");
    // The sign key does not repeat.
    m.handle(KeyEvent::Repeat(Key::A), &idle(), &s);
    assert!(!form(&m).entry().is_negative());
}

#[test]
fn run_hold_resume_abort() {
    let mut m = Menu::new();
    type_keys(&mut m, "2 1", &idle());
    let run = Status { state: RunState::Run, ..Status::default() };
    let hold = Status { state: RunState::Hold, ..Status::default() };
    assert_eq!(type_keys(&mut m, "C", &run), [Did::Act(MenuAction::Control(Control::Hold))]);
    assert_eq!(type_keys(&mut m, "C", &hold), [Did::Act(MenuAction::Control(Control::Resume))]);
    // Digits and # do nothing while a job runs; D aborts and leaves the form as it was.
    assert_eq!(type_keys(&mut m, "5#", &run), []);
    assert_eq!(type_keys(&mut m, "D", &run), [Did::Act(MenuAction::Control(Control::Abort))]);
    assert_eq!(type_keys(&mut m, "D", &hold), [Did::Act(MenuAction::Control(Control::Abort))]);
    assert_eq!(form(&m).entry().digits(), "1");
    assert_eq!(m.message(), Some(UiError::Aborted), "an abort is said until the next key");
    // At rest, the next key only acknowledges it; then D goes back to the mode list.
    assert_eq!(type_keys(&mut m, "D", &idle()), []);
    assert_eq!((m.message(), form(&m).entry().digits()), (None, "1"));
    assert_eq!(type_keys(&mut m, "D", &idle()), []);
    assert_eq!(*m.screen(), Screen::Modes);
}

#[test]
fn no_job_while_busy_or_in_alarm() {
    let mut m = Menu::new();
    let queued = Status { queued_jobs: 1, ..Status::default() };
    assert_eq!(type_keys(&mut m, "2 1# 1#", &queued), []);
    assert_eq!(m.message(), Some(UiError::Busy));
    let alarm = Status { state: RunState::Alarm, ..Status::default() };
    assert_eq!(type_keys(&mut m, "#", &alarm), []);
    assert_eq!(m.message(), Some(UiError::Alarm));
    assert_eq!(type_keys(&mut m, "#", &idle()), [line(100, 100)]);
}

#[test]
fn jog_keys_start_and_stop_the_jog() {
    let mut m = Menu::new();
    let s = Settings::default();
    type_keys(&mut m, "1", &idle());
    assert_eq!(*m.screen(), Screen::Jog);
    let jogging = Status { state: RunState::Jog, ..Status::default() };
    for (k, step) in
        [(2, Step::YP), (8, Step::YN), (4, Step::XN), (6, Step::XP), (3, Step::new(1, 1)), (7, Step::new(-1, -1))]
    {
        assert_eq!(m.handle(KeyEvent::Press(Key::Digit(k)), &idle(), &s), MenuAction::JogStart(step));
        assert_eq!(m.handle(KeyEvent::Release(Key::Digit(k)), &jogging, &s), MenuAction::JogStop);
    }
    assert_eq!(m.handle(KeyEvent::Press(Key::Digit(5)), &idle(), &s), MenuAction::None);
    // Releasing a key other than the jogging one does not stop it.
    assert_eq!(m.handle(KeyEvent::Press(Key::Digit(1)), &idle(), &s), MenuAction::JogStart(Step::new(-1, 1)));
    assert_eq!(m.handle(KeyEvent::Release(Key::Digit(5)), &jogging, &s), MenuAction::None);
    // D while the key is held stops the jog; the late release then does nothing.
    assert_eq!(m.handle(KeyEvent::Press(Key::D), &jogging, &s), MenuAction::JogStop);
    assert_eq!(m.handle(KeyEvent::Release(Key::Digit(7)), &jogging, &s), MenuAction::None);
    // No jog in alarm.
    let alarm = Status { state: RunState::Alarm, ..Status::default() };
    assert_eq!(m.handle(KeyEvent::Press(Key::Digit(3)), &alarm, &s), MenuAction::None);
    assert_eq!(m.message(), Some(UiError::Alarm));
}

#[test]
fn mode_list_by_digit_and_by_navigation() {
    let mut m = Menu::new();
    let s = Settings::default();
    m.handle(KeyEvent::Press(Key::A), &idle(), &s);
    assert_eq!(m.selected(), Mode::Jog, "stops at the top");
    m.handle(KeyEvent::Press(Key::B), &idle(), &s);
    m.handle(KeyEvent::Repeat(Key::B), &idle(), &s);
    assert_eq!(m.selected(), Mode::Circle);
    for _ in 0..20 {
        m.handle(KeyEvent::Repeat(Key::B), &idle(), &s);
    }
    assert_eq!(m.selected(), Mode::Card, "stops at the bottom, no wrap");
    for _ in 0..5 {
        m.handle(KeyEvent::Press(Key::A), &idle(), &s);
    }
    m.handle(KeyEvent::Press(Key::Hash), &idle(), &s);
    assert_eq!(form(&m).mode(), Mode::Function);
    type_keys(&mut m, "D 4", &idle());
    assert_eq!(form(&m).mode(), Mode::Ellipse);
    type_keys(&mut m, "D 7", &idle());
    assert_eq!(*m.screen(), Screen::Settings(SettingPage::new()));
    // The presets open on the one in force (the defaults are the felt tip's), else on the first.
    type_keys(&mut m, "D 9", &idle());
    assert_eq!(*m.screen(), Screen::Presets(SpeedPreset::FeltTip));
    let own = Settings { default_feed_mm_per_min: 1234.0, ..Settings::default() };
    type_keys(&mut m, "D", &idle());
    m.handle(KeyEvent::Press(Key::Digit(9)), &idle(), &own);
    assert_eq!(*m.screen(), Screen::Presets(SpeedPreset::FinePen));
}

#[test]
fn a_setting_is_typed_checked_and_handed_on() {
    let mut m = Menu::new();
    // $0, then down the list to $110 (the 26th).
    type_keys(&mut m, "7", &idle());
    let Screen::Settings(page) = m.screen() else { panic!("{:?}", m.screen()) };
    assert_eq!(page.info().id, 0);
    type_keys(&mut m, &"B".repeat(25), &idle());
    let Screen::Settings(page) = m.screen() else { panic!("{:?}", m.screen()) };
    assert_eq!(page.info().id, 110);
    // Out of range (1..60000): said, and the value stays to be corrected.
    assert_eq!(type_keys(&mut m, "7 0 0 0 0 #", &idle()), []);
    assert_eq!(m.message(), Some(UiError::OutOfRange { min: 1.0, max: 60_000.0, unit: Unit::MmPerMin }));
    assert_eq!(type_keys(&mut m, "B #", &idle()), [Did::Act(MenuAction::SetSetting { id: 110, value: 7000.0 })]);
    // A whole-number setting ($1) refuses a fraction; D drops the value, then leaves.
    type_keys(&mut m, &"A".repeat(24), &idle());
    assert_eq!(type_keys(&mut m, "2 * 5 #", &idle()), []);
    assert_eq!(m.message(), Some(UiError::NotWhole));
    type_keys(&mut m, "D", &idle());
    let Screen::Settings(page) = m.screen() else { panic!("{:?}", m.screen()) };
    assert_eq!((page.info().id, page.edit()), (1, None));
    type_keys(&mut m, "D", &idle());
    assert_eq!(*m.screen(), Screen::Modes);
}

#[test]
fn a_setting_is_set_and_left_with_c_and_a_is_no_sign() {
    let mut m = Menu::new();
    let page = |m: &Menu| match m.screen() {
        Screen::Settings(page) => {
            (page.info().id, page.edit().map(|e| (e.is_negative(), std::string::String::from(e.digits()))))
        }
        s => panic!("{s:?}"),
    };
    // $201: A types no minus; C sets the value and moves on to $202.
    let index = crate::settings::SETTING_INFO.iter().position(|info| info.id == 201).unwrap();
    type_keys(&mut m, &std::format!("7 {}", "B".repeat(index)), &idle());
    assert_eq!(type_keys(&mut m, "7 A 0 0 0", &idle()), []);
    assert_eq!(page(&m), (201, Some((false, "7000".into()))));
    assert_eq!(type_keys(&mut m, "C", &idle()), [Did::Act(MenuAction::SetSetting { id: 201, value: 7000.0 })]);
    assert_eq!(page(&m), (202, None));
    // The change clashes with $110: the keypad task says so, and $201 shows again with why.
    m.refuse(UiError::Clash { set: 201, with: 110 });
    assert_eq!((page(&m), m.message()), ((201, None), Some(UiError::Clash { set: 201, with: 110 })));
}

#[test]
fn a_speed_preset_is_picked_and_handed_on() {
    let mut m = Menu::new();
    assert_eq!(type_keys(&mut m, "9 B B B #", &idle()), [Did::Act(MenuAction::Preset(SpeedPreset::FastDraft))]);
    assert_eq!(type_keys(&mut m, "2 #", &idle()), [Did::Act(MenuAction::Preset(SpeedPreset::FeltTip))]);
    // Not while the machine draws.
    let drawing = Status { state: RunState::Run, ..Status::default() };
    assert_eq!(type_keys(&mut m, "1 #", &drawing), []);
}

/// The shape (in steps) and start of the drawing a key started.
fn curve(did: &Did) -> (Shape, Point) {
    match did {
        Did::Start(job) => (job.drawing.shape().clone(), job.drawing.start()),
        a => panic!("not a drawing: {a:?}"),
    }
}

#[test]
fn circle_defaults_to_a_full_turn() {
    let mut m = Menu::new();
    let status = Status { position: Point::new(1000, 0), ..Status::default() };
    let actions = type_keys(&mut m, "3 10# # #", &status);
    assert_eq!(actions.len(), 1);
    let full = Shape::Arc { center: Point::ORIGIN, to: Point::new(1000, 0), rotation: Rotation::CounterClockwise };
    assert_eq!(curve(&actions[0]), (full, Point::new(1000, 0)));
    // A half turn clockwise from the top.
    let actions = type_keys(&mut m, "3# 90# A180#", &status);
    let half = Shape::Arc { center: Point::new(1000, -300), to: Point::new(1000, -600), rotation: Rotation::Clockwise };
    assert_eq!(curve(&actions[0]), (half, Point::new(1000, 0)));
    // Radius 0 is refused; a circle leaving the travel area too.
    assert_eq!(type_keys(&mut m, "0#", &status), []);
    assert_eq!(m.message(), Some(UiError::OutOfRange { min: 0.1, max: 500.0, unit: Unit::Mm }));
    assert_eq!(type_keys(&mut m, "C150# # #", &status), []);
    assert_eq!(
        m.message(),
        Some(UiError::Drawing(DrawError::Travel)),
        "a full circle of r 150 from x 10 reaches x -290"
    );
}

#[test]
fn ellipse_and_sine_forms() {
    let mut m = Menu::new();
    let a = type_keys(&mut m, "4 20# 10# 45# 90#", &idle());
    let ellipse = Shape::Ellipse {
        center: Point::new(-1414, -707),
        a_steps: 2000,
        b_steps: 1000,
        to: Point::new(-2828, 0),
        rotation: Rotation::CounterClockwise,
    };
    assert_eq!(curve(&a[0]), (ellipse, Point::ORIGIN));
    type_keys(&mut m, "D", &idle());
    let a = type_keys(&mut m, "5 A5# 20# # 40#", &idle());
    let sine = Shape::Sine {
        amplitude_steps: -500.0,
        omega_rad_per_step: core::f32::consts::TAU / 20.0 / 100.0,
        phase_rad: 0.0,
        length_steps: 4000,
    };
    assert_eq!(curve(&a[0]), (sine, Point::ORIGIN));
    assert_eq!(type_keys(&mut m, "5# 20# # 0#", &idle()), []);
    assert_eq!(m.message(), Some(UiError::Zero));
    // A 100 mm amplitude over a 1 mm period rises 628 mm per mm: far over the 5 mm jump limit.
    type_keys(&mut m, "D", &idle());
    assert_eq!(type_keys(&mut m, "5 100# 1# # 10#", &idle()), []);
    assert_eq!(m.message(), Some(UiError::Drawing(DrawError::TooSteep)));
}

#[test]
fn function_presets_and_their_domains() {
    let mut m = Menu::new();
    let a = type_keys(&mut m, "6 2# 0# 20#", &idle());
    let wave = Shape::Function { expr: crate::motion::expr::parse("10*sin(x/5)").unwrap(), x0_mm: 0.0, x1_mm: 20.0 };
    assert_eq!(curve(&a[0]), (wave, Point::ORIGIN));
    // The preset choice is kept for the next drawing; B steps to the next one.
    assert_eq!(form(&m).preset(), FunctionPreset::Wave);
    let a = type_keys(&mut m, "B# 0# 9#", &idle());
    let root = Shape::Function { expr: crate::motion::expr::parse("5*sqrt(x)").unwrap(), x0_mm: 0.0, x1_mm: 9.0 };
    assert_eq!(curve(&a[0]), (root, Point::ORIGIN));
    // sqrt of negative x is refused before anything moves, saying why, and an empty interval too.
    assert_eq!(type_keys(&mut m, "# A4# 9#", &idle()), []);
    assert_eq!(m.message(), Some(UiError::UndefinedAtStart(crate::motion::expr::EvalError::SqrtOfNegative)));
    assert_eq!(type_keys(&mut m, "D 6 B B # 4# A9#", &idle()), []);
    assert!(
        matches!(m.message(), Some(UiError::Drawing(DrawError::Fails { .. }))),
        "undefined part way: {:?}",
        m.message()
    );
    assert_eq!(type_keys(&mut m, "BBBB 9# 9#", &idle()), []);
    assert_eq!(m.message(), Some(UiError::SameEnds));
}

#[test]
fn home_runs_the_homing_cycle_when_homing_is_on_and_d_aborts_it() {
    let mut m = Menu::new();
    assert_eq!(type_keys(&mut m, "8", &idle()), []);
    assert_eq!(m.message(), Some(UiError::HomingOff), "$22=0");
    let homing = Settings { homing: true, ..Settings::default() };
    assert_eq!(m.handle(KeyEvent::Press(Key::Digit(8)), &idle(), &homing), MenuAction::Home);
    assert_eq!(*m.screen(), Screen::Modes, "the mode list stays");
    let running = Status { state: RunState::Home, ..Status::default() };
    assert_eq!(m.handle(KeyEvent::Press(Key::Digit(2)), &running, &homing), MenuAction::None, "busy");
    assert_eq!(m.handle(KeyEvent::Press(Key::D), &running, &homing), MenuAction::Control(Control::Abort));
    // Stopped in an alarm: the key that acknowledges the abort does not home again, the next does.
    let aborted = Status { state: RunState::Alarm, ..Status::default() };
    assert_eq!(m.handle(KeyEvent::Press(Key::Hash), &aborted, &homing), MenuAction::None);
    assert_eq!((m.message(), m.selected()), (None, Mode::Home));
    assert_eq!(m.handle(KeyEvent::Press(Key::Hash), &aborted, &homing), MenuAction::Home);
}

#[test]
fn a_typed_function_is_drawn_and_its_errors_say_the_column() {
    let mut m = Menu::new();
    // C on the function field starts from the preset (x^2/20); three D leave x^2.
    type_keys(&mut m, "6 C D D D", &idle());
    assert_eq!(form(&m).typed().map(ExprEntry::text), Some("x^2"));
    let a = type_keys(&mut m, "# 0# 10#", &idle());
    let square = Shape::Function { expr: crate::motion::expr::parse("x^2").unwrap(), x0_mm: 0.0, x1_mm: 10.0 };
    assert_eq!(curve(&a[0]), (square, Point::ORIGIN));
    // A new form starts from the preset again; x^ does not parse: column 3, the end.
    type_keys(&mut m, "D D 6 C D D D D", &idle());
    assert_eq!(type_keys(&mut m, "#", &idle()), []);
    let end = crate::motion::expr::ParseError { kind: crate::motion::expr::ParseErrorKind::UnexpectedEnd, pos: 2 };
    assert_eq!(m.message(), Some(UiError::Expression(end)));
    // D deletes the rest; held, it stops at the empty text; pressed again it goes back to the
    // presets, then to the mode list.
    type_keys(&mut m, "D", &idle());
    assert_eq!(form(&m).typed().map(ExprEntry::text), Some("x"));
    let s = Settings::default();
    for _ in 0..5 {
        m.handle(KeyEvent::Repeat(Key::D), &idle(), &s);
    }
    assert_eq!(form(&m).typed().map(ExprEntry::text), Some(""));
    type_keys(&mut m, "D", &idle());
    assert_eq!((form(&m).typed(), form(&m).preset()), (None, FunctionPreset::Parabola));
    type_keys(&mut m, "D", &idle());
    assert_eq!(*m.screen(), Screen::Modes);
}

#[test]
fn key_0_switches_the_language_from_the_mode_list() {
    let mut m = Menu::new();
    let english = Settings::default();
    let action = m.handle(KeyEvent::Press(Key::Digit(0)), &idle(), &english);
    assert_eq!(action, MenuAction::SetSetting { id: crate::settings::LANGUAGE_SETTING, value: 1.0 });
    assert_eq!(m.selected(), Mode::Language);
    let chinese = Settings { language: crate::panel::language::Language::Chinese, ..english };
    let action = m.handle(KeyEvent::Press(Key::Hash), &idle(), &chinese);
    assert_eq!(action, MenuAction::SetSetting { id: crate::settings::LANGUAGE_SETTING, value: 0.0 });
}

#[test]
fn drawings_are_named_by_their_figures_in_either_language() {
    use crate::panel::language::Language;
    use crate::panel::texts::readable;
    let cases = [
        ("2 1 0 # 5 #", "Line 10,5", "直线 10,5"),
        ("3 1 2 # # #", "Circle r12", "圆 r12"),
        ("3 1 2 # 3 0 # 9 0 #", "Arc r12 90deg", "圆弧 r12 90度"),
        ("4 3 0 # 1 5 # # #", "Ellipse 30x15", "椭圆 30x15"),
        ("5 5 # 2 0 # # 4 0 #", "Sine A5 P20", "正弦 A5 P20"),
    ];
    for (keys, english, chinese) in cases {
        let mut m = Menu::new();
        type_keys(&mut m, keys, &idle());
        assert_eq!(form(&m).name(Language::English).as_str(), english, "{keys}");
        assert_eq!(readable(&form(&m).name(Language::Chinese)), chinese, "{keys}");
    }
}

/// Types `keys` (spaces ignored) without carrying out what they ask for; the last action.
fn press_keys(menu: &mut Menu, keys: &str, status: &Status) -> MenuAction {
    let s = Settings::default();
    let mut last = MenuAction::None;
    for c in keys.chars().filter(|c| !c.is_whitespace()) {
        last = menu.handle(KeyEvent::Press(key(c)), status, &s);
    }
    last
}

/// The drawing `action` asks for, walked to its end from the pen at `status.position`.
fn walked(action: MenuAction, status: &Status) -> Building {
    let MenuAction::Build(request) = action else { panic!("no drawing asked for: {action:?}") };
    let mut slot = None;
    Building::start(&mut slot, &request, status.position, &Settings::default()).unwrap();
    let mut built = slot.unwrap();
    while !built.advance(BUILD_SLICE_STEPS).done {}
    built
}

#[test]
fn while_its_drawing_is_built_the_form_waits_and_d_drops_it() {
    let s = Settings::default();
    let mut m = Menu::new();
    let asked = press_keys(&mut m, "3 10# # #", &idle());
    assert!(matches!(asked, MenuAction::Build(Request::Ellipse(_))), "{asked:?}");
    assert!(m.building());
    // Every key but D waits for the drawing: the form stays as it was.
    assert_eq!(press_keys(&mut m, "5 B C A #", &idle()), MenuAction::None);
    assert_eq!(m.handle(KeyEvent::Repeat(Key::B), &idle(), &s), MenuAction::None);
    assert_eq!((form(&m).field_index(), form(&m).entry().digits()), (2, ""));
    // D drops it; should it be built after all, the menu no longer takes it.
    assert_eq!(press_keys(&mut m, "D", &idle()), MenuAction::DropBuild);
    assert!(!m.building());
    let mut late = walked(asked, &idle());
    assert_eq!(m.built(&mut late, &idle(), &s), MenuAction::None);
    assert!(matches!(m.screen(), Screen::Form(_)), "no preview");
    // The form is as typed: its last # asks again.
    assert!(matches!(press_keys(&mut m, "#", &idle()), MenuAction::Build(_)));
}

#[test]
fn a_drawing_built_while_the_host_moved_the_pen_is_refused() {
    let s = Settings::default();
    let mut m = Menu::new();
    let asked = press_keys(&mut m, "3 10# # #", &idle());
    let mut built = walked(asked, &idle());
    let moved = Status { position: Point::new(100, 0), ..idle() };
    assert_eq!(m.built(&mut built, &moved, &s), MenuAction::None);
    assert_eq!(m.message(), Some(UiError::Busy));
    assert!(matches!(m.screen(), Screen::Form(_)), "no preview");
    // Built from where the pen is, the preview shows; its # builds the drawing again and starts
    // it, from the pen.
    let asked = press_keys(&mut m, "#", &moved);
    let mut built = walked(asked, &moved);
    assert_eq!(m.built(&mut built, &moved, &s), MenuAction::None);
    assert!(matches!(m.screen(), Screen::Preview { .. }));
    let again = press_keys(&mut m, "#", &moved);
    let mut built = walked(again, &moved);
    assert_eq!(m.built(&mut built, &moved, &s), MenuAction::Start(Feed::MmPerMin(s.default_feed_mm_per_min)));
    let job = built.job(Feed::MmPerMin(s.default_feed_mm_per_min)).unwrap();
    assert_eq!((job.drawing.start(), job.drawing.end()), (moved.position, moved.position), "a full circle");
    assert!(m.run().is_some_and(|r| r.plan.is_some()), "the run screen has the preview's plan");
}

/// The README's table of the forms' fields, checked against the forms: every mode with a form
/// has its rows, one a field in order, with the field's unit, range and empty value.
#[test]
fn the_readme_lists_every_form_field_as_the_forms_have_it() {
    use core::fmt::Write;
    let readme = include_str!("../../../README.md");
    let table = readme.split("| mode | field | unit | range | empty |\n|---|---|---|---|---|\n").nth(1).unwrap();
    let rows: Vec<Vec<std::string::String>> = table
        .lines()
        .take_while(|l| l.starts_with('|'))
        .map(|l| l.trim_matches('|').split('|').map(|c| c.trim().replace('−', "-")).collect())
        .collect();
    let mut at = 0;
    for mode in Mode::ALL.into_iter().filter(|m| !m.fields().is_empty()) {
        for (i, field) in mode.fields().iter().enumerate() {
            let row = &rows[at];
            at += 1;
            if i == 0 {
                let label = crate::panel::texts::Say(mode.label(), crate::panel::language::Language::English);
                let mut want = std::string::String::new();
                write!(want, "{} {}", (mode.index() + 1) % 10, label).unwrap();
                assert!(want.starts_with(&row[0]) && !row[0].is_empty(), "{row:?} for {mode:?}");
            } else {
                assert_eq!(row[0], "", "{row:?}: a row of {mode:?}");
            }
            let (unit, range, empty) = match field {
                Field::Preset => (std::string::String::new(), std::string::String::new(), "the preset shown".into()),
                Field::Number(spec) => {
                    let mut range = std::string::String::new();
                    write!(
                        range,
                        "{}..{}",
                        crate::decimal::Num(*spec.range.start()),
                        crate::decimal::Num(*spec.range.end())
                    )
                    .unwrap();
                    let empty = match spec.default {
                        None => "refused".into(),
                        Some(v) => std::format!("{}", crate::decimal::Num(v)),
                    };
                    (spec.unit.symbol().into(), range, empty)
                }
            };
            assert_eq!((&row[2], &row[3]), (&unit, &range), "{mode:?} field {i}: {row:?}");
            assert!(row[4].starts_with(&empty), "{mode:?} field {i}: {row:?}");
        }
    }
    assert_eq!(at, rows.len(), "no rows for fields the forms lack");
}

#[test]
fn the_card_mode_reads_the_card_lists_its_files_and_plots_the_one_chosen() {
    use crate::card::{CardError, CardFacts, CardFiles, CardProgress};
    let mut m = Menu::new();
    let s = Settings::default();
    for _ in 0..10 {
        m.handle(KeyEvent::Press(Key::B), &idle(), &s);
    }
    assert_eq!(m.selected(), Mode::Card, "the eleventh mode, reached with B");
    assert_eq!(m.handle(KeyEvent::Press(Key::Hash), &idle(), &s), MenuAction::ReadCard);
    assert_eq!(m.handle(KeyEvent::Press(Key::Hash), &idle(), &s), MenuAction::None, "nothing read yet");
    let mut files = CardFiles::new();
    files.offer("B.NC", None, 10);
    files.offer("A.GCODE", None, 20);
    m.card_read(Ok(files));
    assert_eq!(m.handle(KeyEvent::Press(Key::B), &idle(), &s), MenuAction::None);
    assert_eq!(m.handle(KeyEvent::Press(Key::Hash), &idle(), &s), MenuAction::PlotCard);
    assert_eq!(m.card_choice().map(|f| f.short), Some("B.NC".try_into().unwrap()));
    // While it is checked, only `D` acts: it leaves the file.
    assert!(m.observe_card(CardProgress::Checking { lines: 3 }, None, 0));
    assert_eq!(m.handle(KeyEvent::Press(Key::Hash), &idle(), &s), MenuAction::None);
    assert_eq!(m.handle(KeyEvent::Press(Key::D), &idle(), &s), MenuAction::CardAnswer(false));
    // Checked, `#` plots it; the plot is a run with the check's steps and time.
    let facts = CardFacts { lines: 5, size_mm: [30.0, 20.0], plot_time_ms: 9_000, steps: 4_000 };
    assert!(m.observe_card(CardProgress::Checked(facts), None, 0));
    assert_eq!(m.handle(KeyEvent::Press(Key::A), &idle(), &s), MenuAction::None);
    assert_eq!(m.handle(KeyEvent::Press(Key::Hash), &idle(), &s), MenuAction::CardAnswer(true));
    assert!(m.observe_card(CardProgress::Plotting { done: 0, total: 5 }, None, 100));
    let plan = m.run().and_then(|r| r.plan.as_ref()).expect("a run with the check's plan");
    assert_eq!((plan.name.as_str(), plan.steps, plan.estimate_ms, plan.first_step), ("B.NC", 4_000, 9_000, 100));
    // While it plots, the keys act on the plot only.
    assert!(m.is_busy(&idle()));
    assert_eq!(m.handle(KeyEvent::Press(Key::D), &idle(), &s), MenuAction::Control(Control::Abort));
    // A card that gives no files says why; `#` then does nothing.
    m.observe_card(CardProgress::None, None, 0);
    m.run = None;
    type_keys(&mut m, "D", &idle());
    m.card_read(Err(CardError::NoCard));
    assert_eq!(m.handle(KeyEvent::Press(Key::Hash), &idle(), &s), MenuAction::None);
}

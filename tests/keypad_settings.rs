//! Settings changed on the machine's own keypad, on the simulated board: the settings screen,
//! the speed presets and the language write the settings the host link reads, the flash keeps
//! them across a power cycle, and a change that clashes with the other settings changes nothing
//! and says why. The splash greets in the language kept.

use servoplot::panel::language::Language;
use servoplot::settings::presets::SpeedPreset;
use servoplot::settings::{SETTING_INFO, Settings};
use servoplot::sim::flash::SimFlash;
use servoplot::sim::keys::KeyScript;
use servoplot::sim::serial::SimSerial;
use servoplot::sim::{self, SimConfig, SimReport};

mod support;

use support::text;

/// Powers the board on with `flash`, types `keys`, then sends `serial` on the UART link.
fn power_on(flash: SimFlash, keys: &str, serial: &str) -> SimReport {
    sim::run(SimConfig {
        flash,
        keys: KeyScript::parse(keys).unwrap(),
        serial: SimSerial::with_input(serial.as_bytes()),
        keys_start: sim::KeysStart::AtOnce,
        ..SimConfig::default()
    })
}

/// The settings screen (7), down the list to setting `$id`.
fn settings_screen_at(id: u16) -> String {
    let index = SETTING_INFO.iter().position(|info| info.id == id).expect("a listed setting");
    format!("7 {}", "B ".repeat(index))
}

#[test]
fn a_setting_typed_on_the_keypad_is_used_reported_and_kept_across_a_power_cycle() {
    let first = power_on(SimFlash::default(), &format!("{} 4 5 0 0 # wait:500", settings_screen_at(110)), "");
    assert_eq!(first.settings.max_rate_mm_per_min, [4500.0, 6000.0]);
    let (_, last) = first.frames.last().unwrap();
    assert_eq!((text(last, 1, 24), text(last, 2, 24)), ("$110 X max rate".into(), "4500 mm/min".into()));

    let second = power_on(first.flash.clone(), "", "$$\n");
    assert_eq!(second.loaded, Ok(()));
    assert!(second.answers().lines().any(|l| l == "$110=4500.000"), "{}", second.answers());
}

#[test]
fn a_speed_preset_writes_its_speeds_and_they_are_kept() {
    let first = power_on(SimFlash::default(), "9 1 # wait:500", "");
    let (feed, rate, accel) = SpeedPreset::FinePen.speeds();
    let s = &first.settings;
    assert_eq!((s.default_feed_mm_per_min, s.max_rate_mm_per_min, s.accel_mm_per_s2), (feed, [rate; 2], [accel; 2]));
    let (_, last) = first.frames.last().unwrap();
    assert_eq!(text(last, 2, 24), ">1 Fine pen *", "the preset in force is marked");

    let second = power_on(first.flash.clone(), "", "$$\n");
    assert!(SpeedPreset::FinePen.is_set(&second.settings), "{}", second.answers());
}

#[test]
fn a_clashing_setting_changes_nothing_and_says_why() {
    // $201, the start rate, above the axes' top speed of 6000 mm/min.
    let report = power_on(SimFlash::default(), &format!("{} 7 0 0 0 # wait:500", settings_screen_at(201)), "");
    let (_, last) = report.frames.last().unwrap();
    assert_eq!(text(last, 1, 24), "$201 Start rate");
    assert_eq!(text(last, 3, 24), "Clashes with $110", "the setting it clashes with");
    assert_eq!(report.settings, Settings::default());
    assert_eq!(report.flash.bytes_changed(), 0);
}

#[test]
fn c_sets_a_value_and_moves_on_to_the_next_setting() {
    // $110 to 4500 and, with C, on to $111: 5000 and # (set, and stay).
    let report =
        power_on(SimFlash::default(), &format!("{} 4 5 0 0 C 5 0 0 0 # wait:500", settings_screen_at(110)), "");
    assert_eq!(report.settings.max_rate_mm_per_min, [4500.0, 5000.0]);
    let (_, last) = report.frames.last().unwrap();
    assert_eq!((text(last, 1, 24), text(last, 2, 24)), ("$111 Y max rate".into(), "5000 mm/min".into()));
    // The pen drawn 100 mm out (D puts the drawing's end screen away), and a travel set
    // smaller than where it is: refused, saying why.
    let report = sim::run(SimConfig {
        keys: KeyScript::parse(&format!("wait:500 D {} 5 0 # wait:500", settings_screen_at(130))).unwrap(),
        serial: SimSerial::with_input(b"G0 X100\n"),
        keys_start: sim::KeysStart::AfterSerial,
        ..SimConfig::default()
    });
    assert_eq!(report.settings, Settings::default());
    let (_, last) = report.frames.last().unwrap();
    assert_eq!((text(last, 1, 24), text(last, 3, 24)), ("$130 X travel".into(), "Pen beyond new travel".into()));
}

#[test]
fn the_presets_open_on_the_preset_in_force() {
    // The defaults are the felt tip's; after the fast draft is written, 9 opens on it.
    let report = power_on(SimFlash::default(), "9 wait:300", "");
    let (_, last) = report.frames.last().unwrap();
    assert_eq!((text(last, 2, 24), text(last, 3, 24)), (">2 Felt tip *".into(), " 3 Fast draft".into()));
    let report = power_on(SimFlash::default(), "9 3 # D 9 wait:500", "");
    let (_, last) = report.frames.last().unwrap();
    assert_eq!(text(last, 3, 24), ">3 Fast draft *");
}

#[test]
fn key_0_switches_the_screen_to_chinese_and_a_power_cycle_keeps_it() {
    let first = power_on(SimFlash::default(), "0 wait:500", "");
    assert_eq!(first.settings.language, Language::Chinese);
    let (_, last) = first.frames.last().unwrap();
    let lines: Vec<String> = (0..4).map(|line| text(last, line, 24)).collect();
    assert_eq!(lines[0], "SERVOPLOT           空闲");
    // The card mode follows the tenth, without a digit.
    assert_eq!(lines[2..], [">0 语言 Language", "   存储卡文件"]);

    // The next power-up greets in Chinese, and the host link reads and sets the language (once
    // the splash is up: the LCD controller takes 90 ms to start).
    let mut serial = SimSerial::with_input(b"");
    for (i, byte) in "$$\n$216=0\n".bytes().enumerate() {
        serial = serial.with_byte_at(200_000 + i as u64 * 100, byte);
    }
    let second = sim::run(SimConfig {
        flash: first.flash.clone(),
        keys: KeyScript::parse("wait:2500").unwrap(),
        serial,
        keys_start: sim::KeysStart::AtOnce,
        ..SimConfig::default()
    });
    assert!(second.answers().lines().any(|l| l == "$216=1"), "{}", second.answers());
    let (_, splash) = &second.frames[0];
    assert_eq!((text(splash, 1, 24), text(splash, 2, 24)), ("伺服绘图机".into(), "0: English".into()));
    assert_eq!(second.settings.language, Language::English);
    let (_, last) = second.frames.last().unwrap();
    assert_eq!((text(last, 0, 24), text(last, 2, 24)), ("SERVOPLOT           IDLE".into(), ">1 Jog".into()));
}

#[test]
fn the_splash_shows_at_power_up_until_its_time_is_up() {
    let report = power_on(SimFlash::default(), "wait:2500", "");
    let (_, splash) = &report.frames[0];
    let lines: Vec<String> = (0..4).map(|line| text(splash, line, 24)).collect();
    assert_eq!(
        lines,
        [
            format!("SERVOPLOT {}", env!("CARGO_PKG_VERSION")),
            "Servo pen plotter".into(),
            "0: 中文".into(),
            "Any key: menu".into()
        ]
    );
    let times: Vec<u64> = report.frames.iter().map(|(t, _)| *t).collect();
    let (_, last) = report.frames.last().unwrap();
    assert_eq!(text(last, 2, 24), ">1 Jog", "{times:?}");
}

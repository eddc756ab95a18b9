//! A card plot cut by a power loss and resumed at the next power-on, on the simulated board: the
//! card image and the flash carried from one run to the next as a real card and board keep
//! them; keys in, pulses, pen, LCD frames and the card's record out.

use servoplot::card::Card;
use servoplot::card::fat::FatCard;
use servoplot::geom::Point;
use servoplot::sim::card::{ImageBlocks, SimCard, image_of};
use servoplot::sim::flash::SimFlash;
use servoplot::sim::inputs::InputScript;
use servoplot::sim::keys::KeyScript;
use servoplot::sim::lcd::Frame;
use servoplot::sim::{self, SimConfig, SimReport};

mod support;

use support::files::{arc_file, polyline_file};
use support::text;

/// From power-on to the card mode, the first file chosen, checked, then plotted.
const PLOT_FIRST_FILE: &str = "B B B B B B B B B B # # wait:500 #";
/// At power-on, the offer answered: `#` resumes, `D` drops.
const RESUME: &str = "wait:500 #";
const DROP: &str = "wait:500 D";

fn card_of(image: Vec<u8>) -> SimCard {
    FatCard::new(ImageBlocks::new(image))
}

/// One power-on of the board with `card` and `flash`, `keys` pressed, the power cut at
/// `cut_ms` if given.
fn power_on(card: Vec<u8>, flash: SimFlash, keys: &str, cut_ms: Option<u64>) -> SimReport {
    let events = cut_ms.map_or(String::new(), |ms| format!("{ms} off power"));
    let report = sim::run(SimConfig {
        keys: KeyScript::parse(keys).unwrap(),
        events: InputScript::parse(&events).unwrap(),
        card: Some(card_of(card)),
        flash,
        ..SimConfig::default()
    });
    assert!(!report.timed_out);
    report
}

/// The points the pen passed with the pen down, in order.
fn drawn(report: &SimReport) -> Vec<Point> {
    report.strokes().into_iter().filter(|(down, _)| *down).flat_map(|(_, points)| points).collect()
}

/// The record the card keeps, if any.
fn kept_line(image: &[u8]) -> Option<u32> {
    card_of(image.to_vec()).load_resume().unwrap().map(|r| r.line)
}

fn lines(frame: &Frame) -> Vec<String> {
    (0..4).map(|line| text(frame, line, 24)).collect()
}

#[test]
fn a_plot_cut_at_any_instant_resumes_and_the_two_runs_draw_the_one_path() {
    // A vpype file lifting its pen by M3/M5 (`$213=1`).
    cut_and_resumed(&polyline_file(), "vpype.gcode");
}

#[test]
fn an_arc_file_whose_moves_set_the_pen_resumes_on_its_path() {
    // Arcs in G90 and G91, the pen set by each move (`$213=2`: up for G0, down for the rest).
    cut_and_resumed(&format!("$213=2\n{}", arc_file()), "arcs.nc");
}

/// Plots `file` (named `name` on the card) whole, then cut at three instants and resumed each
/// time: the two runs draw the whole plot's path.
fn cut_and_resumed(file: &str, name: &str) {
    let image = image_of(&[(name, file.as_bytes())]).unwrap();
    let whole = power_on(image.clone(), SimFlash::default(), PLOT_FIRST_FILE, None);
    let path = drawn(&whole);
    assert!(path.len() > 10_000, "the whole plot draws");
    assert_eq!(kept_line(whole.card_image.as_ref().unwrap()), None, "a plot that ends keeps no record");
    let first_us = whole.trace.pulses[0].t_ticks / u64::from(servoplot::geom::TICKS_PER_US);
    let plot_us = whole.last_pulse_us() - first_us;

    for share in [0.15, 0.5, 0.9] {
        let cut_ms = (first_us + (plot_us as f64 * share) as u64) / 1_000;
        let cut = power_on(image.clone(), SimFlash::default(), PLOT_FIRST_FILE, Some(cut_ms));
        let before = drawn(&cut);
        assert!(before.len() < path.len() && before[..] == path[..before.len()], "cut at {share}: on the path");
        let card = cut.card_image.clone().unwrap();
        let line = kept_line(&card).expect("the plot kept a record");
        assert!(line > 1, "cut at {share}: the record is of a line past the first: {line}");

        // The next power-on: the same card, the same flash (the file's `$213=1` is kept).
        let resumed = power_on(card, cut.flash.clone(), RESUME, None);
        let offered = resumed.frames.iter().map(|(_, f)| lines(f)).find(|l| l[0].starts_with("RESUME PLOT?"));
        let offered = offered.expect("the LCD offered the resume");
        assert_eq!(offered[1].trim_end(), name, "the file, as the list names it");
        assert!(offered[2].starts_with(&format!("from line {line}/")), "{offered:?}");
        let after = drawn(&resumed);
        assert!(!after.is_empty(), "cut at {share}: the rest is drawn");
        // The resumed run draws the rest of the path from a point the first run had reached:
        // together they draw the whole path, overlapping where the line under way was drawn
        // again, with no step missing or added at the joint.
        let joint = path.len() - after.len();
        assert!(joint <= before.len(), "cut at {share}: no gap: resumed at {joint}, cut at {}", before.len());
        assert_eq!(after[..], path[joint..], "cut at {share}: the rest of the one path");
        assert_eq!(resumed.position, whole.position, "and it ends where the whole plot ends");
        assert_eq!(kept_line(resumed.card_image.as_ref().unwrap()), None, "the plot ended: no record");
    }
}

#[test]
fn a_resume_dropped_at_power_on_moves_nothing_and_clears_the_record() {
    let file = polyline_file();
    let image = image_of(&[("vpype.gcode", file.as_bytes())]).unwrap();
    let cut = power_on(image, SimFlash::default(), PLOT_FIRST_FILE, Some(5_000));
    let card = cut.card_image.unwrap();
    assert!(kept_line(&card).is_some());
    let dropped = power_on(card, cut.flash, DROP, None);
    assert!(dropped.trace.pulses.is_empty(), "nothing moved");
    assert_eq!(kept_line(dropped.card_image.as_ref().unwrap()), None, "the record is gone");
    let end = lines(&dropped.frames.last().unwrap().1);
    assert!(!end[0].starts_with("RESUME"), "the offer is gone: {end:?}");
}

#[test]
fn a_record_of_a_file_changed_since_is_not_offered() {
    let file = polyline_file();
    let image = image_of(&[("vpype.gcode", file.as_bytes())]).unwrap();
    let cut = power_on(image, SimFlash::default(), PLOT_FIRST_FILE, Some(5_000));
    let mut card = card_of(cut.card_image.unwrap());
    let record = card.load_resume().unwrap().expect("a record");
    // The same card with the file written again, longer, and the record kept.
    let longer = format!("{file}G0 X1\n");
    let mut changed = card_of(image_of(&[("vpype.gcode", longer.as_bytes())]).unwrap());
    changed.store_resume(&mut record.clone()).unwrap();
    let report = power_on(changed.image(), cut.flash, RESUME, None);
    assert!(!report.frames.iter().any(|(_, f)| lines(f)[0].starts_with("RESUME")), "not offered");
    assert!(report.trace.pulses.is_empty(), "nothing moved");
    assert_eq!(kept_line(report.card_image.as_ref().unwrap()), None, "the stale record is cleared");
}

#[test]
fn with_homing_on_the_resume_homes_first_then_draws_the_rest_of_the_path() {
    use servoplot::sim::KeysStart;
    use servoplot::sim::inputs::Switches;
    use servoplot::sim::serial::SimSerial;
    // Switches 5 mm beyond each end of the travel; homing on (the plotter powers on locked).
    let switches = Some(Switches { beyond_travel_mm: 5.0 });
    let set_up = sim::run(SimConfig { serial: SimSerial::with_input(b"$22=1\n$213=1\n"), ..SimConfig::default() });
    let image = image_of(&[("vpype.gcode", polyline_file().as_bytes())]).unwrap();
    // Homed from the host, then the file plotted from the keypad.
    let homed_then_plotted = |cut_ms: Option<u64>| {
        let events = cut_ms.map_or(String::new(), |ms| format!("{ms} off power"));
        sim::run(SimConfig {
            serial: SimSerial::with_input(b"$H\n"),
            keys: KeyScript::parse(PLOT_FIRST_FILE).unwrap(),
            keys_start: KeysStart::AfterSerial,
            events: InputScript::parse(&events).unwrap(),
            card: Some(card_of(image.clone())),
            flash: set_up.flash.clone(),
            switches,
            ..SimConfig::default()
        })
    };
    let whole = homed_then_plotted(None);
    assert!(whole.answers().starts_with("\r\nGrbl 1.1h ['$' for help]\r\n[MSG:'$H'|'$X' to unlock]\r\nok"));
    let path = drawn(&whole);
    let cut_ms = whole.last_pulse_us() * 2 / 3 / 1_000;
    let cut = homed_then_plotted(Some(cut_ms));
    let before = drawn(&cut);

    let resumed = sim::run(SimConfig {
        keys: KeyScript::parse(RESUME).unwrap(),
        card: cut.card_image.map(card_of),
        flash: cut.flash,
        switches,
        ..SimConfig::default()
    });
    assert!(!resumed.timed_out);
    // The first pulses home: toward the min switches on both axes, with the pen up.
    let first_moves: Vec<bool> = resumed.trace.pulses.iter().take(100).map(|p| p.sign_high).collect();
    assert!(first_moves.iter().all(|high| !high), "homing first: toward the min switches");
    let after = drawn(&resumed);
    let joint = path.len() - after.len();
    assert!(joint <= before.len() && after[..] == path[joint..], "the rest of the path, in the homed coordinates");
    assert_eq!(kept_line(resumed.card_image.as_ref().unwrap()), None);
}

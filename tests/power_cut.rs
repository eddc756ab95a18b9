//! The power cut on the simulated board (`<ms> off power` in the event script): the run ends at
//! that instant, whatever it is doing; what went out before it is as without the cut, nothing
//! goes out after it, and the card is as the cut left it.

use servoplot::card::Card;
use servoplot::card::fat::FatCard;
use servoplot::geom::TICKS_PER_US;
use servoplot::sim::card::{ImageBlocks, image_of};
use servoplot::sim::inputs::InputScript;
use servoplot::sim::keys::KeyScript;
use servoplot::sim::serial::SimSerial;
use servoplot::sim::{self, SimConfig, SimReport};

mod support;

use support::files::polyline_file;

/// Streams `gcode` over the UART with the event script `events`.
fn stream(gcode: &str, events: &str) -> SimReport {
    let serial = SimSerial::with_input(gcode.as_bytes());
    let events = InputScript::parse(events).unwrap();
    let report = sim::run(SimConfig { serial, events, ..SimConfig::default() });
    assert!(!report.timed_out);
    report
}

#[test]
fn a_power_cut_mid_drawing_ends_the_run_there_with_only_the_pulses_before_it() {
    let drawing = polyline_file();
    let whole = stream(&drawing, "");
    assert_eq!(whole.power_off_us, None, "no cut");
    // Half way through the drawing, on a whole millisecond.
    let cut_ms = whole.last_pulse_us() / 2 / 1_000;
    let cut_us = cut_ms * 1_000;
    let cut = stream(&drawing, &format!("{cut_ms} off power  # the plug pulled mid-drawing"));

    assert_eq!(cut.power_off_us, Some(cut_us), "the report says the power was cut, and when");
    assert_eq!(cut.end_us, cut_us, "the run ended at the cut, no settle time after it");
    let cut_ticks = cut_us * u64::from(TICKS_PER_US);
    assert!(cut.trace.pulses.iter().all(|p| p.t_ticks < cut_ticks), "no pulse at or after the cut");
    assert!(cut.trace.sign_changes.iter().all(|s| s.t_ticks < cut_ticks), "no SIGN change after it");
    let (n_cut, n_whole) = (cut.trace.pulses.len(), whole.trace.pulses.len());
    assert!(n_cut > 1_000 && n_cut < n_whole, "drawing when cut: {n_cut} of {n_whole} pulses");
    // Up to the cut the drawing went as without it, pulse for pulse.
    assert_eq!(cut.trace.pulses[..], whole.trace.pulses[..n_cut]);
    assert!(whole.trace.pulses[n_cut].t_ticks >= cut_ticks, "and every pulse it lacks was due after the cut");
    // Nothing answered or shown after the cut; what was answered before is as without it.
    assert!(cut.serial_lines.iter().all(|(t, _)| *t < cut_us));
    assert!(cut.frames.iter().all(|(t, _)| *t < cut_us));
    assert!(whole.answers().starts_with(&cut.answers()) && cut.answers().len() < whole.answers().len());
    assert!(cut.pen.iter().all(|(t, _)| *t < cut_us));
}

#[test]
fn a_power_cut_at_power_on_runs_nothing() {
    let cut = stream(&polyline_file(), "0 off power");
    assert_eq!((cut.power_off_us, cut.end_us), (Some(0), 0));
    assert!(cut.trace.pulses.is_empty() && cut.frames.is_empty() && cut.serial_out.is_empty());
}

#[test]
fn a_power_cut_after_the_drawing_leaves_the_board_on_until_then() {
    let drawing = "G1 X10 Y5 F3000\n";
    let whole = stream(drawing, "");
    let cut_us = whole.end_us + 5_000_000;
    let cut = stream(drawing, &format!("{} off power", cut_us / 1_000));
    assert_eq!((cut.power_off_us, cut.end_us), (Some(cut_us), cut_us), "on, at rest, until the cut");
    assert_eq!(cut.trace.pulses, whole.trace.pulses, "the drawing is whole");
    assert_eq!(cut.answers(), whole.answers());
}

#[test]
fn the_card_comes_back_in_the_report_as_the_cut_left_it() {
    // A card plot cut 4 s after power-on: the card, as it was at the cut, is in the report.
    let file = polyline_file();
    let image = image_of(&[("vpype.gcode", file.as_bytes())]).unwrap();
    let card = Some(FatCard::new(ImageBlocks::new(image.clone())));
    let keys = KeyScript::parse("B B B B B B B B B B # # wait:500 #").unwrap();
    let events = InputScript::parse("4000 off power").unwrap();
    let report = sim::run(SimConfig { keys, events, card, ..SimConfig::default() });
    assert_eq!(report.power_off_us, Some(4_000_000));
    assert!(!report.trace.pulses.is_empty(), "the plot had begun");
    let kept = report.card_image.expect("the card's image");
    // The plot's resume record is on it (`card_resume.rs` resumes from such a card).
    assert_ne!(kept, image);
    let record = FatCard::new(ImageBlocks::new(kept)).load_resume().unwrap().expect("a resume record");
    assert!(record.line > 1 && record.file.as_str() == "VPYPE~1.GCO", "{record:?}");
    let no_card = stream("G1 X1 F3000\n", "");
    assert_eq!(no_card.card_image, None, "no card, no image");
}

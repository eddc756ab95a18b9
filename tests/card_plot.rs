//! G-code files plotted from a microSD card chosen on the keypad, on the simulated board: the
//! card is a FAT image each test makes; keys in, pulses, LCD frames and host answers out.

use servoplot::card::fat::FatCard;
use servoplot::geom::Point;
use servoplot::sim::card::{ImageBlocks, SimCard, image_of};
use servoplot::sim::inputs::InputScript;
use servoplot::sim::keys::KeyScript;
use servoplot::sim::lcd::Frame;
use servoplot::sim::serial::SimSerial;
use servoplot::sim::{self, SimConfig, SimReport};

mod support;

use support::files::{arc_file, polyline_file};
use support::text;

/// From power-on to the card mode: the mode list's eleventh entry, ten times `B` then `#`.
const TO_CARD: &str = "B B B B B B B B B B #";
/// Once a file is chosen (`#`) and checked: `#` plots it.
const PLOT: &str = "wait:500 #";

/// A drawing as a vector tool writes one: pen moves between strokes, straight strokes and arcs.
fn drawing() -> String {
    let mut g = String::from("G21\nG90\nF3000\n");
    for i in 0..6 {
        let (x, y) = (5 + i * 4, 3 + i * 2);
        g += &format!("G0 X{x} Y{y}\nG1 X{} Y{y}\nG1 X{} Y{}\n", x + 3, x + 3, y + 2);
        g += &format!("G2 X{x} Y{} I-1.5 J0\n", y + 2);
    }
    g + "G0 X0 Y0\n"
}

fn card(files: &[(&str, &[u8])]) -> SimCard {
    FatCard::new(ImageBlocks::new(image_of(files).expect("a FAT image")))
}

fn run_keys_with(card: Option<SimCard>, keys: &str) -> SimReport {
    sim::run(SimConfig { keys: KeyScript::parse(keys).unwrap(), card, ..SimConfig::default() })
}

/// A frame's four lines.
fn lines(frame: &Frame) -> Vec<String> {
    (0..4).map(|line| text(frame, line, 24)).collect()
}

/// Whether any frame has a line containing `what`.
fn shown(report: &SimReport, what: &str) -> bool {
    report.frames.iter().any(|(_, f)| lines(f).iter().any(|l| l.contains(what)))
}

#[test]
fn the_second_file_chosen_on_the_keypad_plots_as_it_does_over_the_wire() {
    let chosen = drawing();
    let first = "G0 X40 Y40\n";
    let files: [(&str, &[u8]); 3] =
        [("first.gcode", first.as_bytes()), ("readme.txt", b"G0 X80\n"), ("second.NC", chosen.as_bytes())];
    let report = run_keys_with(Some(card(&files)), &format!("{TO_CARD} B # {PLOT}"));
    let wire = sim::run_serial(&chosen);
    assert!(!wire.answers().contains("error"), "{}", wire.answers());
    assert_eq!(report.trace.counts(), wire.trace.counts());
    assert_eq!(report.path(), wire.path(), "the same steps in the same order");
    assert_eq!(report.position, wire.position);
    assert!(report.trace.counts().iter().sum::<u64>() > 1000, "it drew");
    // The list showed the G-code files only, and the run screen the file's progress.
    assert!(shown(&report, "first.gcode") && shown(&report, "second.NC"));
    assert!(!shown(&report, "readme"), "not a G-code file");
    let total = chosen.lines().count();
    assert!(shown(&report, &format!("{total} lines ~0:")), "the check gave the lines and the plot time");
    assert!(shown(&report, "# plot  D back"), "and waited for the user");
    assert!(shown(&report, " left 0:"), "the run screen gives the time left");
}

#[test]
fn vpype_and_arc_files_plot_from_the_card_pulse_for_pulse_as_over_the_wire() {
    for (name, file) in [("vpype.gcode", polyline_file()), ("arcs.nc", arc_file())] {
        let report = run_keys_with(Some(card(&[(name, file.as_bytes())])), &format!("{TO_CARD} # {PLOT}"));
        let wire = sim::run_serial(&file);
        assert!(!wire.answers().contains("error"), "{}", wire.answers());
        assert!(wire.trace.counts().iter().sum::<u64>() > 10_000, "{name}: it draws");
        assert_eq!(report.trace.counts(), wire.trace.counts(), "{name}: every pulse");
        assert_eq!(report.path(), wire.path(), "{name}: the same steps in the same order");
        assert_eq!(report.position, wire.position, "{name}");
    }
}

#[test]
fn a_file_that_leaves_the_travel_is_refused_before_the_pen_goes_down() {
    // Every drawing is built within the travel, soft limits on or off: the line that leaves is
    // refused with error:15, as over the wire, before the first move.
    let body = "G21\nG90\nG0 X10 Y10\nM3\nG1 X20 Y10 F3000\nG1 X900 Y10\nM5\n";
    for (head, said) in [("$213=1\n", "Line 7: error:15"), ("$213=1\n$20=0\n", "Line 8: error:15")] {
        let file = format!("{head}{body}");
        let report = run_keys_with(Some(card(&[("wide.gcode", file.as_bytes())])), &format!("{TO_CARD} # {PLOT}"));
        assert!(shown(&report, said), "the LCD says which line: {said}");
        assert!(shown(&report, "Beyond travel limits"), "and why");
        assert_eq!(report.trace.counts(), [0; 4], "nothing moved, not even the moves before it");
        assert_eq!(report.position, Point::ORIGIN);
    }
}

#[test]
fn d_leaves_a_checked_file_and_nothing_moves() {
    let chosen = drawing();
    let files: [(&str, &[u8]); 1] = [("plot.gcode", chosen.as_bytes())];
    let report = run_keys_with(Some(card(&files)), &format!("{TO_CARD} # wait:500 D wait:300 #"));
    assert!(shown(&report, "# plot  D back"), "it was shown checked");
    assert_eq!(report.trace.counts(), [0; 4], "nothing moved");
    let last = lines(&report.frames.last().expect("frames").1);
    assert!(last.iter().any(|l| l.contains("# plot  D back")), "a second `#` checked it again: {last:?}");
}

#[test]
fn a_file_with_an_error_on_line_300_is_refused_before_anything_moves() {
    let mut file = String::from("G21\nG91\n");
    // Lines 3..299: small steps right and up.
    for i in 3..300 {
        file += if i % 2 == 0 { "G1 X0.1 F3000\n" } else { "G1 Y0.1\n" };
    }
    file += "G1 X1 Y1 W5\n"; // line 300: no W axis
    file += "G0 X50\n"; // never sent
    assert_eq!(file.lines().position(|l| l.contains('W')), Some(299));
    let report = run_keys_with(Some(card(&[("bad.gcode", file.as_bytes())])), &format!("{TO_CARD} # {PLOT}"));
    assert_eq!(report.trace.counts(), [0; 4], "the check found it: nothing moved");
    assert_eq!(report.position, Point::ORIGIN);
    // The error the same line gets over the wire.
    let answers = sim::run_serial("G1 X1 Y1 W5\n").answers();
    let error = answers.lines().find(|l| l.starts_with("error:")).expect("refused over the wire");
    assert!(shown(&report, &format!("Line 300: {error}")), "the LCD names the line and the error");
    // and, below them, why in words.
    let said = report.frames.iter().map(|(_, f)| lines(f)).find(|l| l[2].starts_with("Line 300: error:"));
    let said = said.expect("the refusal on the screen");
    assert_eq!(error, "error:20");
    assert_eq!(said[3].trim_end(), "Unsupported command", "{said:?}");
}

#[test]
fn no_card_says_so_and_nothing_moves() {
    let report = run_keys_with(None, &format!("{TO_CARD} # B #"));
    assert!(shown(&report, "No card"));
    assert_eq!(report.trace.counts(), [0; 4]);
    assert_eq!(report.position, Point::ORIGIN);
}

#[test]
fn a_card_that_is_not_fat_says_so_and_nothing_moves() {
    let blank = FatCard::new(ImageBlocks::new(vec![0xA5; 2048 * 512]));
    let report = run_keys_with(Some(blank), &format!("{TO_CARD} # #"));
    assert!(shown(&report, "Card is not FAT"));
    assert_eq!(report.trace.counts(), [0; 4]);
}

#[test]
fn host_lines_are_refused_while_a_card_plot_runs_and_a_status_query_reports_its_line() {
    let chosen = drawing();
    // Typed at 4 s, while the plot runs: a status query, then a line.
    let serial = SimSerial::with_input(b"")
        .with_byte_at(4_000_000, b'?')
        .with_byte_at(4_000_100, b'G')
        .with_byte_at(4_000_200, b'0')
        .with_byte_at(4_000_300, b'\n');
    let keys = KeyScript::parse(&format!("{TO_CARD} # {PLOT}")).unwrap();
    let report = sim::run(SimConfig {
        keys,
        serial,
        card: Some(card(&[("plot.gcode", chosen.as_bytes())])),
        ..SimConfig::default()
    });
    let answers = report.answers();
    assert!(answers.contains("|Ln:"), "{answers}");
    assert!(answers.contains("error:8"), "{answers}");
    assert_eq!(report.path(), sim::run_serial(&chosen).path(), "the host's line moved nothing");
}

#[test]
fn d_aborts_a_card_plot_keeping_the_position_and_sending_nothing_more() {
    let chosen = drawing();
    let files: [(&str, &[u8]); 1] = [("plot.gcode", chosen.as_bytes())];
    let report = run_keys_with(Some(card(&files)), &format!("{TO_CARD} # {PLOT} wait:2000 D"));
    let wire = sim::run_serial(&chosen).path();
    let drawn = report.path();
    assert!(drawn.len() > 10 && drawn.len() < wire.len(), "stopped part way: {} of {}", drawn.len(), wire.len());
    assert_eq!(drawn[..], wire[..drawn.len()], "what was drawn is the file's start");
    assert_eq!(Some(&report.position), drawn.last(), "the position is where the pen stopped");
    assert!(shown(&report, "Aborted") || shown(&report, "aborted"), "the abort is said");
}

#[test]
fn a_reset_on_the_host_link_ends_a_card_plot() {
    let chosen = drawing();
    let serial = SimSerial::with_input(b"").with_byte_at(4_000_000, 0x18);
    let keys = KeyScript::parse(&format!("{TO_CARD} # {PLOT}")).unwrap();
    let card = Some(card(&[("plot.gcode", chosen.as_bytes())]));
    let report = sim::run(SimConfig { keys, serial, card, ..SimConfig::default() });
    let wire = sim::run_serial(&chosen).path();
    let drawn = report.path();
    assert!(drawn.len() > 10 && drawn.len() < wire.len(), "stopped part way: {} of {}", drawn.len(), wire.len());
    assert_eq!(drawn[..], wire[..drawn.len()], "what was drawn is the file's start");
    assert_eq!(report.answers().matches("Grbl 1.1").count(), 2, "the reset's banner: {}", report.answers());
}

#[test]
fn the_card_mode_speaks_chinese_too() {
    // 0 switches the language (the cursor then on it, the tenth mode): B # enters the card mode.
    let report = run_keys_with(None, "0 wait:300 B #");
    assert!(shown(&report, "存储卡"), "the title");
    assert!(shown(&report, "无卡"), "no card");
}

#[test]
fn the_run_screen_follows_a_card_plot_through_its_pen_lifts_and_shows_its_picture() {
    // A vpype file: strokes with pen lifts (rests) between them. `#` during the plot shows the
    // picture page: the name, the share drawn, the time left and the line beside the picture.
    let file = polyline_file();
    let keys = format!("{TO_CARD} # {PLOT} wait:4000 #");
    let report = run_keys_with(Some(card(&[("vpype.gcode", file.as_bytes())])), &keys);
    let total = file.lines().count();
    let page = report
        .frames
        .iter()
        .map(|(_, f)| lines(f))
        .find(|l| l[0].starts_with("vpype.gcode") && l[3].contains(&format!("/{total}")))
        .expect("the picture page");
    let percent: u32 = page[1].split('%').next().unwrap().trim().parse().expect("a share drawn");
    assert!((1..100).contains(&percent), "part way after 4 s, through the rests: {page:?}");
    assert!(page[2].starts_with("left "), "{page:?}");
    // The travel's outline and the strokes are on the picture, right of the text.
    let (_, frame) = report.frames.iter().find(|(_, f)| lines(f) == page).unwrap();
    let lit = (82..122).flat_map(|x| (0..32).map(move |y| (x, y))).filter(|&(x, y)| frame.pixels[y][x]).count();
    assert!(lit > 100, "the picture is drawn: {lit} pixels");
}

#[test]
fn a_card_removed_mid_plot_stops_on_the_path_lifts_the_pen_and_alarms() {
    // A vpype file, pen lifted by M3/M5; the card pulled 4 s after power-on, mid-plot.
    let file = polyline_file();
    let keys = KeyScript::parse(&format!("{TO_CARD} # {PLOT}")).unwrap();
    let events = InputScript::parse("4000 on card-out").unwrap();
    let card = Some(card(&[("vpype.gcode", file.as_bytes())]));
    let report = sim::run(SimConfig { keys, events, card, ..SimConfig::default() });
    let wire = sim::run_serial(&file).path();
    let drawn = report.path();
    assert!(drawn.len() > 100 && drawn.len() < wire.len(), "stopped part way: {} of {}", drawn.len(), wire.len());
    assert_eq!(drawn[..], wire[..drawn.len()], "every step on the file's path: a stop on the path");
    assert_eq!(Some(&report.position), drawn.last(), "the position is where the pen stopped");
    let answers = report.answers();
    assert!(answers.contains("ALARM:22\r\n[MSG:Card lost mid-plot"), "the host is told: {answers}");
    // The pen went down for the strokes, and is up (as at power-on) once stopped.
    let (first, last) = (report.pen.first().expect("pen").1, report.pen.last().expect("pen").1);
    assert!(report.pen.iter().any(|&(_, us)| us != first), "the pen went down");
    assert_eq!(last, first, "and is up at the end");
    let stop_us = report.trace.pulses.last().expect("pulses").t_us;
    let up_at = report.pen.last().unwrap().0;
    assert!(up_at >= stop_us, "lifted once stopped, not while moving");
    let end = lines(&report.frames.last().expect("frames").1);
    assert!(end[0].starts_with("vpype.gcode") && end[0].contains("ALARM"), "the run screen says ALARM: {end:?}");
    assert!(end[3].starts_with("No card"), "and why: {end:?}");
}

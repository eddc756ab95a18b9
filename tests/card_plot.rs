//! G-code files plotted from a microSD card chosen on the keypad, on the simulated board: the
//! card is a FAT image each test makes; keys in, pulses, LCD frames and host answers out.

use servoplot::card::fat::FatCard;
use servoplot::geom::Point;
use servoplot::sim::card::{ImageBlocks, SimCard, image_of};
use servoplot::sim::keys::KeyScript;
use servoplot::sim::lcd::Frame;
use servoplot::sim::serial::SimSerial;
use servoplot::sim::{self, SimConfig, SimReport};

mod support;

use support::text;

/// From power-on to the card mode: the mode list's eleventh entry, ten times `B` then `#`.
const TO_CARD: &str = "B B B B B B B B B B #";

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
    let report = run_keys_with(Some(card(&files)), &format!("{TO_CARD} B #"));
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
    assert!(shown(&report, &format!("/{total}")), "the run screen counts the file's lines");
}

#[test]
fn a_file_with_an_error_on_line_300_stops_there_and_says_so() {
    let mut file = String::from("G21\nG91\n");
    // Lines 3..299: small steps right and up.
    for i in 3..300 {
        file += if i % 2 == 0 { "G1 X0.1 F3000\n" } else { "G1 Y0.1\n" };
    }
    let good = file.clone();
    file += "G1 X1 Y1 W5\n"; // line 300: no W axis
    file += "G0 X50\n"; // never sent
    assert_eq!(file.lines().position(|l| l.contains('W')), Some(299));
    let report = run_keys_with(Some(card(&[("bad.gcode", file.as_bytes())])), &format!("{TO_CARD} #"));
    let wire = sim::run_serial(&good);
    assert_eq!(report.path(), wire.path(), "every line before it, nothing after");
    assert_eq!(report.position, wire.position);
    // The error the same line gets over the wire.
    let answers = sim::run_serial("G1 X1 Y1 W5\n").answers();
    let error = answers.lines().find(|l| l.starts_with("error:")).expect("refused over the wire");
    assert!(shown(&report, &format!("Line 300: {error}")), "the LCD names the line and the error");
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
    let keys = KeyScript::parse(&format!("{TO_CARD} #")).unwrap();
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
    let report = run_keys_with(Some(card(&files)), &format!("{TO_CARD} # wait:2000 D"));
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
    let keys = KeyScript::parse(&format!("{TO_CARD} #")).unwrap();
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

//! The LCD's preview and run screen, read from the frames the simulated ST7920 showed: the text
//! is read back glyph by glyph in the 5x7 font, the preview pixel by pixel.

use embedded_graphics::prelude::{Point as Px, Size};
use embedded_graphics::primitives::Rectangle;
use servoplot::panel::trail::{self, Trail};
use servoplot::sim::{self, lcd::Frame};

mod support;

use support::{Canvas, H, W, text};

/// Lit pixels of `frame` in columns `x0..`.
fn lit_right_of(frame: &Frame, x0: usize) -> Vec<(usize, usize)> {
    (0..H).flat_map(|y| (x0..W).map(move |x| (x, y))).filter(|&(x, y)| frame.pixels[y][x]).collect()
}

const ELLIPSE: &str = "4 3 0 # 1 5 # # # #";

#[test]
fn the_preview_shows_the_planned_curve_before_it_is_drawn() {
    // The form's last # builds the ellipse and shows it; nothing moves until the next #.
    let shown = sim::run_keys("4 3 0 # 1 5 # # # wait:3000").unwrap();
    assert_eq!(shown.trace.counts(), [0, 0, 0, 0], "nothing moved");
    let (_, last) = shown.frames.last().unwrap();
    assert_eq!(text(last, 0, 13), "Ellipse 30x15");
    assert!(text(last, 1, 13).starts_with("Time ~0:0"), "{}", text(last, 1, 13));
    assert_eq!((text(last, 2, 13).as_str(), text(last, 3, 13).as_str()), ("# draw", "D back"));
    // A 30x15 ellipse is twice as wide as high: its dotted outline spans the 56-pixel box.
    let px = lit_right_of(last, 66);
    let (xs, ys): (Vec<usize>, Vec<usize>) = px.iter().copied().unzip();
    let (w, h) =
        (xs.iter().max().unwrap() - xs.iter().min().unwrap(), ys.iter().max().unwrap() - ys.iter().min().unwrap());
    assert!((50..=54).contains(&w) && (25..=28).contains(&h), "{w}x{h}");
    // D goes back to the form as typed.
    let back = sim::run_keys("4 3 0 # 1 5 # # # D").unwrap();
    assert_eq!(text(&back.frames.last().unwrap().1, 0, 24), format!("{:<20}IDLE", "ELLIPSE 4/4"));
}

#[test]
fn while_drawing_the_preview_follows_the_emitted_steps_and_the_end_screen_stays() {
    let report = sim::run_keys(&format!("{ELLIPSE} wait:6000")).unwrap();
    let path = report.path();
    assert_eq!(report.position, servoplot::geom::Point::ORIGIN, "the ellipse closed");
    // The last frame: the end screen, with the whole path drawn beside the numbers.
    let (_, end) = report.frames.last().unwrap();
    assert_eq!(text(end, 0, 18), "Ellipse 30x15 DONE");
    assert!(text(end, 2, 18).starts_with("Plot time 0:0"), "{}", text(end, 2, 18));
    // The preview is the emitted path: drawn from every step, at the screen's scale, it covers
    // what the glass shows within a pixel.
    let mut emitted = Trail::new();
    for p in &path {
        emitted.sample(*p, true);
    }
    let area = Rectangle::new(Px::new(94, 0), Size::new(28, 32));
    let mut expected = Canvas([[false; W]; H]);
    trail::draw(&mut expected, area, None, Some(&emitted), Some(report.position)).unwrap();
    let shown: Vec<(usize, usize)> = lit_right_of(end, 94);
    let near = |&(x, y): &(usize, usize)| {
        (x.saturating_sub(1)..=(x + 1).min(W - 1))
            .any(|xx| (y.saturating_sub(1)..=(y + 1).min(H - 1)).any(|yy| expected.0[yy][xx]))
    };
    let off = shown.iter().filter(|p| !near(p)).count();
    assert!(shown.len() > 40, "the path is drawn: {} pixels", shown.len());
    assert!(off * 20 <= shown.len(), "{off} of {} lit pixels are off the emitted path", shown.len());
}

#[test]
fn progress_rises_and_the_time_left_falls_to_zero() {
    let report = sim::run_keys(&format!("{ELLIPSE} wait:6000")).unwrap();
    let mut seen = Vec::new();
    for (t, frame) in &report.frames {
        let line = text(frame, 2, 18);
        // "42% 0:01 left 0:02"
        let Some((pct, rest)) = line.split_once("% ") else { continue };
        let Ok(pct) = pct.parse::<u32>() else { continue };
        let secs = |s: &str| {
            let (m, s) = s.split_once(':').unwrap();
            m.parse::<u32>().unwrap() * 60 + s.parse::<u32>().unwrap()
        };
        let (elapsed, left) = rest.split_once(" left ").unwrap();
        seen.push((*t, pct, secs(elapsed), secs(left)));
    }
    assert!(seen.len() > 10, "the run screen was shown while drawing: {seen:?}");
    assert!(seen.windows(2).all(|w| w[1].1 >= w[0].1), "progress never falls: {seen:?}");
    assert!(seen.windows(2).all(|w| w[1].2 >= w[0].2), "elapsed never falls: {seen:?}");
    let (first, last) = (seen[0], *seen.last().unwrap());
    assert!(first.1 <= 5 && last.1 >= 90, "from near 0 % to near 100 %: {seen:?}");
    assert!(first.3 >= 2 && last.3 == 0, "the time left falls to 0: {seen:?}");
    // The time left is never off by more than a second from the time the drawing really took.
    let end_s = report.last_pulse_us() / 1_000_000;
    for &(t, _, _, left) in &seen {
        let really = end_s.saturating_sub(t / 1_000_000) as u32;
        assert!(left.abs_diff(really) <= 1, "at {t} µs: {left} s left, really {really}: {seen:?}");
    }
}

#[test]
fn every_write_of_a_whole_session_reaches_the_lcd_at_the_controllers_pace() {
    // Start-up, menu, preview, run screen and end screen: every write the driver made, timed on
    // the simulated link, came at least 72 µs after the one before (1.6 ms after a clear).
    let report = sim::run_keys(&format!("{ELLIPSE} wait:6000")).unwrap();
    assert!(report.frames.len() > 20, "{} pictures", report.frames.len());
    assert_eq!(report.lcd_writes_too_soon, 0);
}

use std::boxed::Box;
use std::string::String;
use std::vec::Vec;

use embedded_graphics::geometry::{OriginDimensions, Point as ScreenPoint, Size};
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_graphics::prelude::DrawTarget;

use super::check::{CheckPlanner, PLAN_SLICE_STEPS, ProgramCheck, Progress, Refusal, Summary};
use super::preview::{self, MapScale, PREVIEW_HEIGHT_PX, PREVIEW_WIDTH_PX, PlotProgress};
use crate::geom::Point;
use crate::host::{GcodeState, GrblError, report};
use crate::machine_io::pen::Pen;
use crate::motion::drawing::BUILD_SLICE_STEPS;
use crate::motion::interp::Method;
use crate::motion::planner::Limits;
use crate::settings::Settings;

/// Checks `program` with `settings` from machine zero, the pen up; the outcome, the summary,
/// the check (for its picture) and the calls of `work` it took.
fn check(program: &str, settings: &Settings) -> (Progress, Summary, Box<ProgramCheck>, usize) {
    let mut planner: Box<CheckPlanner> = Box::new(CheckPlanner::new(Limits::from_settings(settings)));
    let mut check = Box::new(ProgramCheck::new(GcodeState::new(), settings, Pen::Up));
    check.start(GcodeState::new(), settings, Pen::Up, &mut planner);
    let mut calls = 0;
    let mut run = |check: &mut ProgramCheck| {
        loop {
            calls += 1;
            match check.work(&mut planner) {
                Progress::Working => {}
                done => return done,
            }
        }
    };
    for line in program.lines() {
        assert!(check.push_line(line));
        if let Progress::Refused(r) = run(&mut check) {
            let summary = check.summary();
            return (Progress::Refused(r), summary, check, calls);
        }
    }
    assert!(check.end());
    let done = run(&mut check);
    let summary = check.summary();
    (done, summary, check, calls)
}

fn pen_lift() -> Settings {
    Settings { pen_lift: 2, ..Settings::default() }
}

/// What the host link would answer the refusal with.
fn answer(r: Refusal) -> String {
    let mut out = String::new();
    report::error(&mut out, r.error).unwrap();
    out
}

#[test]
fn the_first_bad_line_is_refused_with_its_number_and_the_hosts_answer() {
    let program = "G21\nG0 X10\nG1 X20 Y5 Y6 F600\nG1 X30\n";
    let (done, summary, _, _) = check(program, &Settings::default());
    let refusal = Refusal { line: 3, error: GrblError::RepeatedWord };
    assert_eq!(done, Progress::Refused(refusal));
    assert_eq!(answer(refusal), "error:25\r\n");
    assert_eq!(summary.lines, 3, "the check stops at the bad line");
}

#[test]
fn a_curve_that_cannot_be_drawn_is_refused_with_the_builders_message() {
    // A function undefined part way: found by the walk, as `$C` finds it.
    let program = "G0 X0 Y0\n$F X-1 U1 F600 Y=sqrt(x)\n";
    let (done, _, _, _) = check(program, &Settings::default());
    let Progress::Refused(r) = done else { panic!("accepted: {done:?}") };
    assert_eq!(r.line, 2);
    let text = answer(r);
    assert!(text.ends_with("error:33\r\n") && text.starts_with("[MSG:"), "{text}");
}

#[test]
fn a_program_that_leaves_the_travel_is_refused_before_anything_moves() {
    let settings = Settings::default();
    let beyond = settings.max_travel_mm[0] + 5.0;
    let program = std::format!("G1 X10 Y10 F1000\nG1 X20\nG1 X{beyond}\nG1 X0 Y0\n");
    let (done, _, _, _) = check(&program, &settings);
    let refusal = Refusal { line: 3, error: GrblError::TravelExceeded };
    assert_eq!(done, Progress::Refused(refusal));
    assert_eq!(answer(refusal), "error:15\r\n");
}

#[test]
fn a_session_command_in_a_program_is_refused_as_not_idle() {
    for (line, what) in [("$X", "unlock"), ("$C", "check mode"), ("$RST=$", "restore")] {
        let (done, _, _, _) = check(&std::format!("G0 X1\n{line}\nG0 X2\n"), &Settings::default());
        assert_eq!(done, Progress::Refused(Refusal { line: 2, error: GrblError::NotIdle }), "{what}");
    }
}

#[test]
fn the_summary_gives_lines_boxes_and_travel() {
    let settings = pen_lift();
    let spm = settings.steps_per_mm;
    let program = "G21 G90\nG0 X-30 Y-20\nG1 X10 Y-20 F1200\nG1 X10 Y15\nG0 X40 Y40\n\nM2\n";
    let (done, summary, _, _) = check(program, &settings);
    assert_eq!(done, Progress::Done);
    assert_eq!(summary.lines, 7);
    let at = |x: f32, y: f32| Point::new((x * spm[0]) as i32, (y * spm[1]) as i32);
    let strokes = summary.strokes.expect("strokes");
    assert_eq!((strokes.min, strokes.max), (at(-30.0, -20.0), at(10.0, 15.0)), "pen-down moves only");
    let motion = summary.motion.expect("motion");
    assert_eq!((motion.min, motion.max), (at(-30.0, -20.0), at(40.0, 40.0)), "every move");
    assert!(summary.within_travel);
    assert_eq!(summary.strokes_size_mm(&settings), Some([40.0, 35.0]));
}

#[test]
fn the_plot_time_adds_dwells_and_pen_settles_to_the_planners_steps() {
    let settings = pen_lift();
    let (_, moves, _, _) = check("G1 X20 F600\n", &settings);
    let (_, with_dwell, _, _) = check("G1 X20 F600\nG4 P1.5\n", &settings);
    // 20 mm at 10 mm/s, with the ramps: a little over 2 s; the pen goes down once first.
    let settle_us = u64::from(settings.pen_settle_ms) * 1000;
    let moving = moves.plot_time_us - settle_us;
    assert!((2_000_000..2_200_000).contains(&moving), "{moving} µs");
    assert_eq!(with_dwell.plot_time_us, moves.plot_time_us + 1_500_000);
    let (_, two_strokes, _, _) = check("G1 X20 F600\nG0 X20 Y10\nG1 X0 Y10\n", &settings);
    assert!(two_strokes.plot_time_us > moves.plot_time_us + 3 * settle_us, "down, up, down");
}

#[test]
fn a_long_curve_is_checked_a_bounded_slice_at_a_time() {
    // A circle of 50 mm radius: 40,000 steps one axis at a time (eight times the radius in
    // steps), far more than one call walks or plans.
    let settings = Settings { method: Method::Classic, ..Settings::default() };
    let (done, summary, _, calls) = check("$O R50 F3000\n", &settings);
    assert_eq!(done, Progress::Done);
    let steps = 8 * 50 * settings.steps_per_mm[0] as usize;
    let slices = steps / BUILD_SLICE_STEPS as usize + steps / PLAN_SLICE_STEPS;
    assert!(calls >= slices, "{calls} calls for {slices} slices' worth");
    assert!(summary.plot_time_us > 6_000_000, "{} µs", summary.plot_time_us);
}

#[test]
fn a_line_is_taken_only_when_the_check_waits_for_one() {
    let settings = Settings::default();
    let mut planner: Box<CheckPlanner> = Box::new(CheckPlanner::new(Limits::from_settings(&settings)));
    let mut check = Box::new(ProgramCheck::new(GcodeState::new(), &settings, Pen::Up));
    check.start(GcodeState::new(), &settings, Pen::Up, &mut planner);
    assert!(check.push_line("$O R20"));
    assert!(!check.push_line("G0 X1"), "the circle is not walked yet");
    while check.work(&mut planner) == Progress::Working {}
    assert!(check.push_line("G0 X1"));
    assert_eq!(check.summary().lines, 2);
}

/// A 122x32 screen of pixels.
struct Screen(Vec<bool>);

impl Screen {
    fn new() -> Screen {
        Screen(std::vec![false; usize::from(PREVIEW_WIDTH_PX) * usize::from(PREVIEW_HEIGHT_PX)])
    }

    fn at(&self, x: i32, y: i32) -> bool {
        self.0[y as usize * usize::from(PREVIEW_WIDTH_PX) + x as usize]
    }

    fn lit(&self) -> usize {
        self.0.iter().filter(|p| **p).count()
    }
}

impl OriginDimensions for Screen {
    fn size(&self) -> Size {
        Size::new(u32::from(PREVIEW_WIDTH_PX), u32::from(PREVIEW_HEIGHT_PX))
    }
}

impl DrawTarget for Screen {
    type Color = BinaryColor;
    type Error = core::convert::Infallible;

    fn draw_iter<I: IntoIterator<Item = embedded_graphics::Pixel<BinaryColor>>>(
        &mut self,
        pixels: I,
    ) -> Result<(), Self::Error> {
        for embedded_graphics::Pixel(p, c) in pixels {
            if (0..i32::from(PREVIEW_WIDTH_PX)).contains(&p.x) && (0..i32::from(PREVIEW_HEIGHT_PX)).contains(&p.y) {
                self.0[p.y as usize * usize::from(PREVIEW_WIDTH_PX) + p.x as usize] = c.is_on();
            }
        }
        Ok(())
    }
}

fn picture(check: &ProgramCheck, progress: Option<&PlotProgress>) -> Screen {
    let mut screen = Screen::new();
    preview::draw(&mut screen, ScreenPoint::zero(), check.scale(), check.strokes_map(), progress).unwrap();
    screen
}

/// The travel's outline alone.
fn outline_only(scale: &MapScale) -> Screen {
    let mut screen = Screen::new();
    preview::draw(&mut screen, ScreenPoint::zero(), scale, &preview::StrokeMap::new(), None).unwrap();
    screen
}

const SQUARE: &str = "G0 X-100 Y-100\nG1 X100 Y-100 F3000\nG1 X100 Y100\nG1 X-100 Y100\nG1 X-100 Y-100\nG0 X0 Y0\n";

#[test]
fn a_square_shows_its_four_edges_inside_the_travels_outline() {
    let settings = pen_lift();
    let (done, _, check, _) = check(SQUARE, &settings);
    assert_eq!(done, Progress::Done);
    let screen = picture(&check, None);
    // The travel (±200 mm square) is the screen's height, 31 pixels, centred in the picture's
    // right 40 columns: columns 86 to 117; its middle, machine zero, is pixel (101.5, 15.5); the
    // square (±100 mm) is half of it.
    let ((x0, y0), (x1, y1)) = check.scale().outline();
    assert_eq!(((x0, y0), (x1, y1)), ((86, 0), (117, 31)));
    for x in [x0, x1].map(i32::from) {
        assert!((0..32).all(|y| screen.at(x, y)), "the outline's side at column {x}");
    }
    let (left, right, top, bottom) = (94, 109, 8, 23);
    for x in left..=right {
        assert!(screen.at(x, top) && screen.at(x, bottom), "top and bottom edges at column {x}");
    }
    for y in top..=bottom {
        assert!(screen.at(left, y) && screen.at(right, y), "left and right edges at row {y}");
    }
    let inside = (left + 1..right).flat_map(|x| (top + 1..bottom).map(move |y| (x, y)));
    assert!(inside.clone().all(|(x, y)| !screen.at(x, y)), "nothing inside the square");
    let edges = 2 * (right - left + 1) + 2 * (bottom - top - 1);
    assert_eq!(screen.lit(), outline_only(check.scale()).lit() + edges as usize, "nothing else");
}

#[test]
fn a_program_with_pen_up_moves_only_shows_no_strokes() {
    let settings = pen_lift();
    let (done, summary, check, _) = check("G0 X-100 Y-100\nG0 X100 Y50\nG0 X0 Y0\n", &settings);
    assert_eq!(done, Progress::Done);
    assert_eq!(summary.strokes, None);
    assert!(summary.motion.is_some());
    assert!(check.strokes_map().is_empty());
    assert_eq!(picture(&check, None).0, outline_only(check.scale()).0, "the outline alone");
}

#[test]
fn during_a_plot_the_drawn_part_is_solid_the_rest_dotted_and_the_pen_marked() {
    let settings = pen_lift();
    let (_, _, check, _) = check(SQUARE, &settings);
    let spm = settings.steps_per_mm;
    let at = |x: f32, y: f32| Point::new((x * spm[0]) as i32, (y * spm[1]) as i32);
    let mut progress = PlotProgress::new(*check.scale());
    // The pen went to the corner pen up, drew the bottom edge, and is half way up the right.
    progress.pen_at(at(-100.0, -100.0), false);
    progress.pen_at(at(100.0, -100.0), true);
    progress.pen_at(at(100.0, 0.0), true);
    let screen = picture(&check, Some(&progress));
    assert!((94..=109).all(|x| screen.at(x, 23)), "the bottom edge drawn: solid");
    let top: Vec<bool> = (94..=109).map(|x| screen.at(x, 8)).collect();
    assert!(top.iter().step_by(2).all(|p| !*p) || top.iter().skip(1).step_by(2).all(|p| !*p), "dotted: {top:?}");
    assert!(top.iter().any(|p| *p), "but shown");
    // The pen at (100, 0) mm: pixel (101.5 + 7.75, 15.5) rounded, a hollow square around it.
    assert_eq!(progress.pen(), Some((109, 16)));
    let (px, py) = (109, 16);
    assert!(!screen.at(px, py), "the mark's middle is dark");
    for (dx, dy) in [(-1, -1), (1, -1), (-1, 1), (1, 1), (-1, 0), (0, 1)] {
        assert!(screen.at(px + dx, py + dy), "mark pixel ({dx}, {dy})");
    }
}

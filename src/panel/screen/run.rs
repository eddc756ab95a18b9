//! The screens of a drawing: its preview before it starts, and the run screen while it is drawn
//! and once it is done.
//!
//! ```text
//! Ellipse 30x15  ....   the preview: name, the planner's time,
//! Time ~0:42    :    :  the keys; the planned path on the right,
//! # draw         ....   the pen marked
//! D back
//!
//! Ellipse 30x15  RUN |  the run screen's first page: name and state,
//! X  12.340 Y  -3.000|  the pen in work coordinates, progress,
//! 42% 0:12 left 0:17 |  elapsed and time left (for a keypad
//! F2990 mm/min 100%  |  drawing; the lines queued for the host's),
//!                       the pen's speed and the feed override
//! ```
//!
//! `#` shows the path over the whole screen, then machine coordinates with the keys. Once the
//! machine is at rest the first page says DONE (ALARM if an alarm stopped it) and gives the
//! plot time, until a key.

use core::fmt::{self, Write};

use heapless::String;

use embedded_graphics::geometry::{Point, Size};
use embedded_graphics::primitives::Rectangle;

use super::lines::{CardMark, Live, PreviewBox, ScreenView, TextLine, position_in, state_name};
use crate::card::CardProgress;
use crate::decimal::{Int, write_digits};
use crate::panel::language::Language;
use crate::panel::layout::{
    PREVIEW_BESIDE_WIDTH_PX, PREVIEW_CONFIRM_WIDTH_PX, SCREEN_CHAR_WIDTH_PX, SCREEN_COLUMNS, SCREEN_HEIGHT_PX,
    SCREEN_LINES, SCREEN_MARGIN_PX, SCREEN_WIDTH_PX,
};
use crate::panel::menu::Menu;
use crate::panel::run::{JOB_NAME_CHARS, Plan, Run, RunPage};
use crate::panel::texts::{Msg, Say};
use crate::panel::trail::Trail;
use crate::program::preview::PICTURE_WIDTH_PX;
use crate::program::preview::PlotProgress;
use crate::settings::Settings;
use crate::status::{RunState, Status};
use crate::text::Padded;

/// Characters of text left of a preview `width_px` wide.
const fn columns_beside(width_px: u32) -> usize {
    ((SCREEN_WIDTH_PX - width_px - SCREEN_MARGIN_PX) / SCREEN_CHAR_WIDTH_PX) as usize
}

/// The box of a preview `width_px` wide at the right edge.
fn right_box(width_px: u32) -> Rectangle {
    Rectangle::new(Point::new((SCREEN_WIDTH_PX - width_px) as i32, 0), Size::new(width_px, SCREEN_HEIGHT_PX))
}

fn line(args: fmt::Arguments) -> TextLine {
    TextLine::new(args, false)
}

/// A time as `m:ss` (minutes beyond 59 as they are).
pub(super) struct Clock(pub(super) u32);

impl fmt::Display for Clock {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = self.0 / 1000;
        write!(f, "{}:", Int::from(s / 60))?;
        write_digits(f, u64::from(s % 60), 2)
    }
}

/// A drawing built and not started: its planned path, its name and time, and the keys.
pub(super) fn preview_view(plan: &Plan, status: &Status, language: Language) -> ScreenView {
    let w = columns_beside(PREVIEW_CONFIRM_WIDTH_PX);
    ScreenView {
        lines: [
            TextLine::new(format_args!("{}", Padded::left(&plan.name, w)), true),
            line(format_args!("{} ~{}", Say(Msg::Time, language), Clock(plan.estimate_ms))),
            TextLine::say(Msg::KeysDraw, language),
            TextLine::say(Msg::KeysBack, language),
        ],
        preview: Some(PreviewBox {
            area: right_box(PREVIEW_CONFIRM_WIDTH_PX),
            plan: true,
            drawn_points: 0,
            drawn_last: None,
            pen: Some(status.position),
            card: None,
        }),
    }
}

/// Beside a card file's picture: its name, the share drawn, the time left and the line.
fn card_progress_lines(
    menu: &Menu,
    run: &Run,
    status: &Status,
    live: &Live,
    name: &str,
    language: Language,
) -> [TextLine; SCREEN_LINES] {
    let say = |msg| Say(msg, language);
    let w = columns_beside(u32::from(PICTURE_WIDTH_PX));
    let percent = run.percent(status.emitted_steps).unwrap_or(0);
    let left = run.left_ms(status.emitted_steps, status.overrides.feed_percent, live.now_ms).unwrap_or(0);
    let line_of = match menu.card_progress() {
        CardProgress::Plotting { done, total } => {
            line(format_args!("{} {}/{}", say(Msg::CardLine), Int::from(done), Int::from(total)))
        }
        _ => TextLine::default(),
    };
    [
        TextLine::new(format_args!("{}", Padded::left(name, w)), true),
        line(format_args!("{}% {}", Int::from(percent), Clock(run.elapsed_ms(live.now_ms)))),
        line(format_args!("{} {}", say(Msg::Left), Clock(left))),
        line_of,
    ]
}

/// The run screen, on the menu's page.
pub(super) fn run_view(menu: &Menu, run: &Run, status: &Status, settings: &Settings, live: &Live) -> ScreenView {
    let done = run.ended_ms.is_some();
    let language = settings.language;
    let say = |msg| Say(msg, language);
    let state = say(match status.state {
        // Stopped by an alarm: not done, and locked until unlocked.
        RunState::Alarm => Msg::StateAlarm,
        _ if done => Msg::Done,
        // Confirmed, waiting for the servos or the pen (short, so the name keeps its figures).
        RunState::Idle => Msg::Go,
        _ => state_name(status),
    });
    let mut gcode: String<JOB_NAME_CHARS> = String::new();
    let card_file = menu.card_choice().filter(|_| menu.card_progress() != CardProgress::None);
    let name = match (&run.plan, &card_file) {
        (Some(plan), _) => plan.name.as_str(),
        (None, Some(file)) => file.name.as_str(),
        (None, None) => {
            let _ = write!(gcode, "{}", say(Msg::NameGcode));
            gcode.as_str()
        }
    };
    let preview = |area| PreviewBox {
        area,
        plan: run.plan.is_some(),
        drawn_points: live.drawn.map_or(0, |d| d.points().len()),
        drawn_last: live.drawn.and_then(Trail::last),
        pen: Some(status.position),
        card: None,
    };
    // A card file's plot shows its picture on the whole screen's page, its progress beside it.
    let card = live.picture.map(|p| CardMark { pen: p.progress.as_ref().and_then(PlotProgress::pen) });
    match menu.run_page() {
        RunPage::Preview => ScreenView {
            lines: match card {
                Some(_) => card_progress_lines(menu, run, status, live, name, language),
                None => Default::default(),
            },
            preview: Some(PreviewBox {
                card,
                ..preview(Rectangle::new(Point::zero(), Size::new(SCREEN_WIDTH_PX, SCREEN_HEIGHT_PX)))
            }),
        },
        RunPage::Machine => {
            let w = SCREEN_COLUMNS - state.columns();
            ScreenView {
                lines: [
                    TextLine::new(format_args!("{}{state}", Padded::left(name, w)), true),
                    position_in(status, settings, live.work_offset_mm, Some(say(Msg::Work)), 9),
                    position_in(status, settings, [0.0; 2], Some(say(Msg::Machine)), 9),
                    TextLine::say(if done { Msg::KeysAny } else { Msg::KeysRun }, language),
                ],
                preview: None,
            }
        }
        RunPage::Numbers => {
            let columns = columns_beside(PREVIEW_BESIDE_WIDTH_PX);
            let w = columns - state.columns() - 1;
            let elapsed = Clock(run.elapsed_ms(live.now_ms));
            let progress = match (done, run.percent(status.emitted_steps)) {
                (true, _) => line(format_args!("{} {elapsed}", say(Msg::PlotTime))),
                (false, Some(percent)) => {
                    let feed = status.overrides.feed_percent;
                    let left = run.left_ms(status.emitted_steps, feed, live.now_ms).unwrap_or(0);
                    line(format_args!("{}% {elapsed} {} {}", Int::from(percent), say(Msg::Left), Clock(left)))
                }
                (false, None) => match menu.card_progress() {
                    CardProgress::Plotting { done, total } => {
                        line(format_args!("{elapsed} {} {}/{}", say(Msg::CardLine), Int::from(done), Int::from(total)))
                    }
                    _ => line(format_args!("{elapsed}  {} {}", Int::from(status.queued_jobs), say(Msg::Queued))),
                },
            };
            let speed = if done { 0 } else { (live.speed_mm_per_min + 0.5) as i32 };
            ScreenView {
                lines: [
                    TextLine::new(format_args!("{} {state}", Padded::left(name, w)), true),
                    position_in(status, settings, live.work_offset_mm, None, 7),
                    progress,
                    line(format_args!("F{} mm/min {}%", Int::from(speed), Int::from(status.overrides.feed_percent))),
                ],
                preview: Some(preview(right_box(PREVIEW_BESIDE_WIDTH_PX))),
            }
        }
    }
}

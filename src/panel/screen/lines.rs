//! The pieces every screen is made of: text lines, the preview's box, the view compared between
//! frames, what the LCD task adds to it, and the position and state as the screens write them.

use core::fmt::{self, Write};

use embedded_graphics::primitives::Rectangle;
use heapless::String;

use crate::card::CardPicture;
use crate::geom::{self, Axis};
use crate::panel::language::Language;
use crate::panel::layout::{SCREEN_COLUMNS, SCREEN_LINES};
use crate::panel::texts::{Msg, Say};
use crate::panel::trail::Trail;
use crate::program::preview::Pixel8;
use crate::settings::Settings;
use crate::status::{RunState, Status};
use crate::text::Padded;

/// Widest position value shown (`-500.000`, or fewer decimals for larger values).
const POSITION_CHARS: usize = 9;

/// One line of text; longer text is cut at [`SCREEN_COLUMNS`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct TextLine {
    pub text: String<SCREEN_COLUMNS>,
    /// Light text on a dark bar.
    pub inverted: bool,
}

impl TextLine {
    pub(super) fn new(args: fmt::Arguments, inverted: bool) -> Self {
        let mut line = TextLine { text: String::new(), inverted };
        let _ = Cut(&mut line.text).write_fmt(args);
        line
    }

    /// `msg` in `language`, not inverted.
    pub(super) fn say(msg: Msg, language: Language) -> Self {
        TextLine::new(format_args!("{}", Say(msg, language)), false)
    }

    /// `text` as it is, not inverted.
    pub(super) fn plain(text: &str) -> Self {
        let mut line = TextLine::default();
        let _ = Cut(&mut line.text).write_str(text);
        line
    }
}

/// Where a path is shown and what it shows: the plan (the preview's, or the run's), the path
/// drawn so far (as many points, the last one given), and the pen; or, for a card file, its
/// picture instead.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PreviewBox {
    pub area: Rectangle,
    pub plan: bool,
    pub drawn_points: usize,
    pub drawn_last: Option<geom::Point>,
    pub pen: Option<geom::Point>,
    /// The card file's picture ([`Live::picture`]) is shown, not the paths.
    pub card: Option<CardMark>,
}

/// The card file's picture as shown: where its pen is marked (during a plot), so the view
/// changes when the pen moves on the picture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CardMark {
    pub pen: Option<Pixel8>,
}

/// Everything the screen shows; equal views draw identical frames (for the same plan and path).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ScreenView {
    pub lines: [TextLine; SCREEN_LINES],
    pub preview: Option<PreviewBox>,
}

/// What the LCD task knows besides the menu, the status and the settings.
#[derive(Clone, Copy, Debug)]
pub struct Live<'a> {
    /// The LCD task's clock, ms (wrapping).
    pub now_ms: u32,
    /// How fast the pen moves now.
    pub speed_mm_per_min: f32,
    /// Machine = work + offset, mm.
    pub work_offset_mm: [f32; 2],
    /// The path drawn in the current run.
    pub drawn: Option<&'a Trail>,
    /// The card file's picture, while one is checked or plotted.
    pub picture: Option<&'a CardPicture>,
}

impl Live<'_> {
    /// At time zero, at rest, work = machine coordinates, nothing drawn.
    pub const NONE: Live<'static> =
        Live { now_ms: 0, speed_mm_per_min: 0.0, work_offset_mm: [0.0; 2], drawn: None, picture: None };
}

/// Writes into a fixed string, silently cutting what does not fit.
pub(super) struct Cut<'a, const N: usize>(pub(super) &'a mut String<N>);

impl<const N: usize> Write for Cut<'_, N> {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        for c in s.chars() {
            if self.0.push(c).is_err() {
                break;
            }
        }
        Ok(())
    }
}

pub(super) fn state_name(status: &Status) -> Msg {
    match status.state {
        RunState::Idle => Msg::StateIdle,
        RunState::Run => Msg::StateRun,
        RunState::Hold if status.door => Msg::StateDoor,
        RunState::Hold => Msg::StateHold,
        RunState::Jog => Msg::StateJog,
        RunState::Alarm => Msg::StateAlarm,
        RunState::Check => Msg::StateCheck,
        RunState::Sleep => Msg::StateSleep,
        RunState::Home => Msg::StateHome,
    }
}

/// The pen's position in work coordinates (`offset_mm` the work offset), or in machine
/// coordinates with no offset, `width` characters a value at most.
pub(super) fn position_line(status: &Status, settings: &Settings, offset_mm: [f32; 2]) -> TextLine {
    position_in(status, settings, offset_mm, None, POSITION_CHARS)
}

/// [`position_line`] after `prefix` (if any) and a space, each value at most `width` characters.
pub(super) fn position_in(
    status: &Status,
    settings: &Settings,
    offset_mm: [f32; 2],
    prefix: Option<Say>,
    width: usize,
) -> TextLine {
    let x = mm_text(settings.steps_to_mm(Axis::X, status.position.x) - offset_mm[0], width);
    let y = mm_text(settings.steps_to_mm(Axis::Y, status.position.y) - offset_mm[1], width);
    // Inverted while the position may be wrong: until homed.
    let (x, y) = (Padded::right(&x, width), Padded::right(&y, width));
    let lost = status.position_lost;
    match prefix {
        Some(prefix) => TextLine::new(format_args!("{prefix} X{x} Y{y}"), lost),
        None => TextLine::new(format_args!("X{x} Y{y}"), lost),
    }
}

/// `mm` with 3 decimals, or fewer when it would not fit `width` characters
/// ([`POSITION_CHARS`] at most).
fn mm_text(mm: f32, width: usize) -> String<POSITION_CHARS> {
    let mut s = String::new();
    for decimals in [3, 1, 0] {
        s.clear();
        if crate::decimal::write_fixed(&mut s, mm, decimals).is_ok() && s.len() <= width {
            return s;
        }
    }
    s.clear();
    let _ = s.push_str("-----");
    s
}

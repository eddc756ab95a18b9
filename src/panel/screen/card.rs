//! The card mode's screens: two of the card's G-code files, the cursor on one, each name cut to
//! the line, or what the card is doing or why it gave no files; the chosen file being checked;
//! and the file checked, beside its picture:
//!
//! ```text
//! drawing.gcode    ┌──────┐  name (inverted)
//! 412 lines ~12:34 │ ~~~  │  lines, plot time
//! 80x60 mm         │  ~~  │  the pen-down strokes' size
//! # plot  D back   └──────┘  the keys; the travel's outline, the strokes
//! ```
//!
//! and, at power-on, a plot a power cut stopped, offered to be resumed:
//!
//! ```text
//! RESUME PLOT?               (inverted)
//! drawing.gcode              the file
//! from line 213/412          the line it goes on from, the file's lines
//! # resume  D drop           the keys
//! ```

use embedded_graphics::geometry::{Point, Size};
use embedded_graphics::primitives::Rectangle;

use crate::card::names::cut_to;
use crate::card::{CardError, CardFacts, ResumeOffer};
use crate::decimal::Int;
use crate::panel::language::Language;
use crate::panel::layout::{SCREEN_CHAR_WIDTH_PX, SCREEN_COLUMNS, SCREEN_HEIGHT_PX, SCREEN_MARGIN_PX, SCREEN_WIDTH_PX};
use crate::panel::menu::CardList;
use crate::panel::texts::{Msg, Say};
use crate::program::preview::PICTURE_WIDTH_PX;
use crate::text::Text;

use super::lines::{CardMark, PreviewBox, ScreenView, TextLine};
use super::run::Clock;

/// Columns of text beside the card file's picture.
const COLUMNS_BESIDE_PICTURE: usize =
    ((SCREEN_WIDTH_PX - PICTURE_WIDTH_PX as u32 - SCREEN_MARGIN_PX) / SCREEN_CHAR_WIDTH_PX) as usize;

/// What the card says when it gave no files.
pub const fn card_error_text(e: CardError) -> Msg {
    match e {
        CardError::NoCard => Msg::CardNoCard,
        CardError::NotFat => Msg::CardNotFat,
        CardError::Unreadable => Msg::CardUnreadable,
        CardError::NoSuchFile => Msg::CardNoFile,
    }
}

/// The card mode's third and fourth lines.
pub fn card_lines(list: &CardList, language: Language) -> [TextLine; 2] {
    let Some(files) = list.files() else {
        let said = list.error().map_or(Msg::CardReading, card_error_text);
        return [TextLine::say(said, language), TextLine::say(Msg::KeysBack, language)];
    };
    if files.is_empty() {
        return [TextLine::say(Msg::CardEmpty, language), TextLine::say(Msg::KeysBack, language)];
    }
    let first = list.at().min(files.len().saturating_sub(2));
    let mut lines: [TextLine; 2] = Default::default();
    for (line, (i, file)) in lines.iter_mut().zip(files.iter().enumerate().skip(first)) {
        let marker = Text(if i == list.at() { ">" } else { " " });
        *line = TextLine::new(format_args!("{marker}{}", Text(cut_to(&file.name, SCREEN_COLUMNS - 1))), false);
    }
    if files.len() == 1 {
        lines[1] = TextLine::say(Msg::KeysCard, language);
    }
    lines
}

/// The card mode's third and fourth lines while the chosen file is checked, `lines` of it so
/// far.
pub fn checking_lines(lines: u32, language: Language) -> [TextLine; 2] {
    let say = |msg| Say(msg, language);
    [
        TextLine::new(format_args!("{} {}", say(Msg::CardChecking), Int::from(lines)), false),
        TextLine::say(Msg::KeysBack, language),
    ]
}

/// The chosen file checked: what the check found, beside the file's picture.
pub fn checked_view(name: &str, facts: &CardFacts, language: Language) -> ScreenView {
    let say = |msg| Say(msg, language);
    let w = COLUMNS_BESIDE_PICTURE;
    let [width, height] = facts.size_mm.map(|mm| Int::from((mm + 0.5) as i32));
    let area_x = SCREEN_WIDTH_PX - u32::from(PICTURE_WIDTH_PX);
    ScreenView {
        lines: [
            TextLine::new(format_args!("{}", Text(cut_to(name, w))), true),
            TextLine::new(
                format_args!("{} {} ~{}", Int::from(facts.lines), say(Msg::CardLines), Clock(facts.plot_time_ms)),
                false,
            ),
            TextLine::new(format_args!("{width}x{height} mm"), false),
            TextLine::say(Msg::KeysCardPlot, language),
        ],
        preview: Some(PreviewBox {
            area: Rectangle::new(
                Point::new(area_x as i32, 0),
                Size::new(u32::from(PICTURE_WIDTH_PX), SCREEN_HEIGHT_PX),
            ),
            plan: false,
            drawn_points: 0,
            drawn_last: None,
            pen: None,
            card: Some(CardMark { pen: None }),
        }),
    }
}

/// At power-on, the plot a power cut stopped, offered to be resumed.
pub fn offer_view(offer: &ResumeOffer, language: Language) -> ScreenView {
    let say = |msg| Say(msg, language);
    ScreenView {
        lines: [
            TextLine { inverted: true, ..TextLine::say(Msg::ResumeTitle, language) },
            TextLine::new(format_args!("{}", Text(cut_to(offer.name(), SCREEN_COLUMNS))), false),
            TextLine::new(
                format_args!("{} {}/{}", say(Msg::ResumeFrom), Int::from(offer.line), Int::from(offer.lines)),
                false,
            ),
            TextLine::say(Msg::KeysResume, language),
        ],
        preview: None,
    }
}

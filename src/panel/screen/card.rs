//! The card mode's lines: two of the card's G-code files, the cursor on one, each name cut to
//! the line; or what the card is doing or why it gave no files.

use crate::card::CardError;
use crate::card::names::cut_to;
use crate::panel::language::Language;
use crate::panel::layout::SCREEN_COLUMNS;
use crate::panel::menu::CardList;
use crate::panel::texts::Msg;
use crate::text::Text;

use super::lines::TextLine;

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

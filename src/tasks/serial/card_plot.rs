//! A file from the card as the line loop's third line source: the session of the file the
//! keypad chose ([`CardSession`]), which `card_turns` carries out. The file is first checked
//! whole, before anything moves ([`ProgramCheck`], a bounded piece of work per turn of the
//! loop): the first refused line (a line leaving the travel among them) ends it there, said on
//! the LCD and in a log line. A file that passes is shown (its lines, size, plot time and
//! picture) until the user answers: `#` plots it, `D` leaves it.
//!
//! The plot reads the file again a line at a time. The line loop carries each line out with the
//! one parser, exactly as the same line sent on a host link, and tells the plot its answer: `ok`
//! goes on to the next line; an `error:N` stops the plot, and the line number and the error go
//! to the LCD and a log line; nothing after it is sent. Once every line is sent, the plot lasts
//! until the machine rests.
//!
//! From the check's start to the plot's end, lines from the host links are answered `error:8`
//! (not idle); their realtime bytes act as ever, and `?` reports the plot's line in `|Ln:` (0
//! until the first line runs).

use embedded_io_async::{ErrorType, Write};

use crate::card::{CardError, CardFacts, CardFile, CardLine, CardLines, CardProgress, CardSlot, CardStop};
use crate::host::GrblError;
use crate::program::check::{CheckPlanner, ProgramCheck};
use crate::program::preview::PlotProgress;

/// A line from a host link while a card file is checked or plotted: refused, not idle.
pub const HOST_LINE_DURING_CARD_PLOT: GrblError = GrblError::NotIdle;

/// Microseconds per millisecond, for the check's plot time.
pub const US_PER_MS: u64 = 1000;

/// The card as the line loop has it: the slot the keypad chooses files from, and where the
/// chosen file is checked: the check (4 KB) and the planner it times the plot with (50 KB), both
/// in the board's static storage.
pub struct CardRoom<'r, 'c> {
    pub slot: &'r CardSlot<'c>,
    pub check: &'r mut ProgramCheck,
    pub planner: &'r mut CheckPlanner,
}

/// Where the card stands in the line loop.
pub enum CardSession {
    /// No file chosen: waiting for the keypad.
    Idle,
    /// The file is being checked: its lines as read so far, and the number of the last one
    /// handed to the check.
    Checking { file: CardFile, lines: CardLines, line: u32 },
    /// The file is checked and shown: waiting for the user's answer.
    Checked { file: CardFile, facts: CardFacts },
    /// The file is being plotted.
    Plotting(CardPlot),
}

/// What the card brings the line loop.
pub enum CardTurn {
    /// The keypad chose a file.
    Chosen(CardFile),
    /// The user answered the check: plot (`true`) or leave.
    Answer(bool),
    /// A piece of the check, or the plot's next line.
    Step,
}

/// The file being plotted, where its reading has got to, and its number of lines.
pub struct CardPlot {
    lines: CardLines,
    total: u32,
    /// Every line is sent: the plot ends once the machine rests.
    sent_all: bool,
}

/// What the plot gives the line loop next.
pub enum CardStep<'a> {
    /// Line `number`, to carry out and answer with [`CardPlot::answered`].
    Line { number: u32, text: &'a str },
    /// Line `number` broke a framing rule: answered with `error` as on a link.
    Refused { number: u32, error: GrblError },
    /// Every line is sent: the plot lasts until the machine rests.
    SentAll,
    /// The card failed (removed, unreadable) before every line was sent.
    Lost(CardError),
    /// The plot is over: every line was sent.
    Over,
}

impl CardPlot {
    /// Starts plotting `file` of `total` lines, from its start. A file that cannot be opened
    /// says why, and nothing moves.
    pub fn start(slot: &CardSlot<'_>, file: &CardFile, total: u32) -> Option<CardPlot> {
        info!("card plot: {}", file.name.as_str());
        if let Err(e) = slot.with(|card| card.open(file)) {
            end(slot);
            slot.stopped(CardStop::Card(e));
            return None;
        }
        let _before = slot.take_abort();
        slot.set_progress(CardProgress::Plotting { done: 0, total });
        if let Some(picture) = slot.picture_mut().as_mut() {
            picture.progress = Some(PlotProgress::new(picture.scale));
        }
        Some(CardPlot { lines: CardLines::new(), total, sent_all: false })
    }

    /// True once every line is sent: the plot lasts until the machine rests.
    pub fn sent_all(&self) -> bool {
        self.sent_all
    }

    /// The plot's next line, read from the card.
    pub fn next<'s>(&'s mut self, slot: &CardSlot<'_>) -> CardStep<'s> {
        if self.sent_all {
            return CardStep::Over;
        }
        let lines = &mut self.lines;
        match slot.with(move |card| lines.next(card)) {
            Ok(CardLine::Line { number, text }) => CardStep::Line { number, text },
            Ok(CardLine::Refused { number, error }) => CardStep::Refused { number, error },
            Ok(CardLine::End) => {
                info!("card plot: all {} lines sent", self.total);
                self.sent_all = true;
                CardStep::SentAll
            }
            Err(e) => CardStep::Lost(e),
        }
    }

    /// Line `number` was answered `ok` (`refused` is `None`) or `error:N`: true if the plot goes
    /// on.
    pub fn answered(&self, slot: &CardSlot<'_>, number: u32, refused: Option<GrblError>) -> bool {
        slot.set_progress(CardProgress::Plotting { done: number, total: self.total });
        match refused {
            None => true,
            Some(error) => {
                slot.stopped(CardStop::Refused { line: number, error });
                false
            }
        }
    }
}

/// The card's file is done with (checked and left, refused, plotted or aborted): closed, and
/// the LCD shows neither progress nor picture.
pub fn end(slot: &CardSlot<'_>) {
    slot.with(|card| card.close());
    if slot.progress() != CardProgress::None {
        slot.set_progress(CardProgress::None);
    }
    *slot.picture_mut() = None;
}

/// Answers to the card plot's lines beyond `ok` and `error:N` (reports, messages) have no
/// reader: taken and dropped.
pub struct Unread;

impl ErrorType for Unread {
    type Error = core::convert::Infallible;
}

impl Write for Unread {
    async fn write(&mut self, buf: &[u8]) -> Result<usize, Self::Error> {
        Ok(buf.len())
    }

    async fn flush(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
}

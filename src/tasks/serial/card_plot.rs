//! A card plot as the line loop's third line source: the file the keypad chose, read a line at
//! a time from the card. The line loop carries each line out with the one parser, exactly as the
//! same line sent on a host link, and tells the plot its answer: `ok` goes on to the next line;
//! the first `error:N` stops the plot, and the line number and the error go to the LCD and a log
//! line; nothing after it is sent. Once every line is sent, the plot lasts until the machine
//! rests.
//!
//! While a plot runs, lines from the host links are answered `error:8` (not idle); their
//! realtime bytes act as ever, and `?` reports the plot's line in `|Ln:`.

use embassy_futures::yield_now;
use embedded_io_async::{ErrorType, Write};

use crate::card::{CardError, CardFile, CardLine, CardLines, CardProgress, CardSlot, CardStop};
use crate::host::GrblError;

/// Lines counted between two yields to the other tasks, when a file's lines are counted before
/// its plot.
pub const CARD_COUNT_LINES_PER_TURN: u32 = 64;

/// A line from a host link while a card plot runs: refused, not idle.
pub const HOST_LINE_DURING_CARD_PLOT: GrblError = GrblError::NotIdle;

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
    /// The plot is over: the card failed, or the last move has ended.
    Over,
}

impl CardPlot {
    /// Starts plotting `file`: counts its lines (for the LCD's progress), then opens it again
    /// at its start. A file that cannot be read says why, and nothing moves.
    pub async fn start(slot: &CardSlot<'_>, file: &CardFile) -> Option<CardPlot> {
        info!("card plot: {}", file.name.as_str());
        let counted = async {
            slot.with(|card| card.open(file))?;
            let total = count_lines(slot).await?;
            slot.with(|card| card.open(file))?;
            Ok::<u32, CardError>(total)
        };
        match counted.await {
            Ok(total) => {
                let _before = slot.take_abort();
                slot.set_progress(CardProgress::Plotting { done: 0, total });
                Some(CardPlot { lines: CardLines::new(), total, sent_all: false })
            }
            Err(e) => {
                Self::end(slot);
                slot.stopped(CardStop::Card(e));
                None
            }
        }
    }

    /// True once every line is sent.
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
            Err(e) => {
                slot.stopped(CardStop::Card(e));
                CardStep::Over
            }
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

    /// The plot is over: the file is closed, and the LCD shows no progress.
    pub fn end(slot: &CardSlot<'_>) {
        slot.with(|card| card.close());
        if slot.progress() != CardProgress::None {
            slot.set_progress(CardProgress::None);
        }
    }
}

/// The open file's lines, read to its end, the other tasks running every
/// `CARD_COUNT_LINES_PER_TURN` lines.
async fn count_lines(slot: &CardSlot<'_>) -> Result<u32, CardError> {
    let mut lines = CardLines::new();
    loop {
        if slot.with(|card| lines.next(card))? == CardLine::End {
            return Ok(lines.lines_done());
        }
        if lines.lines_done().is_multiple_of(CARD_COUNT_LINES_PER_TURN) {
            yield_now().await;
        }
    }
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

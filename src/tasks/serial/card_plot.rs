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
//!
//! While it runs, the plot keeps its resume record on the card ([`ResumeKeeper`]): the place
//! after the last line whose motion has completed, at most once a second. A plot that ends, is
//! refused or is aborted clears it; a power cut leaves it. At power-on a record found is offered
//! on the LCD; resumed, the plot first makes its own moves ([`ResumeMove`]): home if `$22` is on,
//! the pen up, a rapid to where the completed line left the pen, the parser's state as it was
//! there and the pen as that state has it; then the file's lines go on from the next.

use core::fmt::Write as _;

use embedded_io_async::{ErrorType, Write};
use heapless::String;

use crate::card::keeper::ResumeKeeper;
use crate::card::resume::ResumeRecord;
use crate::card::{CardError, CardFacts, CardFile, CardLine, CardLines, CardProgress, CardSlot, CardStop, ResumeOffer};
use crate::decimal::write_fixed;
use crate::geom::Point;
use crate::host::GrblError;
use crate::host::gcode::{Modal, Spindle};
use crate::program::check::{CheckPlanner, ProgramCheck};
use crate::program::preview::PlotProgress;
use crate::settings::Settings;

/// A line from a host link while a card file is checked or plotted: refused, not idle.
pub const HOST_LINE_DURING_CARD_PLOT: GrblError = GrblError::NotIdle;

/// Microseconds per millisecond, for the check's plot time.
pub const US_PER_MS: u64 = 1000;

/// The card as the line loop has it: the slot the keypad chooses files from, where the chosen
/// file is checked (the check, 4 KB, and the planner it times the plot with, 50 KB), and the
/// plot's resume bookkeeping (2 KB), all in the board's static storage.
pub struct CardRoom<'r, 'c> {
    pub slot: &'r CardSlot<'c>,
    pub check: &'r mut ProgramCheck,
    pub planner: &'r mut CheckPlanner,
    pub keeper: &'r mut ResumeKeeper,
}

/// Where the card stands in the line loop.
pub enum CardSession {
    /// Power-on: a resume record is looked for.
    PowerOn,
    /// A plot a power cut stopped is offered: waiting for the user's answer.
    Offered { file: CardFile, record: ResumeRecord },
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

/// The file being plotted, where its reading has got to, its number of lines, and a resumed
/// plot's own moves still to make.
pub struct CardPlot {
    lines: CardLines,
    total: u32,
    /// Every line is sent: the plot ends once the machine rests.
    sent_all: bool,
    /// The resume's next move; [`ResumeMove::Lines`] for a plot from the start.
    next_move: ResumeMove,
    /// A resumed plot's state, as restored, has the pen down.
    pen_down: bool,
    /// The file's lines have begun: the resume's bookkeeping counts from then.
    begun: bool,
}

/// Bytes of the resume's rapid: `G21 G53 G0 X<mm> Y<mm>`, each coordinate to 4 decimals.
pub const TRAVEL_LINE_BYTES: usize = 64;
/// Decimals of the resume's rapid: a ten-thousandth of a millimetre, far below a step.
const TRAVEL_DECIMALS: u8 = 4;

/// A resumed plot's moves before its file's lines, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResumeMove {
    /// `$H`, with homing on (`$22`).
    Home,
    /// `M5`: the pen up.
    PenUp,
    /// A rapid, in machine coordinates, to where the completed line left the pen.
    Travel,
    /// The parser's state as it was after the completed line.
    Restore,
    /// `M3` or `M4` if that state has the pen down.
    PenDown,
    /// The file's lines.
    Lines,
}

/// What the plot gives the line loop next.
pub enum CardStep<'a> {
    /// A line of the resume's own moves, to carry out: the plot stops if it is refused.
    Move(&'static str),
    /// The resume's rapid to where the plot goes on ([`travel_line`]), a move as well.
    Travel,
    /// The parser's state is to be the one the plot goes on with, planned from where the rapid
    /// left the pen.
    Restore,
    /// `M3` or `M4`, as the restored state has the pen down.
    PenDown,
    /// The file's lines begin: the plot's counts are to be taken at rest.
    Begin,
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
    pub fn start(
        slot: &CardSlot<'_>,
        keeper: &mut ResumeKeeper,
        file: &CardFile,
        total: u32,
        at: Point,
        modal: Modal,
    ) -> Option<CardPlot> {
        info!("card plot: {}", file.name.as_str());
        let record = ResumeRecord {
            seq: 0,
            file: file.short.clone(),
            name: file.name.clone(),
            file_bytes: file.bytes,
            offset: 0,
            line: 1,
            after_cr: false,
            position: at,
            lines: total,
            modal,
        };
        let plot = CardPlot::open(slot, file, &record, ResumeMove::Lines)?;
        keeper.start(record);
        if let Some(picture) = slot.picture_mut().as_mut() {
            picture.progress = Some(PlotProgress::new(picture.scale));
        }
        Some(plot)
    }

    /// Goes on with the plot `record` was kept of, `file` on the card: the resume's moves, then
    /// the file's lines from the line after the last completed one.
    pub fn resume(
        slot: &CardSlot<'_>,
        keeper: &mut ResumeKeeper,
        file: &CardFile,
        record: &ResumeRecord,
        settings: &Settings,
    ) -> Option<CardPlot> {
        info!("card plot: {} resumed from line {}", file.name.as_str(), record.line);
        let first = if settings.homing { ResumeMove::Home } else { ResumeMove::PenUp };
        let mut plot = CardPlot::open(slot, file, record, first)?;
        plot.pen_down = record.modal.spindle != Spindle::Off;
        keeper.start(record.clone());
        Some(plot)
    }

    /// Opens `file` at `record`'s place; `first` is the plot's first move.
    fn open(slot: &CardSlot<'_>, file: &CardFile, record: &ResumeRecord, first: ResumeMove) -> Option<CardPlot> {
        let (offset, line) = (record.offset, record.line);
        let opened = slot.with(|card| card.open(file).and_then(|_| card.seek(offset)));
        if let Err(e) = opened {
            end(slot);
            slot.stopped(CardStop::Card(e));
            return None;
        }
        let _before = slot.take_abort();
        let total = record.lines;
        slot.set_progress(CardProgress::Plotting { done: line - 1, total });
        Some(CardPlot {
            lines: CardLines::resumed(offset, line - 1, record.after_cr),
            total,
            sent_all: false,
            next_move: first,
            pen_down: false,
            begun: false,
        })
    }

    /// True once every line is sent: the plot lasts until the machine rests.
    pub fn sent_all(&self) -> bool {
        self.sent_all
    }

    /// The plot's next move or line, read from the card.
    pub fn next<'s>(&'s mut self, slot: &CardSlot<'_>) -> CardStep<'s> {
        if let Some(step) = self.next_move() {
            return match step {
                ResumeMove::Home => CardStep::Move("$H"),
                ResumeMove::PenUp => CardStep::Move("M5"),
                ResumeMove::Travel => CardStep::Travel,
                ResumeMove::Restore => CardStep::Restore,
                ResumeMove::PenDown => CardStep::PenDown,
                ResumeMove::Lines => CardStep::Begin,
            };
        }
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

    /// The resume's next move, if one is left (`Lines` once: the file's lines begin).
    fn next_move(&mut self) -> Option<ResumeMove> {
        let step = self.next_move;
        let pen_down = self.pen_down;
        self.next_move = match step {
            ResumeMove::Home => ResumeMove::PenUp,
            ResumeMove::PenUp => ResumeMove::Travel,
            ResumeMove::Travel => ResumeMove::Restore,
            ResumeMove::Restore if pen_down => ResumeMove::PenDown,
            ResumeMove::Restore | ResumeMove::PenDown | ResumeMove::Lines => ResumeMove::Lines,
        };
        if step == ResumeMove::Lines {
            if self.begun {
                return None;
            }
            self.begun = true;
        }
        Some(step)
    }

    /// Where the next line starts: its number, its byte offset, and whether the line before
    /// ended in a CR.
    pub fn place(&self) -> (u32, u32, bool) {
        (self.lines.lines_done() + 1, self.lines.bytes_done(), self.lines.after_cr())
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

/// Stores the plot's resume record if one is due, `emitted_steps` emitted at `now_ms`. A card
/// that takes no record says so in a log line, and the plot goes on.
#[inline(never)]
pub fn keep(slot: &CardSlot<'_>, keeper: &mut ResumeKeeper, emitted_steps: u32, now_ms: u64) {
    if let Some(record) = keeper.due(emitted_steps, now_ms)
        && let Err(e) = slot.with(|card| card.store_resume(record))
    {
        warn!("card: resume record not kept: {}", e.message());
    }
}

/// The plot ends as it was meant to (its last line, a refusal, an abort), or a resume is
/// dropped: no record stays.
#[inline(never)]
pub fn clear(slot: &CardSlot<'_>, keeper: &mut ResumeKeeper) {
    info!("card plot over: its resume record, kept {} times, cleared", keeper.stores());
    keeper.stop();
    if let Err(e) = slot.with(|card| card.clear_resume()) {
        warn!("card: resume record not cleared: {}", e.message());
    }
}

/// The resume's rapid to `at`: in millimetres, machine coordinates.
pub fn travel_line(at: Point, settings: &Settings) -> String<TRAVEL_LINE_BYTES> {
    let mut line = String::new();
    let mm = |axis: usize, steps: i32| steps as f32 / settings.steps_per_mm[axis];
    let _fits = write!(line, "G21 G53 G0 X")
        .and_then(|()| write_fixed(&mut line, mm(0, at.x), TRAVEL_DECIMALS))
        .and_then(|()| line.write_str(" Y"))
        .and_then(|()| write_fixed(&mut line, mm(1, at.y), TRAVEL_DECIMALS));
    line
}

/// The offer of the plot `record` was kept of, if its file is on the card as it was (same name,
/// same length); a record of a file changed or gone is cleared.
pub fn offer(slot: &CardSlot<'_>, record: &ResumeRecord) -> Option<CardFile> {
    let file = CardFile { name: record.name.clone(), short: record.file.clone(), bytes: record.file_bytes };
    let bytes = slot.with(|card| {
        let bytes = card.open(&file);
        card.close();
        bytes
    });
    if bytes != Ok(record.file_bytes) {
        warn!(
            "card: the plot stopped at line {} of {} cannot resume: its file changed",
            record.line,
            file.name.as_str()
        );
        if let Err(e) = slot.with(|card| card.clear_resume()) {
            warn!("card: resume record not cleared: {}", e.message());
        }
        return None;
    }
    info!("card: the plot of {} stopped at line {}: offered to resume", file.name.as_str(), record.line);
    slot.set_progress(CardProgress::Offer(ResumeOffer::new(&file.name, record.line, record.lines)));
    Some(file)
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

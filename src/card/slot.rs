//! The card slot as the keypad task (which lists the card's files), the serial task (which
//! checks and plots one) and the LCD task (which shows it) share it: the board's card, reached
//! by one of them at a time, the file the keypad chose, the user's answer to its check, how far
//! its check or plot has come, and its picture.
//!
//! The three tasks run in thread mode on one executor, and none waits while it holds the card
//! or the picture, so a plain `RefCell` does.

use core::cell::{Cell, Ref, RefCell, RefMut};

use embassy_sync::blocking_mutex::raw::NoopRawMutex;
use embassy_sync::signal::Signal;

use super::names::CARD_NAME_MAX_BYTES;
use super::{Card, CardError, CardFile, CardFiles};
use crate::host::GrblError;
use crate::program::preview::{MapScale, PlotProgress, StrokeMap};

/// How a card plot ended, other than at the file's end.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum CardStop {
    /// Line `line` was refused with `error` (by the check, before anything moved, or as it
    /// ran); nothing after it was sent.
    Refused { line: u32, error: GrblError },
    /// The card failed (removed, unreadable) or the file could not be opened.
    Card(CardError),
}

/// What the check found of a whole file, shown before its plot.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct CardFacts {
    /// The file's lines.
    pub lines: u32,
    /// The pen-down strokes' width and height, mm (0 when nothing is drawn).
    pub size_mm: [f32; 2],
    /// The plot's time by the planner's model at 100 % feed, ms.
    pub plot_time_ms: u32,
    /// Step commands the plot emits.
    pub steps: u32,
}

/// How far the card plot has come.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum CardProgress {
    /// No file chosen.
    #[default]
    None,
    /// The chosen file is being checked: `lines` of it so far.
    Checking { lines: u32 },
    /// The file is checked and shown: `#` plots it, `D` leaves it.
    Checked(CardFacts),
    /// `done` of the file's `total` lines sent.
    Plotting { done: u32, total: u32 },
    /// At power-on, a plot a power cut stopped is offered: `#` resumes it, `D` drops it.
    Offer(ResumeOffer),
}

/// A plot a power cut stopped, as the LCD offers it: the file's name as listed, the line it
/// goes on from and the file's lines.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct ResumeOffer {
    name: [u8; CARD_NAME_MAX_BYTES],
    pub line: u32,
    pub lines: u32,
}

impl ResumeOffer {
    pub fn new(name: &str, line: u32, lines: u32) -> Self {
        // A name longer than the room (never one the list gives) is cut at a character's end.
        let mut bytes = [0; CARD_NAME_MAX_BYTES];
        let mut len = name.len().min(CARD_NAME_MAX_BYTES);
        while !name.is_char_boundary(len) {
            len -= 1;
        }
        bytes[..len].copy_from_slice(&name.as_bytes()[..len]);
        ResumeOffer { name: bytes, line, lines }
    }

    /// The file's name.
    pub fn name(&self) -> &str {
        let len = self.name.iter().position(|&b| b == 0).unwrap_or(CARD_NAME_MAX_BYTES);
        core::str::from_utf8(&self.name[..len]).unwrap_or("?")
    }
}

impl CardProgress {
    /// True while the chosen file is plotted.
    pub fn plotting(self) -> bool {
        matches!(self, CardProgress::Plotting { .. })
    }
}

/// The chosen file's picture ([`crate::program::preview`]): the pen-down strokes the check
/// found, and the part a plot has drawn so far.
#[derive(Clone, Debug, PartialEq)]
pub struct CardPicture {
    pub scale: MapScale,
    pub strokes: StrokeMap,
    /// The plot under way, if one is.
    pub progress: Option<PlotProgress>,
}

/// A board without a card slot (the model board): every look says there is no card, and it
/// keeps no resume record.
pub struct NoSlot;

impl Card for NoSlot {
    fn files(&mut self) -> Result<CardFiles, CardError> {
        Err(CardError::NoCard)
    }
    fn open(&mut self, _: &CardFile) -> Result<u32, CardError> {
        Err(CardError::NoCard)
    }
    fn read(&mut self, _: &mut [u8]) -> Result<usize, CardError> {
        Err(CardError::NoCard)
    }
    fn seek(&mut self, _: u32) -> Result<(), CardError> {
        Err(CardError::NoCard)
    }
    fn close(&mut self) {}
}

/// The board's card and the plot the keypad asked for; see the module documentation.
pub struct CardSlot<'c> {
    card: RefCell<&'c mut dyn Card>,
    /// The file the keypad chose, for the serial task to check and plot.
    plot: Signal<NoopRawMutex, CardFile>,
    /// The user's answer to the check: plot (true) or leave (false).
    answer: Signal<NoopRawMutex, bool>,
    progress: Cell<CardProgress>,
    /// The chosen file's picture, once its check began.
    picture: RefCell<Option<CardPicture>>,
    /// Why the last plot stopped early, until the keypad takes it.
    stop: Cell<Option<CardStop>>,
    /// The keypad aborted the plot: it stops before its next line.
    abort: Cell<bool>,
}

impl<'c> CardSlot<'c> {
    pub fn new(card: &'c mut dyn Card) -> Self {
        CardSlot {
            card: RefCell::new(card),
            plot: Signal::new(),
            answer: Signal::new(),
            progress: Cell::new(CardProgress::None),
            picture: RefCell::new(None),
            stop: Cell::new(None),
            abort: Cell::new(false),
        }
    }

    /// Reaches the card through `f`, which runs to its end without waiting.
    pub fn with<R>(&self, f: impl FnOnce(&mut dyn Card) -> R) -> R {
        f(*self.card.borrow_mut())
    }

    /// The card's G-code files; a card that gives none says why in a log line.
    pub fn files(&self) -> Result<CardFiles, CardError> {
        let files = self.with(|card| card.files());
        if let Err(e) = files {
            warn!("card: {}", e.message());
        }
        files
    }

    /// Asks for `file` to be checked, shown and, once the user says so, plotted.
    pub fn request_plot(&self, file: CardFile) {
        self.answer.reset();
        self.plot.signal(file);
    }

    /// Waits for the keypad to choose a file to plot.
    pub async fn plot_requested(&self) -> CardFile {
        self.plot.wait().await
    }

    /// The user's answer to the check shown: plot the file (`true`) or leave it.
    pub fn answer(&self, plot: bool) {
        self.answer.signal(plot);
    }

    /// Waits for the user's answer to the check shown.
    pub async fn answered(&self) -> bool {
        self.answer.wait().await
    }

    /// The chosen file's picture, to read (for the LCD).
    pub fn picture(&self) -> Ref<'_, Option<CardPicture>> {
        self.picture.borrow()
    }

    /// The chosen file's picture, to change: hold it only where nothing waits.
    pub fn picture_mut(&self) -> RefMut<'_, Option<CardPicture>> {
        self.picture.borrow_mut()
    }

    /// How far the card plot has come.
    pub fn progress(&self) -> CardProgress {
        self.progress.get()
    }

    /// The plot has come this far.
    pub fn set_progress(&self, progress: CardProgress) {
        self.progress.set(progress);
    }

    /// The plot stopped early: why (said in a log line, and on the LCD once the keypad task takes
    /// it).
    pub fn stopped(&self, stop: CardStop) {
        match stop {
            CardStop::Refused { line, error } => warn!("card file refused at line {}: error:{}", line, error.code()),
            CardStop::Card(e) => warn!("card plot stopped: {}", e.message()),
        }
        self.progress.set(CardProgress::None);
        self.stop.set(Some(stop));
    }

    /// The keypad aborted the check or the plot (if one runs).
    pub fn abort(&self) {
        self.abort.set(self.progress.get() != CardProgress::None);
    }

    /// Whether the plot was aborted since last asked.
    pub fn take_abort(&self) -> bool {
        self.abort.take()
    }

    /// Why the last plot stopped early, once.
    pub fn take_stop(&self) -> Option<CardStop> {
        self.stop.take()
    }
}

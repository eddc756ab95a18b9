//! The card slot as the keypad task (which lists the card's files) and the serial task (which
//! plots one) share it: the board's card, reached by one of them at a time, the file the keypad
//! asked to plot, and how far the plot has come (for the LCD).
//!
//! Both tasks run in thread mode on one executor, and neither waits while it holds the card,
//! so a plain `RefCell` does.

use core::cell::{Cell, RefCell};

use embassy_sync::blocking_mutex::raw::NoopRawMutex;
use embassy_sync::signal::Signal;

use super::{Card, CardError, CardFile, CardFiles};
use crate::host::GrblError;

/// How a card plot ended, other than at the file's end.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum CardStop {
    /// Line `line` was refused with `error`; nothing after it was sent.
    Refused { line: u32, error: GrblError },
    /// The card failed (removed, unreadable) or the file could not be opened.
    Card(CardError),
}

/// How far the card plot has come.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum CardProgress {
    /// No card plot.
    #[default]
    None,
    /// `done` of the file's `total` lines sent.
    Plotting { done: u32, total: u32 },
}

/// A board without a card slot (the model board): every look says there is no card.
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
    fn close(&mut self) {}
}

/// The board's card and the plot the keypad asked for; see the module documentation.
pub struct CardSlot<'c> {
    card: RefCell<&'c mut dyn Card>,
    /// The file the keypad chose, for the serial task to plot.
    plot: Signal<NoopRawMutex, CardFile>,
    progress: Cell<CardProgress>,
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
            progress: Cell::new(CardProgress::None),
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

    /// Asks for `file` to be plotted.
    pub fn request_plot(&self, file: CardFile) {
        self.plot.signal(file);
    }

    /// Waits for the keypad to choose a file to plot.
    pub async fn plot_requested(&self) -> CardFile {
        self.plot.wait().await
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
            CardStop::Refused { line, error } => warn!("card plot stopped at line {}: error:{}", line, error.code()),
            CardStop::Card(e) => warn!("card plot stopped: {}", e.message()),
        }
        self.progress.set(CardProgress::None);
        self.stop.set(Some(stop));
    }

    /// The keypad aborted the plot (if one runs).
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

//! The simulated board's card slot: the simulator's card (if any), taken out and put back as
//! the event script says (`card-out`, see [`crate::sim::inputs`]). While the card is out every
//! look at it finds none, as the board's card-detect input tells it; the file open when it was
//! taken out is closed, so a card put back is read again from its files.

use crate::card::resume::{ResumeBytes, ResumeSlots};
use crate::card::{Card, CardError, CardFile, CardFiles};
use crate::sim::card::SimCard;
use crate::sim::inputs::SimInputs;

/// The slot; see the module documentation.
pub struct SimSlot {
    card: Option<SimCard>,
    inputs: SimInputs,
    /// The card was out at the last look.
    out: bool,
}

impl SimSlot {
    /// A slot holding `card` (none: an empty slot), taken out as `inputs`' script says.
    pub fn new(card: Option<SimCard>, inputs: SimInputs) -> Self {
        SimSlot { card, inputs, out: false }
    }

    /// The card, if it is in the slot now.
    fn present(&mut self) -> Result<&mut SimCard, CardError> {
        let out = self.inputs.card_out();
        if out
            && !self.out
            && let Some(card) = &mut self.card
        {
            card.close();
        }
        self.out = out;
        match &mut self.card {
            Some(card) if !out => Ok(card),
            _ => Err(CardError::NoCard),
        }
    }
}

impl Card for SimSlot {
    fn files(&mut self) -> Result<CardFiles, CardError> {
        self.present()?.files()
    }

    fn open(&mut self, file: &CardFile) -> Result<u32, CardError> {
        self.present()?.open(file)
    }

    fn read(&mut self, buf: &mut [u8]) -> Result<usize, CardError> {
        self.present()?.read(buf)
    }

    fn seek(&mut self, offset: u32) -> Result<(), CardError> {
        self.present()?.seek(offset)
    }

    fn close(&mut self) {
        if let Ok(card) = self.present() {
            card.close();
        }
    }

    fn read_resume(&mut self, slots: &mut ResumeSlots) -> Result<(), CardError> {
        self.present()?.read_resume(slots)
    }

    fn write_resume(&mut self, slot: usize, bytes: &ResumeBytes) -> Result<(), CardError> {
        self.present()?.write_resume(slot, bytes)
    }
}

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

    /// The card the slot held (out or in), with what the plotter wrote on it: for its image at
    /// the end of a run.
    pub fn into_card(self) -> Option<SimCard> {
        self.card
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

#[cfg(test)]
mod tests {
    use std::cell::RefCell;
    use std::rc::Rc;

    use super::*;
    use crate::card::fat::FatCard;
    use crate::card::resume::ResumeRecord;
    use crate::geom::Point;
    use crate::host::GcodeState;
    use crate::settings::Settings;
    use crate::sim::card::{ImageBlocks, card_from_image, image_of, keep_image};
    use crate::sim::inputs::InputScript;
    use crate::sim::pins::PulseTrace;

    /// A slot holding `card`, never taken out.
    fn slot_with(card: SimCard) -> SimSlot {
        let inputs = SimInputs::new(
            Rc::new(RefCell::new(PulseTrace::default())),
            None,
            InputScript::default(),
            &Settings::default(),
        );
        SimSlot::new(Some(card), inputs)
    }

    fn record(line: u32) -> ResumeRecord {
        ResumeRecord {
            seq: 0,
            file: "PLOT.NC".try_into().unwrap(),
            name: "plot.nc".try_into().unwrap(),
            file_bytes: 4_000,
            offset: line * 20,
            line,
            after_cr: false,
            position: Point::new(120, -40),
            lines: 200,
            modal: GcodeState::new().modal(),
        }
    }

    /// A file in the system's temporary folder, named for this test and this process.
    fn temp_path(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(std::format!("servoplot-{name}-{}.img", std::process::id()))
    }

    #[test]
    fn a_record_stored_through_the_slot_is_kept_in_the_image_file_for_the_next_power_on() {
        let image = image_of(&[("plot.nc", b"G1 X10 Y10 F3000\n")]).unwrap();
        let path = temp_path("kept-card");
        std::fs::write(&path, &image).unwrap();
        let mut slot = slot_with(card_from_image(&path).unwrap());
        let mut stored = record(12);
        slot.store_resume(&mut stored).unwrap();
        let after = slot.into_card().expect("the card stays in the slot").image();
        assert_ne!(after, image, "the record is on the card");

        assert!(keep_image(&path, &image, &after).unwrap(), "a changed card is written back");
        assert_eq!(std::fs::read(&path).unwrap(), after, "the file holds the card as the run left it");
        // The next power-on reads the same record from the file.
        let mut again = card_from_image(&path).unwrap();
        assert_eq!(again.load_resume(), Ok(Some(stored)));
        let leftovers: std::vec::Vec<_> = std::fs::read_dir(std::env::temp_dir())
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().starts_with(&*path.file_name().unwrap().to_string_lossy()))
            .map(|e| e.file_name())
            .collect();
        assert_eq!(leftovers.len(), 1, "no temporary file left beside it: {leftovers:?}");
        std::fs::remove_file(&path).unwrap();
    }

    #[test]
    fn an_unchanged_card_is_not_written_back() {
        let path = temp_path("unchanged-card");
        std::fs::write(&path, b"changed since the run began").unwrap();
        let image = image_of(&[("plot.nc", b"G1 X10\n")]).unwrap();
        let slot = slot_with(FatCard::new(ImageBlocks::new(image.clone())));
        let after = slot.into_card().unwrap().image();
        assert!(!keep_image(&path, &image, &after).unwrap(), "nothing to write");
        assert_eq!(std::fs::read(&path).unwrap(), b"changed since the run began", "the file is left alone");
        std::fs::remove_file(&path).unwrap();
    }

    #[test]
    fn a_card_image_that_cannot_be_written_back_says_why_and_leaves_nothing() {
        let path = temp_path("gone-card");
        let err = keep_image(&path, b"before", b"after").unwrap_err();
        assert_eq!(err.kind(), std::io::ErrorKind::NotFound);
        assert!(!path.exists());
    }
}

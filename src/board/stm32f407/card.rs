//! The microSD card slot: the card on SPI3 in SPI mode, its own chip select, and the slot's
//! card-detect switch. SPI3 is free on the board (the LCD has SPI2 to itself, write-only and in
//! SPI mode 3, where the card needs MISO and mode 0; SPI1 carries the Discovery board's
//! accelerometer), on PB3/PB4/PB5 away from the audio codec's I2S pins.
//!
//! A card is brought up at its slow clock (`CARD_INIT_SPI_DIVIDER`: at most 400 kHz while it is
//! identified, as the SD specification asks), then read at its full one (`CARD_SPI_DIVIDER`). A card taken out is seen at the next look
//! through the card-detect input, and brought up again once put back.

use core::mem::MaybeUninit;

use embassy_stm32::gpio::{Input, Output};
use embassy_stm32::mode::Blocking;
use embassy_stm32::spi::{self, Spi};
use embassy_stm32::time::Hertz;
use embedded_hal_bus::spi::ExclusiveDevice;

use super::spi_delay::SpiDelay;
use embedded_sdmmc::SdCard;
use servoplot::card::fat::FatCard;
use servoplot::card::resume::{ResumeBytes, ResumeSlots};
use servoplot::card::{Card, CardError, CardFile, CardFiles};

/// SPI3's clock while a card is identified: its bus clock (APB1, 42 MHz) / 128, 328 kHz (at most
/// 400 kHz).
pub const CARD_INIT_SPI_DIVIDER: u32 = 128;
/// SPI3's clock once the card is up: its bus clock / 2, 21 MHz (an SD card takes up to 25 MHz).
pub const CARD_SPI_DIVIDER: u32 = 2;

/// The card's SPI device: SPI3 with its own chip select.
pub type CardSpi = ExclusiveDevice<Spi<'static, Blocking, spi::mode::Master>, Output<'static>, SpiDelay>;

/// The slot: the FAT card on SPI3 and the card-detect input.
pub struct SpiCard {
    fat: FatCard<SdCard<CardSpi, SpiDelay>>,
    /// Low while a card is in (the slot's switch closes to GND; pull-up).
    detect: Input<'static>,
    /// The card in the slot has been brought up.
    up: bool,
    /// SPI3's bus clock, Hz.
    bus_hz: u32,
}

/// SPI3's settings at `hz`, SPI mode 0.
pub fn spi_config(hz: u32) -> spi::Config {
    let mut config = spi::Config::default();
    config.frequency = Hertz(hz);
    config.mode = spi::MODE_0;
    config
}

impl SpiCard {
    /// The slot, built into `slot` in a frame of its own (out of the board's set-up).
    #[inline(never)]
    pub fn place(
        slot: &'static mut MaybeUninit<SpiCard>,
        spi: CardSpi,
        detect: Input<'static>,
        bus_hz: u32,
    ) -> &'static mut SpiCard {
        slot.write(SpiCard { fat: FatCard::new(SdCard::new(spi, SpiDelay)), detect, up: false, bus_hz })
    }

    /// A card is in the slot and up: brought up now if it was just put in.
    fn ready(&mut self) -> Result<(), CardError> {
        if self.detect.is_high() {
            if self.up {
                self.fat.with_blocks(|sd| sd.mark_card_uninit());
                self.up = false;
            }
            return Err(CardError::NoCard);
        }
        if !self.up {
            let (slow, fast) = (self.bus_hz / CARD_INIT_SPI_DIVIDER, self.bus_hz / CARD_SPI_DIVIDER);
            let size = self.fat.with_blocks(|sd| {
                let _ = sd.spi(|dev| dev.bus_mut().set_config(&spi_config(slow)));
                let size = sd.num_bytes();
                let _ = sd.spi(|dev| dev.bus_mut().set_config(&spi_config(fast)));
                size
            });
            if size.is_err() {
                self.fat.with_blocks(|sd| sd.mark_card_uninit());
                return Err(CardError::NoCard);
            }
            self.up = true;
        }
        Ok(())
    }
}

/// Files are read; the resume record's file (and only it) is written.
impl Card for SpiCard {
    fn files(&mut self) -> Result<CardFiles, CardError> {
        self.ready()?;
        self.fat.files()
    }

    fn open(&mut self, file: &CardFile) -> Result<u32, CardError> {
        self.ready()?;
        self.fat.open(file)
    }

    fn read(&mut self, buf: &mut [u8]) -> Result<usize, CardError> {
        if self.detect.is_high() {
            // Taken out while read.
            return Err(CardError::Unreadable);
        }
        self.fat.read(buf)
    }

    fn seek(&mut self, offset: u32) -> Result<(), CardError> {
        self.fat.seek(offset)
    }

    fn close(&mut self) {
        self.fat.close();
    }

    fn read_resume(&mut self, slots: &mut ResumeSlots) -> Result<(), CardError> {
        self.ready()?;
        self.fat.read_resume(slots)
    }

    fn write_resume(&mut self, slot: usize, bytes: &ResumeBytes) -> Result<(), CardError> {
        self.ready()?;
        self.fat.write_resume(slot, bytes)
    }
}

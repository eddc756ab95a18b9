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
use embedded_sdmmc::{Block, BlockCount, BlockDevice, BlockIdx, SdCard, SdCardError};
use servoplot::card::fat::FatCard;
use servoplot::card::{Card, CardError, CardFile, CardFiles};

/// SPI3's clock while a card is identified: its bus clock (APB1, 42 MHz) / 128, 328 kHz (at most
/// 400 kHz).
pub const CARD_INIT_SPI_DIVIDER: u32 = 128;
/// SPI3's clock once the card is up: its bus clock / 2, 21 MHz (an SD card takes up to 25 MHz).
pub const CARD_SPI_DIVIDER: u32 = 2;

/// The card's SPI device: SPI3 with its own chip select.
pub type CardSpi = ExclusiveDevice<Spi<'static, Blocking, spi::mode::Master>, Output<'static>, SpiDelay>;

/// The card's blocks as the plot reads them: read, never written (nothing on the card is written
/// yet), so the SD protocol's write commands stay out of the image.
pub struct ReadOnlySd(SdCard<CardSpi, SpiDelay>);

impl BlockDevice for ReadOnlySd {
    type Error = SdCardError;

    fn read(&self, blocks: &mut [Block], start_block_idx: BlockIdx) -> Result<(), SdCardError> {
        self.0.read(blocks, start_block_idx)
    }

    fn write(&self, _blocks: &[Block], _start_block_idx: BlockIdx) -> Result<(), SdCardError> {
        Err(SdCardError::WriteError)
    }

    fn num_blocks(&self) -> Result<BlockCount, SdCardError> {
        self.0.num_blocks()
    }
}

/// The slot: the FAT card on SPI3 and the card-detect input.
pub struct SpiCard {
    fat: FatCard<ReadOnlySd>,
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
        slot.write(SpiCard { fat: FatCard::new(ReadOnlySd(SdCard::new(spi, SpiDelay))), detect, up: false, bus_hz })
    }

    /// A card is in the slot and up: brought up now if it was just put in.
    fn ready(&mut self) -> Result<(), CardError> {
        if self.detect.is_high() {
            if self.up {
                self.fat.with_blocks(|sd| sd.0.mark_card_uninit());
                self.up = false;
            }
            return Err(CardError::NoCard);
        }
        if !self.up {
            let (slow, fast) = (self.bus_hz / CARD_INIT_SPI_DIVIDER, self.bus_hz / CARD_SPI_DIVIDER);
            let size = self.fat.with_blocks(|sd| {
                let _ = sd.0.spi(|dev| dev.bus_mut().set_config(&spi_config(slow)));
                let size = sd.0.num_bytes();
                let _ = sd.0.spi(|dev| dev.bus_mut().set_config(&spi_config(fast)));
                size
            });
            if size.is_err() {
                self.fat.with_blocks(|sd| sd.0.mark_card_uninit());
                return Err(CardError::NoCard);
            }
            self.up = true;
        }
        Ok(())
    }
}

/// The board keeps no resume record yet (the trait's `read_resume` and `write_resume` say there
/// is none): nothing writes one during a plot, and the card's write path and the record's code
/// (about 12 KB of flash) come in with what does.
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

    fn close(&mut self) {
        self.fat.close();
    }
}

//! The model's card slot: a FAT image QEMU loads into the model's 16 MiB PSRAM
//! (`-device loader,file=IMAGE,addr=0x21000000,force-raw=on`, see model/card.py), read and written
//! a 512-byte block at a time as the F407 reads its card over SPI, and taking the F407's time
//! for it: each block busies the caller for [`MODEL_CARD_BLOCK_US`] of the model's time, as the
//! board's blocking SPI transfer does. Without an image (no boot sector signature) the slot is
//! empty, as the card-detect switch would say.

use core::mem::MaybeUninit;

use embassy_time::{Duration, block_for};
use embedded_sdmmc::{Block, BlockCount, BlockDevice, BlockIdx};
use servoplot::card::fat::FatCard;
use servoplot::card::resume::{ResumeBytes, ResumeSlots};
use servoplot::card::{Card, CardError, CardFile, CardFiles};

/// Where the image lies (the model's PSRAM, which the firmware does not use otherwise), and at
/// most how long it is: 16 MiB, a small FAT16 volume.
pub const MODEL_CARD_IMAGE_ADDR: usize = 0x2100_0000;
pub const MODEL_CARD_IMAGE_BYTES: usize = 16 * 1024 * 1024;
const BLOCK_BYTES: usize = 512;

/// One block's transfer on the F407: 512 data bytes, the CRC and the command and its answer,
/// about 520 bytes of 8 bits at SPI3's 21 MHz, and the card's read latency: 250 µs.
pub const MODEL_CARD_BLOCK_US: u64 = 250;

/// A FAT boot sector's last two bytes.
const BOOT_SIGNATURE: [u8; 2] = [0x55, 0xAA];

/// Reading past the image.
#[derive(Debug)]
pub struct PastTheImage;

impl core::fmt::Display for PastTheImage {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("block past the card image")
    }
}

impl core::error::Error for PastTheImage {}

/// The image's blocks.
pub struct ImageBlocks;

impl ImageBlocks {
    /// The bytes of block `index`, if the image holds it.
    fn block(index: BlockIdx) -> Result<*mut u8, PastTheImage> {
        let at = index.0 as usize * BLOCK_BYTES;
        if at + BLOCK_BYTES > MODEL_CARD_IMAGE_BYTES {
            return Err(PastTheImage);
        }
        Ok((MODEL_CARD_IMAGE_ADDR + at) as *mut u8)
    }

    /// True when QEMU loaded an image: its first block ends in a boot sector's signature.
    fn present() -> bool {
        // SAFETY: the image's region is the model's PSRAM, which nothing else uses.
        let signature = unsafe { core::ptr::read_volatile((MODEL_CARD_IMAGE_ADDR + 510) as *const [u8; 2]) };
        signature == BOOT_SIGNATURE
    }
}

impl BlockDevice for ImageBlocks {
    type Error = PastTheImage;

    fn read(&self, blocks: &mut [Block], start: BlockIdx) -> Result<(), PastTheImage> {
        for (i, block) in blocks.iter_mut().enumerate() {
            let from = Self::block(BlockIdx(start.0 + i as u32))?;
            // SAFETY: `from` is a whole block within the image's RAM (checked above).
            unsafe { core::ptr::copy_nonoverlapping(from, block.contents.as_mut_ptr(), BLOCK_BYTES) };
            block_for(Duration::from_micros(MODEL_CARD_BLOCK_US));
        }
        Ok(())
    }

    fn write(&self, blocks: &[Block], start: BlockIdx) -> Result<(), PastTheImage> {
        for (i, block) in blocks.iter().enumerate() {
            let to = Self::block(BlockIdx(start.0 + i as u32))?;
            // SAFETY: as for `read`.
            unsafe { core::ptr::copy_nonoverlapping(block.contents.as_ptr(), to, BLOCK_BYTES) };
            block_for(Duration::from_micros(MODEL_CARD_BLOCK_US));
        }
        Ok(())
    }

    fn num_blocks(&self) -> Result<BlockCount, PastTheImage> {
        Ok(BlockCount((MODEL_CARD_IMAGE_BYTES / BLOCK_BYTES) as u32))
    }
}

/// The slot: the image's FAT volume, when QEMU loaded one.
pub struct ModelCard(FatCard<ImageBlocks>);

impl ModelCard {
    /// The slot, built into `slot` in a frame of its own (out of the board's set-up).
    #[inline(never)]
    pub fn place(slot: &'static mut MaybeUninit<ModelCard>) -> &'static mut ModelCard {
        slot.write(ModelCard(FatCard::new(ImageBlocks)))
    }

    fn ready(&self) -> Result<(), CardError> {
        if ImageBlocks::present() { Ok(()) } else { Err(CardError::NoCard) }
    }
}

impl Card for ModelCard {
    fn files(&mut self) -> Result<CardFiles, CardError> {
        self.ready()?;
        self.0.files()
    }

    fn open(&mut self, file: &CardFile) -> Result<u32, CardError> {
        self.ready()?;
        self.0.open(file)
    }

    fn read(&mut self, buf: &mut [u8]) -> Result<usize, CardError> {
        self.0.read(buf)
    }

    fn seek(&mut self, offset: u32) -> Result<(), CardError> {
        self.0.seek(offset)
    }

    fn close(&mut self) {
        self.0.close();
    }

    fn read_resume(&mut self, slots: &mut ResumeSlots) -> Result<(), CardError> {
        self.ready()?;
        self.0.read_resume(slots)
    }

    fn write_resume(&mut self, slot: usize, bytes: &ResumeBytes) -> Result<(), CardError> {
        self.ready()?;
        self.0.write_resume(slot, bytes)
    }
}

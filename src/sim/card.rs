//! The simulator's card: a FAT image file (`--sd IMAGE`), or one made from a folder's files
//! (`--sd-dir DIR`), as the 512-byte blocks the card module reads.

use std::cell::RefCell;
use std::io::{Cursor, Read, Seek, SeekFrom, Write};
use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

use embedded_sdmmc::{Block, BlockCount, BlockDevice, BlockIdx};

use crate::card::fat::FatCard;

/// Size of the image `--sd-dir` makes, in 512-byte blocks: 16 MiB, a FAT16 volume.
pub const SD_DIR_IMAGE_BLOCKS: u32 = 32 * 1024;
const BLOCK_BYTES: usize = Block::LEN;

/// A read past the image's end.
#[derive(Debug)]
pub struct PastTheEnd;

impl core::fmt::Display for PastTheEnd {
    fn fmt(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
        f.write_str("block past the end of the card image")
    }
}

impl core::error::Error for PastTheEnd {}

/// A card image in memory, as blocks.
pub struct ImageBlocks {
    bytes: RefCell<Vec<u8>>,
}

impl ImageBlocks {
    pub fn new(bytes: Vec<u8>) -> Self {
        ImageBlocks { bytes: RefCell::new(bytes) }
    }

    fn range(&self, start: BlockIdx, blocks: usize) -> Result<core::ops::Range<usize>, PastTheEnd> {
        let from = start.0 as usize * BLOCK_BYTES;
        let to = from + blocks * BLOCK_BYTES;
        if to > self.bytes.borrow().len() { Err(PastTheEnd) } else { Ok(from..to) }
    }
}

impl BlockDevice for ImageBlocks {
    type Error = PastTheEnd;

    fn read(&self, blocks: &mut [Block], start: BlockIdx) -> Result<(), PastTheEnd> {
        let range = self.range(start, blocks.len())?;
        let bytes = self.bytes.borrow();
        for (block, chunk) in blocks.iter_mut().zip(bytes[range].chunks(BLOCK_BYTES)) {
            block.contents.copy_from_slice(chunk);
        }
        Ok(())
    }

    fn write(&self, blocks: &[Block], start: BlockIdx) -> Result<(), PastTheEnd> {
        let range = self.range(start, blocks.len())?;
        let mut bytes = self.bytes.borrow_mut();
        for (block, chunk) in blocks.iter().zip(bytes[range].chunks_mut(BLOCK_BYTES)) {
            chunk.copy_from_slice(&block.contents);
        }
        Ok(())
    }

    fn num_blocks(&self) -> Result<BlockCount, PastTheEnd> {
        Ok(BlockCount((self.bytes.borrow().len() / BLOCK_BYTES) as u32))
    }
}

/// The simulator's card: a FAT volume on an image in memory.
pub type SimCard = FatCard<ImageBlocks>;

/// The card whose image is the file at `path`.
pub fn card_from_image(path: &Path) -> Result<SimCard, String> {
    let bytes = std::fs::read(path).map_err(|e| std::format!("--sd {}: {e}", path.display()))?;
    Ok(FatCard::new(ImageBlocks::new(bytes)))
}

/// A FAT16 image of [`SD_DIR_IMAGE_BLOCKS`] blocks holding `files` (name, bytes) in its top
/// folder, without a partition table, as `mkfs.fat -C` and `mcopy` make one.
pub fn image_of(files: &[(&str, &[u8])]) -> Result<Vec<u8>, String> {
    let mut disk = Cursor::new(std::vec![0u8; SD_DIR_IMAGE_BLOCKS as usize * BLOCK_BYTES]);
    let options = fatfs::FormatVolumeOptions::new().fat_type(fatfs::FatType::Fat16);
    fatfs::format_volume(&mut disk, options).map_err(|e| std::format!("formatting the card image: {e}"))?;
    disk.seek(SeekFrom::Start(0)).map_err(|e| e.to_string())?;
    {
        let fs = fatfs::FileSystem::new(&mut disk, fatfs::FsOptions::new()).map_err(|e| e.to_string())?;
        let root = fs.root_dir();
        for (name, bytes) in files {
            let mut file = root.create_file(name).map_err(|e| std::format!("{name}: {e}"))?;
            file.write_all(bytes).map_err(|e| std::format!("{name}: {e}"))?;
        }
    }
    Ok(disk.into_inner())
}

/// The card made from the files (not the folders) in `dir`.
pub fn card_from_dir(dir: &Path) -> Result<SimCard, String> {
    let mut files = Vec::new();
    let entries = std::fs::read_dir(dir).map_err(|e| std::format!("--sd-dir {}: {e}", dir.display()))?;
    for entry in entries {
        let entry = entry.map_err(|e| e.to_string())?;
        if !entry.file_type().map_err(|e| e.to_string())?.is_file() {
            continue;
        }
        let mut bytes = Vec::new();
        std::fs::File::open(entry.path()).and_then(|mut f| f.read_to_end(&mut bytes)).map_err(|e| e.to_string())?;
        files.push((entry.file_name().to_string_lossy().into_owned(), bytes));
    }
    let named: Vec<(&str, &[u8])> = files.iter().map(|(n, b)| (n.as_str(), b.as_slice())).collect();
    Ok(FatCard::new(ImageBlocks::new(image_of(&named)?)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::card::{Card, CardError, CardLine, CardLines};

    fn lines_of(card: &mut SimCard, index: usize) -> Vec<String> {
        let files = card.files().unwrap();
        card.open(files.get(index).unwrap()).unwrap();
        let mut lines = CardLines::new();
        let mut out = Vec::new();
        while let CardLine::Line { text, .. } = lines.next(card).unwrap() {
            out.push(text.into());
        }
        out
    }

    #[test]
    fn the_card_lists_its_gcode_files_and_reads_them() {
        let big: String = (0..2000).map(|i| std::format!("G1 X{} Y{}\n", i % 50, i % 30)).collect();
        let image = image_of(&[
            ("square.gcode", b"G0 X0 Y0\nG1 X10\n"),
            ("NOTES.TXT", b"not G-code"),
            ("A Long Name For A Plot.NC", big.as_bytes()),
        ])
        .unwrap();
        let mut card = FatCard::new(ImageBlocks::new(image));
        let files = card.files().unwrap();
        let names: Vec<&str> = files.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, ["A Long Name For A Plot.NC", "square.gcode"]);
        assert_eq!(lines_of(&mut card, 1), ["G0X0Y0", "G1X10"]);
        let long = lines_of(&mut card, 0);
        assert_eq!(long.len(), 2000);
        assert_eq!(long[1999], "G1X49Y19");
        assert_eq!(files.get(0).unwrap().bytes as usize, big.len());
    }

    #[test]
    fn a_card_with_a_partition_table_reads_the_same() {
        let bare = image_of(&[("plot.nc", b"G0 X1\nG1 Y2\n")]).unwrap();
        let mut image = std::vec![0u8; BLOCK_BYTES];
        let entry = &mut image[446..462];
        entry[4] = 0x0E;
        entry[8..12].copy_from_slice(&1u32.to_le_bytes());
        entry[12..16].copy_from_slice(&((bare.len() / BLOCK_BYTES) as u32).to_le_bytes());
        image[510..512].copy_from_slice(&[0x55, 0xAA]);
        image.extend_from_slice(&bare);
        let mut card = FatCard::new(ImageBlocks::new(image));
        assert_eq!(lines_of(&mut card, 0), ["G0X1", "G1Y2"]);
    }

    #[test]
    fn a_card_that_is_not_fat_says_so() {
        let mut card = FatCard::new(ImageBlocks::new(std::vec![0x5Au8; 64 * BLOCK_BYTES]));
        assert_eq!(card.files(), Err(CardError::NotFat));
    }

    #[test]
    fn a_file_gone_from_the_card_says_so() {
        let mut card = FatCard::new(ImageBlocks::new(image_of(&[("A.NC", b"G0X1\n")]).unwrap()));
        let mut file = card.files().unwrap().get(0).unwrap().clone();
        file.short = "B.NC".try_into().unwrap();
        assert_eq!(card.open(&file), Err(CardError::NoSuchFile));
        // The card is still read after the failure.
        assert_eq!(card.files().unwrap().len(), 1);
    }
}

//! The simulator's card: a FAT image file (`--sd IMAGE`), or one made from a folder's files
//! (`--sd-dir DIR`), as the 512-byte blocks the card module reads; and the image file kept
//! after a run ([`keep_image`]).

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

impl SimCard {
    /// The image's bytes as they are now, what the plotter wrote included.
    pub fn image(&self) -> Vec<u8> {
        self.with_blocks(|blocks| blocks.bytes.borrow().clone())
    }
}

/// The card whose image is the file at `path`.
pub fn card_from_image(path: &Path) -> Result<SimCard, String> {
    let bytes = std::fs::read(path).map_err(|e| std::format!("--sd {}: {e}", path.display()))?;
    Ok(FatCard::new(ImageBlocks::new(bytes)))
}

/// Keeps a run's card in the image file at `path` (`--sd IMAGE`): writes `after` there if it
/// differs from `before`, the image the run began with, and tells whether it did. The bytes go
/// to a new file beside it first (with its permissions), which then takes its place, so a
/// write cut short leaves the old image whole, never a torn one.
pub fn keep_image(path: &Path, before: &[u8], after: &[u8]) -> std::io::Result<bool> {
    if before == after {
        return Ok(false);
    }
    // Beside the file itself, not a link to it: the link stays a link.
    let path = std::fs::canonicalize(path)?;
    let name = path.file_name().ok_or_else(|| std::io::Error::other("no file name"))?;
    let mut temp_name = name.to_os_string();
    temp_name.push(std::format!(".{}.tmp", std::process::id()));
    let temp = path.with_file_name(temp_name);
    let written = (|| {
        let mut file = std::fs::File::create(&temp)?;
        file.write_all(after)?;
        file.sync_all()?;
        std::fs::set_permissions(&temp, std::fs::metadata(&path)?.permissions())?;
        std::fs::rename(&temp, &path)
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&temp);
    }
    written.map(|()| true)
}

/// A FAT16 image of [`SD_DIR_IMAGE_BLOCKS`] blocks holding `files` (name, bytes) in its top
/// folder, without a partition table, as `mkfs.fat -C` and `mcopy` make one.
pub fn image_of(files: &[(&str, &[u8])]) -> Result<Vec<u8>, String> {
    let options = fatfs::FormatVolumeOptions::new().fat_type(fatfs::FatType::Fat16);
    image_formatted(options, SD_DIR_IMAGE_BLOCKS, files)
}

/// Size of the FAT32 image [`fat32_image_of`] makes, in 512-byte blocks: 36 MiB, the least
/// that holds the clusters of a FAT32 volume (65,525 or more) at a block per cluster.
pub const FAT32_IMAGE_BLOCKS: u32 = 72 * 1024;

/// A FAT32 image of [`FAT32_IMAGE_BLOCKS`] blocks (one per cluster) holding `files`, as
/// [`image_of`] makes a FAT16 one.
pub fn fat32_image_of(files: &[(&str, &[u8])]) -> Result<Vec<u8>, String> {
    let options =
        fatfs::FormatVolumeOptions::new().fat_type(fatfs::FatType::Fat32).bytes_per_cluster(BLOCK_BYTES as u32);
    image_formatted(options, FAT32_IMAGE_BLOCKS, files)
}

/// An image of `blocks` blocks formatted with `options`, holding `files` in its top folder.
fn image_formatted(
    options: fatfs::FormatVolumeOptions,
    blocks: u32,
    files: &[(&str, &[u8])],
) -> Result<Vec<u8>, String> {
    let mut disk = Cursor::new(std::vec![0u8; blocks as usize * BLOCK_BYTES]);
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
mod tests;

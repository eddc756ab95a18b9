//! The resume record: where a card plot had come to, kept on the card so that after a power cut
//! the plot can go on from the last line whose motion completed. This module owns the record,
//! its bytes and the choice between the two slots of its file; the card writes the file
//! ([`Card`](super::Card)).
//!
//! A record is [`RESUME_RECORD_BYTES`] little-endian bytes: a magic word, the format version,
//! the record's fields and a CRC-32 over everything before it. Bytes that are not a whole
//! record of this format are never taken for one: [`ResumeRecord::decode`] says why
//! ([`BadResume`]).
//!
//! The file ([`RESUME_FILE_NAME`], in the card's top folder) holds two slots of
//! [`RESUME_SLOT_BYTES`], each a record at its start. A store writes the slot that does not
//! hold the newest valid record, numbered one after it, so a power cut during a store can
//! only tear that slot: the record before it stays whole in the other. Reading takes the valid
//! record with the highest sequence number (compared so that it may wrap), or none.

use heapless::String;

use crate::card::names::{CARD_NAME_MAX_BYTES, CARD_SHORT_NAME_MAX_BYTES, CardFile, FileName};
use crate::crc::crc32;
use crate::fields::FieldWriter;
use crate::geom::Point;
use crate::host::gcode::{Coolant, Distance, KEPT_OFFSETS, Modal, MotionMode, Spindle, Units, WorkSystem};

/// The record file's 8.3 name, in the card's top folder.
pub const RESUME_FILE_NAME: &str = "RESUME.SPR";
/// One slot of the file: a block of the card, so that a store writes one block.
pub const RESUME_SLOT_BYTES: usize = 512;
/// The file's slots.
pub const RESUME_SLOTS: usize = 2;
/// The file's length: its two slots.
pub const RESUME_FILE_BYTES: usize = RESUME_SLOT_BYTES * RESUME_SLOTS;

/// The first word of every record: "SPRR".
const RESUME_MAGIC: u32 = u32::from_le_bytes(*b"SPRR");
/// The record's layout; a record of another is not read.
pub const RESUME_FORMAT: u16 = 1;

/// Flag bits: the parser has had an F word, an S word; the line before the offset ended in a
/// CR (so an LF at the offset ends no line of its own).
const FLAG_FEED: u8 = 1;
const FLAG_SPEED: u8 = 2;
const FLAG_AFTER_CR: u8 = 4;

/// A record's bytes: magic 4, format 2, flags 1, tool 1, sequence 4, file name 12, file length
/// 4, offset 4, line 4, position 8, the file's lines 4, modes 6, two bytes kept zero, feed 4,
/// S 4, the kept offsets 8 each, G92 8, the name as listed 32, CRC 4.
pub const RESUME_RECORD_BYTES: usize = 4
    + 2
    + 1
    + 1
    + 4
    + CARD_SHORT_NAME_MAX_BYTES
    + 4
    + 4
    + 4
    + 8
    + 4
    + 6
    + 2
    + 4
    + 4
    + 8 * KEPT_OFFSETS
    + 8
    + CARD_NAME_MAX_BYTES
    + 4;

const _: () = assert!(RESUME_RECORD_BYTES <= RESUME_SLOT_BYTES);

/// One record's bytes.
pub type ResumeBytes = [u8; RESUME_RECORD_BYTES];

/// Why bytes are not a resume record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum BadResume {
    /// Fewer bytes than a record.
    Short,
    /// Not a record (an empty slot, or another file's bytes).
    Magic,
    /// A record of another format.
    Version,
    /// The bytes changed since they were written (a torn or damaged write).
    Checksum,
    /// The file name is empty or not text.
    Name,
    /// The place in the file is impossible: past the file's end, past its last line, or line 0.
    Place,
    /// A modal group's value, or a flag, is unknown.
    Mode,
    /// A feed rate, S word or offset is not a finite number in its range.
    Number,
}

/// Where a card plot had come to; see the module documentation.
#[derive(Clone, Debug, PartialEq)]
pub struct ResumeRecord {
    /// Grows by one with every store (wrapping).
    pub seq: u32,
    /// The plotted file's 8.3 name ([`CardFile::short`]).
    pub file: String<CARD_SHORT_NAME_MAX_BYTES>,
    /// Its name as the card's list shows it ([`CardFile::name`]).
    pub name: FileName,
    /// The file's length when it was plotted, bytes: a file of another length has changed.
    pub file_bytes: u32,
    /// Where in the file the line after the last completed one starts, bytes.
    pub offset: u32,
    /// That line's number, from 1.
    pub line: u32,
    /// The line before the offset ended in a CR: an LF at the offset belongs to it.
    pub after_cr: bool,
    /// The pen's machine position once the completed line had run, steps.
    pub position: Point,
    /// The file's lines, as its check counted them.
    pub lines: u32,
    /// The parser's state after the completed line.
    pub modal: Modal,
}

impl ResumeRecord {
    /// Whether the record is of `file` as it is on the card now (same name, same length).
    pub fn is_for(&self, file: &CardFile) -> bool {
        self.file == file.short && self.file_bytes == file.bytes
    }

    /// The record's bytes.
    pub fn encode(&self) -> ResumeBytes {
        let mut out = [0u8; RESUME_RECORD_BYTES];
        let m = &self.modal;
        let flags = if m.feed_mm_per_min.is_some() { FLAG_FEED } else { 0 }
            | if m.spindle_speed.is_some() { FLAG_SPEED } else { 0 }
            | if self.after_cr { FLAG_AFTER_CR } else { 0 };
        let mut short = [0u8; CARD_SHORT_NAME_MAX_BYTES];
        short[..self.file.len()].copy_from_slice(self.file.as_bytes());
        let mut name = [0u8; CARD_NAME_MAX_BYTES];
        name[..self.name.len()].copy_from_slice(self.name.as_bytes());
        let mut w = FieldWriter::new(&mut out);
        w.put(&RESUME_MAGIC.to_le_bytes());
        w.put(&RESUME_FORMAT.to_le_bytes());
        w.put(&[flags, m.tool]);
        w.put(&self.seq.to_le_bytes());
        w.put(&short);
        for word in [self.file_bytes, self.offset, self.line] {
            w.put(&word.to_le_bytes());
        }
        w.put(&self.position.x.to_le_bytes());
        w.put(&self.position.y.to_le_bytes());
        w.put(&self.lines.to_le_bytes());
        let system = m.work_system.index() as u8;
        w.put(&[motion_code(m.motion), units_code(m.units), distance_code(m.distance), system]);
        w.put(&[spindle_code(m.spindle), coolant_code(m.coolant), 0, 0]);
        w.put(&m.feed_mm_per_min.unwrap_or(0.0).to_le_bytes());
        w.put(&m.spindle_speed.unwrap_or(0.0).to_le_bytes());
        for pair in m.kept_mm.iter().chain([&m.g92_mm]) {
            w.put(&pair[0].to_le_bytes());
            w.put(&pair[1].to_le_bytes());
        }
        w.put(&name);
        let crc = crc32(&out[..RESUME_RECORD_BYTES - 4]);
        out[RESUME_RECORD_BYTES - 4..].copy_from_slice(&crc.to_le_bytes());
        out
    }

    /// The record in `bytes` (its first [`RESUME_RECORD_BYTES`]), or why there is none.
    pub fn decode(bytes: &[u8]) -> Result<ResumeRecord, BadResume> {
        let bytes = bytes.get(..RESUME_RECORD_BYTES).ok_or(BadResume::Short)?;
        let mut r = Reader { bytes, at: 0 };
        if u32::from_le_bytes(r.take()) != RESUME_MAGIC {
            return Err(BadResume::Magic);
        }
        if u16::from_le_bytes(r.take()) != RESUME_FORMAT {
            return Err(BadResume::Version);
        }
        let (body, crc) = bytes.split_at(RESUME_RECORD_BYTES - 4);
        if crc32(body).to_le_bytes() != crc {
            return Err(BadResume::Checksum);
        }
        let [flags, tool] = r.take();
        if flags & !(FLAG_FEED | FLAG_SPEED | FLAG_AFTER_CR) != 0 {
            return Err(BadResume::Mode);
        }
        let seq = u32::from_le_bytes(r.take());
        let file = text(&r.take())?;
        let file_bytes = u32::from_le_bytes(r.take());
        let offset = u32::from_le_bytes(r.take());
        let line = u32::from_le_bytes(r.take());
        if line == 0 || offset > file_bytes || line - 1 > offset {
            return Err(BadResume::Place);
        }
        let position = Point::new(i32::from_le_bytes(r.take()), i32::from_le_bytes(r.take()));
        let lines = u32::from_le_bytes(r.take());
        if line - 1 > lines {
            return Err(BadResume::Place);
        }
        let [motion, units, distance, system, spindle, coolant, zero_a, zero_b] = r.take();
        let modes = (
            motion_of(motion),
            units_of(units),
            distance_of(distance),
            WorkSystem::from_index(usize::from(system)),
            spindle_of(spindle),
            coolant_of(coolant),
        );
        let (Some(motion), Some(units), Some(distance), Some(work_system), Some(spindle), Some(coolant)) = modes else {
            return Err(BadResume::Mode);
        };
        if [zero_a, zero_b] != [0, 0] {
            return Err(BadResume::Mode);
        }
        let feed_mm_per_min = optional(r.f32(), flags & FLAG_FEED != 0)?;
        let spindle_speed = optional(r.f32(), flags & FLAG_SPEED != 0)?;
        let mut offsets_mm = [[0.0; 2]; KEPT_OFFSETS + 1];
        for pair in &mut offsets_mm {
            *pair = [r.f32(), r.f32()];
            if !(pair[0].is_finite() && pair[1].is_finite()) {
                return Err(BadResume::Number);
            }
        }
        let mut kept_mm = [[0.0; 2]; KEPT_OFFSETS];
        kept_mm.copy_from_slice(&offsets_mm[..KEPT_OFFSETS]);
        let g92_mm = offsets_mm[KEPT_OFFSETS];
        let name = text(&r.take())?;
        let modal = Modal {
            motion,
            units,
            distance,
            work_system,
            spindle,
            coolant,
            feed_mm_per_min,
            spindle_speed,
            tool,
            kept_mm,
            g92_mm,
        };
        let after_cr = flags & FLAG_AFTER_CR != 0;
        Ok(ResumeRecord { seq, file, name, file_bytes, offset, line, after_cr, position, lines, modal })
    }
}

/// A feed rate or S word: present (finite, not negative) or absent (stored as zero).
fn optional(value: f32, present: bool) -> Result<Option<f32>, BadResume> {
    match present {
        true if value.is_finite() && value >= 0.0 => Ok(Some(value)),
        false if value.to_bits() == 0 => Ok(None),
        _ => Err(BadResume::Number),
    }
}

/// A file name's bytes: UTF-8 text without control bytes, then zeros to the end.
fn text<const N: usize>(bytes: &[u8; N]) -> Result<String<N>, BadResume> {
    let len = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    let text = core::str::from_utf8(&bytes[..len]).map_err(|_| BadResume::Name)?;
    if len == 0 || bytes[len..].iter().any(|&b| b != 0) || text.chars().any(char::is_control) {
        return Err(BadResume::Name);
    }
    String::try_from(text).map_err(|_| BadResume::Name)
}

/// The record file's two slots as read, each a record's bytes.
#[derive(Clone, Debug, PartialEq)]
pub struct ResumeSlots {
    pub slots: [ResumeBytes; RESUME_SLOTS],
}

impl Default for ResumeSlots {
    fn default() -> Self {
        Self::new()
    }
}

impl ResumeSlots {
    /// Two empty slots (as a card without the file gives).
    pub const fn new() -> Self {
        ResumeSlots { slots: [[0; RESUME_RECORD_BYTES]; RESUME_SLOTS] }
    }

    /// The slot holding the newest valid record, and the record.
    pub fn newest(&self) -> Option<(usize, ResumeRecord)> {
        let mut newest: Option<(usize, ResumeRecord)> = None;
        for (slot, bytes) in self.slots.iter().enumerate() {
            if let Ok(record) = ResumeRecord::decode(bytes)
                && newest.as_ref().is_none_or(|(_, other)| newer(record.seq, other.seq))
            {
                newest = Some((slot, record));
            }
        }
        newest
    }

    /// The slot holding the newest valid record, and its sequence number (the record itself is
    /// not kept: a store needs no more).
    pub fn newest_seq(&self) -> Option<(usize, u32)> {
        let mut newest: Option<(usize, u32)> = None;
        for (slot, bytes) in self.slots.iter().enumerate() {
            if let Ok(seq) = ResumeRecord::decode(bytes).map(|record| record.seq)
                && newest.is_none_or(|(_, other)| newer(seq, other))
            {
                newest = Some((slot, seq));
            }
        }
        newest
    }

    /// Where the next store goes: the slot not holding the newest valid record, and the
    /// sequence number one after it (the first slot, number 1, when neither holds one).
    pub fn next_write(&self) -> (usize, u32) {
        match self.newest_seq() {
            Some((slot, seq)) => (1 - slot, seq.wrapping_add(1)),
            None => (0, 1),
        }
    }
}

/// Whether sequence number `a` was given after `b`, across a wrap: within half the range.
pub fn newer(a: u32, b: u32) -> bool {
    (a.wrapping_sub(b) as i32) > 0
}

/// Reads a record's fields in order; `bytes` is a whole record, so every take is in it.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        if let Some(bytes) = self.bytes.get(self.at..self.at + N) {
            out.copy_from_slice(bytes);
        }
        self.at += N;
        out
    }

    fn f32(&mut self) -> f32 {
        f32::from_le_bytes(self.take())
    }
}

/// The modal groups' values as bytes, and back (`None` for a byte no value has).
fn motion_code(m: MotionMode) -> u8 {
    match m {
        MotionMode::Rapid => 0,
        MotionMode::Linear => 1,
        MotionMode::ArcCw => 2,
        MotionMode::ArcCcw => 3,
        MotionMode::Off => 4,
    }
}

fn motion_of(b: u8) -> Option<MotionMode> {
    [MotionMode::Rapid, MotionMode::Linear, MotionMode::ArcCw, MotionMode::ArcCcw, MotionMode::Off]
        .get(usize::from(b))
        .copied()
}

fn units_code(u: Units) -> u8 {
    match u {
        Units::Mm => 0,
        Units::Inch => 1,
    }
}

fn units_of(b: u8) -> Option<Units> {
    [Units::Mm, Units::Inch].get(usize::from(b)).copied()
}

fn distance_code(d: Distance) -> u8 {
    match d {
        Distance::Absolute => 0,
        Distance::Incremental => 1,
    }
}

fn distance_of(b: u8) -> Option<Distance> {
    [Distance::Absolute, Distance::Incremental].get(usize::from(b)).copied()
}

fn spindle_code(s: Spindle) -> u8 {
    match s {
        Spindle::Cw => 0,
        Spindle::Ccw => 1,
        Spindle::Off => 2,
    }
}

fn spindle_of(b: u8) -> Option<Spindle> {
    [Spindle::Cw, Spindle::Ccw, Spindle::Off].get(usize::from(b)).copied()
}

fn coolant_code(c: Coolant) -> u8 {
    match c {
        Coolant::Flood => 0,
        Coolant::Off => 1,
    }
}

fn coolant_of(b: u8) -> Option<Coolant> {
    [Coolant::Flood, Coolant::Off].get(usize::from(b)).copied()
}

#[cfg(test)]
mod tests;

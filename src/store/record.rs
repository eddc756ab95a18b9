//! The one record the flash store keeps, and its bytes.
//!
//! Layout, little-endian: a 16-bit layout tag, every setting's value as an `f32` in
//! [`SETTING_INFO`] order, the kept offsets (G54–G59, G28, G30) as `f32` pairs, then each startup
//! block and the build info line as a length byte and its UTF-8 bytes. The tag sums up the layout
//! (the setting numbers, the counts of offsets and blocks, [`RECORD_FORMAT`]): a record written
//! by a firmware with other settings does not read back as this one's.

use crate::fields::FieldWriter;
use crate::host::gcode::{KEPT_OFFSETS, Offsets};
use crate::host::startup::{STARTUP_LINE_MAX_BYTES, STARTUP_LINES, StartupLine, StartupLines, ascii_line};
use crate::settings::{SETTING_INFO, Settings};

/// Bumped whenever the layout changes in a way the tag would not see.
pub const RECORD_FORMAT: u16 = 1;

/// The longest record, in bytes.
pub const RECORD_MAX_BYTES: usize =
    2 + 4 * SETTING_INFO.len() + 8 * KEPT_OFFSETS + (1 + STARTUP_LINE_MAX_BYTES) * (STARTUP_LINES + 1);

/// Sums up the layout: see the module documentation.
pub const LAYOUT_TAG: u16 = {
    // FNV-1a over the setting numbers and the counts, folded to 16 bits.
    let mut hash: u32 = 0x811c_9dc5;
    let words = [RECORD_FORMAT, KEPT_OFFSETS as u16, STARTUP_LINES as u16, STARTUP_LINE_MAX_BYTES as u16];
    let mut i = 0;
    while i < SETTING_INFO.len() + words.len() {
        let word = if i < SETTING_INFO.len() { SETTING_INFO[i].id } else { words[i - SETTING_INFO.len()] };
        hash = (hash ^ word as u32).wrapping_mul(0x0100_0193);
        i += 1;
    }
    ((hash >> 16) ^ hash) as u16
};

/// Why stored bytes are not a record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum BadRecord {
    /// Written by a firmware with another layout.
    OtherLayout,
    /// The right layout, but a value out of its range, too short or not text.
    Invalid,
}

/// Everything a power cycle keeps.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Record {
    pub settings: Settings,
    /// G54–G59, G28 and G30: [`Offsets::kept_mm`].
    pub offsets_mm: [[f32; 2]; KEPT_OFFSETS],
    pub startup: StartupLines,
}

impl Record {
    /// The values a power cycle keeps of these.
    pub fn of(settings: &Settings, offsets: &Offsets, startup: &StartupLines) -> Record {
        Record { settings: *settings, offsets_mm: offsets.kept_mm(), startup: startup.clone() }
    }

    /// Writes the record into `out` (at least [`RECORD_MAX_BYTES`] long); returns its length.
    pub fn encode(&self, out: &mut [u8]) -> usize {
        let mut w = FieldWriter::new(out);
        w.put(&LAYOUT_TAG.to_le_bytes());
        for value in self.settings.values() {
            w.put(&value.to_le_bytes());
        }
        for value in self.offsets_mm.iter().flatten() {
            w.put(&value.to_le_bytes());
        }
        for line in self.startup.all().chain([self.startup.build_info.as_str()]) {
            w.put(&[line.len() as u8]);
            w.put(line.as_bytes());
        }
        w.written()
    }

    /// The record `bytes` hold, all of them.
    pub fn decode(bytes: &[u8]) -> Result<Record, BadRecord> {
        let mut r = Reader { bytes };
        if u16::from_le_bytes(r.take()?) != LAYOUT_TAG {
            return Err(BadRecord::OtherLayout);
        }
        let mut values = [0.0f32; SETTING_INFO.len()];
        for value in &mut values {
            *value = f32::from_le_bytes(r.take()?);
        }
        let settings = Settings::from_values(values).map_err(|_| BadRecord::Invalid)?;
        let mut offsets_mm = [[0.0f32; 2]; KEPT_OFFSETS];
        for value in offsets_mm.iter_mut().flatten() {
            *value = f32::from_le_bytes(r.take()?);
            if !value.is_finite() {
                return Err(BadRecord::Invalid);
            }
        }
        let mut startup = StartupLines::new();
        for index in 0..STARTUP_LINES {
            startup.set(index, r.line()?);
        }
        startup.build_info = r.line()?;
        if !r.bytes.is_empty() {
            return Err(BadRecord::Invalid);
        }
        Ok(Record { settings, offsets_mm, startup })
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], BadRecord> {
        let (head, rest) = self.bytes.split_first_chunk::<N>().ok_or(BadRecord::Invalid)?;
        self.bytes = rest;
        Ok(*head)
    }

    fn line(&mut self) -> Result<StartupLine, BadRecord> {
        let [len] = self.take()?;
        let (text, rest) = self.bytes.split_at_checked(usize::from(len)).ok_or(BadRecord::Invalid)?;
        self.bytes = rest;
        ascii_line(text).ok_or(BadRecord::Invalid)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Record {
        let mut settings = Settings::default();
        settings.set(100, 80.0).unwrap();
        settings.set(3, 2.0).unwrap();
        let mut startup = StartupLines::new();
        startup.set(1, StartupLine::try_from("G21G90").unwrap());
        startup.build_info = StartupLine::try_from("plotter 1").unwrap();
        let mut offsets_mm = [[0.0; 2]; KEPT_OFFSETS];
        offsets_mm[0] = [10.5, -3.25];
        offsets_mm[KEPT_OFFSETS - 1] = [1.0, 2.0];
        Record { settings, offsets_mm, startup }
    }

    #[test]
    fn a_record_reads_back_as_written() {
        let mut buf = [0u8; RECORD_MAX_BYTES];
        for record in [Record::default(), sample()] {
            let n = record.encode(&mut buf);
            assert_eq!(Record::decode(&buf[..n]), Ok(record));
        }
    }

    #[test]
    fn the_longest_record_fits() {
        let mut record = sample();
        let long = StartupLine::try_from("G1X1".repeat(STARTUP_LINE_MAX_BYTES / 4).as_str()).unwrap();
        for index in 0..STARTUP_LINES {
            record.startup.set(index, long.clone());
        }
        record.startup.build_info = long;
        let mut buf = [0u8; RECORD_MAX_BYTES];
        assert_eq!(record.encode(&mut buf), RECORD_MAX_BYTES);
        assert_eq!(Record::decode(&buf), Ok(record));
    }

    #[test]
    fn other_layouts_and_bad_values_are_refused() {
        let mut buf = [0u8; RECORD_MAX_BYTES];
        let n = sample().encode(&mut buf);
        let mut other = buf;
        other[0] ^= 1;
        assert_eq!(Record::decode(&other[..n]), Err(BadRecord::OtherLayout));
        // 0 steps/mm ($100) is out of its range.
        let at = SETTING_INFO.iter().position(|i| i.id == 100).unwrap();
        let mut bad = buf;
        bad[2 + 4 * at..2 + 4 * (at + 1)].copy_from_slice(&0.0f32.to_le_bytes());
        assert_eq!(Record::decode(&bad[..n]), Err(BadRecord::Invalid));
        let mut nan = buf;
        nan[2 + 4 * SETTING_INFO.len()..][..4].copy_from_slice(&f32::NAN.to_le_bytes());
        assert_eq!(Record::decode(&nan[..n]), Err(BadRecord::Invalid));
        assert_eq!(Record::decode(&buf[..n - 1]), Err(BadRecord::Invalid));
        assert_eq!(Record::decode(&buf[..n + 1]), Err(BadRecord::Invalid));
        assert_eq!(Record::decode(&[]), Err(BadRecord::Invalid));
    }
}

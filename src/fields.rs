//! A record written as its fields in order, each a run of bytes: how the flash store's record
//! and the card's resume record are laid out (each reads its own back, with its own checks).

/// Writes a record's fields in order into `out`, which has room for them all.
pub struct FieldWriter<'a> {
    out: &'a mut [u8],
    at: usize,
}

impl<'a> FieldWriter<'a> {
    pub fn new(out: &'a mut [u8]) -> Self {
        FieldWriter { out, at: 0 }
    }

    /// Appends `bytes` after the fields written so far.
    pub fn put(&mut self, bytes: &[u8]) {
        self.out[self.at..self.at + bytes.len()].copy_from_slice(bytes);
        self.at += bytes.len();
    }

    /// Bytes written so far.
    pub fn written(&self) -> usize {
        self.at
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_land_one_after_another() {
        let mut out = [0u8; 8];
        let mut w = FieldWriter::new(&mut out);
        w.put(&0x0102u16.to_le_bytes());
        w.put(&[7]);
        w.put(b"ab");
        assert_eq!(w.written(), 5);
        assert_eq!(out, [2, 1, 7, b'a', b'b', 0, 0, 0]);
    }
}

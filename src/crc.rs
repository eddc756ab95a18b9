//! The CRC-32 that guards what the plotter keeps across a power cut: the flash store's records
//! and the card's resume record.

/// CRC-32 (IEEE 802.3, reflected), bit by bit: a few hundred bytes per save or record read.
/// Out of line, so that its callers share one copy in the image.
#[inline(never)]
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &byte in bytes {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            crc = (crc >> 1) ^ (0xEDB8_8320 & (crc & 1).wrapping_neg());
        }
    }
    !crc
}

#[cfg(test)]
mod tests {
    use super::crc32;

    #[test]
    fn it_gives_the_standard_check_value() {
        // The check value every CRC-32/ISO-HDLC implementation gives for "123456789".
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32(b""), 0);
    }
}

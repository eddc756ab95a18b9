//! 64-bit integers divided by small divisors with the core's 32-bit divide.
//!
//! The Cortex-M4 divides 32-bit integers in hardware but not 64-bit ones: a `u64` `/` or `%`
//! calls the runtime's software division, about 1 KB of flash for the few places that divide a
//! 64-bit count (the clock's ticks, the digits of a number). A divisor that fits 16 bits needs
//! none of it: long division, 16 bits of the dividend at a time, keeps every step within 32 bits.

/// `value / divisor` and `value % divisor`, exactly as `u64` division gives them.
pub fn div_rem(value: u64, divisor: u16) -> (u64, u32) {
    let divisor = u32::from(divisor);
    let mut quotient = 0u64;
    let mut rem = 0u32;
    for shift in [48u32, 32, 16, 0] {
        // rem < divisor ≤ 2^16: the partial dividend stays below 2^32.
        let part = (rem << 16) | ((value >> shift) as u32 & 0xFFFF);
        quotient |= u64::from(part / divisor) << shift;
        rem = part % divisor;
    }
    (quotient, rem)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_as_u64_division() {
        let values = [0, 1, 9, 10, 999, 1000, 65_535, 65_536, 1 << 32, (1 << 32) + 7, u64::MAX - 1, u64::MAX];
        for value in values.into_iter().chain((0..64).map(|k| 0x9E37_79B9_7F4A_7C15u64.rotate_left(k))) {
            for divisor in [1u16, 2, 3, 7, 10, 125, 1000, 4096, 65_535] {
                let d = u64::from(divisor);
                assert_eq!(div_rem(value, divisor), (value / d, (value % d) as u32), "{value} / {divisor}");
            }
        }
    }
}

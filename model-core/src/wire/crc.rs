//! CRC-32 (ISO-HDLC, the zlib/Ethernet CRC: polynomial 0x04C11DB7 reflected, init and final
//! XOR 0xFFFFFFFF) over the bytes between a frame's `$` and `*`.
//!
//! Why this CRC: anyone can check a frame by hand (`python3 -c "import zlib;
//! print('%08X' % zlib.crc32(b'T1,...'))"`), it detects every burst up to 32 bits and every
//! error of up to 4 bits in frames this short (at most 1 960 checked bits; Hamming distance 5
//! up to 2 974 bits), and a frame hit by other damage is falsely accepted with probability
//! 2^-32 = 2.3e-10.
//! A 256-entry table (1 KiB of flash) keeps it at about one table look-up per byte, which the
//! host decoder needs for its 100 MB/s and the MCU can afford.

/// The reflected CRC-32 polynomial.
const POLY_REFLECTED: u32 = 0xEDB8_8320;

/// The byte-wise look-up table, computed at compile time.
const TABLE: [u32; 256] = build_table();

const fn build_table() -> [u32; 256] {
    let mut table = [0u32; 256];
    let mut i = 0;
    while i < 256 {
        let mut crc = i as u32;
        let mut bit = 0;
        while bit < 8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ POLY_REFLECTED
            } else {
                crc >> 1
            };
            bit += 1;
        }
        table[i] = crc;
        i += 1;
    }
    table
}

/// CRC-32/ISO-HDLC of `bytes` (check value: `crc32(b"123456789") == 0xCBF43926`).
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xFFFF_FFFFu32;
    for &b in bytes {
        // `as u8` keeps the low byte: the index is always < 256.
        crc = (crc >> 8) ^ TABLE[usize::from((crc as u8) ^ b)];
    }
    !crc
}

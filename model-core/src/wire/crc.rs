//! CRC-32 (ISO-HDLC, the zlib/Ethernet CRC: polynomial 0x04C11DB7 reflected, init and final
//! XOR 0xFFFFFFFF) over the bytes between a frame's `$` and `*`.
//!
//! Why this CRC: anyone can check a frame by hand (`python3 -c "import zlib;
//! print('%08X' % zlib.crc32(b'T1,...'))"`), it detects every burst up to 32 bits and every
//! error of up to 4 bits in frames this short (at most 1 960 checked bits; Hamming distance 5
//! up to 2 974 bits), and a frame hit by other damage is falsely accepted with probability
//! 2^-32 = 2.3e-10.

/// The reflected CRC-32 polynomial.
const POLY_REFLECTED: u32 = 0xEDB8_8320;

/// Tables of the slicing-by-N method: `TABLES[0]` is the byte-wise table, `TABLES[k][i]` the
/// CRC of byte `i` followed by `k` zero bytes. On the host, 8 tables (8 KiB) let the decoder
/// handle 8 bytes per step (the replay speed). The MCU (`target_os = "none"`) uses the 16-entry
/// nibble table instead (64 bytes of flash, two look-ups a byte: plenty for 50 frames a second
/// and the commands; the 1 KiB byte table would cost the flash budget). Every path is checked
/// against the bit-by-bit definition and the catalogue check value.
#[cfg(not(target_os = "none"))]
const SLICES: usize = 8;
#[cfg(target_os = "none")]
const SLICES: usize = 1;

static TABLES: [[u32; 256]; SLICES] = build_tables();

const fn build_tables() -> [[u32; 256]; SLICES] {
    let mut tables = [[0u32; 256]; SLICES];
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
        tables[0][i] = crc;
        i += 1;
    }
    let mut k = 1;
    while k < SLICES {
        let mut i = 0;
        while i < 256 {
            let prev = tables[k - 1][i];
            tables[k][i] = (prev >> 8) ^ tables[0][(prev & 0xFF) as usize];
            i += 1;
        }
        k += 1;
    }
    tables
}

/// CRC-32/ISO-HDLC of `bytes` (check value: `crc32(b"123456789") == 0xCBF43926`).
///
/// On the MCU one out-of-line copy serves the encoder, the decoder and the firmware's parameter
/// log: inlined (and unrolled) into each it costs about 400 bytes of flash a copy.
#[cfg_attr(target_os = "none", inline(never))]
pub fn crc32(bytes: &[u8]) -> u32 {
    !update(0xFFFF_FFFF, bytes)
}

/// Eight bytes per step with the eight tables (host only).
#[cfg(not(target_os = "none"))]
fn update(mut crc: u32, bytes: &[u8]) -> u32 {
    let t = &TABLES;
    let mut chunks = bytes.chunks_exact(8);
    for c in &mut chunks {
        let lo = u32::from_le_bytes([c[0], c[1], c[2], c[3]]) ^ crc;
        let hi = u32::from_le_bytes([c[4], c[5], c[6], c[7]]);
        // Every index is masked to 0..=255.
        crc = t[7][(lo & 0xFF) as usize]
            ^ t[6][((lo >> 8) & 0xFF) as usize]
            ^ t[5][((lo >> 16) & 0xFF) as usize]
            ^ t[4][(lo >> 24) as usize]
            ^ t[3][(hi & 0xFF) as usize]
            ^ t[2][((hi >> 8) & 0xFF) as usize]
            ^ t[1][((hi >> 16) & 0xFF) as usize]
            ^ t[0][(hi >> 24) as usize];
    }
    update_bytewise(crc, chunks.remainder())
}

#[cfg(target_os = "none")]
fn update(crc: u32, bytes: &[u8]) -> u32 {
    update_nibblewise(crc, bytes)
}

/// `NIBBLES[i]`: the CRC register after shifting the 4-bit value `i` through the polynomial.
static NIBBLES: [u32; 16] = build_nibbles();

const fn build_nibbles() -> [u32; 16] {
    let mut t = [0u32; 16];
    let mut i = 0;
    while i < 16 {
        let mut crc = i as u32;
        let mut bit = 0;
        while bit < 4 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ POLY_REFLECTED
            } else {
                crc >> 1
            };
            bit += 1;
        }
        t[i] = crc;
        i += 1;
    }
    t
}

/// Two 16-entry look-ups per byte (the MCU's path).
fn update_nibblewise(mut crc: u32, bytes: &[u8]) -> u32 {
    for &b in bytes {
        crc ^= u32::from(b);
        // Masked to 0..=15.
        crc = (crc >> 4) ^ NIBBLES[(crc & 0xF) as usize];
        crc = (crc >> 4) ^ NIBBLES[(crc & 0xF) as usize];
    }
    crc
}

/// The nibble-wise path (the MCU's) on any target, for tests that compare it with the others.
pub fn crc32_nibblewise(bytes: &[u8]) -> u32 {
    !update_nibblewise(0xFFFF_FFFF, bytes)
}

/// One table look-up per byte.
fn update_bytewise(mut crc: u32, bytes: &[u8]) -> u32 {
    for &b in bytes {
        // `as u8` keeps the low byte: the index is always < 256.
        crc = (crc >> 8) ^ TABLES[0][usize::from((crc as u8) ^ b)];
    }
    crc
}

/// The byte-wise path alone, for tests that compare it with the sliced one.
pub fn crc32_bytewise(bytes: &[u8]) -> u32 {
    !update_bytewise(0xFFFF_FFFF, bytes)
}

//! Fuzzes the streaming wire decoder: no panic on any bytes, every byte accounted for, and
//! every accepted frame re-encodes to exactly the bytes it came from.
#![no_main]

use libfuzzer_sys::fuzz_target;
use model_core::wire::{Decoder, MAX_FRAME_LEN, encode};

fuzz_target!(|data: &[u8]| {
    let mut decoder = Decoder::new();
    let mut ok_bytes = 0u64;
    let mut line_start = None;
    for (i, &b) in data.iter().enumerate() {
        if b == b'$' {
            line_start = Some(i);
        }
        if let Some(Ok(frame)) = decoder.push(b) {
            let mut buf = [0u8; MAX_FRAME_LEN];
            let n = encode(&frame, &mut buf).expect("an accepted frame encodes");
            let start = line_start.expect("a frame starts at a $");
            let raw = &data[start..=i];
            // The only accepted non-canonical byte is a `\r` before the `\n`.
            let raw_trimmed: Vec<u8> = if raw.len() >= 2 && raw[raw.len() - 2] == b'\r' {
                [&raw[..raw.len() - 2], b"\n"].concat()
            } else {
                raw.to_vec()
            };
            assert_eq!(&buf[..n], &raw_trimmed[..]);
            ok_bytes += raw.len() as u64;
        }
    }
    decoder.finish();
    let s = decoder.stats();
    assert_eq!(s.bytes, data.len() as u64);
    assert_eq!(ok_bytes + s.bytes_skipped, s.bytes);
});

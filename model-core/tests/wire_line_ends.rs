//! Line ends: a line ends at `\r\n` (what the rig and `bowl` send), `\r` (Enter in a serial
//! console) or `\n`, each once; the streaming decoder accounts for every byte.

mod wire_support;

use model_core::wire::*;
use wire_support::*;

/// A line ends at `\r\n`, `\r` or `\n`, one line end each: no empty line, no noise, no
/// frame lost, every byte in a good frame (a console's Enter sends `\r`).
#[test]
fn cr_lf_and_crlf_each_end_one_line() {
    let base = match decode_frame(b"$T1,2000,100,5,2,0,12,0,40,0,0,0,2,12,-1,-2*17BB20C2\r\n") {
        Ok(Frame::Telemetry(t)) => t,
        other => panic!("{other:?}"),
    };
    let mut bytes = Vec::new();
    for (seq, end) in [b"\r\n".as_slice(), b"\r", b"\n", b"\r\n", b"\r"]
        .iter()
        .enumerate()
    {
        let line = encode_vec(&telemetry_with_seq(&base, seq as u16, 20 * seq as u32));
        bytes.extend(&line[..line.len() - 2]);
        bytes.extend(*end);
    }
    // Byte by byte and in bulk, the same.
    let mut d = Decoder::new();
    let mut one_by_one = Vec::new();
    for &b in &bytes {
        one_by_one.extend(d.push(b));
    }
    assert_eq!(*d.stats(), decode_all(&bytes).1);
    let (frames, stats) = decode_all(&bytes);
    assert_eq!(one_by_one.len(), 5, "one result per line: {one_by_one:?}");
    assert_eq!(frames.len(), 5);
    assert_eq!(stats.frames_corrupt, 0);
    assert_eq!(stats.bytes_skipped, 0);
    assert_eq!(stats.bytes, bytes.len() as u64);
    // A damaged line ended by `\r\n`: its `\n` is skipped with it, and counted once.
    let mut bad = encode_vec(&telemetry_with_seq(&base, 9, 180));
    bad[3] ^= 1;
    let (frames, stats) = decode_all(&bad);
    assert!(frames.is_empty());
    assert_eq!(
        (stats.frames_corrupt, stats.bytes_skipped),
        (1, bad.len() as u64)
    );
}

//! The streaming decoder on damaged streams: no panic, fixed memory, resynchronisation at the
//! next frame, every frame that was not touched comes out, every lost telemetry frame counted.

mod wire_support;

use model_core::wire::*;
use proptest::prelude::*;
use wire_support::*;

/// One frame's place in a capture: its byte range and the frame.
struct Placed {
    start: usize,
    end: usize, // exclusive, after the `\r\n`
    frame: Frame,
}

/// A capture of `n` telemetry frames (seq 0..n, the fields from `base`) with `noise[i]`
/// between frame i and i+1.
fn capture(base: &Telemetry, n: usize, noise: &[Vec<u8>]) -> (Vec<u8>, Vec<Placed>) {
    let mut bytes = Vec::new();
    let mut placed = Vec::new();
    for i in 0..n {
        let frame = telemetry_with_seq(base, i as u16, 20 * i as u32);
        let start = bytes.len();
        bytes.extend(encode_vec(&frame));
        placed.push(Placed {
            start,
            end: bytes.len(),
            frame,
        });
        if let Some(junk) = noise.get(i) {
            bytes.extend(junk);
        }
    }
    (bytes, placed)
}

/// A damage to the original capture.
#[derive(Debug, Clone)]
enum Damage {
    /// XOR the byte at this index with a non-zero mask (a bit flip when the mask has one bit).
    Xor(usize, u8),
    /// Drop the byte.
    Drop(usize),
    /// Insert a byte before this index.
    Insert(usize, u8),
}

impl Damage {
    fn index(&self) -> usize {
        match *self {
            Damage::Xor(i, _) | Damage::Drop(i) | Damage::Insert(i, _) => i,
        }
    }

    /// Whether this damage touches a frame occupying `start..end`. An insertion right before
    /// the `$` or right after the `\n` lands between frames.
    fn touches(&self, start: usize, end: usize) -> bool {
        // (The `\n` of the `\r\n` counts as part of the frame here, though a frame already
        // ended by its `\r` survives damage to it: such a frame may come out, see below.)
        match *self {
            Damage::Xor(i, _) | Damage::Drop(i) => (start..end).contains(&i),
            Damage::Insert(i, _) => i > start && i < end,
        }
    }
}

fn apply(bytes: &[u8], damage: &[Damage]) -> Vec<u8> {
    let mut sorted = damage.to_vec();
    sorted.sort_by_key(|d| d.index());
    let mut out = Vec::with_capacity(bytes.len() + damage.len());
    let mut next = sorted.iter().peekable();
    for (i, &b) in bytes.iter().enumerate() {
        let mut keep = Some(b);
        while let Some(d) = next.next_if(|d| d.index() == i) {
            match *d {
                Damage::Insert(_, x) => out.push(x),
                Damage::Drop(_) => keep = None,
                Damage::Xor(_, m) => keep = keep.map(|k| k ^ m),
            }
        }
        out.extend(keep);
    }
    out
}

fn damage_strategy(len: usize) -> impl Strategy<Value = Damage> {
    prop_oneof![
        (0..len, 0u32..8).prop_map(|(i, bit)| Damage::Xor(i, 1 << bit)),
        (0..len, 1u8..=255).prop_map(|(i, m)| Damage::Xor(i, m)),
        (0..len).prop_map(Damage::Drop),
        (0..len, any::<u8>()).prop_map(|(i, b)| Damage::Insert(i, b)),
    ]
}

/// Checks the decoder's output on a damaged capture against the damage list.
fn check_damaged(
    base: &Telemetry,
    n: usize,
    noise: &[Vec<u8>],
    damage: &[Damage],
) -> Result<(), TestCaseError> {
    let (clean, placed) = capture(base, n, noise);
    // Keep the first and last frames intact so every loss lies between two received frames.
    let damage: Vec<Damage> = damage
        .iter()
        .filter(|d| d.index() < clean.len())
        .filter(|d| !d.touches(placed[0].start, placed[0].end + 1))
        .filter(|d| !d.touches(placed[n - 1].start - 1, placed[n - 1].end))
        .filter(|d| d.index() < placed[n - 1].start)
        .cloned()
        .collect();
    let damaged = apply(&clean, &damage);
    let (frames, stats) = decode_all(&damaged);

    let untouched: Vec<Frame> = placed
        .iter()
        .filter(|p| !damage.iter().any(|d| d.touches(p.start, p.end)))
        .map(|p| p.frame)
        .collect();
    // Every untouched frame comes out, in order; anything else that comes out is an original
    // frame too (a harmless damage, like a `\r` inserted before `\n`), never a wrong one.
    let mut it = frames.iter();
    for u in &untouched {
        prop_assert!(it.any(|f| f == u), "untouched frame {:?} lost", u);
    }
    let originals: Vec<Frame> = placed.iter().map(|p| p.frame).collect();
    for f in &frames {
        prop_assert!(
            originals.contains(f),
            "decoded a frame that was never sent: {:?}",
            f
        );
    }
    // Every lost frame is counted, as corrupt (it arrived damaged) or as missing (nothing of it
    // arrived), never as both; a `$` in the damage or the noise can add corrupt candidates.
    prop_assert!(stats.frames_ok + stats.frames_missing <= n as u64);
    prop_assert!(stats.frames_ok + stats.frames_missing + stats.frames_corrupt >= n as u64);
    prop_assert_eq!(stats.frames_ok, frames.len() as u64);
    // Byte accounting: good-frame bytes plus skipped bytes is everything. This test counts a
    // good frame as its encoding; the decoder counts the bytes that arrived. They differ by
    // one byte where a line end was touched: a `\r` inserted (it ends the line early, the
    // original `\r\n` becomes noise), or a byte of the `\r\n` hit, dropped or split (the frame
    // still ends at one of them and is good with one byte fewer).
    let ok_bytes: u64 = frames.iter().map(|f| encode_vec(f).len() as u64).sum();
    let returns = damage
        .iter()
        .filter(|d| matches!(d, Damage::Insert(_, b'\r')))
        .count() as u64;
    let line_end_hits = damage
        .iter()
        .filter(|d| {
            placed
                .iter()
                .any(|p| (p.end - 2..p.end).contains(&d.index()))
        })
        .count() as u64;
    let accounted = ok_bytes + stats.bytes_skipped;
    prop_assert!(
        accounted <= damaged.len() as u64 + line_end_hits + returns
            && damaged.len() as u64 <= accounted + returns,
        "{} bytes, {} accounted, {} returns inserted",
        damaged.len(),
        accounted,
        returns
    );
    prop_assert_eq!(stats.bytes, damaged.len() as u64);
    prop_assert_eq!(
        stats.frames_corrupt,
        stats.bad_crc + stats.malformed + stats.oversize + stats.truncated
    );
    Ok(())
}

fn noise_strategy(n: usize) -> impl Strategy<Value = Vec<Vec<u8>>> {
    proptest::collection::vec(
        prop_oneof![
            3 => Just(Vec::new()),
            1 => proptest::collection::vec(any::<u8>(), 0..40),
            // Printable junk without an end of line: looks like a frame start in progress.
            1 => proptest::collection::vec(0x20u8..0x7F, 0..300),
        ],
        n,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    #[test]
    fn random_bytes_never_panic_and_are_all_accounted(bytes in proptest::collection::vec(any::<u8>(), 0..4000)) {
        let (frames, stats) = decode_all(&bytes);
        let ok_bytes: u64 = frames.iter().map(|f| encode_vec(f).len() as u64).sum();
        prop_assert_eq!(ok_bytes + stats.bytes_skipped, bytes.len() as u64);
    }

    #[test]
    fn random_frame_alphabet_never_panics(raw in proptest::collection::vec(any::<u8>(), 0..4000)) {
        // Bytes drawn from the frame alphabet, so many candidates get far into the parser.
        const ALPHABET: &[u8] = b"$$\n\n,,**--0123456789ABCDEFTHCARSP1";
        let bytes: Vec<u8> = raw.iter().map(|&b| ALPHABET[usize::from(b) % ALPHABET.len()]).collect();
        let (_frames, stats) = decode_all(&bytes);
        prop_assert_eq!(stats.bytes, bytes.len() as u64);
    }

    #[test]
    fn damaged_captures_lose_only_touched_frames(
        base in telemetry(),
        n in 3usize..40,
        noise in noise_strategy(40),
        damage in proptest::collection::vec(damage_strategy(4000), 0..12),
    ) {
        check_damaged(&base, n, &noise, &damage)?;
    }

    /// Truncated frames (a prefix, no end of line) and oversize lines between good frames cost
    /// nothing but themselves.
    #[test]
    fn truncated_and_oversize_frames_resync(
        base in telemetry(),
        cut in 1usize..100,
        long in 250usize..600,
    ) {
        let a = encode_vec(&telemetry_with_seq(&base, 0, 0));
        let b = encode_vec(&telemetry_with_seq(&base, 1, 20));
        let c = encode_vec(&telemetry_with_seq(&base, 2, 40));
        let mut bytes = a.clone();
        bytes.extend(&b[..cut.min(b.len() - 2)]); // frame 1 cut short, before its `\r\n`
        bytes.extend(&c);
        bytes.push(b'$');
        bytes.extend(std::iter::repeat_n(b'7', long)); // oversize line
        bytes.push(b'\n');
        bytes.extend(encode_vec(&telemetry_with_seq(&base, 3, 60)));
        let (frames, stats) = decode_all(&bytes);
        prop_assert_eq!(frames.len(), 3);
        // Frame 1 arrived cut short: corrupt, not also missing.
        prop_assert_eq!(stats.frames_missing, 0);
        prop_assert!(stats.frames_corrupt >= 2);
    }
}

/// Tiny deterministic generator (xorshift64*), so the 1 % test is reproducible.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
}

#[test]
fn one_percent_corrupted_bytes_lose_only_the_touched_frames() {
    // The typical frame of docs/protocol.md (its time and sequence number are replaced).
    let Ok(Frame::Telemetry(base)) = decode_frame(
        b"$T1,123456,6172,3,0,1800,1796,4521,315,2100,2101,5230,367,3381,2345,2410*86D01424\r\n",
    ) else {
        panic!("the doc's telemetry example decodes")
    };
    let n = 20_000; // wraps the 16-bit sequence number too
    let (clean, placed) = capture(&base, n, &[]);
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut damaged = clean.clone();
    let mut hit = vec![false; n];
    let mut corrupted = 0;
    let mut dollars = 0u64;
    let mut frame_of = 0;
    for (i, byte) in damaged.iter_mut().enumerate() {
        while placed[frame_of].end <= i {
            frame_of += 1;
        }
        let first_or_last = frame_of == 0 || frame_of == n - 1;
        if !first_or_last && rng.next().is_multiple_of(100) {
            *byte ^= (1 + rng.next() % 255) as u8;
            dollars += u64::from(*byte == b'$');
            // The `\n` after the `\r` that ended the frame: the frame is already complete.
            let lf = i + 1 == placed[frame_of].end;
            hit[frame_of] |= !lf;
            corrupted += 1;
        }
    }
    let (frames, stats) = decode_all(&damaged);
    let untouched: Vec<Frame> = placed
        .iter()
        .zip(&hit)
        .filter(|(_, h)| !**h)
        .map(|(p, _)| p.frame)
        .collect();
    let hit_frames = hit.iter().filter(|h| **h).count();
    assert_eq!(frames, untouched, "exactly the untouched frames come out");
    assert_eq!(stats.frames_ok as usize + hit_frames, n);
    // Each hit frame is counted once, as corrupt or as missing; a byte turned into `$` can
    // split one hit frame into two corrupt candidates.
    let counted = stats.frames_corrupt + stats.frames_missing;
    assert!(
        counted >= hit_frames as u64 && counted <= hit_frames as u64 + dollars,
        "{counted} counted for {hit_frames} hit frames ({dollars} bytes turned into $)"
    );
    // About 1 % of the bytes; about 56 % of the 83-byte frames hit before their `\n`
    // (1 - 0.99^82).
    assert!((corrupted as f64 / clean.len() as f64 - 0.01).abs() < 0.001);
    eprintln!(
        "1 %: {} bytes, {} corrupted, {} frames hit of {}, ok {}, missing {}, corrupt {}, skipped {}",
        clean.len(),
        corrupted,
        hit_frames,
        n,
        stats.frames_ok,
        stats.frames_missing,
        stats.frames_corrupt,
        stats.bytes_skipped
    );
}

proptest! {
    /// The bulk path and the byte-wise path agree on every input, however it is split.
    #[test]
    fn push_slice_equals_push(
        base in telemetry(),
        noise in noise_strategy(8),
        damage in proptest::collection::vec(damage_strategy(1000), 0..8),
        split in 1usize..300,
    ) {
        let (clean, _) = capture(&base, 8, &noise);
        let bytes = apply(&clean, &damage);
        let mut bytewise = Decoder::new();
        let mut expected = Vec::new();
        for &b in &bytes {
            if let Some(r) = bytewise.push(b) {
                expected.push(r);
            }
        }
        let mut bulk = Decoder::new();
        let mut got = Vec::new();
        for chunk in bytes.chunks(split) {
            bulk.push_slice(chunk, |r, _| got.push(r));
        }
        prop_assert_eq!(got, expected);
        prop_assert_eq!(bulk.stats(), bytewise.stats());
    }
}

#[test]
fn memory_is_fixed() {
    // One frame buffer plus counters, whatever the input.
    assert!(core::mem::size_of::<Decoder>() <= MAX_FRAME_LEN + 160);
}

#[test]
fn restarts_and_duplicates_are_not_counted_as_missing() {
    let base = match decode_frame(b"$T1,2000,100,4,2,0,12,0,40,0,0,0,2,12,-1,-2*2BDBC3CA\n") {
        Ok(Frame::Telemetry(t)) => t,
        other => panic!("{other:?}"),
    };
    let mut bytes = Vec::new();
    for (seq, time) in [(10u16, 1000u32), (11, 1020), (11, 1020), (14, 1080)] {
        bytes.extend(encode_vec(&telemetry_with_seq(&base, seq, time)));
    }
    // Device reset: hello, then the sequence starts again.
    bytes.extend(encode_vec(&Frame::Hello(Hello {
        reset_cause: ResetCause::Pin,
        reset_count: 2,
    })));
    for k in 0..40u16 {
        bytes.extend(encode_vec(&telemetry_with_seq(
            &base,
            k,
            5 + 20 * u32::from(k),
        )));
    }
    // Reset with the hello lost: time and sequence start again.
    bytes.extend(encode_vec(&telemetry_with_seq(&base, 0, 3)));
    let (_, stats) = decode_all(&bytes);
    assert_eq!(stats.frames_missing, 2);
    assert_eq!(stats.duplicates, 1);
    assert_eq!(stats.restarts, 2);
    assert_eq!(stats.reordered, 0);
}

fn stats_of(frames: &[(u16, u32)]) -> DecodeStats {
    let base = match decode_frame(b"$T1,2000,100,4,2,0,12,0,40,0,0,0,2,12,-1,-2*2BDBC3CA\n") {
        Ok(Frame::Telemetry(t)) => t,
        other => panic!("{other:?}"),
    };
    let mut bytes = Vec::new();
    for &(seq, time) in frames {
        bytes.extend(encode_vec(&telemetry_with_seq(&base, seq, time)));
    }
    decode_all(&bytes).1
}

/// A 30-minute outage at 50 Hz is 90,000 frames: the 16-bit sequence wraps once in it, and the
/// device clock says so.
#[test]
fn an_outage_longer_than_the_sequence_wrap_counts_every_frame() {
    let mut frames: Vec<(u16, u32)> = (0..10u16).map(|k| (k, 20 * u32::from(k))).collect();
    let last = 9u32;
    let resume = last + 90_001; // frames 10 ..= 90_009 lost
    for k in resume..resume + 5 {
        frames.push(((k % 65_536) as u16, 20 * k));
    }
    let stats = stats_of(&frames);
    assert_eq!(stats.frames_missing, 90_000);
    assert_eq!(stats.restarts, 0);
}

/// The device's millisecond clock wraps after 49.7 days: a step forward, not a restart.
#[test]
fn a_clock_wrap_is_not_a_restart() {
    let start = u32::MAX - 45;
    let frames: Vec<(u16, u32)> = (0..6u16)
        .map(|k| (k, start.wrapping_add(20 * u32::from(k))))
        .filter(|&(k, _)| k != 3)
        .collect();
    let stats = stats_of(&frames);
    assert_eq!(stats.restarts, 0);
    assert_eq!(stats.frames_missing, 1, "frame 3 was left out");
}

/// A frame that comes a few frames late is late, not a restart, and not missing either.
#[test]
fn a_late_frame_is_reordered_not_a_restart() {
    let frames = [(0u16, 0u32), (1, 20), (3, 60), (4, 80), (2, 40), (5, 100)];
    let stats = stats_of(&frames);
    assert_eq!(stats.restarts, 0);
    assert_eq!(stats.reordered, 1);
    assert_eq!(stats.frames_missing, 0, "frame 2 came after all");
}

/// A hit delimiter costs only its own frame: whatever replaces the line end (`\r`) of frame 1 or
/// the `$` of frame 3 (any of the 255 other byte values), frames 0, 2 and 4 come out; frame 1
/// too where its `\r` became the other line end, `\n`. Whatever replaces the `\n` after the
/// `\r`, nothing is lost.
#[test]
fn a_hit_delimiter_never_takes_a_neighbour() {
    let base = match decode_frame(b"$T1,2000,100,5,2,0,12,0,40,0,0,0,2,12,-1,-2*17BB20C2\n") {
        Ok(Frame::Telemetry(t)) => t,
        other => panic!("{other:?}"),
    };
    let (clean, placed) = capture(&base, 5, &[]);
    for x in 1..=255u8 {
        for (frame, at) in [
            (1, placed[1].end - 2),
            (3, placed[3].start),
            (5, placed[1].end - 1),
        ] {
            let mut bytes = clean.clone();
            bytes[at] ^= x;
            let lost = match frame {
                1 => bytes[at] != b'\n',
                3 => true,
                _ => false,
            };
            let (frames, stats) = decode_all(&bytes);
            let seqs: Vec<u16> = frames
                .iter()
                .map(|f| match f {
                    Frame::Telemetry(t) => t.seq,
                    other => panic!("{other:?}"),
                })
                .collect();
            let want: Vec<u16> = (0..5).filter(|&s| !lost || s != frame).collect();
            assert_eq!(
                seqs, want,
                "delimiter of frame {frame} hit with xor {x:#04x}"
            );
            // The hit frame is counted once (as corrupt, or as missing when nothing of it
            // was recognised), twice only where the hit byte became a `$`.
            let counted = stats.frames_corrupt + stats.frames_missing;
            let extra = u64::from(bytes[at] == b'$');
            let once = u64::from(lost);
            assert!(
                (once..=once + extra).contains(&counted),
                "{counted} counted, frame {frame}, xor {x:#04x}"
            );
        }
    }
}

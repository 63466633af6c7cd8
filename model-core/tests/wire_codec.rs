//! Encoder and decoder agree on every frame, and the frame sizes are what the spec says.

mod wire_support;

use model_core::wire::crc::crc32;
use model_core::wire::*;
use proptest::prelude::*;
use wire_support::*;

/// Bit-by-bit CRC-32 straight from the definition: an independent reference for the table.
fn crc32_bitwise(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        for i in 0..8 {
            let bit = ((b >> i) & 1) as u32 ^ (crc & 1);
            crc >>= 1;
            if bit != 0 {
                crc ^= 0xEDB8_8320;
            }
        }
    }
    !crc
}

#[test]
fn crc_check_value() {
    assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    assert_eq!(crc32(b""), 0);
}

#[test]
fn widest_telemetry_is_max_telemetry_len() {
    let widest_motor = MotorTelemetry {
        set_mrad_s: i16::MIN,
        measured_mrad_s: i16::MIN,
        duty_bp: -10_000,
        pulses: u16::MAX,
    };
    let t = Telemetry {
        time_ms: u32::MAX,
        seq: u16::MAX,
        state: DeviceState::Faulted,
        fault: FaultCode::InvalidConfiguration,
        precession: widest_motor,
        spin: widest_motor,
        bowl_mrad_s: u16::MAX,
        residence_flat: Residence::Ms(RESIDENCE_MAX_MS),
        residence_coriolis: Residence::Ms(RESIDENCE_MAX_MS),
    };
    assert_eq!(encode_vec(&Frame::Telemetry(t)).len(), MAX_TELEMETRY_LEN);
}

/// The widest PARAMS answer (every value at the wider end of its range, the longest id) fits
/// in `MAX_FRAME_LEN`: the residence-time table's ten parameters were sized for it.
#[test]
fn the_widest_params_answer_fits_the_frame_limit() {
    let mut values = [0i32; PARAM_COUNT];
    for (v, id) in values.iter_mut().zip(ParamId::ALL) {
        let (lo, hi) = id.range();
        *v = if lo.to_string().len() > hi.to_string().len() {
            lo
        } else {
            hi
        };
    }
    let n = encode_vec(&Frame::Params { id: 65535, values }).len();
    assert!(n <= MAX_FRAME_LEN, "{n} bytes");
    println!("widest PARAMS answer: {n} of {MAX_FRAME_LEN} bytes");
}

#[test]
fn out_of_range_fields_are_refused_by_the_encoder() {
    let mut buf = [0u8; MAX_FRAME_LEN];
    let bad = Frame::Command {
        id: 1,
        command: Command::SetParam {
            id: ParamId::Teeth1,
            value: 0,
        },
    };
    assert_eq!(encode(&bad, &mut buf), Err(EncodeError::FieldOutOfRange));
    let mut small = [0u8; 10];
    assert_eq!(
        encode(&Frame::Ack { id: 65535 }, &mut small),
        Err(EncodeError::BufferTooSmall)
    );
}

#[test]
fn residence_from_seconds() {
    assert_eq!(Residence::from_seconds(Some(2.3456)), Residence::Ms(2346));
    assert_eq!(Residence::from_seconds(None), Residence::NeverLeaves);
    assert_eq!(
        Residence::from_seconds(Some(f32::NAN)),
        Residence::Unavailable
    );
    assert_eq!(Residence::from_seconds(Some(-1.0)), Residence::Unavailable);
    assert_eq!(Residence::from_seconds(Some(1e5)), Residence::Unavailable);
    assert_eq!(
        Residence::from_seconds(Some(9_999.999)),
        Residence::Ms(RESIDENCE_MAX_MS)
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn crc_table_matches_bitwise_definition(bytes in proptest::collection::vec(any::<u8>(), 0..300)) {
        prop_assert_eq!(crc32(&bytes), crc32_bitwise(&bytes));
        prop_assert_eq!(model_core::wire::crc::crc32_bytewise(&bytes), crc32_bitwise(&bytes));
        prop_assert_eq!(model_core::wire::crc::crc32_nibblewise(&bytes), crc32_bitwise(&bytes));
    }

    #[test]
    fn every_frame_round_trips(frame in frame()) {
        let bytes = encode_vec(&frame);
        prop_assert!(bytes.len() <= MAX_FRAME_LEN);
        if let Frame::Telemetry(_) = frame {
            prop_assert!(bytes.len() <= MAX_TELEMETRY_LEN);
        }
        // Printable ASCII between `$` and the `\r\n` every frame ends with: one readable line
        // in any console.
        prop_assert!(bytes.ends_with(b"\r\n"));
        prop_assert!(bytes[1..bytes.len() - 2].iter().all(|b| (0x20..0x7F).contains(b) && *b != b'$'));
        prop_assert_eq!(decode_frame(&bytes), Ok(frame));
    }

    /// Any line the decoder accepts is canonical: re-encoding gives the same bytes.
    #[test]
    fn accepted_lines_are_canonical(frame in frame(), pos in any::<prop::sample::Index>(), b in 0x20u8..0x7F) {
        let mut bytes = encode_vec(&frame);
        // Change one payload byte and fix the CRC up: only the field check stands in the way.
        let star = bytes.len() - 11;
        let i = 1 + pos.index(star - 1);
        bytes[i] = b;
        let crc = crc32(&bytes[1..star]);
        let hex = format!("{crc:08X}");
        bytes[star + 1..star + 9].copy_from_slice(hex.as_bytes());
        if let Ok(decoded) = decode_frame(&bytes) {
            prop_assert_eq!(encode_vec(&decoded), bytes);
        }
    }

    /// Up to four flipped bits between `$` and `*` are always detected (Hamming distance 5 at
    /// these lengths), whatever else the flips do to the fields.
    #[test]
    fn up_to_four_bit_errors_in_the_checked_part_are_detected(
        frame in frame(),
        bits in proptest::collection::vec(any::<prop::sample::Index>(), 1..=4),
    ) {
        let mut bytes = encode_vec(&frame);
        let checked = 1..bytes.len() - 11;
        let nbits = checked.len() * 8;
        let positions: std::collections::BTreeSet<usize> = bits.iter().map(|i| i.index(nbits)).collect();
        for p in &positions {
            bytes[checked.start + p / 8] ^= 1 << (p % 8);
        }
        prop_assert!(decode_frame(&bytes).is_err(), "{} flips undetected", positions.len());
    }

    /// One changed byte anywhere is always detected (CRC-32 catches every burst of <= 32 bits).
    #[test]
    fn single_byte_damage_is_always_detected(frame in frame(), pos in any::<prop::sample::Index>(), x in 1u8..=255) {
        let mut bytes = encode_vec(&frame);
        let i = pos.index(bytes.len());
        bytes[i] ^= x;
        if i + 2 >= bytes.len() && matches!(bytes[i], b'\r' | b'\n') {
            // The line end is outside the check: one line end turned into another still ends
            // the same intact line, so it may decode, but only to the frame that was sent.
            prop_assert!(decode_frame(&bytes).is_err() || decode_frame(&bytes) == Ok(frame));
        } else {
            prop_assert!(decode_frame(&bytes).is_err());
        }
    }
}

proptest! {
    /// The rig's command-only parser agrees with the full parser on every command frame, and
    /// refuses every other kind as an unknown kind (it never reads their fields).
    #[test]
    fn command_parser_agrees_on_commands_and_skips_the_rest(frame in frame()) {
        let bytes = encode_vec(&frame);
        let line = &bytes[1..bytes.len() - 1];
        let full = parse_line(line);
        prop_assert_eq!(full, Ok(frame));
        match frame {
            Frame::Command { .. } => prop_assert_eq!(parse_command_line(line), full),
            _ => prop_assert_eq!(parse_command_line(line), Err(FrameError::UnknownKind)),
        }
    }
}

/// Every refusal reason's wire token reads back as that reason (one table both ways); a word
/// that is not a token, in another case or with a space, names none.
#[test]
fn reason_tokens_read_back() {
    let mut tokens: Vec<&str> = Reason::ALL.iter().map(|r| r.token()).collect();
    for &r in Reason::ALL.iter() {
        assert_eq!(Reason::from_token(r.token().as_bytes()), Some(r), "{r:?}");
    }
    tokens.sort_unstable();
    tokens.dedup();
    assert_eq!(tokens.len(), Reason::ALL.len(), "two reasons share a token");
    for word in ["", "range", "Range", "RANGE ", "OK", "NONE"] {
        assert_eq!(Reason::from_token(word.as_bytes()), None, "{word:?}");
    }
}

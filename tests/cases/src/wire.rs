//! Cases for the serial protocol (`model_core::wire`) on the target: the CRC against its
//! published check value, the spec's worked example against its human reading, resynchronisation;
//! benchmarks of building and decoding one telemetry frame (the MCU builds 50 a second).

use crate::check::{Bench, Case, Failure, ensure};
use model_core::wire::crc::crc32;
use model_core::wire::{
    Decoder, DeviceState, FaultCode, Frame, MAX_FRAME_LEN, MotorTelemetry, Residence, Telemetry,
    encode,
};

/// Cases of this module.
pub static CASES: &[Case] = &[
    Case {
        name: "wire::crc32_check_value",
        run: crc_check_value,
    },
    Case {
        name: "wire::doc_example_decodes_and_re_encodes",
        run: doc_example,
    },
    Case {
        name: "wire::decoder_resyncs_after_a_lost_end_of_line",
        run: resync,
    },
];

/// Benchmarks of this module.
pub static BENCHES: &[Bench] = &[
    Bench {
        name: "wire::encode_telemetry",
        inputs: 8,
        run: bench_encode,
        budget_instructions: None,
    },
    Bench {
        name: "wire::decode_telemetry_frame",
        inputs: 1,
        run: bench_decode,
        budget_instructions: None,
    },
];

/// The first telemetry example of docs/protocol.md, with the `\r\n` every frame ends with.
const EXAMPLE: &[u8] =
    b"$T1,123456,6172,3,0,1800,1796,4521,315,2100,2101,5230,367,3381,2345,2410*86D01424\r\n";

/// What the doc says the example means: "123.456 s after reset, frame 6172, running, no fault;
/// precession set 1.800 rad/s, measured 1.796, duty 45.21 %, 315 pulses; spin set 2.100, measured
/// 2.101, duty 52.30 %, 367 pulses; bowl 3.381 rad/s; 2.345 s (flat), 2.410 s (Coriolis)".
fn example_meaning() -> Telemetry {
    Telemetry {
        time_ms: 123_456,
        seq: 6172,
        state: DeviceState::Running,
        fault: FaultCode::None,
        precession: MotorTelemetry {
            set_mrad_s: 1800,
            measured_mrad_s: 1796,
            duty_bp: 4521,
            pulses: 315,
        },
        spin: MotorTelemetry {
            set_mrad_s: 2100,
            measured_mrad_s: 2101,
            duty_bp: 5230,
            pulses: 367,
        },
        bowl_mrad_s: 3381,
        residence_flat: Residence::Ms(2345),
        residence_coriolis: Residence::Ms(2410),
    }
}

fn crc_check_value() -> Result<(), Failure> {
    // The catalogue check value of CRC-32/ISO-HDLC.
    ensure(
        "crc32(123456789) == CBF43926",
        crc32(b"123456789") == 0xCBF4_3926,
    )
}

fn doc_example() -> Result<(), Failure> {
    let decoded = model_core::wire::decode_frame(EXAMPLE);
    ensure(
        "decoded example equals its reading",
        decoded == Ok(Frame::Telemetry(example_meaning())),
    )?;
    let mut buf = [0u8; MAX_FRAME_LEN];
    let n = encode(&Frame::Telemetry(example_meaning()), &mut buf);
    ensure("re-encoded length", n == Ok(EXAMPLE.len()))?;
    ensure(
        "re-encoded bytes",
        buf.get(..EXAMPLE.len()) == Some(EXAMPLE),
    )
}

fn resync() -> Result<(), Failure> {
    let mut d = Decoder::new();
    let mut ok = 0u32;
    // Noise, the example with its `\r\n` lost, then the example intact.
    let first = EXAMPLE.get(..EXAMPLE.len() - 2).unwrap_or(&[]);
    for part in [&b"\x00\xffnoise"[..], first, EXAMPLE] {
        d.push_slice(part, |r, _| ok += u32::from(r.is_ok()));
    }
    ensure("exactly the intact frame decodes", ok == 1)?;
    ensure("one corrupt candidate", d.stats().frames_corrupt == 1)
}

fn bench_encode(i: usize) -> f32 {
    let mut t = example_meaning();
    // Vary the widths a little across the grid.
    t.time_ms = t.time_ms.wrapping_mul(i as u32 + 1);
    t.seq = t.seq.wrapping_add(i as u16 * 9000);
    t.spin.duty_bp = -(i as i16) * 1000;
    let mut buf = [0u8; MAX_FRAME_LEN];
    match encode(&Frame::Telemetry(t), &mut buf) {
        Ok(n) => n as f32,
        Err(_) => f32::NAN,
    }
}

fn bench_decode(_i: usize) -> f32 {
    let mut d = Decoder::new();
    let mut n = 0u32;
    d.push_slice(core::hint::black_box(EXAMPLE), |r, _| {
        n += u32::from(r.is_ok())
    });
    if n == 1 { 1.0 } else { f32::NAN }
}

//! Shared proptest strategies for the wire tests.
#![allow(dead_code)]

use model_core::wire::*;
use proptest::prelude::*;

/// Every frame a byte stream holds, and the decoder's counters after its end.
pub fn decode_all(bytes: &[u8]) -> (Vec<Frame>, DecodeStats) {
    let mut d = Decoder::new();
    let mut frames = Vec::new();
    d.push_slice(bytes, |r, _| {
        if let Ok(f) = r {
            frames.push(f)
        }
    });
    d.finish();
    (frames, *d.stats())
}

pub fn device_state() -> impl Strategy<Value = DeviceState> {
    (0i64..6).prop_map(|c| DeviceState::from_code(c).unwrap())
}

pub fn fault() -> impl Strategy<Value = FaultCode> {
    (0i64..15).prop_map(|c| FaultCode::from_code(c).unwrap())
}

pub fn reset_cause() -> impl Strategy<Value = ResetCause> {
    (0i64..7).prop_map(|c| ResetCause::from_code(c).unwrap())
}

pub fn residence() -> impl Strategy<Value = Residence> {
    prop_oneof![
        (0u32..=RESIDENCE_MAX_MS).prop_map(Residence::Ms),
        Just(Residence::NeverLeaves),
        Just(Residence::Unavailable),
    ]
}

pub fn motor() -> impl Strategy<Value = MotorTelemetry> {
    (
        any::<i16>(),
        any::<i16>(),
        -10_000i16..=10_000,
        any::<u16>(),
    )
        .prop_map(
            |(set_mrad_s, measured_mrad_s, duty_bp, pulses)| MotorTelemetry {
                set_mrad_s,
                measured_mrad_s,
                duty_bp,
                pulses,
            },
        )
}

pub fn telemetry() -> impl Strategy<Value = Telemetry> {
    (
        any::<u32>(),
        any::<u16>(),
        device_state(),
        fault(),
        motor(),
        motor(),
        any::<u16>(),
        residence(),
        residence(),
    )
        .prop_map(
            |(time_ms, seq, state, fault, p, s, bowl, rf, rc)| Telemetry {
                time_ms,
                seq,
                state,
                fault,
                precession: p,
                spin: s,
                bowl_mrad_s: bowl,
                residence_flat: rf,
                residence_coriolis: rc,
            },
        )
}

pub fn param_value(id: ParamId) -> impl Strategy<Value = i32> {
    let (lo, hi) = id.range();
    lo..=hi
}

pub fn param_values() -> impl Strategy<Value = ParamValues> {
    let strategies: Vec<_> = ParamId::ALL.iter().map(|&id| param_value(id)).collect();
    strategies.prop_map(|v| {
        let mut out = [0i32; PARAM_COUNT];
        out.copy_from_slice(&v);
        out
    })
}

pub fn command() -> impl Strategy<Value = Command> {
    let model = prop_oneof![Just(ResidenceModel::Flat), Just(ResidenceModel::Coriolis)];
    let param = (0..PARAM_COUNT).prop_flat_map(|i| {
        let id = ParamId::ALL[i];
        param_value(id).prop_map(move |value| Command::SetParam { id, value })
    });
    prop_oneof![
        (0..=i16::MAX, 0..=i16::MAX).prop_map(|(p, s)| Command::SetSpeeds {
            precession_mrad_s: p,
            spin_mrad_s: s
        }),
        (model, 1u32..=RESIDENCE_MAX_MS)
            .prop_map(|(model, time_ms)| Command::SetResidence { model, time_ms }),
        Just(Command::Start),
        Just(Command::Stop),
        Just(Command::ClearFault),
        param,
        Just(Command::GetStatus),
        Just(Command::GetParams),
        Just(Command::Ping),
        Just(Command::Commission),
        Just(Command::GetModels),
        Just(Command::Release),
        (0..Injection::ALL.len()).prop_map(|i| Command::Inject {
            what: Injection::ALL[i]
        }),
    ]
}

pub fn frame() -> impl Strategy<Value = Frame> {
    prop_oneof![
        4 => telemetry().prop_map(Frame::Telemetry),
        1 => (reset_cause(), any::<u16>()).prop_map(|(reset_cause, reset_count)| Frame::Hello(Hello {
            reset_cause,
            reset_count
        })),
        1 => (any::<bool>(), any::<u32>(), any::<u16>()).prop_map(|(exit, time_us, boot)| {
            Frame::Event(GateEvent {
                kind: if exit { GateKind::Exit } else { GateKind::Release },
                time_us,
                boot,
            })
        }),
        1 => (any::<u16>(), command()).prop_map(|(id, command)| Frame::Command { id, command }),
        1 => any::<u16>().prop_map(|id| Frame::Ack { id }),
        1 => (any::<u16>(), 0..Reason::ALL.len()).prop_map(|(id, r)| Frame::Reject {
            id,
            reason: Reason::ALL[r]
        }),
        1 => (
            any::<u16>(),
            device_state(),
            fault(),
            reset_cause(),
            any::<u16>(),
            any::<u32>(),
            0u8..=50,
            any::<u8>()
        )
            .prop_map(|(id, state, fault, reset_cause, reset_count, uptime_ms, hz, flags)| {
                Frame::Status {
                    id,
                    status: Status {
                        state,
                        fault,
                        reset_cause,
                        reset_count,
                        uptime_ms,
                        telemetry_hz: hz,
                        flags,
                    },
                }
            }),
        1 => (any::<u16>(), param_values()).prop_map(|(id, values)| Frame::Params { id, values }),
        1 => (any::<u16>(), axis_model(), axis_model())
            .prop_map(|(id, a, b)| Frame::Models { id, axes: [a, b] }),
        1 => (
            any::<u16>(),
            prop_oneof![Just(ResidenceModel::Flat), Just(ResidenceModel::Coriolis)],
            any::<i16>(),
            any::<i16>()
        )
            .prop_map(|(id, model, precession_mrad_s, spin_mrad_s)| {
                Frame::ResidenceSet {
                    id,
                    model,
                    precession_mrad_s,
                    spin_mrad_s,
                }
            }),
    ]
}

pub fn axis_model() -> impl Strategy<Value = AxisModel> {
    let v = || 0..=MODEL_FIELD_MAX;
    (any::<bool>(), v(), v(), v(), v(), v()).prop_map(|(identified, ke, fr, tau, kp, ki)| {
        AxisModel {
            identified,
            back_emf_uv_per_rad_s: ke,
            friction_ppm: fr,
            time_constant_us: tau,
            kp_ppm_per_rad_s: kp,
            ki_ppm_per_rad: ki,
        }
    })
}

pub fn encode_vec(frame: &Frame) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME_LEN];
    let n = encode(frame, &mut buf).expect("in-range frame encodes");
    buf[..n].to_vec()
}

/// A telemetry frame with sequence number `seq` and the other fields from `base`.
pub fn telemetry_with_seq(base: &Telemetry, seq: u16, time_ms: u32) -> Frame {
    let mut t = *base;
    t.seq = seq;
    t.time_ms = time_ms;
    Frame::Telemetry(t)
}

//! The device side of the protocol over a recording test rig: every command gets exactly one
//! answer, a rejected command never reaches the rig, telemetry is paced and numbered.

mod wire_support;

use model_core::wire::device::{Backend, Device, ResidenceChoice};
use model_core::wire::*;
use proptest::prelude::*;

/// A rig that records what it was asked to do.
#[derive(Default)]
struct Recorder {
    calls: Vec<String>,
    speed_max: i32,
    now_ms: u32,
}

impl Backend for Recorder {
    fn telemetry(&self) -> Telemetry {
        Telemetry {
            time_ms: self.now_ms,
            seq: 9999, // overwritten by Device
            state: DeviceState::Idle,
            fault: FaultCode::None,
            precession: MotorTelemetry::default(),
            spin: MotorTelemetry::default(),
            bowl_mrad_s: 0,
            residence_flat: Residence::Unavailable,
            residence_coriolis: Residence::Unavailable,
        }
    }
    fn reset_info(&self) -> Hello {
        Hello {
            reset_cause: ResetCause::Pin,
            reset_count: 4,
        }
    }
    fn set_speeds(&mut self, p: i16, s: i16) -> Result<(), Reason> {
        self.calls.push(format!("speeds {p} {s}"));
        Ok(())
    }
    /// The Coriolis model answers (with setpoints made from the target), the flat one cannot.
    fn set_residence(&mut self, m: ResidenceModel, t: u32) -> Result<ResidenceChoice, Reason> {
        self.calls.push(format!("residence {m:?} {t}"));
        match m {
            ResidenceModel::Coriolis => Ok(ResidenceChoice {
                model: m,
                precession_mrad_s: (t / 2) as i16,
                spin_mrad_s: (t / 3) as i16,
            }),
            ResidenceModel::Flat => Err(Reason::Infeasible),
        }
    }
    fn start(&mut self) -> Result<(), Reason> {
        self.calls.push("start".into());
        Ok(())
    }
    fn stop(&mut self) {
        self.calls.push("stop".into());
    }
    fn clear_fault(&mut self) -> Result<(), Reason> {
        self.calls.push("clear".into());
        Err(Reason::State)
    }
    fn set_param(&mut self, id: ParamId, v: i32) -> Result<(), Reason> {
        self.calls.push(format!("param {} {v}", id.token()));
        Ok(())
    }
    fn param(&self, id: ParamId) -> i32 {
        match id {
            ParamId::SpeedMax1MradS | ParamId::SpeedMax2MradS => self.speed_max,
            _ => id.range().0,
        }
    }
}

fn answers(device: &mut Device, rig: &mut Recorder, input: &[u8]) -> Vec<Frame> {
    let mut out = Vec::new();
    device.receive(rig, input, |bytes| out.push(decode_frame(bytes).unwrap()));
    out
}

fn line(payload: &str) -> Vec<u8> {
    format!(
        "${payload}*{:08X}\n",
        model_core::wire::crc::crc32(payload.as_bytes())
    )
    .into_bytes()
}

/// A recording rig that allows 5,000 mrad/s, and a fresh device.
fn rig_and_device() -> (Recorder, Device) {
    let rig = Recorder {
        speed_max: 5000,
        ..Default::default()
    };
    (rig, Device::new())
}

/// RTIME is answered with the model that answered and the setpoints it chose; a resend after a
/// lost answer gets the same answer without a second run.
#[test]
fn rtime_says_which_model_answered_and_a_resend_repeats_it() {
    let (mut rig, mut d) = rig_and_device();
    let mut input = line("C1,21,RTIME,CORI,3000");
    input.extend(line("C1,21,RTIME,CORI,3000"));
    let got = answers(&mut d, &mut rig, &input);
    let want = Frame::ResidenceSet {
        id: 21,
        model: ResidenceModel::Coriolis,
        precession_mrad_s: 1500,
        spin_mrad_s: 1000,
    };
    assert_eq!(got, vec![want, want]);
    assert_eq!(rig.calls, vec!["residence Coriolis 3000"]);
}

#[test]
fn each_command_gets_its_answer() {
    let (mut rig, mut d) = rig_and_device();
    let mut input = Vec::new();
    for p in [
        "C1,1,SPEED,1800,2100",
        "C1,2,SPEED,1800,5001",
        "C1,3,SPEED,-1,0",
        "C1,4,RTIME,FLAT,2000",
        "C1,5,START",
        "C1,6,STOP",
        "C1,7,CLEAR",
        "C1,8,SET,TEETH2,12",
        "C1,9,SET,TELEM_HZ,51",
        "C1,10,SET,TELEM_HZ,25",
        "C1,11,STATUS",
        "C1,12,PARAMS",
        "C1,13,INJECT,STALL1",
        "C1,14,FLY",
        "C2,15,START",
    ] {
        input.extend(line(p));
    }
    let got = answers(&mut d, &mut rig, &input);
    use Reason::*;
    let expect_simple = [
        (1, None),
        (2, Some(Range)),
        (3, Some(Range)),
        (4, Some(Infeasible)),
        (5, None),
        (6, None),
        (7, Some(State)),
        (8, None),
        (9, Some(Range)),
        (10, None),
    ];
    for (frame, (id, reason)) in got.iter().zip(expect_simple) {
        let want = match reason {
            None => Frame::Ack { id },
            Some(reason) => Frame::Reject { id, reason },
        };
        assert_eq!(*frame, want);
    }
    match got[10] {
        Frame::Status { id: 11, status } => {
            assert_eq!(status.telemetry_hz, 25);
            assert_eq!(status.reset_cause, ResetCause::Pin);
            assert_eq!(status.reset_count, 4);
        }
        ref other => panic!("{other:?}"),
    }
    match got[11] {
        Frame::Params { id: 12, values } => {
            assert_eq!(values[ParamId::SpeedMax2MradS.index()], 5000);
            assert_eq!(values[ParamId::TelemetryHz.index()], 25);
        }
        ref other => panic!("{other:?}"),
    }
    assert_eq!(
        got[12],
        Frame::Reject {
            id: 13,
            reason: Unsupported
        }
    );
    assert_eq!(
        got[13],
        Frame::Reject {
            id: 14,
            reason: UnknownCommand
        }
    );
    assert_eq!(
        got[14],
        Frame::Reject {
            id: 15,
            reason: Version
        }
    );
    assert_eq!(got.len(), 15);
    // The rejected SPEED commands never reached the rig.
    assert_eq!(
        rig.calls,
        [
            "speeds 1800 2100",
            "residence Flat 2000",
            "start",
            "stop",
            "clear",
            "param TEETH2 12"
        ]
    );
}

#[test]
fn a_resent_command_runs_once_and_is_answered_again() {
    let (mut rig, mut d) = rig_and_device();
    // The answer to START id 40 was lost; the PC sends it again with the same id.
    let first = answers(&mut d, &mut rig, &line("C1,40,START"));
    let again = answers(&mut d, &mut rig, &line("C1,40,START"));
    assert_eq!(first, vec![Frame::Ack { id: 40 }]);
    assert_eq!(again, first);
    assert_eq!(rig.calls, vec!["start"], "carried out once");
    // A rejected command resent gets the same reject, and still reaches the rig once.
    let reject = answers(&mut d, &mut rig, &line("C1,41,CLEAR"));
    let reject_again = answers(&mut d, &mut rig, &line("C1,41,CLEAR"));
    assert_eq!(
        reject,
        vec![Frame::Reject {
            id: 41,
            reason: Reason::State
        }]
    );
    assert_eq!(reject_again, reject);
    assert_eq!(rig.calls, vec!["start", "clear"]);
    // A new id is a new request, even with the same words.
    answers(&mut d, &mut rig, &line("C1,42,START"));
    // The same id with other words is a new request too (the PC reused an id).
    answers(&mut d, &mut rig, &line("C1,42,STOP"));
    assert_eq!(rig.calls, vec!["start", "clear", "start", "stop"]);
    // Queries are answered afresh each time: the second STATUS reports the time now.
    let s1 = answers(&mut d, &mut rig, &line("C1,43,STATUS"));
    rig.now_ms = 500;
    let s2 = answers(&mut d, &mut rig, &line("C1,43,STATUS"));
    let uptime = |f: &[Frame]| match f {
        [Frame::Status { status, .. }] => status.uptime_ms,
        other => panic!("{other:?}"),
    };
    assert_eq!((uptime(&s1), uptime(&s2)), (0, 500));
    // After another command, an old id with the same words runs again (only the last is kept).
    answers(&mut d, &mut rig, &line("C1,40,START"));
    assert_eq!(rig.calls, vec!["start", "clear", "start", "stop", "start"]);
}

#[test]
fn telemetry_is_paced_and_numbered() {
    let mut rig = Recorder::default();
    let mut d = Device::new();
    let mut buf = [0u8; MAX_FRAME_LEN];
    let mut seqs = Vec::new();
    let mut times = Vec::new();
    for ms in 0..10_000u32 {
        rig.now_ms = ms;
        if let Some(n) = d.poll_telemetry(&rig, ms, &mut buf) {
            match decode_frame(&buf[..n]).unwrap() {
                Frame::Telemetry(t) => {
                    seqs.push(t.seq);
                    times.push(t.time_ms);
                }
                other => panic!("{other:?}"),
            }
        }
    }
    assert_eq!(seqs.len(), 500);
    assert!(seqs.iter().enumerate().all(|(i, &s)| usize::from(s) == i));
    assert!(times.windows(2).all(|w| w[1] - w[0] == 20));
    // A late poll (the loop stalled for 1 s) skips the missed slots instead of bursting.
    let mut burst = 0;
    for ms in [11_000u32, 11_000, 11_001, 11_019, 11_020] {
        rig.now_ms = ms;
        burst += d.poll_telemetry(&rig, ms, &mut buf).is_some() as u32;
    }
    assert_eq!(burst, 2);
}

proptest! {
    /// Any bytes: at most one answer per `\n`, no panic, each answer a valid frame.
    #[test]
    fn arbitrary_input_gets_valid_answers(bytes in proptest::collection::vec(any::<u8>(), 0..2000)) {
        let (mut rig, mut d) = rig_and_device();
        let got = answers(&mut d, &mut rig, &bytes);
        let newlines = bytes.iter().filter(|&&b| b == b'\n').count();
        prop_assert!(got.len() <= newlines);
    }

    /// Every well-formed command gets exactly one answer with its id.
    #[test]
    fn every_command_is_answered(id in any::<u16>(), command in wire_support::command()) {
        let (mut rig, mut d) = rig_and_device();
        let bytes = wire_support::encode_vec(&Frame::Command { id, command });
        let got = answers(&mut d, &mut rig, &bytes);
        prop_assert_eq!(got.len(), 1);
        prop_assert_eq!(got[0].answer_id(), Some(id));
    }
}

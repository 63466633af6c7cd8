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
    heartbeats: u32,
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
            ResidenceModel::Flat | ResidenceModel::Table => Err(Reason::Infeasible),
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
    fn heartbeat(&mut self) {
        self.heartbeats += 1;
    }
}

/// Every command that arrives intact shows the host is there, whatever its answer: queries,
/// refusals (by the decoder or the device), copies, PING. A damaged line does not.
#[test]
fn every_intact_command_counts_as_host_presence() {
    let (mut rig, mut d) = rig_and_device();
    let mut input = Vec::new();
    for p in [
        "C1,1,STATUS",
        "C1,2,PARAMS",
        "C1,3,SPEED,1800,5001",
        "C1,4,FLY",
        "C1,5,START",
        "C1,5,START",
        "C1,6,PING",
    ] {
        input.extend(line(p));
    }
    assert_eq!(answers(&mut d, &mut rig, &input).len(), 7);
    assert_eq!(rig.heartbeats, 7);
    answers(&mut d, &mut rig, b"$C1,7,PING*00000000\r\n");
    assert_eq!(rig.heartbeats, 7, "a damaged line is not the host");
}

/// A line typed at a plain console (picocom, tio: words, spaces, Enter; no `$`, id or CRC) is
/// answered with the frame a `$` command gets, id 0, and counts as the host being there. It is
/// carried out each time it is typed (no ids, no copies), a typo is refused with the frame's
/// reason. A line that is not words (an arrow key, what a damaged frame leaves: commas, `*`)
/// is refused `UNREADABLE` and is no sign of the host.
#[test]
fn a_line_typed_at_a_console_is_answered_like_a_frame() {
    let (mut rig, mut d) = rig_and_device();
    let got = answers(&mut d, &mut rig, b"status\r");
    assert!(
        matches!(got.as_slice(), [Frame::Status { id: 0, .. }]),
        "{got:?}"
    );
    let got = answers(
        &mut d,
        &mut rig,
        b"speed 1800 2100\r\nstart\r\nspeed 1000 1000\rspeed 1800 2100\r",
    );
    assert_eq!(got, vec![Frame::Ack { id: 0 }; 4]);
    assert_eq!(
        rig.calls,
        [
            "speeds 1800 2100",
            "start",
            "speeds 1000 1000",
            "speeds 1800 2100"
        ]
    );
    assert_eq!(rig.heartbeats, 5);
    let got = answers(&mut d, &mut rig, b"speed 1800 9000\rstatsu\r");
    assert_eq!(
        got,
        [
            Frame::Reject {
                id: 0,
                reason: Reason::Range
            },
            Frame::Reject {
                id: 0,
                reason: Reason::UnknownCommand
            }
        ]
    );
    // A frame that lost its `$` is refused, not carried out, and is not the host; typing cut
    // by a frame is dropped, and what follows the frame is a line of its own (`rt`, not
    // `start`). The CRLF of the frame ends no second line.
    let mut input = b"C1,9,START*00000000\r\nsta".to_vec();
    input.extend(line("C1,10,PING"));
    input.extend(b"rt\r");
    let got = answers(&mut d, &mut rig, &input);
    let unreadable = Frame::Reject {
        id: 0,
        reason: Reason::Unreadable,
    };
    assert_eq!(
        got,
        [
            unreadable,
            Frame::Ack { id: 10 },
            Frame::Reject {
                id: 0,
                reason: Reason::UnknownCommand
            }
        ]
    );
    assert_eq!(rig.calls.len(), 4, "{:?}", rig.calls);
    assert_eq!(rig.heartbeats, 9, "the ping and the typed `rt` only");
    // An arrow key (ESC [ A) typed after a command: refused in a frame, not met with silence,
    // and no heartbeat (line noise looks the same).
    let got = answers(&mut d, &mut rig, b"status\x1b[A\r\n");
    assert_eq!(got, [unreadable]);
    assert_eq!(rig.heartbeats, 9);
    assert_eq!(rig.calls.len(), 4, "{:?}", rig.calls);
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
    // After other commands, a late copy of an old one is answered again, not run again.
    let late = answers(&mut d, &mut rig, &line("C1,40,START"));
    assert_eq!(late, vec![Frame::Ack { id: 40 }]);
    assert_eq!(rig.calls, vec!["start", "clear", "start", "stop"]);
}

/// The issue's case: SPEED id 600, SPEED id 601, then a late copy of 600. The copy gets 600's
/// answer and the setpoints stay at 601's.
#[test]
fn a_late_copy_of_an_old_speed_is_answered_and_not_run() {
    let (mut rig, mut d) = rig_and_device();
    let mut input = line("C1,600,SPEED,1800,2100");
    input.extend(line("C1,601,SPEED,1000,1000"));
    input.extend(line("C1,600,SPEED,1800,2100"));
    let got = answers(&mut d, &mut rig, &input);
    let ack = |id| Frame::Ack { id };
    assert_eq!(got, vec![ack(600), ack(601), ack(600)]);
    assert_eq!(rig.calls, vec!["speeds 1800 2100", "speeds 1000 1000"]);
    // A refused one is remembered with its refusal: the copy is refused again, never run.
    let mut input = line("C1,602,SPEED,1800,5001");
    input.extend(line("C1,603,STOP"));
    input.extend(line("C1,602,SPEED,1800,5001"));
    let got = answers(&mut d, &mut rig, &input);
    let range = Frame::Reject {
        id: 602,
        reason: Reason::Range,
    };
    assert_eq!(got, vec![range, ack(603), range]);
    assert_eq!(rig.calls.last().map(String::as_str), Some("stop"));
}

/// START id 700, STOP id 701, then a late copy of START 700: the rig stays stopped. The same
/// holds with the copy behind 15 other commands; behind 16 the window has moved on (the PC never
/// resends that long: it resends for at most its timeout).
#[test]
fn a_late_start_after_stop_does_not_restart() {
    let (mut rig, mut d) = rig_and_device();
    let mut input = line("C1,700,START");
    input.extend(line("C1,701,STOP"));
    input.extend(line("C1,700,START"));
    let got = answers(&mut d, &mut rig, &input);
    assert_eq!(
        got,
        vec![
            Frame::Ack { id: 700 },
            Frame::Ack { id: 701 },
            Frame::Ack { id: 700 }
        ]
    );
    assert_eq!(rig.calls, vec!["start", "stop"]);
    // 14 more commands: START 700 is now 16 commands back, still in the window.
    for id in 702..716 {
        answers(
            &mut d,
            &mut rig,
            &line(&format!("C1,{id},SET,TEETH1,{}", id - 690)),
        );
    }
    answers(&mut d, &mut rig, &line("C1,700,START"));
    assert_eq!(rig.calls.iter().filter(|c| *c == "start").count(), 1);
    // One more pushes it out: the same id and words are now a new request.
    answers(&mut d, &mut rig, &line("C1,716,SET,TEETH1,30"));
    answers(&mut d, &mut rig, &line("C1,700,START"));
    assert_eq!(rig.calls.iter().filter(|c| *c == "start").count(), 2);
}

/// A remembered command answers its copies for `RESEND_HORIZON_MS` of device time (the clock
/// `poll_telemetry` is given); after that the same id and words are a new request (ids repeat).
#[test]
fn a_remembered_command_ages_out_after_the_resend_horizon() {
    use model_core::wire::device::RESEND_HORIZON_MS;
    let (mut rig, mut d) = rig_and_device();
    let mut buf = [0u8; MAX_FRAME_LEN];
    d.poll_telemetry(&rig, 1_000, &mut buf);
    answers(&mut d, &mut rig, &line("C1,5,START"));
    d.poll_telemetry(&rig, 1_000 + RESEND_HORIZON_MS, &mut buf);
    answers(&mut d, &mut rig, &line("C1,5,START"));
    assert_eq!(rig.calls, vec!["start"], "a copy within the horizon");
    d.poll_telemetry(&rig, 1_001 + RESEND_HORIZON_MS, &mut buf);
    answers(&mut d, &mut rig, &line("C1,5,START"));
    assert_eq!(rig.calls, vec!["start", "start"], "a new request after it");
}

/// The issue's case: 30 s at 50 Hz, then `SET TELEM_HZ 20`: frames go on at once, every 50 ms,
/// numbered on from where they were (before the fix the rig fell silent for 30 s).
#[test]
fn telemetry_goes_on_at_the_new_rate_after_set_telem_hz() {
    let (mut rig, mut d) = rig_and_device();
    let mut buf = [0u8; MAX_FRAME_LEN];
    let mut sent = Vec::new();
    for ms in 0..40_000u32 {
        rig.now_ms = ms;
        if ms == 30_000 {
            let got = answers(&mut d, &mut rig, &line("C1,9,SET,TELEM_HZ,20"));
            assert_eq!(got, vec![Frame::Ack { id: 9 }]);
        }
        if let Some(n) = d.poll_telemetry(&rig, ms, &mut buf) {
            match decode_frame(&buf[..n]) {
                Ok(Frame::Telemetry(t)) => sent.push((t.time_ms, t.seq)),
                other => panic!("{other:?}"),
            }
        }
    }
    let after: Vec<_> = sent.iter().filter(|(t, _)| *t >= 30_000).collect();
    assert_eq!(
        after.first().map(|f| f.0),
        Some(30_000),
        "the first frame at once"
    );
    assert_eq!(after.len(), 200, "10 s at 20 Hz");
    assert!(after.windows(2).all(|w| w[1].0 - w[0].0 == 50));
    // The sequence numbers go on without a gap: nothing looks lost to the PC.
    assert!(sent.windows(2).all(|w| w[1].1 == w[0].1 + 1));
    assert_eq!(sent.len(), 1500 + 200);
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
        // A line ends at `\n` or `\r` (a `\r\n` is one end, so this bound is loose there).
        let newlines = bytes.iter().filter(|&&b| b == b'\n' || b == b'\r').count();
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

//! The one request loop against a scripted rig: stale and wrong-kind answers, resends,
//! timeouts, unreadable answers and the rig's answer to a line it could not read.

use std::io::{BufRead, BufReader, Write};

use model_core::wire::{DeviceState, FaultCode, ResetCause, Status, encode};

use super::*;
use crate::lines::command_line;
use crate::link::Stream;

fn bytes(frame: &Frame) -> Vec<u8> {
    let mut buf = [0u8; 512];
    let n = encode(frame, &mut buf).unwrap();
    buf[..n].to_vec()
}

fn status(id: u16) -> Frame {
    status_at(id, 5)
}

fn status_at(id: u16, uptime_ms: u32) -> Frame {
    Frame::Status {
        id,
        status: Status {
            state: DeviceState::Running,
            fault: FaultCode::None,
            reset_cause: ResetCause::Pin,
            reset_count: 1,
            uptime_ms,
            telemetry_hz: 50,
            flags: 0,
        },
    }
}

/// A link whose other end is a scripted rig: it gets each command line the PC sent and
/// returns what to answer. Returns the link and the thread that yields the lines it saw.
fn scripted(
    before: Vec<u8>,
    mut answer: impl FnMut(usize, &str) -> Vec<u8> + Send + 'static,
) -> (Link, std::thread::JoinHandle<Vec<String>>) {
    let (pc, mut rig) = Stream::pair().unwrap();
    rig.write_all(&before).unwrap();
    let rig_thread = std::thread::spawn(move || {
        let mut seen = Vec::new();
        let mut reader = BufReader::new(rig.try_clone().unwrap());
        let mut line = String::new();
        while reader.read_line(&mut line).unwrap_or(0) > 0 {
            let reply = answer(seen.len(), &line);
            seen.push(std::mem::take(&mut line));
            if rig.write_all(&reply).is_err() {
                break;
            }
        }
        seen
    });
    // Let the stale bytes arrive before the command is sent.
    std::thread::sleep(Duration::from_millis(20));
    (Link::Monitor(pc), rig_thread)
}

#[test]
fn a_stale_answer_and_an_answer_of_the_wrong_kind_are_not_taken() {
    // Left over from an earlier STATUS with the same id (its answer came late): discarded
    // before sending.
    let (mut link, rig) = scripted(bytes(&status_at(77, 1)), |_, _| {
        // The same id but the kind STOP gets, then the STATUS answer.
        let mut out = bytes(&Frame::Ack { id: 77 });
        out.extend(bytes(&status(77)));
        out
    });
    let line = command_line(77, &["status".into()]).unwrap();
    let got = transact(&mut link, 77, &line, Duration::from_millis(1000)).unwrap();
    assert_eq!(got, Ok(status(77)));
    drop(link);
    assert_eq!(rig.join().unwrap().len(), 1, "answered at the first try");
}

/// The rig's answer to a line it could not read (id 0: a frame that lost its `$`, a
/// person's typing) is no tool's answer: `bowl send` (`transact`) and commissioning (`Rig`,
/// whose `arrived` gets what the loop hands on) wait on for their own, with the ids they
/// count through (never 0, `ids`). Unanswered, the command says the rig could not read what
/// it got.
#[test]
fn the_rigs_answer_to_a_line_it_could_not_read_is_no_ones_answer() {
    let unreadable = bytes(&Frame::Reject {
        id: 0,
        reason: Reason::Unreadable,
    });
    let first = unreadable.clone();
    // The first send is answered `UNREADABLE` only (it came damaged), the resend with
    // `UNREADABLE` first, then the ack with the id the line carried.
    let (mut link, rig) = scripted(Vec::new(), move |n, line| {
        let mut out = first.clone();
        if n > 0 {
            let id = line.split(',').nth(1).unwrap().parse().unwrap();
            out.extend(bytes(&Frame::Ack { id }));
        }
        out
    });
    let id = next_id(u16::MAX);
    let mut req = Request::new(id, Command::Start).unwrap();
    let mut arrived = Vec::new();
    let timeout = Duration::from_millis(1000);
    let got = request(
        &mut link,
        &mut Reader::default(),
        &mut req,
        timeout,
        &mut |f| arrived.push(f),
    );
    assert_eq!(got.unwrap(), Ok(Frame::Ack { id }));
    assert_ne!(id, 0);
    assert!(
        !arrived.is_empty() && arrived.iter().all(crate::lines::unread_by_rig),
        "{arrived:?}"
    );
    drop(link);
    assert_eq!(rig.join().unwrap().len(), 2, "sent again, answered then");

    // Only the rig's `UNREADABLE` comes back: a timeout that says so.
    let (mut link, rig) = scripted(Vec::new(), move |_, _| unreadable.clone());
    let line = command_line(5, &["stop".into()]).unwrap();
    let got = transact(&mut link, 5, &line, Duration::from_millis(400)).unwrap();
    let garbled = got.unwrap_err();
    assert!((1..=2).contains(&garbled.unread_by_rig), "{garbled:?}");
    let advice = garbled.advice();
    assert!(
        advice.contains("the rig could not read")
            && advice.contains("the line to the rig is noisy"),
        "{advice}"
    );
    drop(link);
    rig.join().unwrap();
}

#[test]
fn a_lost_answer_is_asked_again_with_the_same_id() {
    // The first answer is lost on the way; the resend is answered.
    let (mut link, rig) = scripted(Vec::new(), |n, _| {
        if n == 0 {
            Vec::new()
        } else {
            bytes(&Frame::Ack { id: 9 })
        }
    });
    let line = command_line(9, &["start".into()]).unwrap();
    let got = transact(&mut link, 9, &line, Duration::from_millis(1000)).unwrap();
    assert_eq!(got, Ok(Frame::Ack { id: 9 }));
    drop(link);
    let seen = rig.join().unwrap();
    assert_eq!(seen.len(), 2);
    assert_eq!(seen[0], seen[1], "the resend is the same line, same id");
    assert_eq!(seen[0].as_bytes(), line.as_slice());
}

#[test]
fn no_answer_is_a_timeout_after_resends() {
    let (mut link, rig) = scripted(Vec::new(), |_, _| Vec::new());
    let line = command_line(5, &["stop".into()]).unwrap();
    let started = Instant::now();
    let got = transact(&mut link, 5, &line, Duration::from_millis(600)).unwrap();
    let silence = got.unwrap_err();
    assert_eq!(
        (silence.sent, silence.frames_ok, silence.frames_corrupt),
        (3, 0, 0)
    );
    assert!(silence.advice().contains("nothing came from the port"));
    assert!(started.elapsed() >= Duration::from_millis(600));
    drop(link);
    assert_eq!(rig.join().unwrap().len(), 3, "sent every 200 ms");
}

/// A raw line with a correct CRC.
fn raw(payload: &str) -> Vec<u8> {
    let crc = model_core::wire::crc::crc32(payload.as_bytes());
    format!("${payload}*{crc:08X}\r\n").into_bytes()
}

#[test]
fn an_answer_bowl_cannot_read_is_reported_as_what_it_is() {
    for (answer, says) in [
        ("R1,5,BOGUS", "a word or a field this bowl does not know"),
        ("A2,5", "in protocol version 2 (this bowl speaks version 1)"),
        ("X1,5", "a kind of frame this bowl does not know ('X')"),
    ] {
        // Another request's unreadable answer first: not ours, not taken.
        let (mut link, rig) = scripted(Vec::new(), move |_, _| {
            let mut out = raw("R1,6,BOGUS");
            out.extend(raw(answer));
            out
        });
        let line = command_line(5, &["stop".into()]).unwrap();
        let started = Instant::now();
        let err = transact(&mut link, 5, &line, Duration::from_millis(1000)).unwrap_err();
        assert!(
            started.elapsed() < Duration::from_millis(500),
            "not a timeout"
        );
        let text = err.to_string();
        assert!(text.contains("request 5"), "{text}");
        assert!(text.contains(says), "{text}");
        assert!(
            text.contains(&format!("`${answer}*")),
            "the line as it came: {text}"
        );
        assert!(err.downcast_ref::<UnreadableAnswer>().is_some());
        drop(link);
        rig.join().unwrap();
    }
    // A damaged line (CRC wrong) is no answer at all: the PC resends and times out.
    let (mut link, rig) = scripted(Vec::new(), |_, _| b"$R1,5,BOGUS*00000000\r\n".to_vec());
    let line = command_line(5, &["stop".into()]).unwrap();
    let got = transact(&mut link, 5, &line, Duration::from_millis(400)).unwrap();
    let noisy = got.unwrap_err();
    assert!(
        (1..=u64::from(noisy.sent)).contains(&noisy.frames_corrupt),
        "{noisy:?}"
    );
    assert!(
        noisy.advice().contains("the line is noisy"),
        "{}",
        noisy.advice()
    );
    assert!(noisy.advice().contains("--timeout-ms"));
    drop(link);
    rig.join().unwrap();
}

#[test]
fn each_command_takes_only_its_kind_of_answer() {
    let ack = Frame::Ack { id: 1 };
    let reject = Frame::Reject {
        id: 1,
        reason: model_core::wire::Reason::State,
    };
    assert!(answers_kind(&Command::Start, &ack));
    assert!(answers_kind(&Command::Start, &reject));
    assert!(!answers_kind(&Command::Start, &status(1)));
    assert!(answers_kind(&Command::GetStatus, &status(1)));
    assert!(answers_kind(&Command::GetStatus, &reject));
    assert!(!answers_kind(&Command::GetStatus, &ack));
    assert!(!answers_kind(&Command::GetParams, &ack));
    assert!(!answers_kind(&Command::GetModels, &status(1)));
}

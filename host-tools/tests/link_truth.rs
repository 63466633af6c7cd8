//! A link that never lies, end to end on the virtual rig (`bowl serve`): telemetry goes on at
//! the new rate after `SET TELEM_HZ`; a late copy of an old command is answered again and not
//! carried out again; a command typed in a serial console (ended by Enter, CR) is answered; every
//! frame the rig sends ends in CRLF.

mod common;

use std::io::{Read, Write};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use common::{Sim, bowl, capture_timed, csv_rows, replay_to_csv, stdout, temp_dir};
use model_core::wire::crc::crc32;
use model_core::wire::{Decoder, DeviceState, Frame};

/// The test's side of the virtual rig's pseudo-terminal, as a serial console would hold it:
/// raw bytes out, everything the rig sends collected on a reader thread.
struct Console {
    port: std::fs::File,
    rx: mpsc::Receiver<Vec<u8>>,
    /// Every byte received so far, raw.
    raw: Vec<u8>,
    decoder: Decoder,
}

impl Console {
    fn open(sim: &Sim) -> Console {
        let port = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .open(&sim.path)
            .unwrap();
        let mut reader = port.try_clone().unwrap();
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n) = reader.read(&mut buf) {
                if n == 0 || tx.send(buf[..n].to_vec()).is_err() {
                    break;
                }
            }
        });
        Console {
            port,
            rx,
            raw: Vec::new(),
            decoder: Decoder::new(),
        }
    }

    /// Types `payload` as a whole frame line ended by `end`.
    fn send(&mut self, payload: &str, end: &str) {
        let line = format!("${payload}*{:08X}{end}", crc32(payload.as_bytes()));
        self.port.write_all(line.as_bytes()).unwrap();
    }

    /// Every frame that arrives within `for_time`.
    fn frames_for(&mut self, for_time: Duration) -> Vec<Frame> {
        let end = Instant::now() + for_time;
        let mut frames = Vec::new();
        while let Some(left) = end.checked_duration_since(Instant::now()) {
            if let Ok(bytes) = self.rx.recv_timeout(left) {
                self.raw.extend_from_slice(&bytes);
                for b in bytes {
                    if let Some(Ok(f)) = self.decoder.push(b) {
                        frames.push(f);
                    }
                }
            }
        }
        frames
    }

    /// The answers (frames with a request id) that arrive within 600 ms.
    fn answers(&mut self) -> Vec<Frame> {
        self.frames_for(Duration::from_millis(600))
            .into_iter()
            .filter(|f| f.answer_id().is_some())
            .collect()
    }

    /// The precession and spin setpoints and the state of the telemetry in the next 300 ms.
    fn telemetry(&mut self) -> Vec<(i16, i16, DeviceState)> {
        self.frames_for(Duration::from_millis(300))
            .into_iter()
            .filter_map(|f| match f {
                Frame::Telemetry(t) => Some((t.precession.set_mrad_s, t.spin.set_mrad_s, t.state)),
                _ => None,
            })
            .collect()
    }
}

/// The issue's case: SPEED id 600, SPEED id 601, then a late copy of 600. The copy gets 600's
/// answer again; the setpoints stay at 601's. Then START 700, STOP 701 and a late copy of START
/// 700: answered, and the rig does not start again.
#[test]
fn a_late_copy_is_answered_again_and_never_run_again() {
    let sim = Sim::start(&["--seconds", "30"]);
    let mut c = Console::open(&sim);
    let ack = |id| Frame::Ack { id };
    c.send("C1,600,SPEED,1800,2100", "\r\n");
    assert_eq!(c.answers(), vec![ack(600)]);
    c.send("C1,601,SPEED,1000,1000", "\r\n");
    assert_eq!(c.answers(), vec![ack(601)]);
    c.send("C1,600,SPEED,1800,2100", "\r\n");
    assert_eq!(
        c.answers(),
        vec![ack(600)],
        "the copy gets the original answer"
    );
    let after = c.telemetry();
    assert!(after.len() >= 5, "telemetry flows: {after:?}");
    assert!(
        after.iter().all(|&(p, s, _)| (p, s) == (1000, 1000)),
        "the setpoints stay at 601's: {after:?}"
    );

    c.send("C1,700,START", "\r\n");
    assert_eq!(c.answers(), vec![ack(700)]);
    c.send("C1,701,STOP", "\r\n");
    assert_eq!(c.answers(), vec![ack(701)]);
    c.send("C1,700,START", "\r\n");
    assert_eq!(c.answers(), vec![ack(700)]);
    let after = c.telemetry();
    assert!(!after.is_empty());
    assert!(
        after
            .iter()
            .all(|&(.., state)| matches!(state, DeviceState::Stopping | DeviceState::Idle)),
        "the late START did not start the rig again: {after:?}"
    );
}

/// docs/protocol.md's example command typed in a console and ended by Enter (CR alone) is
/// answered with the doc's answer; a CRLF ends one command, never a second (empty) one. Every
/// line the rig sends ends in CRLF, so a console shows one line per frame.
#[test]
fn a_command_ended_by_cr_is_answered_and_every_frame_ends_in_crlf() {
    let sim = Sim::start(&["--seconds", "30"]);
    let mut c = Console::open(&sim);
    c.frames_for(Duration::from_millis(300));
    c.port
        .write_all(b"$C1,7,SPEED,1800,2100*5D416E98\r")
        .unwrap();
    c.frames_for(Duration::from_millis(600));
    let answer = b"$A1,7*A6C9A142\r\n";
    assert!(
        c.raw.windows(answer.len()).any(|w| w == answer),
        "the doc's answer, CRLF-ended"
    );
    // CR, LF and CRLF: one answer each, and nothing else (no reject of an empty line).
    c.send("C1,8,PING", "\r\n");
    c.send("C1,9,PING", "\n");
    c.send("C1,10,PING", "\r");
    let acks: Vec<u16> = (8..=10).collect();
    let got: Vec<u16> = c.answers().iter().filter_map(Frame::answer_id).collect();
    assert_eq!(got, acks);
    assert_eq!(c.decoder.stats().frames_corrupt, 0);
    // Every frame line ends in CRLF: no bare LF, no CR that is not before an LF.
    let text = String::from_utf8_lossy(&c.raw);
    let lines: Vec<&str> = text.split_inclusive('\n').collect();
    assert!(lines.len() > 20);
    for line in lines.iter().skip(1) {
        assert!(
            line.starts_with('$') && line.ends_with("\r\n") && line.matches('\r').count() == 1,
            "{line:?}"
        );
    }
}

/// The issue's case: 30 s at 50 Hz, then `SET TELEM_HZ 20`: telemetry goes on at once at
/// 20 frames/s (before the fix not one frame came in the next 30 s).
#[test]
fn telemetry_goes_on_at_the_new_rate_after_set_telem_hz() {
    let csv = captured_csv(
        "telem-hz",
        "40",
        &["0:speed,1500,1500", "0:start", "30000:set,TELEM_HZ,20"],
    );
    let times: Vec<u64> = csv_rows(&csv)
        .iter()
        .filter_map(|r| r.get("device_time_ms")?.parse().ok())
        .collect();
    let before = times.iter().filter(|&&t| t < 30_000).count();
    let after: Vec<u64> = times.iter().copied().filter(|&t| t >= 30_000).collect();
    assert!((1495..=1501).contains(&before), "{before} frames before");
    // The first frame within one new period of the change, then every 50 ms to the end.
    assert!(after.first().is_some_and(|&t| t <= 30_050), "{after:?}");
    assert!(
        (195..=201).contains(&after.len()),
        "{} frames after",
        after.len()
    );
    assert!(after.windows(2).all(|w| w[1] - w[0] == 50), "{after:?}");
}

/// A rig that answers `bowl send` with a line this bowl cannot read (an unknown reason word,
/// another protocol version): reported as such, with the line, exit 1; never as "no answer"
/// (exit 4).
#[test]
fn an_answer_bowl_cannot_read_is_reported_with_its_text() {
    for (answer, says) in [
        ("R1,{id},BOGUS", "a word or a field this bowl does not know"),
        ("A2,{id}", "in protocol version 2"),
    ] {
        let (mut master, path) = common::open_pty();
        let rig = std::thread::spawn(move || {
            // Read the command line, answer it once.
            let mut got = Vec::new();
            let mut byte = [0u8; 1];
            while !got.ends_with(b"\n") && master.read(&mut byte).unwrap_or(0) == 1 {
                got.push(byte[0]);
            }
            let id = match model_core::wire::decode_frame(&got) {
                Ok(Frame::Command { id, .. }) => id,
                other => panic!("{other:?}: {:?}", String::from_utf8_lossy(&got)),
            };
            let payload = answer.replace("{id}", &id.to_string());
            let line = format!("${payload}*{:08X}\r\n", crc32(payload.as_bytes()));
            master.write_all(line.as_bytes()).unwrap();
            // Keep the terminal open until bowl is done with it.
            std::thread::sleep(Duration::from_millis(1500));
            payload
        });
        let out = bowl(&["send", &path, "stop", "--timeout-ms", "1000"]);
        let payload = rig.join().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{}{err}", stdout(&out));
        assert!(err.contains(says), "{err}");
        assert!(err.contains(&payload), "the line as it came: {err}");
        assert!(!stdout(&out).contains("timeout"), "{}", stdout(&out));
    }
}

/// The monitor shows what it cannot read instead of dropping it silently: an answer in words it
/// does not know (with its text), and frames in another protocol version (said once).
#[test]
fn the_monitor_says_what_it_cannot_read() {
    let (mut master, path) = common::open_pty();
    let rig = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(500));
        for payload in ["R1,77,BOGUS", "T2,1,2,3", "T2,2,3,4"] {
            let line = format!("${payload}*{:08X}\r\n", crc32(payload.as_bytes()));
            master.write_all(line.as_bytes()).unwrap();
        }
        std::thread::sleep(Duration::from_millis(1500));
    });
    let out = bowl(&["monitor", &path, "--plain", "--seconds", "1.5"]);
    rig.join().unwrap();
    let text = stdout(&out);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("the rig answered request 77 with a word or a field this bowl does not know")
            && text.contains("`$R1,77,BOGUS*"),
        "{text}"
    );
    assert_eq!(
        text.matches("the rig sends another protocol version")
            .count(),
        1,
        "said once: {text}"
    );
}

/// A capture with the telemetry paused (`SET TELEM_HZ 0` for 3 s): `replay --csv` marks the gap
/// with the monitor's own words at the device times it began and ended, and `bowl chart log`
/// breaks its lines there (no line drawn across data the rig never sent).
#[test]
fn replay_marks_a_gap_in_the_telemetry_as_the_monitor_does() {
    let csv = captured_csv(
        "replay-gap",
        "8",
        &[
            "0:speed,1500,1500",
            "2000:set,TELEM_HZ,0",
            "5000:set,TELEM_HZ,50",
        ],
    );
    let dir = csv.parent().unwrap().to_path_buf();
    let rows = csv_rows(&csv);
    let events: Vec<(u64, &str)> = rows
        .iter()
        .filter(|r| !r["event"].is_empty())
        .map(|r| (r["device_time_ms"].parse().unwrap(), r["event"].as_str()))
        .collect();
    assert_eq!(events.len(), 2, "{events:?}");
    let (began, ended) = (events[0], events[1]);
    assert_eq!(began.1, "no telemetry", "{events:?}");
    assert!((2000..=2060).contains(&began.0), "{events:?}");
    assert!(
        ended.1.starts_with("telemetry again after 3.0 s"),
        "{events:?}"
    );
    assert!((5000..=5040).contains(&ended.0), "{events:?}");
    // Telemetry rows lie outside the gap only.
    let inside = rows
        .iter()
        .filter(|r| r["event"].is_empty())
        .filter_map(|r| r["device_time_ms"].parse::<u64>().ok())
        .filter(|t| (began.0 + 1..ended.0).contains(t))
        .count();
    assert_eq!(inside, 0);
    let chart = bowl(&[
        "chart",
        "log",
        "--csv",
        csv.to_str().unwrap(),
        "--out",
        dir.join("run.svg").to_str().unwrap(),
    ]);
    assert!(chart.status.success(), "{}", stdout(&chart));
    let svg = std::fs::read_to_string(dir.join("run-spin.svg")).unwrap();
    assert!(
        svg.contains("no telemetry"),
        "the gap is marked on the chart"
    );
}

/// A capture of `seconds` with the timed `commands`, replayed to CSV: the CSV's path (in a
/// scratch directory named `name`).
fn captured_csv(name: &str, seconds: &str, commands: &[&str]) -> std::path::PathBuf {
    let dir = temp_dir(name);
    let csv = dir.join("run.csv");
    let replay = replay_to_csv(&capture_timed(&dir, seconds, commands), &csv);
    assert!(replay.status.success(), "{}", stdout(&replay));
    csv
}

/// A granule released 4300.5 s after the rig's reset, past the gates' microsecond wrap
/// (4294.967 s): `replay --csv` puts its row at 4300500 ms among the telemetry, where a chart
/// draws it, not at the 5532.704 ms its own count reads.
#[test]
fn a_gate_after_the_microsecond_wrap_is_placed_on_the_telemetry_clock() {
    let dir = temp_dir("gate-wrap");
    let frame = |payload: String| format!("${payload}*{:08X}\r\n", crc32(payload.as_bytes()));
    let mut bytes = String::new();
    for (seq, ms) in (4_300_000u32..=4_301_000).step_by(20).enumerate() {
        bytes += &frame(format!(
            "T1,{ms},{seq},3,0,1800,1800,4000,10,2100,2100,5000,10,3381,2345,2410"
        ));
        if ms == 4_300_500 {
            let us = (4_300_500_000u64 - (1u64 << 32)) as u32;
            bytes += &frame(format!("E1,0,{us},0"));
        }
    }
    let capture = dir.join("wrap.bin");
    std::fs::write(&capture, bytes).unwrap();
    let csv = dir.join("wrap.csv");
    let out = replay_to_csv(&capture, &csv);
    assert!(out.status.success(), "{out:?}");
    let rows = csv_rows(&csv);
    let gate = rows
        .iter()
        .find(|r| r["event"].starts_with("release gate"))
        .expect("the gate's row");
    assert_eq!(gate["device_time_ms"], "4300500.000", "{gate:?}");
}

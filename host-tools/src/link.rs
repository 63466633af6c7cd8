//! The way a command reaches the rig: the serial port itself, or, while a `bowl monitor` holds
//! the port, the local socket that monitor serves (the port is opened exclusively, so a second
//! program could not open it). The socket carries the same bytes as the port in both
//! directions, so the command code is the same for both.

use std::io::{Read, Write};
use std::path::PathBuf;
use std::time::{Duration, Instant};

use model_core::wire::{Command, Decoder, Frame, decode_frame};

use crate::serial::{LinkError, Port, ReadOutcome};
pub use crate::unreadable::{LineTap, UnreadableAnswer};

#[cfg(unix)]
pub(crate) type Stream = std::os::unix::net::UnixStream;
#[cfg(not(unix))]
pub(crate) type Stream = std::net::TcpStream;

/// Where the monitor of `port` serves its socket (a Unix socket; on Windows a file that holds
/// the TCP port on 127.0.0.1). Keyed on the port's real path, so a symlink and its target meet.
pub(crate) fn socket_path(port: &str) -> PathBuf {
    let real = std::fs::canonicalize(port)
        .map(|p| p.to_string_lossy().into_owned())
        .unwrap_or_else(|_| port.to_owned());
    let name: String = real
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    std::env::temp_dir().join(format!("bowl-monitor{name}.sock"))
}

/// Connects to the monitor holding `port`, if one is running.
pub(crate) fn connect_monitor(port: &str) -> Option<Stream> {
    let path = socket_path(port);
    #[cfg(unix)]
    {
        Stream::connect(path).ok()
    }
    #[cfg(not(unix))]
    {
        let tcp_port: u16 = std::fs::read_to_string(path).ok()?.trim().parse().ok()?;
        Stream::connect(("127.0.0.1", tcp_port)).ok()
    }
}

/// A connection to the rig.
pub enum Link {
    /// The serial port, held by this process.
    Port(Port),
    /// Through the monitor that holds the port.
    Monitor(Stream),
}

impl Link {
    /// Goes through a running monitor of `port` if there is one (and says so on stderr),
    /// otherwise opens the port.
    pub fn open(port: &str, baud: u32) -> Result<Link, LinkError> {
        if let Some(stream) = connect_monitor(port) {
            eprintln!("{port} is held by a running `bowl monitor`: sending through it");
            return Ok(Link::Monitor(stream));
        }
        Port::open(port, baud).map(Link::Port)
    }

    /// Reads what is there, waiting at most `timeout`.
    pub fn read(&mut self, buf: &mut [u8], timeout: Duration) -> Result<ReadOutcome, LinkError> {
        match self {
            Link::Port(p) => p.read(buf, timeout),
            Link::Monitor(s) => {
                let _ = s.set_read_timeout(Some(timeout.max(Duration::from_millis(1))));
                match s.read(buf) {
                    Ok(0) => Ok(ReadOutcome::Gone),
                    Ok(n) => Ok(ReadOutcome::Data(n)),
                    Err(e)
                        if matches!(
                            e.kind(),
                            std::io::ErrorKind::WouldBlock
                                | std::io::ErrorKind::TimedOut
                                | std::io::ErrorKind::Interrupted
                        ) =>
                    {
                        Ok(ReadOutcome::Timeout)
                    }
                    Err(_) => Ok(ReadOutcome::Gone),
                }
            }
        }
    }

    /// Writes a whole command line.
    pub fn write_all(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        match self {
            Link::Port(p) => p.write_all(bytes),
            Link::Monitor(s) => s
                .write_all(bytes)
                .map_err(|e| LinkError(format!("the monitor's socket closed: {e}"))),
        }
    }

    /// Throws away what arrived and was not read yet.
    pub fn discard_input(&mut self) {
        if let Link::Port(p) = self {
            p.discard_input();
        }
        let mut buf = [0u8; 4096];
        while let Ok(ReadOutcome::Data(_)) = self.read(&mut buf, Duration::from_millis(1)) {}
    }
}

/// Whether `frame` is the kind of answer `command` gets, as the command table says (`S` to
/// STATUS, `P` to PARAMS, `M` to MODELS, `W` to RTIME, `A` to the rest), or `R` (anything can
/// be refused).
pub fn answers_kind(command: &Command, frame: &Frame) -> bool {
    matches!(frame, Frame::Reject { .. })
        || model_core::wire::encode::kind_letter(frame) == command.kind().answer().letter()
}

/// A request id for the first command of a process: the wall clock in milliseconds, mod 2^16
/// (one turn in 65.5 s). The rig takes a command with the id and words of one of its recent
/// commands, up to 60 s old, for a copy and does not carry it out again (docs/protocol.md), so
/// ids must not come back within 60 s: from the clock, each process starts past the ids of
/// the ones before it and counts up from there (a process sends far fewer than one command a
/// millisecond). `u16::MAX` is left to the monitor's heartbeat.
pub fn fresh_id() -> u16 {
    let ms = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_millis())
        .unwrap_or(0);
    match (ms % 65_536) as u16 {
        u16::MAX => 0,
        id => id,
    }
}

/// How long one attempt waits before the command is sent again with the same id (the rig carries
/// a resend out once). The rig answers within a few ms; a damaged answer is never repaired.
pub const RESEND_EVERY: Duration = Duration::from_millis(200);

/// What came from the rig while a command waited in vain for its answer: enough to say whether
/// the line is dead, noisy, or alive but not answering.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Unanswered {
    /// Frames that arrived intact (telemetry, other tools' answers).
    pub frames_ok: u64,
    /// Frames that arrived damaged.
    pub frames_corrupt: u64,
    /// How many times the command was sent (the first time and the resends).
    pub sent: u32,
}

impl Unanswered {
    /// What to try, in words.
    pub fn advice(&self) -> String {
        let seen = format!(
            "sent {} times; meanwhile {} frames arrived intact and {} damaged",
            self.sent, self.frames_ok, self.frames_corrupt
        );
        let todo = if self.frames_corrupt > 0 {
            "the line is noisy: give it longer (`--timeout-ms 5000` resends every 200 ms until \
             then), check the cable, its ground and the baud rate (`--baud`); `bowl monitor PORT` \
             shows the frame counters"
        } else if self.frames_ok == 0 {
            "nothing came from the port at all: is the rig powered, is this its port (`bowl \
             ports`), is the baud rate right (`--baud`)?"
        } else {
            "the rig is sending but did not answer: give it longer (`--timeout-ms 5000`); \
             `bowl monitor PORT` shows its state and the frame counters"
        };
        format!("{seen}; {todo}")
    }
}

/// Sends the command `line` (request `id`) and waits for its answer: the frame with this id and
/// the kind the command gets. Old input is discarded first; when no answer comes within
/// [`RESEND_EVERY`], the same line is sent again, until `timeout` has passed. `Ok(Err(..))`
/// when nothing answered (with what came instead); an error when the link failed
/// ([`LinkError`]) or the answer could not be read ([`UnreadableAnswer`]).
pub fn transact(
    link: &mut Link,
    id: u16,
    line: &[u8],
    timeout: Duration,
) -> anyhow::Result<Result<Frame, Unanswered>> {
    let command = match decode_frame(line) {
        Ok(Frame::Command { command, .. }) => command,
        _ => anyhow::bail!("not a command line (a bug in bowl)"),
    };
    let end = Instant::now() + timeout;
    let mut buf = [0u8; 4096];
    let mut unanswered = Unanswered::default();
    while let Some(left) = end.checked_duration_since(Instant::now()) {
        link.discard_input();
        link.write_all(line)?;
        unanswered.sent += 1;
        let deadline = Instant::now() + left.min(RESEND_EVERY);
        let mut decoder = Decoder::new();
        let mut tap = LineTap::default();
        while let Some(left) = deadline.checked_duration_since(Instant::now()) {
            match link.read(&mut buf, left.min(Duration::from_millis(50)))? {
                ReadOutcome::Data(n) => {
                    for &b in &buf[..n] {
                        tap.push(b);
                        match decoder.push(b) {
                            Some(Ok(frame))
                                if frame.answer_id() == Some(id)
                                    && answers_kind(&command, &frame) =>
                            {
                                return Ok(Ok(frame));
                            }
                            Some(Ok(_)) => unanswered.frames_ok += 1,
                            Some(Err(e)) => {
                                if let Some(u) = tap.unreadable_answer(e)
                                    && u.id == id
                                {
                                    return Err(u.into());
                                }
                                unanswered.frames_corrupt += 1;
                            }
                            None => {}
                        }
                    }
                }
                ReadOutcome::Timeout => {}
                ReadOutcome::Gone => {
                    return Err(LinkError(
                        "the link went away while waiting for the answer".into(),
                    )
                    .into());
                }
            }
        }
    }
    Ok(Err(unanswered))
}

#[cfg(all(test, unix))]
mod tests {
    use std::io::{BufRead, BufReader};

    use model_core::wire::{DeviceState, FaultCode, ResetCause, Status, encode};

    use super::*;
    use crate::send::command_line;

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
}

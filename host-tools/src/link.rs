//! The way a command reaches the rig: the serial port itself, or, while a `bowl monitor` holds
//! the port, the local socket that monitor serves (the port is opened exclusively, so a second
//! program could not open it). The socket carries the same bytes as the port in both
//! directions, so the command code is the same for both.

use std::io::{Read, Write};
use std::path::PathBuf;
use std::time::{Duration, Instant};

use model_core::wire::{Command, Decoder, Frame, decode_frame};

use crate::serial::{LinkError, Port, ReadOutcome};

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

/// Whether `frame` is the kind of answer `command` gets: `S` to STATUS, `P` to PARAMS, `M` to
/// MODELS, `A` or `R` to the rest (and `R` to anything: a query can be refused too).
pub fn answers_kind(command: &Command, frame: &Frame) -> bool {
    match (command, frame) {
        (_, Frame::Reject { .. }) => true,
        (Command::GetStatus, f) => matches!(f, Frame::Status { .. }),
        (Command::GetParams, f) => matches!(f, Frame::Params { .. }),
        (Command::GetModels, f) => matches!(f, Frame::Models { .. }),
        (_, f) => matches!(f, Frame::Ack { .. }),
    }
}

/// How long one attempt waits before the command is sent again with the same id (the rig carries
/// a resend out once). The rig answers within a few ms; a damaged answer is never repaired.
pub const RESEND_EVERY: Duration = Duration::from_millis(200);

/// Sends the command `line` (request `id`) and waits for its answer: the frame with this id and
/// the kind the command gets. Old input is discarded first; when no answer comes within
/// [`RESEND_EVERY`], the same line is sent again, until `timeout` has passed.
pub fn transact(
    link: &mut Link,
    id: u16,
    line: &[u8],
    timeout: Duration,
) -> Result<Option<Frame>, LinkError> {
    let command = match decode_frame(line) {
        Ok(Frame::Command { command, .. }) => command,
        _ => return Err(LinkError("not a command line (a bug in bowl)".into())),
    };
    let end = Instant::now() + timeout;
    let mut buf = [0u8; 4096];
    while let Some(left) = end.checked_duration_since(Instant::now()) {
        link.discard_input();
        link.write_all(line)?;
        let deadline = Instant::now() + left.min(RESEND_EVERY);
        let mut decoder = Decoder::new();
        while let Some(left) = deadline.checked_duration_since(Instant::now()) {
            match link.read(&mut buf, left.min(Duration::from_millis(50)))? {
                ReadOutcome::Data(n) => {
                    for &b in &buf[..n] {
                        if let Some(Ok(frame)) = decoder.push(b)
                            && frame.answer_id() == Some(id)
                            && answers_kind(&command, &frame)
                        {
                            return Ok(Some(frame));
                        }
                    }
                }
                ReadOutcome::Timeout => {}
                ReadOutcome::Gone => {
                    return Err(LinkError(
                        "the link went away while waiting for the answer".into(),
                    ));
                }
            }
        }
    }
    Ok(None)
}

//! The way a command reaches the rig: the serial port itself, or, while a `bowl monitor` holds
//! the port, the local socket that monitor serves (the port is opened exclusively, so a second
//! program could not open it). The socket carries the same bytes as the port in both
//! directions, so the command code is the same for both.

use std::io::{Read, Write};
use std::path::PathBuf;
use std::time::Duration;

use crate::serial::{LinkError, Port, ReadOutcome, other_holders, shared_port_warning};

#[cfg(unix)]
pub type Stream = std::os::unix::net::UnixStream;
#[cfg(not(unix))]
pub type Stream = std::net::TcpStream;

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
        let opened = Port::open(port, baud)?;
        if let Some(warning) = shared_port_warning(port, &other_holders(port)) {
            eprintln!("{warning}");
        }
        Ok(Link::Port(opened))
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

    /// The link ended (a read saw [`ReadOutcome::Gone`]), in words that say which end went:
    /// through a monitor, it is the monitor that ended, not the rig's cable.
    pub fn gone(&self) -> LinkError {
        LinkError(match self {
            Link::Port(_) => "the rig's port went away (unplugged? `bowl ports` lists the \
                              ports there are)"
                .into(),
            Link::Monitor(_) => "the `bowl monitor` this went through ended (it held the \
                                 port, and this link with it); run this again once it runs, \
                                 or without it"
                .into(),
        })
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

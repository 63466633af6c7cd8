//! The monitor's side of [`crate::link`]: while `bowl monitor` holds the port, it serves a local
//! socket. Every byte from the rig goes to every client; every whole line a client writes goes to
//! the rig as one write, so commands from several clients never interleave.

use std::io::{ErrorKind, Read, Write};
use std::path::PathBuf;

use anyhow::{Context, Result};

use crate::link::{Stream, socket_path};

#[cfg(unix)]
type Listener = std::os::unix::net::UnixListener;
#[cfg(not(unix))]
type Listener = std::net::TcpListener;

/// Bytes queued for one slow client before it is dropped.
const CLIENT_BACKLOG_MAX: usize = 256 * 1024;
/// The longest line a client may write (a command is far shorter).
const LINE_MAX: usize = 512;

struct Client {
    stream: Stream,
    /// A partial line from the client.
    line: Vec<u8>,
    /// Bytes for the client that it has not taken yet.
    out: Vec<u8>,
}

/// The socket and its clients.
pub struct Relay {
    listener: Listener,
    path: PathBuf,
    clients: Vec<Client>,
}

impl Relay {
    /// Serves the socket of `port`. A socket left by a monitor that died is replaced; one a
    /// running monitor answers on is not (that monitor holds the port, so we could not either).
    pub fn serve(port: &str) -> Result<Relay> {
        let path = socket_path(port);
        if crate::link::connect_monitor(port).is_some() {
            anyhow::bail!(crate::serial::LinkError(format!(
                "another `bowl monitor` already holds {port} (its socket is {})",
                path.display()
            )));
        }
        let _ = std::fs::remove_file(&path);
        #[cfg(unix)]
        let listener = Listener::bind(&path)
            .with_context(|| format!("cannot serve the socket {}", path.display()))?;
        #[cfg(not(unix))]
        let listener = {
            let l = Listener::bind(("127.0.0.1", 0)).context("cannot serve on 127.0.0.1")?;
            std::fs::write(&path, l.local_addr()?.port().to_string())
                .with_context(|| format!("cannot write {}", path.display()))?;
            l
        };
        listener.set_nonblocking(true)?;
        Ok(Relay {
            listener,
            path,
            clients: Vec::new(),
        })
    }

    /// How many tools are connected.
    pub fn client_count(&self) -> usize {
        self.clients.len()
    }

    /// Accepts new clients and returns the whole lines they wrote, to go to the rig.
    pub fn poll(&mut self) -> Vec<Vec<u8>> {
        while let Ok((stream, _)) = self.listener.accept() {
            if stream.set_nonblocking(true).is_ok() {
                self.clients.push(Client {
                    stream,
                    line: Vec::new(),
                    out: Vec::new(),
                });
            }
        }
        let mut lines = Vec::new();
        let mut buf = [0u8; 1024];
        self.clients.retain_mut(|c| {
            loop {
                match c.stream.read(&mut buf) {
                    Ok(0) => return false,
                    Ok(n) => {
                        for &b in &buf[..n] {
                            c.line.push(b);
                            if b == b'\r' || b == b'\n' {
                                // A line ends at CR, LF or CRLF, as on the rig. A line end
                                // alone (the LF of a CRLF) goes nowhere: the rig needs none.
                                let line = std::mem::take(&mut c.line);
                                if line.len() > 1 {
                                    lines.push(line);
                                }
                            } else if c.line.len() > LINE_MAX {
                                c.line.clear();
                            }
                        }
                    }
                    Err(e) if e.kind() == ErrorKind::WouldBlock => return true,
                    Err(e) if e.kind() == ErrorKind::Interrupted => {}
                    Err(_) => return false,
                }
            }
        });
        lines
    }

    /// Sends bytes from the rig to every client (queued for a client that is not reading;
    /// a client far behind is dropped).
    pub fn broadcast(&mut self, bytes: &[u8]) {
        self.clients.retain_mut(|c| {
            c.out.extend_from_slice(bytes);
            while !c.out.is_empty() {
                match c.stream.write(&c.out) {
                    Ok(0) => return false,
                    Ok(n) => {
                        c.out.drain(..n);
                    }
                    Err(e) if e.kind() == ErrorKind::WouldBlock => break,
                    Err(e) if e.kind() == ErrorKind::Interrupted => {}
                    Err(_) => return false,
                }
            }
            c.out.len() <= CLIENT_BACKLOG_MAX
        });
    }
}

impl Drop for Relay {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

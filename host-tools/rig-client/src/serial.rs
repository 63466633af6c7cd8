//! A serial port (or a pseudo-terminal) through the `serialport` crate: raw 8N1 at any baud rate,
//! opened exclusively (no second program can open it while we hold it), read with timeouts.
//! Linux, macOS and Windows. Open errors are explained in plain words ([`LinkError`]).

use std::io::{Read, Write};
use std::time::Duration;

use serialport::{ClearBuffer, SerialPort, SerialPortType};

/// A problem with the link itself (missing, busy, not permitted, gone): `bowl` exits with
/// `exit_code::LINK` when an error carries one of these.
#[derive(Debug)]
pub struct LinkError(pub String);

impl std::fmt::Display for LinkError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for LinkError {}

#[cfg(unix)]
type Native = serialport::TTYPort;
#[cfg(windows)]
type Native = serialport::COMPort;

/// An open port in raw 8N1 mode.
pub struct Port {
    inner: Native,
    path: String,
}

/// What a read returned.
pub enum ReadOutcome {
    /// This many bytes (at least one).
    Data(usize),
    /// Nothing within the timeout.
    Timeout,
    /// The device went away (USB unplugged, the pseudo-terminal's other side closed).
    Gone,
}

/// Why `path` cannot be a serial port before we try to open it, if that can be told.
fn refuse_before_open(path: &str) -> Option<String> {
    if cfg!(windows) {
        return None;
    }
    match std::fs::metadata(path) {
        Err(_) => Some(format!(
            "no serial port at {path}: the path does not exist. `bowl ports` lists the ports \
             found; check the cable, or start a virtual rig with `bowl serve --pty`"
        )),
        Ok(m) if m.is_file() => Some(format!(
            "{path} is a regular file, not a serial port; to decode a recorded capture use \
             `bowl replay {path}`"
        )),
        Ok(m) if m.is_dir() => Some(format!("{path} is a directory, not a serial port")),
        Ok(_) => None,
    }
}

/// The plain-words reason an open failed.
fn explain_open_error(path: &str, e: &serialport::Error) -> String {
    let text = e.to_string();
    let lower = text.to_ascii_lowercase();
    if lower.contains("permission") || lower.contains("access is denied") {
        if cfg!(target_os = "linux") {
            format!(
                "permission denied opening {path}: your user may not use serial ports. Add it to \
                 the `dialout` group (`sudo usermod -aG dialout $USER`), then log out and in again"
            )
        } else if cfg!(windows) {
            format!("{path} is in use by another program (or access is denied): close it and retry")
        } else {
            format!("permission denied opening {path}: check the device's owner and group ({text})")
        }
    } else if lower.contains("exclusive lock") || lower.contains("busy") {
        // Named where the system lets us see (`bowl` is a `commission` or `experiment` that
        // holds it until it ends; a monitor would have let the command through).
        let who: Vec<String> = other_holders(path).iter().map(Holder::to_string).collect();
        let who = if who.is_empty() {
            "another program (a second `bowl monitor`, tio, screen?)".to_string()
        } else {
            format!("another program: {}", who.join(", "))
        };
        format!("{path} is in use by {who}; close it, or send through a running `bowl monitor`")
    } else if lower.contains("not a typewriter") || lower.contains("inappropriate ioctl") {
        format!("{path} is not a serial port or terminal")
    } else if lower.contains("no such file") || lower.contains("cannot find") {
        format!("no serial port at {path}: it does not exist. `bowl ports` lists the ports found")
    } else {
        format!("cannot open the serial port {path}: {text}")
    }
}

impl Port {
    /// Opens `path` in raw 8N1 mode at `baud`, exclusively.
    pub fn open(path: &str, baud: u32) -> Result<Port, LinkError> {
        if let Some(why) = refuse_before_open(path) {
            return Err(LinkError(why));
        }
        let inner = serialport::new(path, baud)
            .timeout(Duration::from_millis(50))
            .open_native()
            .map_err(|e| LinkError(explain_open_error(path, &e)))?;
        Ok(Port {
            inner,
            path: path.to_owned(),
        })
    }

    /// Reads what is there, waiting at most `timeout` for the first byte. A read of 0 bytes is
    /// not taken as the device's end (a terminal may report readable and then have nothing):
    /// only a hang-up, an I/O error or the path's disappearance is.
    pub fn read(&mut self, buf: &mut [u8], timeout: Duration) -> Result<ReadOutcome, LinkError> {
        let _ = self
            .inner
            .set_timeout(timeout.max(Duration::from_millis(1)));
        match self.inner.read(buf) {
            Ok(0) => Ok(if self.path_vanished() {
                ReadOutcome::Gone
            } else {
                ReadOutcome::Timeout
            }),
            Ok(n) => Ok(ReadOutcome::Data(n)),
            Err(e) => match e.kind() {
                std::io::ErrorKind::TimedOut
                | std::io::ErrorKind::Interrupted
                | std::io::ErrorKind::WouldBlock => Ok(ReadOutcome::Timeout),
                // Hang-up (the other side closed), EIO (USB unplugged) and the like.
                _ => Ok(ReadOutcome::Gone),
            },
        }
    }

    fn path_vanished(&self) -> bool {
        !cfg!(windows) && std::fs::metadata(&self.path).is_err()
    }

    /// Throws away what arrived and was not read yet, so an old answer cannot be taken for the
    /// answer to the next command. Telemetry in between is lost, which a command can afford.
    pub fn discard_input(&mut self) {
        let _ = self.inner.clear(ClearBuffer::Input);
    }

    /// Writes all of `bytes`.
    pub fn write_all(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.inner
            .write_all(bytes)
            .and_then(|()| self.inner.flush())
            .map_err(|e| LinkError(format!("cannot write to {}: {e}", self.path)))
    }
}

/// Another program that has the same port open.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Holder {
    /// Its process id.
    pub pid: u32,
    /// Its name, as the system knows it (`picocom`, `python3`, ...).
    pub name: String,
}

impl std::fmt::Display for Holder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} (pid {})", self.name, self.pid)
    }
}

/// Other programs that have `path` open, as far as this system lets us see (Linux, through
/// `/proc`; elsewhere none are found). Our exclusive open keeps later programs out, but one that
/// opened the port before us without locking it (tio and screen without their lock, `cat`, a
/// script) goes on reading: each byte the rig sends reaches only one of us, so frames and answers
/// go missing at random with nothing else to show why. A program that also holds the
/// pseudo-terminal's master side is the rig's side (a virtual rig, an emulator), not a reader.
pub fn other_holders(path: &str) -> Vec<Holder> {
    #[cfg(target_os = "linux")]
    {
        linux_holders::find(path)
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = path;
        Vec::new()
    }
}

/// The warning shown when [`other_holders`] found someone, in words: who, what it does to the
/// link, what to do.
pub fn shared_port_warning(path: &str, holders: &[Holder]) -> Option<String> {
    if holders.is_empty() {
        return None;
    }
    let who: Vec<String> = holders.iter().map(Holder::to_string).collect();
    Some(format!(
        "warning: {path} is also open in {}, which does not lock it: it takes some of the rig's \
         bytes, so frames and answers will go missing. Close it; to share the rig between programs, \
         keep one `bowl monitor` open (other `bowl` commands send through it)",
        who.join(", ")
    ))
}

#[cfg(target_os = "linux")]
mod linux_holders {
    use std::os::unix::fs::{FileTypeExt, MetadataExt};

    use super::Holder;

    /// The pseudo-terminal index of a `/dev/pts/N` path.
    fn pts_index(path: &str) -> Option<u32> {
        std::fs::canonicalize(path)
            .ok()?
            .to_str()?
            .strip_prefix("/dev/pts/")?
            .parse()
            .ok()
    }

    /// Whether process `pid` holds the master side of pseudo-terminal `index` (its `fdinfo`
    /// names the index of the terminal a `/dev/ptmx` descriptor opened).
    fn holds_master(pid: &str, index: u32) -> bool {
        let Ok(fds) = std::fs::read_dir(format!("/proc/{pid}/fd")) else {
            return false;
        };
        fds.flatten().any(|fd| {
            let target = std::fs::read_link(fd.path()).unwrap_or_default();
            if !target.to_string_lossy().ends_with("ptmx") {
                return false;
            }
            let info = std::fs::read_to_string(format!(
                "/proc/{pid}/fdinfo/{}",
                fd.file_name().to_string_lossy()
            ))
            .unwrap_or_default();
            info.lines().any(|l| {
                l.strip_prefix("tty-index:")
                    .and_then(|v| v.trim().parse::<u32>().ok())
                    == Some(index)
            })
        })
    }

    pub(super) fn find(path: &str) -> Vec<Holder> {
        let Ok(device) = std::fs::metadata(path) else {
            return Vec::new();
        };
        if !device.file_type().is_char_device() {
            return Vec::new();
        }
        let me = std::process::id().to_string();
        let pts = pts_index(path);
        let Ok(procs) = std::fs::read_dir("/proc") else {
            return Vec::new();
        };
        let mut found = Vec::new();
        for entry in procs.flatten() {
            let pid = entry.file_name().to_string_lossy().into_owned();
            if pid == me || !pid.bytes().all(|b| b.is_ascii_digit()) {
                continue;
            }
            // Other users' descriptors are not readable: those holders stay unseen.
            let Ok(fds) = std::fs::read_dir(format!("/proc/{pid}/fd")) else {
                continue;
            };
            let holds = fds.flatten().any(|fd| {
                std::fs::metadata(fd.path())
                    .is_ok_and(|m| m.file_type().is_char_device() && m.rdev() == device.rdev())
            });
            if !holds || pts.is_some_and(|i| holds_master(&pid, i)) {
                continue;
            }
            let name = std::fs::read_to_string(format!("/proc/{pid}/comm"))
                .map(|n| n.trim().to_owned())
                .unwrap_or_else(|_| "a program".to_owned());
            if let Ok(pid) = pid.parse() {
                found.push(Holder { pid, name });
            }
        }
        found.sort_by_key(|h| h.pid);
        found
    }
}

impl Drop for Port {
    fn drop(&mut self) {
        // A terminal keeps its exclusive flag while anyone else holds it open (the virtual rig
        // holds its pseudo-terminal), which would lock the next user out.
        #[cfg(unix)]
        let _ = self.inner.set_exclusive(false);
    }
}

/// One line per serial port found, with its USB description where there is one.
pub fn list_ports() -> Result<Vec<String>, LinkError> {
    let ports = serialport::available_ports()
        .map_err(|e| LinkError(format!("cannot list the serial ports: {e}")))?;
    Ok(ports
        .into_iter()
        .map(|p| match p.port_type {
            SerialPortType::UsbPort(u) => format!(
                "{}  USB {:04x}:{:04x}  {}{}{}",
                p.port_name,
                u.vid,
                u.pid,
                u.manufacturer.unwrap_or_default(),
                u.product.map(|s| format!(" {s}")).unwrap_or_default(),
                u.serial_number
                    .map(|s| format!(" (serial {s})"))
                    .unwrap_or_default()
            ),
            SerialPortType::PciPort => format!("{}  PCI", p.port_name),
            SerialPortType::BluetoothPort => format!("{}  Bluetooth", p.port_name),
            SerialPortType::Unknown => p.port_name,
        })
        .collect())
}

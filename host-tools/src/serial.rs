//! A serial port (or a pseudo-terminal) in raw mode through termios, with read timeouts.
//! No libudev: the port is a path, `/dev/ttyUSB0`, `/dev/ttyACM0` or `/dev/pts/N`.

use std::fs::{File, OpenOptions};
use std::io::{Read, Write};
use std::os::fd::{AsFd, AsRawFd};
use std::os::unix::fs::OpenOptionsExt;
use std::time::Duration;

use anyhow::{Context, Result, bail};
use nix::poll::{PollFd, PollFlags, PollTimeout, poll};
use nix::sys::termios::{self, BaudRate, SetArg, SpecialCharacterIndices};

use crate::exit_code::LinkError;

/// An open port in raw 8N1 mode.
pub struct Port {
    file: File,
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

/// The termios speed for `baud`; an error in plain words for a rate the port cannot be set to.
pub fn baud_rate(baud: u32) -> Result<BaudRate> {
    Ok(match baud {
        9600 => BaudRate::B9600,
        19200 => BaudRate::B19200,
        38400 => BaudRate::B38400,
        57600 => BaudRate::B57600,
        115_200 => BaudRate::B115200,
        230_400 => BaudRate::B230400,
        460_800 => BaudRate::B460800,
        921_600 => BaudRate::B921600,
        1_000_000 => BaudRate::B1000000,
        2_000_000 => BaudRate::B2000000,
        other => bail!(
            "baud rate {other} is not one this port can be set to: use 9600, 19200, 38400, 57600, \
             115200 (the rig's), 230400, 460800, 921600, 1000000 or 2000000"
        ),
    })
}

/// Puts an open terminal into raw 8N1 mode at `baud`.
pub fn make_raw(file: &File, baud: u32) -> Result<()> {
    let mut t = termios::tcgetattr(file.as_fd()).context("not a terminal (tcgetattr)")?;
    termios::cfmakeraw(&mut t);
    termios::cfsetspeed(&mut t, baud_rate(baud)?).context("cfsetspeed")?;
    t.control_flags |= termios::ControlFlags::CLOCAL | termios::ControlFlags::CREAD;
    t.control_flags &= !(termios::ControlFlags::CSTOPB | termios::ControlFlags::CRTSCTS);
    t.control_chars[SpecialCharacterIndices::VMIN as usize] = 0;
    t.control_chars[SpecialCharacterIndices::VTIME as usize] = 0;
    termios::tcsetattr(file.as_fd(), SetArg::TCSANOW, &t).context("tcsetattr")?;
    Ok(())
}

/// Checks, before waiting for it, that `path` can become a serial port: an existing path must
/// be a character device (a regular file or a folder never will be). A missing path is fine:
/// a USB adapter may be plugged in later.
pub fn check_path(path: &str) -> Result<()> {
    use std::os::unix::fs::FileTypeExt;
    match std::fs::metadata(path) {
        Ok(m) if !m.file_type().is_char_device() => Err(LinkError(format!(
            "{path} is not a serial port (it is a {}); give the rig's device, e.g. /dev/ttyUSB0, \
             or see `ls /dev/tty*`",
            if m.is_dir() { "folder" } else { "regular file" }
        ))
        .into()),
        _ => Ok(()),
    }
}

/// Why a port did not open, in plain words with what to do.
fn open_failure(path: &str, e: &std::io::Error) -> String {
    let what_to_do = match e.raw_os_error() {
        Some(nix::libc::EBUSY) => {
            " - another program holds the port (a running `bowl monitor`, tio, screen?): \
             close it first"
        }
        Some(nix::libc::EACCES) | Some(nix::libc::EPERM) => {
            " - no permission: add yourself to the group that owns it (usually `dialout`: \
             `sudo usermod -aG dialout $USER`, then log in again)"
        }
        Some(nix::libc::ENOENT) => {
            " - no such device: is the rig plugged in? `bowl monitor` waits for it to appear"
        }
        _ => "",
    };
    format!("cannot open the serial port {path}: {e}{what_to_do}")
}

impl Port {
    /// Opens `path` in raw mode at `baud`.
    pub fn open(path: &str, baud: u32) -> Result<Port> {
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .custom_flags(nix::libc::O_NOCTTY)
            .open(path)
            .map_err(|e| LinkError(open_failure(path, &e)))?;
        // Exclusive use: a second program opening the port would take half of the bytes.
        // SAFETY: TIOCEXCL takes no argument and only sets a flag on this open terminal.
        if unsafe { nix::libc::ioctl(file.as_raw_fd(), nix::libc::TIOCEXCL) } != 0 {
            return Err(LinkError(format!(
                "cannot take {path} for this program alone: {}",
                std::io::Error::last_os_error()
            ))
            .into());
        }
        make_raw(&file, baud).map_err(|e| {
            LinkError(format!(
                "cannot set up {path} as a serial port (is it a serial device?): {e:#}"
            ))
        })?;
        Ok(Port { file })
    }

    /// Reads what is there, waiting at most `timeout` for the first byte.
    pub fn read(&mut self, buf: &mut [u8], timeout: Duration) -> Result<ReadOutcome> {
        let ms = u16::try_from(timeout.as_millis()).unwrap_or(u16::MAX);
        let mut fds = [PollFd::new(self.file.as_fd(), PollFlags::POLLIN)];
        let n = match poll(&mut fds, PollTimeout::from(ms)) {
            Ok(n) => n,
            Err(nix::errno::Errno::EINTR) => return Ok(ReadOutcome::Timeout),
            Err(e) => return Err(e).context("poll"),
        };
        if n == 0 {
            return Ok(ReadOutcome::Timeout);
        }
        let revents = fds[0].revents().unwrap_or(PollFlags::empty());
        if revents.contains(PollFlags::POLLIN) {
            return match self.file.read(buf) {
                // Readable but empty (raw mode, VMIN = 0): nothing after all, unless the other side
                // hung up. Never a reason on its own to call the device gone.
                Ok(0) if revents.contains(PollFlags::POLLHUP) => Ok(ReadOutcome::Gone),
                Ok(0) => Ok(ReadOutcome::Timeout),
                Ok(n) => Ok(ReadOutcome::Data(n)),
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => Ok(ReadOutcome::Timeout),
                // EIO: the pseudo-terminal's master closed, or the USB device vanished.
                Err(_) => Ok(ReadOutcome::Gone),
            };
        }
        if revents.intersects(PollFlags::POLLHUP | PollFlags::POLLERR | PollFlags::POLLNVAL) {
            return Ok(ReadOutcome::Gone);
        }
        Ok(ReadOutcome::Timeout)
    }

    /// Writes all of `bytes`.
    pub fn write_all(&mut self, bytes: &[u8]) -> Result<()> {
        self.file.write_all(bytes).context("write to port")?;
        Ok(())
    }
}

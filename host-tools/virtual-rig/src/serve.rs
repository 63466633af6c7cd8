//! The virtual rig ([`crate::rig`]) on a transport (`bowl serve`). Either a
//! pseudo-terminal speaking the protocol in real time (`--pty`), or a capture file written
//! faster than real time with exactly the bytes the rig would send (`--capture FILE --seconds S`).
//! The demo serves its host rig with the same loop ([`serve_on_pty`]).

// The ANSI dashboard and the pseudo-terminal serve the demo, which needs a Unix system.
#![cfg_attr(not(unix), allow(dead_code, unused_imports))]

use std::fs::File;
use std::io::{BufWriter, Read, Write};
#[cfg(unix)]
use std::os::fd::AsFd;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
#[cfg(unix)]
use nix::fcntl::OFlag;
#[cfg(unix)]
use nix::pty::{PtyMaster, grantpt, posix_openpt, ptsname_r, unlockpt};
#[cfg(unix)]
use nix::sys::termios::{FlushArg, tcflush};

use model_core::wire::{Command, Frame, MAX_FRAME_LEN, encode};

use crate::rig::VirtualRig;

/// Corrupts a fraction of the bytes on their way out (xorshift PRNG, seeded: reproducible).
pub struct LineNoise {
    state: u64,
    threshold: u64,
}

impl LineNoise {
    /// A clean line.
    pub fn none() -> Self {
        Self {
            state: 1,
            threshold: 0,
        }
    }

    /// A line that corrupts `percent` % of the bytes (seeded).
    pub fn new(percent: f64, seed: u32) -> Result<Self> {
        if !(percent.is_finite() && (0.0..=100.0).contains(&percent)) {
            bail!("--line-noise-percent must be between 0 and 100 (got {percent})");
        }
        Ok(Self {
            state: 0x9E37_79B9_7F4A_7C15 ^ u64::from(seed),
            threshold: (percent / 100.0 * u64::MAX as f64) as u64,
        })
    }

    fn next(&mut self) -> u64 {
        self.state ^= self.state << 13;
        self.state ^= self.state >> 7;
        self.state ^= self.state << 17;
        self.state
    }

    fn apply(&mut self, bytes: &mut [u8]) {
        if self.threshold == 0 {
            return;
        }
        for b in bytes {
            if self.next() < self.threshold {
                // A non-zero mask: the byte always changes.
                *b ^= (self.next() % 255 + 1) as u8;
            }
        }
    }
}

/// A scheduled command: device time and the command line bytes.
pub struct Scheduled {
    /// Device time it is fed to the rig, ms.
    pub at_ms: u32,
    /// The command line, as the PC would send it.
    pub line: Vec<u8>,
}

/// The scripted PC heartbeats like every host tool (PING once a second of device time), so the
/// rig's link-loss timeout stays quiet between scripted commands.
const SCRIPT_PING_EVERY_MS: u32 = 1000;
/// The heartbeat's command id, apart from the scripted commands' 1, 2, ...
const SCRIPT_PING_ID: u16 = 9000;

/// The heartbeat line due at device time `now_ms`, if a script runs and one is due.
fn script_heartbeat(scripted: bool, now_ms: u32) -> Option<Vec<u8>> {
    (scripted && now_ms > 0 && now_ms.is_multiple_of(SCRIPT_PING_EVERY_MS))
        .then(|| {
            let mut buf = [0u8; MAX_FRAME_LEN];
            let ping = Frame::Command {
                id: SCRIPT_PING_ID,
                command: Command::Ping,
            };
            encode(&ping, &mut buf).ok().map(|n| buf[..n].to_vec())
        })
        .flatten()
}

/// The run length `bowl serve --seconds` takes: a finite time from 0 to 4e6 s (46 days).
pub fn check_seconds(seconds: f64) -> Result<()> {
    if !(seconds.is_finite() && (0.0..=4_000_000.0).contains(&seconds)) {
        bail!(
            "--seconds must be between 0 and 4e6 (got {seconds}): give the run's length in seconds"
        );
    }
    Ok(())
}

/// Runs `rig` for `seconds` of device time faster than real time and writes its output bytes
/// (with `noise`) to `path`: `bowl serve --capture`.
pub fn capture(
    path: &PathBuf,
    seconds: f64,
    commands: Vec<Scheduled>,
    mut rig: VirtualRig,
    mut noise: LineNoise,
) -> Result<()> {
    check_seconds(seconds)?;
    let mut file = BufWriter::new(
        File::create(path).with_context(|| format!("cannot create {}", path.display()))?,
    );
    let mut out = Vec::with_capacity(4096);
    rig.boot(&mut out);
    let total_ms = (seconds * 1000.0).round() as u64;
    let scripted = !commands.is_empty();
    let mut pending = commands.into_iter().peekable();
    let mut written = 0u64;
    for _ in 0..total_ms {
        let mut received = Vec::new();
        while let Some(c) = pending.next_if(|c| c.at_ms <= rig.now_ms) {
            received.extend(c.line);
        }
        received.extend(script_heartbeat(scripted, rig.now_ms).unwrap_or_default());
        rig.step_1ms(&received, &mut out);
        if out.len() >= 4096 {
            noise.apply(&mut out);
            file.write_all(&out)?;
            written += out.len() as u64;
            out.clear();
        }
    }
    noise.apply(&mut out);
    file.write_all(&out)?;
    written += out.len() as u64;
    file.flush()?;
    eprintln!(
        "wrote {written} bytes ({seconds} s of rig output) to {}",
        path.display()
    );
    Ok(())
}

#[cfg(unix)]
/// A pseudo-terminal pair: the master side the rig is served on, and the slave's path.
pub struct Pty {
    master: PtyMaster,
    /// Held open so the master never sees a hang-up between clients.
    slave: File,
    /// The slave's device path, for the client.
    pub path: String,
}

#[cfg(unix)]
impl Pty {
    /// Opens a pair. The slave is put in raw mode so nothing is echoed or line-buffered before a
    /// client configures it.
    pub fn open() -> Result<Pty> {
        let master = posix_openpt(OFlag::O_RDWR | OFlag::O_NOCTTY | OFlag::O_NONBLOCK)
            .context("posix_openpt")?;
        grantpt(&master).context("grantpt")?;
        unlockpt(&master).context("unlockpt")?;
        let path = ptsname_r(&master).context("ptsname")?;
        let slave = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .open(&path)
            .with_context(|| format!("open {path}"))?;
        make_raw(&slave)?;
        Ok(Pty {
            master,
            slave,
            path,
        })
    }
}

#[cfg(unix)]
/// Puts a terminal into raw 8N1 mode (no echo, no line buffering, reads return what is there).
fn make_raw(file: &File) -> Result<()> {
    use nix::sys::termios::{self, BaudRate, SetArg};
    let mut t = termios::tcgetattr(file.as_fd()).context("not a terminal (tcgetattr)")?;
    termios::cfmakeraw(&mut t);
    termios::cfsetspeed(&mut t, BaudRate::B115200).context("cfsetspeed")?;
    t.control_flags |= termios::ControlFlags::CLOCAL | termios::ControlFlags::CREAD;
    termios::tcsetattr(file.as_fd(), SetArg::TCSANOW, &t).context("tcsetattr")?;
    Ok(())
}

/// What happens to output bytes nobody reads.
#[derive(Clone, Copy, Debug)]
pub enum Backlog {
    /// Drop them, like a UART with no listener, so a client that connects later starts with
    /// fresh frames (`bowl serve`).
    DropWhenUnread,
    /// Keep up to this many bytes queued, then drop them all (the demo: its client is always
    /// there, only slower at times).
    KeepUpTo(usize),
}

/// How the served rig keeps time and when it stops.
pub struct Pacing<'a> {
    /// Device milliseconds per wall millisecond (1 = real time).
    pub device_ms_per_wall_ms: f64,
    /// Stops the loop when set.
    pub stop: &'a AtomicBool,
    /// Stops the loop after this much wall time.
    pub stop_after: Option<Duration>,
    /// Unread output.
    pub backlog: Backlog,
}

/// What the server saw.
#[derive(Debug, Default, Clone, Copy)]
pub struct ServeStats {
    /// Device time reached, ms.
    pub device_ms: u32,
    /// Bytes that could not be delivered because nobody read them.
    pub bytes_dropped: u64,
}

/// Serves `rig` on `pty` until `pacing` says stop: the rig catches up with the (scaled) wall
/// clock one millisecond at a time, reading what the client sent before each millisecond and
/// writing what the rig answered after each pass.
#[cfg(unix)]
pub fn serve_on_pty(
    mut pty: Pty,
    mut rig: VirtualRig,
    pacing: Pacing<'_>,
    commands: Vec<Scheduled>,
    mut noise: LineNoise,
) -> Result<ServeStats> {
    // At most this many device ms per pass, so reading and writing keep interleaving.
    const MAX_STEPS_PER_PASS: u32 = 50;
    let mut out = Vec::with_capacity(8192);
    let mut stats = ServeStats::default();
    rig.boot(&mut out);
    let mut noisy_from = 0;
    let started = Instant::now();
    let scripted = !commands.is_empty();
    let mut pending = commands.into_iter().peekable();
    let mut inbuf = [0u8; 1024];
    while !pacing.stop.load(Ordering::Relaxed) {
        let elapsed = started.elapsed();
        if pacing.stop_after.is_some_and(|s| elapsed >= s) {
            break;
        }
        let wall_ms = elapsed.as_secs_f64() * 1000.0 * pacing.device_ms_per_wall_ms;
        let due_ms = u32::try_from(wall_ms as u64).unwrap_or(u32::MAX);
        let mut steps = 0;
        while rig.now_ms < due_ms && steps < MAX_STEPS_PER_PASS {
            let mut received = Vec::new();
            // An error is WouldBlock (nothing sent) or EIO (no client right now).
            if let Ok(n) = pty.master.read(&mut inbuf) {
                received.extend_from_slice(&inbuf[..n]);
            }
            while let Some(c) = pending.next_if(|c| c.at_ms <= rig.now_ms) {
                received.extend(c.line);
            }
            received.extend(script_heartbeat(scripted, rig.now_ms).unwrap_or_default());
            rig.step_1ms(&received, &mut out);
            steps += 1;
        }
        // Bytes not yet sent were already corrupted once; only the new ones get noise.
        if let Some(fresh) = out.get_mut(noisy_from..) {
            noise.apply(fresh);
        }
        write_pending(&mut pty, &mut out, pacing.backlog, &mut stats);
        noisy_from = out.len();
        if steps < MAX_STEPS_PER_PASS {
            std::thread::sleep(Duration::from_millis(1));
        }
    }
    stats.device_ms = rig.now_ms;
    Ok(stats)
}

#[cfg(unix)]
/// Writes what the pty takes of `out`; what it does not take is kept or dropped per `backlog`.
fn write_pending(pty: &mut Pty, out: &mut Vec<u8>, backlog: Backlog, stats: &mut ServeStats) {
    while !out.is_empty() {
        match pty.master.write(out) {
            Ok(0) => break,
            Ok(n) => {
                out.drain(..n);
            }
            Err(e) => {
                if let Backlog::DropWhenUnread = backlog {
                    if e.kind() == std::io::ErrorKind::WouldBlock {
                        // Nobody reads: what the slave holds is stale too.
                        let _ = tcflush(pty.slave.as_fd(), FlushArg::TCIFLUSH);
                    }
                    stats.bytes_dropped += out.len() as u64;
                    out.clear();
                }
                break;
            }
        }
    }
    if let Backlog::KeepUpTo(max) = backlog
        && out.len() > max
    {
        stats.bytes_dropped += out.len() as u64;
        out.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_noise_changes_the_asked_fraction_of_bytes_and_a_clean_line_none() {
        let clean = vec![0x55u8; 100_000];
        let mut bytes = clean.clone();
        LineNoise::none().apply(&mut bytes);
        assert_eq!(bytes, clean);
        LineNoise::new(10.0, 7).unwrap().apply(&mut bytes);
        let changed = bytes.iter().zip(&clean).filter(|(a, b)| a != b).count();
        // Binomial(100 000, 0.1): standard deviation 95 bytes; 1 000 is over ten of them.
        assert!((9_000..=11_000).contains(&changed), "{changed} changed");
        for bad in [-1.0, 100.5, f64::NAN] {
            let err = LineNoise::new(bad, 1).err().expect("refused").to_string();
            assert!(err.contains("between 0 and 100"), "{err}");
        }
    }
}

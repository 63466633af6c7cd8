//! Shares a board's link between the telemetry decoder and `bowl` commands.
//!
//! Why a splitter: a serial port (or pseudo-terminal) has one input queue, so two readers
//! (`bowl monitor` and `bowl send`) would steal each other's bytes. The splitter reads the board
//! once, decodes every frame for itself, and copies the bytes to one pseudo-terminal per
//! client: the monitor's always, the command terminal's while a `bowl send` runs. A test
//! harness: it panics, with the reason, when a pseudo-terminal cannot be had or the board stops
//! sending.

use std::io::{Read, Write};
use std::os::fd::{AsRawFd, OwnedFd};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use model_core::wire::{Decoder, Frame, Telemetry};

/// What the splitter decoded from the board.
#[derive(Default)]
pub struct Seen {
    /// Every telemetry frame, in arrival order.
    pub telemetry: Vec<Telemetry>,
    /// Boot announcements.
    pub hello: usize,
    /// Gate events, in arrival order.
    pub gate_events: Vec<model_core::wire::GateEvent>,
    /// Frames that failed their check or did not parse.
    pub corrupt: usize,
}

/// Sits between the board's USART socket and pseudo-terminals (see the module docs).
pub struct Splitter {
    seen: Arc<Mutex<Seen>>,
    forward: Arc<AtomicBool>,
    command_pty: PathBuf,
    command_slave: OwnedFd,
    monitor_pty: Option<(PathBuf, OwnedFd)>,
}

fn raw_pty() -> (OwnedFd, OwnedFd, PathBuf) {
    use nix::sys::termios;
    let pty = nix::pty::openpty(None, None).expect("openpty");
    let mut t = termios::tcgetattr(&pty.slave).expect("tcgetattr");
    termios::cfmakeraw(&mut t);
    termios::tcsetattr(&pty.slave, termios::SetArg::TCSANOW, &t).expect("tcsetattr");
    let path = std::fs::read_link(format!("/proc/self/fd/{}", pty.slave.as_raw_fd()))
        .expect("the slave's path");
    (pty.master, pty.slave, path)
}

impl Splitter {
    /// Starts relaying `usart`. With `monitor`, a second terminal receives every byte from the
    /// board (someone must read it, or the relay blocks and with it the board's virtual time).
    pub fn start(usart: UnixStream, monitor: bool) -> Splitter {
        let (master, command_slave, command_pty) = raw_pty();
        let mut monitor_w = None;
        let monitor_pty = monitor.then(|| {
            let (m, s, p) = raw_pty();
            // The monitor is a viewer: if it falls behind, its terminal drops bytes (it counts
            // the frames it missed) instead of stalling this relay and with it the board.
            let flags = nix::fcntl::fcntl(&m, nix::fcntl::FcntlArg::F_GETFL).expect("F_GETFL");
            let flags =
                nix::fcntl::OFlag::from_bits_truncate(flags) | nix::fcntl::OFlag::O_NONBLOCK;
            nix::fcntl::fcntl(&m, nix::fcntl::FcntlArg::F_SETFL(flags)).expect("F_SETFL");
            monitor_w = Some(std::fs::File::from(m));
            (p, s)
        });
        let seen = Arc::new(Mutex::new(Seen::default()));
        let forward = Arc::new(AtomicBool::new(false));
        let mut command_w = std::fs::File::from(master.try_clone().expect("dup"));
        let mut command_r = std::fs::File::from(master);
        let mut from_board = usart.try_clone().expect("dup");
        let mut to_board = usart;
        {
            let (seen, forward) = (seen.clone(), forward.clone());
            std::thread::spawn(move || {
                let mut decoder = Decoder::new();
                let mut buf = vec![0u8; 4096];
                while let Ok(n) = from_board.read(&mut buf) {
                    if n == 0 {
                        break;
                    }
                    if forward.load(Ordering::Acquire) {
                        let _ = command_w.write_all(&buf[..n]);
                    }
                    if let Some(m) = monitor_w.as_mut() {
                        let _ = m.write_all(&buf[..n]);
                    }
                    let mut s = seen.lock().expect("lock");
                    for &b in &buf[..n] {
                        match decoder.push(b) {
                            Some(Ok(Frame::Telemetry(t))) => s.telemetry.push(t),
                            Some(Ok(Frame::Hello(_))) => s.hello += 1,
                            Some(Ok(Frame::Event(e))) => s.gate_events.push(e),
                            Some(Ok(_)) => {}
                            Some(Err(_)) => s.corrupt += 1,
                            None => {}
                        }
                    }
                }
            });
        }
        std::thread::spawn(move || {
            let mut buf = [0u8; 256];
            while let Ok(n) = command_r.read(&mut buf) {
                if n == 0 || to_board.write_all(&buf[..n]).is_err() {
                    break;
                }
            }
        });
        Splitter {
            seen,
            forward,
            command_pty,
            command_slave,
            monitor_pty,
        }
    }

    /// The monitor's terminal, if one was asked for.
    pub fn monitor_pty(&self) -> Option<&Path> {
        self.monitor_pty.as_ref().map(|(p, _)| p.as_path())
    }

    /// Runs `bowl send PTY words...` and returns its exit code and output.
    pub fn send(&self, bowl: &Path, words: &[&str]) -> (i32, String) {
        // Stale telemetry queued while nobody listened must not reach this send.
        let _ =
            nix::sys::termios::tcflush(&self.command_slave, nix::sys::termios::FlushArg::TCIFLUSH);
        self.forward.store(true, Ordering::Release);
        let out = Command::new(bowl)
            .arg("send")
            .arg(&self.command_pty)
            .args(words)
            .args(["--timeout-ms", "3000"])
            .output()
            .expect("bowl runs");
        self.forward.store(false, Ordering::Release);
        let text = String::from_utf8_lossy(&out.stdout).into_owned()
            + &String::from_utf8_lossy(&out.stderr);
        println!(
            "bowl send {} -> {:?}: {}",
            words.join(" "),
            out.status.code(),
            text.trim()
        );
        (out.status.code().unwrap_or(-1), text)
    }

    /// The newest telemetry frame.
    pub fn last(&self) -> Telemetry {
        let s = self.seen.lock().expect("lock");
        *s.telemetry.last().expect("telemetry arrives")
    }

    /// Runs `f` on everything decoded so far.
    pub fn with_seen<R>(&self, f: impl FnOnce(&Seen) -> R) -> R {
        f(&self.seen.lock().expect("lock"))
    }

    /// Waits until the board's clock has advanced `ms` past `from_ms`; returns the frames of
    /// that interval. Panics if no such frame comes within two minutes of host time.
    pub fn wait_device_ms(&self, from_ms: u32, ms: u32) -> Vec<Telemetry> {
        let deadline = Instant::now() + Duration::from_secs(120);
        loop {
            {
                let s = self.seen.lock().expect("lock");
                if s.telemetry
                    .last()
                    .is_some_and(|t| t.time_ms >= from_ms + ms)
                {
                    return s
                        .telemetry
                        .iter()
                        .filter(|t| t.time_ms >= from_ms)
                        .copied()
                        .collect();
                }
            }
            assert!(
                Instant::now() < deadline,
                "the board stopped sending telemetry"
            );
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    /// [`Splitter::wait_device_ms`] as a host tool waits: PINGs once a second of device time,
    /// so the board's link-loss timeout (`LINK_TIMEOUT_MS`) stays quiet.
    pub fn wait_device_ms_alive(&self, bowl: &Path, from_ms: u32, ms: u32) -> Vec<Telemetry> {
        let end_ms = from_ms + ms;
        loop {
            let now_ms = self.last().time_ms;
            if now_ms >= end_ms {
                return self.wait_device_ms(from_ms, ms);
            }
            self.wait_device_ms(now_ms, (end_ms - now_ms).min(1000));
            self.send(bowl, &["ping"]);
        }
    }
}

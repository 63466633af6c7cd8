//! The virtual rig's transport: `bowl sim --pty` (a pseudo-terminal speaking the protocol in real
//! time) and `bowl sim --capture FILE --seconds S` (the same rig faster than real time, writing
//! exactly the bytes it would send). The protocol side is `model_core::wire::device`, the same
//! code the firmware runs; the rig behind it is [`crate::rig_binding`].

use std::fs::File;
use std::io::{BufWriter, Read, Write};
use std::os::fd::AsFd;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use model_core::wire::MAX_FRAME_LEN;
use model_core::wire::device::Device;
use nix::fcntl::OFlag;
use nix::pty::{PtyMaster, grantpt, posix_openpt, ptsname_r, unlockpt};
use nix::sys::termios::{FlushArg, tcflush};

use crate::rig_binding::SimulatedRig;
use crate::send::command_line;

/// Flags of the virtual rig (`bowl sim --pty` / `bowl sim --capture`).
#[derive(clap::Args)]
pub struct Args {
    /// Serve the virtual rig on a new pseudo-terminal; its path is printed on the first line.
    #[arg(long, conflicts_with = "capture")]
    pty: bool,
    /// Also make this symlink point at the pseudo-terminal (replaced if it exists).
    #[arg(long, requires = "pty")]
    link: Option<PathBuf>,
    /// Run faster than real time and write the rig's output bytes to this file.
    #[arg(long, requires = "seconds")]
    capture: Option<PathBuf>,
    /// Simulated seconds to run (with --pty: stop after this many real seconds).
    #[arg(long)]
    seconds: Option<f64>,
    /// Commands fed to the rig as if from the PC, `AT_MS:WORDS`, e.g. `0:speed,1800,2100`
    /// `0:start` `5000:inject,sensor2` (repeatable; the answers appear in the output).
    #[arg(long = "command", value_name = "AT_MS:WORDS")]
    commands: Vec<String>,
    /// Seed of the simulated plant's noise.
    #[arg(long, default_value_t = 1)]
    seed: u32,
}

/// A scheduled command: device time and the command line bytes.
struct Scheduled {
    at_ms: u32,
    line: Vec<u8>,
}

fn parse_commands(specs: &[String]) -> Result<Vec<Scheduled>> {
    let mut out = Vec::new();
    for (i, spec) in specs.iter().enumerate() {
        let (at, words) = spec
            .split_once(':')
            .with_context(|| format!("--command {spec}: expected AT_MS:WORDS"))?;
        let at_ms: u32 = at
            .parse()
            .with_context(|| format!("--command {spec}: bad time"))?;
        let id = u16::try_from(i + 1).unwrap_or(u16::MAX);
        let line = command_line(id, &[words.to_string()])
            .map_err(|r| anyhow::anyhow!("--command {spec}: rejected locally ({})", r.token()))?;
        out.push(Scheduled { at_ms, line });
    }
    out.sort_by_key(|s| s.at_ms);
    Ok(out)
}

/// The rig plus the protocol, advanced one millisecond at a time by either transport.
pub(crate) struct VirtualRig {
    rig: SimulatedRig,
    device: Device,
    pub(crate) now_ms: u32,
}

impl VirtualRig {
    pub(crate) fn new(seed: u32) -> Result<Self> {
        Ok(Self {
            rig: SimulatedRig::new(seed)?,
            device: Device::new(),
            now_ms: 0,
        })
    }

    /// The boot announcement.
    pub(crate) fn boot(&mut self, out: &mut Vec<u8>) {
        let mut buf = [0u8; MAX_FRAME_LEN];
        if let Some(n) = self.device.hello(&self.rig, &mut buf) {
            out.extend_from_slice(&buf[..n]);
        }
    }

    /// One millisecond: take the received bytes, run the plant and controller, send what is due.
    pub(crate) fn step_1ms(&mut self, received: &[u8], out: &mut Vec<u8>) {
        self.device.receive(&mut self.rig, received, |answer| {
            out.extend_from_slice(answer)
        });
        self.now_ms = self.now_ms.wrapping_add(1);
        self.rig.advance_to_ms(self.now_ms);
        let mut buf = [0u8; MAX_FRAME_LEN];
        if let Some(n) = self.device.poll_telemetry(&self.rig, self.now_ms, &mut buf) {
            out.extend_from_slice(&buf[..n]);
        }
    }
}

/// Runs `bowl sim --pty` or `bowl sim --capture`.
pub fn run(args: &Args) -> Result<()> {
    let commands = parse_commands(&args.commands)?;
    if let Some(path) = &args.capture {
        let seconds = args.seconds.unwrap_or(0.0);
        return capture(path, seconds, commands, args.seed);
    }
    if args.pty {
        return serve_pty(args, commands);
    }
    bail!("say --pty or --capture FILE --seconds S")
}

fn capture(path: &PathBuf, seconds: f64, commands: Vec<Scheduled>, seed: u32) -> Result<()> {
    if !(seconds.is_finite() && (0.0..=4_000_000.0).contains(&seconds)) {
        bail!("--seconds must be between 0 and 4e6");
    }
    let mut file = BufWriter::new(
        File::create(path).with_context(|| format!("cannot create {}", path.display()))?,
    );
    let mut rig = VirtualRig::new(seed)?;
    let mut out = Vec::with_capacity(4096);
    rig.boot(&mut out);
    let total_ms = (seconds * 1000.0).round() as u64;
    let mut pending = commands.into_iter().peekable();
    let mut written = 0u64;
    for _ in 0..total_ms {
        let mut received = Vec::new();
        while let Some(c) = pending.next_if(|c| c.at_ms <= rig.now_ms) {
            received.extend(c.line);
        }
        rig.step_1ms(&received, &mut out);
        if out.len() >= 4096 {
            file.write_all(&out)?;
            written += out.len() as u64;
            out.clear();
        }
    }
    file.write_all(&out)?;
    written += out.len() as u64;
    file.flush()?;
    eprintln!(
        "wrote {written} bytes ({seconds} s of rig output) to {}",
        path.display()
    );
    Ok(())
}

/// Opens a pseudo-terminal pair; returns the master and the slave path. The slave is put in raw
/// mode so nothing is echoed or line-buffered before a client configures it.
pub(crate) fn open_pty() -> Result<(PtyMaster, String, File)> {
    let master = posix_openpt(OFlag::O_RDWR | OFlag::O_NOCTTY | OFlag::O_NONBLOCK)
        .context("posix_openpt")?;
    grantpt(&master).context("grantpt")?;
    unlockpt(&master).context("unlockpt")?;
    let path = ptsname_r(&master).context("ptsname")?;
    // Holding the slave open keeps the master from seeing a hang-up between clients.
    let slave = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(&path)
        .with_context(|| format!("open {path}"))?;
    crate::serial::make_raw(&slave, model_core::wire::DEFAULT_BAUD)?;
    Ok((master, path, slave))
}

fn serve_pty(args: &Args, commands: Vec<Scheduled>) -> Result<()> {
    let (mut master, path, slave) = open_pty()?;
    if let Some(link) = &args.link {
        let _ = std::fs::remove_file(link);
        std::os::unix::fs::symlink(&path, link)
            .with_context(|| format!("cannot link {} to {path}", link.display()))?;
    }
    println!("{path}");
    std::io::stdout().flush()?;

    let mut rig = VirtualRig::new(args.seed)?;
    let mut out = Vec::with_capacity(4096);
    rig.boot(&mut out);
    let started = Instant::now();
    let stop_after = args.seconds.map(Duration::from_secs_f64);
    let mut pending = commands.into_iter().peekable();
    let mut inbuf = [0u8; 1024];
    loop {
        let elapsed = started.elapsed();
        if stop_after.is_some_and(|s| elapsed >= s) {
            break;
        }
        // Catch up with the wall clock, one millisecond at a time.
        let wall_ms = u32::try_from(elapsed.as_millis()).unwrap_or(u32::MAX);
        while rig.now_ms < wall_ms {
            let mut received = Vec::new();
            match master.read(&mut inbuf) {
                Ok(n) => received.extend_from_slice(&inbuf[..n]),
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {}
                // EIO: no client on the other side right now.
                Err(_) => {}
            }
            while let Some(c) = pending.next_if(|c| c.at_ms <= rig.now_ms) {
                received.extend(c.line);
            }
            rig.step_1ms(&received, &mut out);
        }
        if !out.is_empty() {
            match master.write(&out) {
                Ok(n) => {
                    out.drain(..n);
                }
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                    // Nobody reads: drop what is queued, like a UART with no listener, so a
                    // client that connects later starts with fresh frames.
                    let _ = tcflush(slave.as_fd(), FlushArg::TCIFLUSH);
                    out.clear();
                }
                Err(_) => out.clear(),
            }
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    if let Some(link) = &args.link {
        let _ = std::fs::remove_file(link);
    }
    Ok(())
}

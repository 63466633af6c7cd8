//! The virtual rig's transport: `bowl sim --pty` (a pseudo-terminal speaking the protocol in real
//! time) and `bowl sim --capture FILE --seconds S` (the same rig faster than real time, writing
//! exactly the bytes it would send). The protocol side is `model_core::wire::device`, the same
//! code the firmware runs; the rig behind it is [`crate::simulated_backend`].

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

use crate::send::command_line;
use crate::simulated_backend::SimulatedBackend;

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
    /// Seed of the simulated plant's noise (and of the line noise).
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// A noisy line: this percentage of the bytes sent is replaced by a different random byte
    /// (what the PC receives, to try the decoder and the counters; default 0).
    #[arg(long, default_value_t = 0.0)]
    line_noise_percent: f64,
}

/// Corrupts a fraction of the bytes on their way out (xorshift PRNG, seeded: reproducible).
struct LineNoise {
    state: u64,
    threshold: u64,
}

impl LineNoise {
    fn new(percent: f64, seed: u32) -> Result<Self> {
        if !(percent.is_finite() && (0.0..=100.0).contains(&percent)) {
            bail!("--line-noise-percent must be between 0 and 100");
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
    rig: SimulatedBackend,
    device: Device,
    pub(crate) now_ms: u32,
}

impl VirtualRig {
    pub(crate) fn new(seed: u32) -> Result<Self> {
        Ok(Self {
            rig: SimulatedBackend::new(seed)?,
            device: Device::new(),
            now_ms: 0,
        })
    }

    /// The boot announcement.
    pub(crate) fn boot(&mut self, out: &mut Vec<u8>) {
        let mut buf = [0u8; MAX_FRAME_LEN];
        if let Some(n) = self.device.hello(self.rig.bound(), &mut buf) {
            out.extend_from_slice(&buf[..n]);
        }
    }

    /// One millisecond: take the received bytes, run the plant and controller, send what is due.
    pub(crate) fn step_1ms(&mut self, received: &[u8], out: &mut Vec<u8>) {
        self.device
            .receive(self.rig.bound_mut(), received, |answer| {
                out.extend_from_slice(answer)
            });
        self.now_ms = self.now_ms.wrapping_add(1);
        self.rig.advance_to_ms(self.now_ms);
        let mut buf = [0u8; MAX_FRAME_LEN];
        if let Some(n) = self
            .device
            .poll_telemetry(self.rig.bound(), self.now_ms, &mut buf)
        {
            out.extend_from_slice(&buf[..n]);
        }
    }
}

/// Runs `bowl sim --pty` or `bowl sim --capture`.
pub fn run(args: &Args) -> Result<()> {
    let commands = parse_commands(&args.commands)?;
    if let Some(path) = &args.capture {
        let seconds = args.seconds.unwrap_or(0.0);
        let noise = LineNoise::new(args.line_noise_percent, args.seed)?;
        return capture(path, seconds, commands, args.seed, noise);
    }
    if args.pty {
        return serve_pty(args, commands);
    }
    bail!("say --pty or --capture FILE --seconds S")
}

fn capture(
    path: &PathBuf,
    seconds: f64,
    commands: Vec<Scheduled>,
    seed: u32,
    mut noise: LineNoise,
) -> Result<()> {
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

    let mut noise = LineNoise::new(args.line_noise_percent, args.seed)?;
    let mut rig = VirtualRig::new(args.seed)?;
    let mut out = Vec::with_capacity(4096);
    rig.boot(&mut out);
    let mut noisy_from = 0;
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
        // Bytes not yet sent were already corrupted once; only the new ones get noise.
        if let Some(fresh) = out.get_mut(noisy_from..) {
            noise.apply(fresh);
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
        noisy_from = out.len();
        std::thread::sleep(Duration::from_millis(1));
    }
    if let Some(link) = &args.link {
        let _ = std::fs::remove_file(link);
    }
    Ok(())
}

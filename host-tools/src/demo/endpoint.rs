//! Where the demo's rig runs. Either way the demo reaches it only through a serial device path
//! (a pseudo-terminal) speaking `model_core::wire`, exactly as it would reach a real board:
//!
//! - [`RigChoice::Host`]: the virtual rig of `bowl sim --pty` (the controller and the simulated
//!   plant behind `model_core::wire::device`), served on a pseudo-terminal from a thread of this
//!   process. Always available.
//! - [`RigChoice::Qemu`]: the firmware's emulated-board image (`qemu-rig`: the firmware's tasks and
//!   controller binding on an emulated Cortex-M4F with the plant in place of the motors), its
//!   USART1 on a pseudo-terminal. Needs `qemu-system-arm` and the thumb target.
//! - [`RigChoice::Blackpill`]: the exact Black Pill image on the emulated STM32F411
//!   (tests/blackpill, [`super::blackpill`]), USART2 on a pseudo-terminal.

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow, bail};
use nix::pty::PtyMaster;

use crate::virtual_rig::{VirtualRig, open_pty};

/// Which rig the demo drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum RigChoice {
    /// The emulated board when `qemu-system-arm` and its image are available, else the host rig.
    Auto,
    /// The virtual rig on the host (the same controller code, no emulator).
    Host,
    /// The firmware image on the emulated board (fails if it cannot be built or started).
    Qemu,
    /// The Black Pill image (`cargo fw`) on the emulated STM32F411 against the project's plant.
    Blackpill,
}

/// The firmware binary that runs the rig on the emulated board.
pub const QEMU_RIG_BIN: &str = "qemu-rig";

/// Device milliseconds per wall millisecond of the host rig in `--fast` mode. High enough that
/// a 40 s session takes a few seconds, low enough that 50 telemetry frames per device second
/// (20 kB/s at this rate) never fill the pseudo-terminal.
pub const FAST_FACTOR: f64 = 10.0;

/// A running rig and the path of its serial device.
pub struct Endpoint {
    /// The serial device to open.
    pub port: String,
    /// One line saying which rig this is.
    pub description: String,
    /// Short name for the summary: `host`, `qemu` or `blackpill`.
    pub kind: &'static str,
    /// Why the emulated board is not used, when it is not.
    pub qemu_note: Option<String>,
    pub(super) running: Running,
}

pub(super) enum Running {
    Host {
        stop: Arc<AtomicBool>,
        thread: Option<JoinHandle<Result<HostStats>>>,
    },
    Emulator {
        child: Child,
        console: Option<JoinHandle<Vec<String>>>,
        /// Lines to the emulator (`inject WHAT`), when it takes them.
        control: Option<std::process::ChildStdin>,
    },
}

/// What the host rig's server saw.
#[derive(Debug, Default, Clone, Copy)]
pub struct HostStats {
    /// Device time reached, ms.
    pub device_ms: u32,
    /// Bytes that could not be delivered because nobody read them (a stuck client).
    pub bytes_dropped: u64,
}

/// What the endpoint reported when it was shut down.
#[derive(Debug, Default)]
pub struct Shutdown {
    /// Host rig counters.
    pub host: Option<HostStats>,
    /// The emulated board's semihosting console (its last lines).
    pub console: Vec<String>,
}

impl Endpoint {
    /// Starts the chosen rig. `fast` runs it faster than real time.
    pub fn start(choice: RigChoice, fast: bool, seed: u32, seconds: f64) -> Result<Endpoint> {
        match choice {
            RigChoice::Host => start_host(fast, seed, None),
            RigChoice::Qemu => start_qemu(fast, seconds),
            RigChoice::Blackpill => super::blackpill::start(seconds),
            RigChoice::Auto => match start_qemu(fast, seconds) {
                Ok(e) => Ok(e),
                Err(why) => start_host(fast, seed, Some(format!("{why:#}"))),
            },
        }
    }

    /// Fault injection into the emulated world, for a rig whose firmware refuses `INJECT`
    /// (the Black Pill image): each call sends `inject WHAT` to the emulator.
    pub fn injector(&mut self) -> Option<impl FnMut(&str) -> Result<()> + '_> {
        match &mut self.running {
            Running::Emulator {
                control: Some(stdin),
                ..
            } => Some(move |what: &str| {
                writeln!(stdin, "inject {what}")
                    .and_then(|()| stdin.flush())
                    .context("the emulator's control input is closed")
            }),
            _ => None,
        }
    }

    /// Stops the rig and collects what it reported.
    pub fn shutdown(self) -> Result<Shutdown> {
        match self.running {
            Running::Host { stop, mut thread } => {
                stop.store(true, Ordering::Relaxed);
                let stats = match thread.take().map(|t| t.join()) {
                    Some(Ok(r)) => r?,
                    Some(Err(_)) => bail!("the host rig's thread panicked"),
                    None => HostStats::default(),
                };
                Ok(Shutdown {
                    host: Some(stats),
                    console: Vec::new(),
                })
            }
            Running::Emulator {
                mut child,
                mut console,
                ..
            } => {
                let _ = child.kill();
                let _ = child.wait();
                let console = console
                    .take()
                    .and_then(|t| t.join().ok())
                    .unwrap_or_default();
                Ok(Shutdown {
                    host: None,
                    console,
                })
            }
        }
    }
}

fn start_host(fast: bool, seed: u32, qemu_note: Option<String>) -> Result<Endpoint> {
    let rig = VirtualRig::new(seed)?;
    let (master, path, slave) = open_pty()?;
    let stop = Arc::new(AtomicBool::new(false));
    let speed = if fast { FAST_FACTOR } else { 1.0 };
    let thread = {
        let stop = Arc::clone(&stop);
        std::thread::Builder::new()
            .name("host-rig".into())
            .spawn(move || serve(master, slave, rig, speed, &stop))
            .context("cannot start the host rig's thread")?
    };
    let pace = if fast {
        format!("{FAST_FACTOR}x real time")
    } else {
        "real time".into()
    };
    Ok(Endpoint {
        port: path.clone(),
        description: format!(
            "host rig: model_core::wire::device + the controller against the simulated plant, \
             on pseudo-terminal {path} ({pace})"
        ),
        kind: "host",
        qemu_note,
        running: Running::Host {
            stop,
            thread: Some(thread),
        },
    })
}

/// Serves the virtual rig on the pseudo-terminal's master side, `speed` device milliseconds
/// per wall millisecond, until `stop`. Unlike `bowl sim --pty` it keeps undelivered bytes
/// queued (up to a bound) instead of dropping them, because the demo's client is always there.
fn serve(
    mut master: PtyMaster,
    _slave: File,
    mut rig: VirtualRig,
    speed: f64,
    stop: &AtomicBool,
) -> Result<HostStats> {
    const MAX_QUEUE: usize = 1 << 20;
    let mut out = Vec::with_capacity(8192);
    let mut stats = HostStats::default();
    rig.boot(&mut out);
    let started = Instant::now();
    let mut inbuf = [0u8; 1024];
    while !stop.load(Ordering::Relaxed) {
        let wall_ms = started.elapsed().as_secs_f64() * 1000.0 * speed;
        let due_ms = u32::try_from(wall_ms as u64).unwrap_or(u32::MAX);
        // At most 50 device ms per pass, so reading and writing keep interleaving.
        let mut steps = 0;
        while rig.now_ms < due_ms && steps < 50 {
            // An error is WouldBlock (nothing sent) or EIO (no client right now).
            let received: &[u8] = match master.read(&mut inbuf) {
                Ok(n) => &inbuf[..n],
                Err(_) => &[],
            };
            rig.step_1ms(received, &mut out);
            steps += 1;
        }
        while !out.is_empty() {
            match master.write(&out) {
                Ok(0) => break,
                Ok(n) => {
                    out.drain(..n);
                }
                Err(_) => break,
            }
        }
        if out.len() > MAX_QUEUE {
            stats.bytes_dropped += out.len() as u64;
            out.clear();
        }
        if steps < 50 {
            std::thread::sleep(Duration::from_millis(1));
        }
    }
    stats.device_ms = rig.now_ms;
    Ok(stats)
}

/// The workspace root (host-tools' parent), where the firmware crate lives.
pub(super) fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|dir| dir.join(program).is_file()))
}

/// The cargo arguments that build the emulated board's image.
const QEMU_BUILD_ARGS: [&str; 11] = [
    "build",
    "--release",
    "-p",
    "firmware",
    "--no-default-features",
    "--features",
    "qemu",
    "--target",
    "thumbv7em-none-eabihf",
    "--bin",
    QEMU_RIG_BIN,
];

/// Builds the emulated board's image; returns the ELF path or why it cannot be had.
fn build_qemu_image() -> Result<PathBuf> {
    if !on_path("qemu-system-arm") {
        bail!("qemu-system-arm is not installed (`bash tests/run` installs it)");
    }
    let root = workspace_root();
    eprintln!(
        "building the emulated board's image ({QEMU_RIG_BIN}; the first build takes minutes)..."
    );
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut child = Command::new(cargo)
        .current_dir(&root)
        .args(QEMU_BUILD_ARGS)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .context("cannot run cargo to build the emulated board's image")?;
    // Cargo's progress lines are shown as they come (a first build takes minutes); the first
    // error is kept as the reason.
    let mut first_error = None;
    if let Some(stderr) = child.stderr.take() {
        for line in BufReader::new(stderr).lines().map_while(|l| l.ok()) {
            let trimmed = line.trim_start();
            if trimmed.starts_with("Compiling") || trimmed.starts_with("Finished") {
                eprintln!("  {trimmed}");
            } else if first_error.is_none() && trimmed.starts_with("error") {
                first_error = Some(trimmed.to_string());
            }
        }
    }
    let status = child.wait().context("waiting for cargo")?;
    if !status.success() {
        bail!(
            "the emulated board's image did not build ({}; to see why: cargo {})",
            first_error.as_deref().unwrap_or("unknown error"),
            QEMU_BUILD_ARGS.join(" ")
        );
    }
    let target_dir = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"));
    let elf = target_dir
        .join("thumbv7em-none-eabihf")
        .join("release")
        .join(QEMU_RIG_BIN);
    if !elf.is_file() {
        bail!("built, but no image at {}", elf.display());
    }
    Ok(elf)
}

fn start_qemu(fast: bool, seconds: f64) -> Result<Endpoint> {
    let elf = build_qemu_image()?;
    // The board ends its run by itself a little after the session (a safety net: we kill it).
    let run_s = (seconds * 1.5 + 60.0).ceil() as u64;
    // -icount: virtual time counts instructions (1 ns each, as in firmware/qemu-rig-run and the
    // QEMU tests). sleep=off lets an idle board's clock jump ahead (about 4x real time here);
    // sleep=on waits for the wall clock when idle (about 0.6x real time here: the busy parts
    // take longer than their 1 ns per instruction). shift=auto would track the wall clock, but
    // its varying instruction time trips the board's emulated watchdog.
    let icount = if fast {
        "shift=0,sleep=off"
    } else {
        "shift=0,sleep=on"
    };
    let mut child = Command::new("qemu-system-arm")
        .args([
            "-machine",
            "netduinoplus2",
            "-cpu",
            "cortex-m4",
            "-display",
            "none",
            "-monitor",
            "none",
            "-serial",
            "pty",
            "-semihosting-config",
            "enable=on,target=native",
            "-icount",
            icount,
            "-kernel",
        ])
        .arg(&elf)
        .args(["-append", &format!("seconds={run_s}")])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .context("cannot start qemu-system-arm")?;
    // QEMU names the pseudo-terminal ("char device redirected to /dev/pts/N (label serial0)")
    // on stdout, among the board's semihosting lines; older versions on stderr.
    let (tx, rx) = mpsc::channel();
    let stderr = child.stderr.take().ok_or_else(|| anyhow!("no stderr"))?;
    let tx_err = tx.clone();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(|l| l.ok()) {
            let _ = tx_err.send(line);
        }
    });
    let stdout = child.stdout.take().ok_or_else(|| anyhow!("no stdout"))?;
    let console = std::thread::spawn(move || {
        let mut keep = Vec::new();
        let mut reported = false;
        for line in BufReader::new(stdout).lines().map_while(|l| l.ok()) {
            if !reported && line.contains("redirected to ") {
                reported = true;
                let _ = tx.send(line);
                continue;
            }
            if keep.len() == 200 {
                keep.remove(0);
            }
            keep.push(line);
        }
        keep
    });
    let pty_of = |line: &str| {
        line.split("redirected to ")
            .nth(1)
            .and_then(|rest| rest.split_whitespace().next())
            .map(str::to_string)
    };
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut qemu_said = Vec::new();
    let mut found = None;
    while found.is_none() {
        let left = deadline.saturating_duration_since(Instant::now());
        match rx.recv_timeout(left) {
            Ok(line) => match pty_of(&line) {
                Some(p) => found = Some(p),
                None => qemu_said.push(line),
            },
            Err(_) => break,
        }
    }
    let Some(port) = found else {
        let _ = child.kill();
        let _ = child.wait();
        bail!(
            "qemu-system-arm did not report its serial pseudo-terminal{}",
            qemu_said
                .last()
                .map_or(String::new(), |l| format!(" (it said: {l})"))
        );
    };
    Ok(Endpoint {
        description: format!(
            "emulated board: firmware image {} on QEMU netduinoplus2 (Cortex-M4F), USART1 on {port}{}",
            elf.display(),
            if fast {
                " (virtual time, runs ahead when idle)"
            } else {
                ""
            }
        ),
        port,
        kind: "qemu",
        qemu_note: None,
        running: Running::Emulator {
            child,
            console: Some(console),
            control: None,
        },
    })
}

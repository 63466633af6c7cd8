//! Where the demo's rig runs. Either way the demo reaches it only through a serial device path
//! (a pseudo-terminal) speaking `model_core::wire`, exactly as it would reach a real board:
//!
//! - [`RigChoice::Host`]: the virtual rig of `bowl serve --pty` (the controller and the simulated
//!   plant behind `model_core::wire::device`), served on a pseudo-terminal from a thread of this
//!   process. Always available.
//! - [`RigChoice::Qemu`]: the firmware's emulated-board image (`qemu-rig`: the firmware's tasks and
//!   controller binding on an emulated Cortex-M4F with the plant in place of the motors), its
//!   USART1 on a pseudo-terminal. Needs `qemu-system-arm` and the thumb target.
//! - [`RigChoice::Blackpill`]: the exact Black Pill image on the emulated STM32F411
//!   (tests/blackpill, [`bowl_emulator::blackpill`]), USART2 on a pseudo-terminal.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;

use anyhow::{Context, Result, bail};
use bowl_emulator::qemu::{self, Profile, PtyBoard};
use bowl_emulator::{blackpill, image};

use virtual_rig::VirtualRig;
use virtual_rig::serve::{Backlog, LineNoise, Pacing, Pty, ServeStats, serve_on_pty};

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
    /// Device seconds per wall second: above 1 only for the host rig run fast (the emulated
    /// boards run at or below real time).
    pub device_per_wall: f64,
    running: Running,
}

enum Running {
    Host {
        stop: Arc<AtomicBool>,
        thread: Option<JoinHandle<Result<ServeStats>>>,
    },
    Qemu(PtyBoard),
    Blackpill(blackpill::PtyBoard),
}

/// What the endpoint reported when it was shut down.
#[derive(Debug, Default)]
pub struct Shutdown {
    /// Host rig counters.
    pub host: Option<ServeStats>,
    /// The emulated board's semihosting console (its last lines).
    pub console: Vec<String>,
}

impl Endpoint {
    /// Starts the chosen rig. `fast` runs it faster than real time.
    pub fn start(choice: RigChoice, fast: bool, seed: u32, seconds: f64) -> Result<Endpoint> {
        match choice {
            RigChoice::Host => start_host(fast, seed, None),
            RigChoice::Qemu => start_qemu(fast, seconds),
            RigChoice::Blackpill => start_blackpill(seconds),
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
            Running::Blackpill(board) => Some(move |what: &str| board.inject(what)),
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
                    None => ServeStats::default(),
                };
                Ok(Shutdown {
                    host: Some(stats),
                    console: Vec::new(),
                })
            }
            Running::Qemu(board) => Ok(Shutdown {
                host: None,
                console: board.stop(),
            }),
            Running::Blackpill(board) => Ok(Shutdown {
                host: None,
                console: board.stop(),
            }),
        }
    }
}

fn start_host(fast: bool, seed: u32, qemu_note: Option<String>) -> Result<Endpoint> {
    let rig = VirtualRig::new(seed)?;
    let pty = Pty::open()?;
    let path = pty.path.clone();
    let stop = Arc::new(AtomicBool::new(false));
    let speed = if fast { FAST_FACTOR } else { 1.0 };
    let thread = {
        let stop = Arc::clone(&stop);
        std::thread::Builder::new()
            .name("host-rig".into())
            .spawn(move || {
                let pacing = Pacing {
                    device_ms_per_wall_ms: speed,
                    stop: &stop,
                    stop_after: None,
                    // The demo's client is always there: keep what it has not read yet.
                    backlog: Backlog::KeepUpTo(1 << 20),
                };
                serve_on_pty(pty, rig, pacing, Vec::new(), LineNoise::none())
            })
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
            "host rig: the protocol device and the controller against the simulated plant, \
             on pseudo-terminal {path} ({pace})"
        ),
        kind: "host",
        qemu_note,
        device_per_wall: speed,
        running: Running::Host {
            stop,
            thread: Some(thread),
        },
    })
}

fn start_qemu(fast: bool, seconds: f64) -> Result<Endpoint> {
    if !qemu::installed() {
        bail!(
            "{} is not installed (`bash tests/run` installs it)",
            qemu::PROGRAM
        );
    }
    let elf = image::build(image::RIG_IMAGE)?;
    // The board ends its run by itself a little after the session (a safety net: we kill it).
    let run_s = (seconds * 1.5 + 60.0).ceil() as u64;
    let profile = if fast {
        Profile::VirtualTime
    } else {
        Profile::RealTime
    };
    let board = PtyBoard::boot(&elf, profile, &["-append", &format!("seconds={run_s}")])?;
    Ok(Endpoint {
        description: format!(
            "emulated board: firmware image {} on QEMU netduinoplus2 (Cortex-M4F), USART1 on {}{}",
            elf.display(),
            board.port,
            if fast {
                " (virtual time, runs ahead when idle)"
            } else {
                ""
            }
        ),
        port: board.port.clone(),
        kind: "qemu",
        qemu_note: None,
        // Virtual time may run ahead of the wall clock: counted as the host rig's fast pace.
        device_per_wall: if fast { FAST_FACTOR } else { 1.0 },
        running: Running::Qemu(board),
    })
}

fn start_blackpill(seconds: f64) -> Result<Endpoint> {
    // The board ends its run by itself a little after the session (a safety net: we stop it).
    let board = blackpill::PtyBoard::boot(seconds * 1.5 + 60.0)?;
    Ok(Endpoint {
        description: format!(
            "emulated Black Pill: image {} on an emulated STM32F411 (tests/blackpill), USART2 on \
             {}; defmt log in target/test-logs/blackpill-defmt.log",
            blackpill::image_path().display(),
            board.port
        ),
        port: board.port.clone(),
        kind: "blackpill",
        qemu_note: None,
        device_per_wall: 1.0,
        running: Running::Blackpill(board),
    })
}

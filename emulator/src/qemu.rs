//! QEMU, the one launcher: every `qemu-system-arm` the project starts is built by [`command`].
//! The board is netduinoplus2 (an STM32F405: the F411's Cortex-M4F, flash and RAM addresses),
//! output and exit status of test images come over semihosting, and virtual time counts
//! executed instructions (`-icount`) in one of three [`Profile`]s.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow, bail};

use crate::process::EmulatorProcess;
use crate::workspace;

/// The emulator's program.
pub const PROGRAM: &str = "qemu-system-arm";
/// The rig image's semihosting line once its link is up (firmware/src/bin/qemu-rig.rs).
const RIG_UP: &str = "qemu-rig: up";
/// How long the rig may take to commission itself on its plant at boot (about 0.5 s of CPU
/// time; a loaded 2-core machine takes several times that).
const RIG_UP_WITHIN: Duration = Duration::from_secs(60);

/// How the emulated board's clock relates to the instructions it runs and to the wall clock.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Profile {
    /// Exact instruction counting for the benchmarks (`-icount shift=7`): 128 ns of virtual time
    /// per instruction, so SysTick (at the 168 MHz core clock, about 21 ticks per instruction)
    /// resolves single instructions and a run repeats exactly on a loaded machine.
    InstructionCount,
    /// Virtual time for the rig (`-icount shift=0,sleep=off`): 1 ns per instruction, enough for
    /// the firmware's 1 kHz loop, and idle time skipped, so an idle board runs ahead of the wall
    /// clock (about 4x here). Exact and repeatable: the end-to-end tests bound device time only.
    VirtualTime,
    /// Real time for people watching (`-icount shift=0,sleep=on`): as `virtual-time`, but an idle
    /// board waits for the wall clock (about 0.6x real time here: busy stretches take longer
    /// than their 1 ns per instruction). `shift=auto` would track the wall clock, but its varying
    /// instruction time trips the board's emulated watchdog.
    RealTime,
}

impl Profile {
    /// The `-icount` option's value.
    pub fn icount(self) -> &'static str {
        match self {
            Profile::InstructionCount => "shift=7",
            Profile::VirtualTime => "shift=0,sleep=off",
            Profile::RealTime => "shift=0,sleep=on",
        }
    }
}

/// Where the board's USART1 goes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Serial {
    /// Nowhere (benchmarks: everything comes over semihosting).
    None,
    /// A new pseudo-terminal; QEMU names it on its output ("char device redirected to ...").
    Pty,
    /// A Unix socket QEMU listens on and waits for before starting the board, so no byte is lost.
    Socket(std::path::PathBuf),
}

/// Whether QEMU is installed.
pub fn installed() -> bool {
    workspace::on_path(PROGRAM)
}

/// The one QEMU command line: `elf` on netduinoplus2 with `profile`'s clock and USART1 on
/// `serial`; semihosting on (the console is QEMU's stdout). Callers add `-append ...` (the image's
/// arguments) and choose stdio.
pub fn command(elf: &Path, profile: Profile, serial: &Serial) -> Command {
    let mut cmd = Command::new(PROGRAM);
    cmd.args(["-machine", "netduinoplus2", "-cpu", "cortex-m4"])
        .args(["-nographic", "-monitor", "none"])
        .args(["-semihosting-config", "enable=on,target=native"])
        .args(["-icount", profile.icount()]);
    match serial {
        Serial::None => {
            cmd.args(["-serial", "none"]);
        }
        Serial::Pty => {
            cmd.args(["-serial", "pty"]);
        }
        Serial::Socket(path) => {
            cmd.arg("-chardev")
                .arg(format!(
                    "socket,id=usart1,path={},server=on,wait=on",
                    path.display()
                ))
                .args(["-serial", "chardev:usart1"]);
        }
    }
    cmd.arg("-kernel").arg(elf);
    cmd
}

/// A board running with its USART1 on a pseudo-terminal (the demo's emulated rig).
pub struct PtyBoard {
    /// The serial device to open.
    pub port: String,
    process: EmulatorProcess,
}

impl PtyBoard {
    /// Boots the rig image `elf` with `extra` QEMU arguments, waits (10 s at most) for QEMU to
    /// name the pseudo-terminal, then for the rig to say it is up. The semihosting console's last 200 lines are kept for [`Self::stop`].
    pub fn boot(elf: &Path, profile: Profile, extra: &[&str]) -> Result<PtyBoard> {
        if !installed() {
            bail!("{PROGRAM} is not installed (`bash tests/run` installs it)");
        }
        let mut child = command(elf, profile, &Serial::Pty)
            .args(extra)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .with_context(|| format!("cannot start {PROGRAM}"))?;
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
        let process = EmulatorProcess::watch(
            child,
            stdout,
            |l| pty_named_in(l).is_some() || l.starts_with(RIG_UP),
            tx.clone(),
        );
        let deadline = Instant::now() + Duration::from_secs(10);
        let mut qemu_said = Vec::new();
        let mut found = None;
        while found.is_none() {
            let left = deadline.saturating_duration_since(Instant::now());
            match rx.recv_timeout(left) {
                Ok(line) => match pty_named_in(&line) {
                    Some(p) => found = Some(p),
                    None => qemu_said.push(line),
                },
                Err(_) => break,
            }
        }
        let Some(port) = found else {
            drop(process);
            bail!(
                "{PROGRAM} did not report its serial pseudo-terminal{}",
                qemu_said
                    .last()
                    .map_or(String::new(), |l| format!(" (it said: {l})"))
            );
        };
        // The rig commissions itself on its plant before its link comes up: wait for that.
        let deadline = Instant::now() + RIG_UP_WITHIN;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match rx.recv_timeout(left) {
                Ok(line) if line.starts_with(RIG_UP) => break,
                Ok(_) => {}
                Err(_) => {
                    drop(process);
                    bail!(
                        "the emulated board did not come up within {} s (no `{RIG_UP}` line)",
                        RIG_UP_WITHIN.as_secs()
                    );
                }
            }
        }
        Ok(PtyBoard { port, process })
    }

    /// Stops the board; returns the last lines of its semihosting console.
    pub fn stop(self) -> Vec<String> {
        self.process.stop()
    }
}

/// The device path in QEMU's "char device redirected to /dev/pts/N (label serial0)".
fn pty_named_in(line: &str) -> Option<String> {
    line.split("redirected to ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .map(str::to_string)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_pty_qemu_names() {
        assert_eq!(
            pty_named_in("char device redirected to /dev/pts/7 (label serial0)").as_deref(),
            Some("/dev/pts/7")
        );
        assert_eq!(pty_named_in("plant t_ms=0"), None);
    }

    #[test]
    fn one_command_line_per_profile_and_link() {
        let args = |p, s| -> Vec<String> {
            command(Path::new("img"), p, &s)
                .get_args()
                .map(|a| a.to_string_lossy().into_owned())
                .collect()
        };
        let bench = args(Profile::InstructionCount, Serial::None);
        assert_eq!(
            bench.join(" "),
            "-machine netduinoplus2 -cpu cortex-m4 -nographic -monitor none \
             -semihosting-config enable=on,target=native -icount shift=7 -serial none -kernel img"
        );
        let rig = args(Profile::VirtualTime, Serial::Socket("/tmp/s".into()));
        assert!(
            rig.windows(2)
                .any(|w| w == ["-icount", "shift=0,sleep=off"])
        );
        assert!(
            rig.windows(2)
                .any(|w| w == ["-chardev", "socket,id=usart1,path=/tmp/s,server=on,wait=on"])
        );
        let live = args(Profile::RealTime, Serial::Pty);
        assert!(
            live.windows(2)
                .any(|w| w == ["-icount", "shift=0,sleep=on"])
        );
        assert!(live.windows(2).any(|w| w == ["-serial", "pty"]));
    }
}

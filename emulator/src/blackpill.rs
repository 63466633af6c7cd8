//! The second emulator: the exact Black Pill image (`cargo fw`) on an
//! emulated STM32F411, run by `tests/blackpill/run_board.py` (qiling with the project's
//! peripheral models, the simulated plant through `tests/blackpill/plant-ffi`). USART2 is served
//! on a pseudo-terminal. The emulator's Python environment, the thumb target and flip-link are
//! installed by the one installer `bash tests/run` uses too (`ensure_blackpill_emulator` and
//! friends in tests/lib/ensure-tools.sh): [`install`] runs it when the board is booted, so a
//! fresh clone's `bowl demo --rig blackpill` sets itself up, with progress.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{ChildStdin, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use anyhow::{Context, Result, anyhow, bail};

use crate::process::EmulatorProcess;
use crate::workspace;

/// The Black Pill image: the release build of the firmware's board binary.
pub fn image_path() -> PathBuf {
    workspace::target_dir().join("thumbv7em-none-eabihf/firmware/firmware")
}

/// The emulator's Python interpreter (its virtual environment under the target directory).
pub fn python() -> PathBuf {
    workspace::root().join("target/venv-blackpill/bin/python")
}

/// The shared installer's steps the emulated board needs, as `bash tests/run` runs them.
const INSTALL_STEPS: &str = "source tests/lib/ensure-tools.sh && ensure_thumb_target && \
                             ensure_flip_link && ensure_blackpill_emulator";

/// Installs what the emulated board needs and a fresh machine lacks (the thumb target,
/// flip-link, the emulator's venv with its pinned qiling and unicorn, defmt-print), through the
/// installer `bash tests/run` uses; quiet and quick when everything is there. Progress is shown
/// (pip's own lines): the first install downloads and builds for a few minutes.
pub fn install() -> Result<()> {
    let fresh = !python().is_file();
    if fresh {
        eprintln!(
            "the Black Pill emulator is not installed yet: installing it into {} (python3 venv, \
             pinned qiling and unicorn from PyPI; a few minutes, once)",
            python()
                .parent()
                .and_then(Path::parent)
                .unwrap_or(Path::new(""))
                .display()
        );
    }
    let status = Command::new("bash")
        .current_dir(workspace::root())
        .args(["-c", INSTALL_STEPS])
        // pip shows what it collects and builds: the progress of the long first install.
        .env("ENSURE_VERBOSE", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::inherit())
        .stderr(Stdio::inherit())
        .status()
        .context("cannot run bash for the emulator's installer (tests/lib/ensure-tools.sh)")?;
    if !status.success() || !python().is_file() {
        bail!(
            "installing the Black Pill emulator failed (tests/lib/ensure-tools.sh, output above): \
             it needs python3 with venv and pip and access to PyPI; fix that and run again, or run \
             the demo on the host (--rig host)"
        );
    }
    if fresh {
        eprintln!(
            "the Black Pill emulator is installed: {}",
            python().display()
        );
    }
    Ok(())
}

/// Builds what the emulated board needs: the image and the plant library.
pub fn build() -> Result<()> {
    for args in [
        &[
            "build",
            "--profile",
            "firmware",
            "-p",
            "firmware",
            "--target",
            "thumbv7em-none-eabihf",
        ][..],
        &["build", "-p", "plant-ffi"][..],
    ] {
        eprintln!("building: cargo {}", args.join(" "));
        let status = Command::new(workspace::cargo())
            .current_dir(workspace::root())
            .args(args)
            .stdin(Stdio::null())
            .status()
            .context("cannot run cargo")?;
        if !status.success() {
            bail!("`cargo {}` failed", args.join(" "));
        }
    }
    Ok(())
}

/// `defmt-print`: `DEFMT_PRINT`, else the copy `bash tests/run` installs, else the path's.
fn defmt_print(root: &Path) -> String {
    if let Some(p) = std::env::var_os("DEFMT_PRINT") {
        return p.to_string_lossy().into_owned();
    }
    let local = root.join("target/defmt-tools/bin/defmt-print");
    if local.is_file() {
        local.to_string_lossy().into_owned()
    } else {
        "defmt-print".into()
    }
}

/// A running emulated Black Pill with its USART2 on a pseudo-terminal.
pub struct PtyBoard {
    /// The serial device to open.
    pub port: String,
    process: EmulatorProcess,
    control: Option<ChildStdin>,
}

/// How `run_board.py` names its pseudo-terminal on its first output line of that kind.
const PTY_PREFIX: &str = "pty: ";

impl PtyBoard {
    /// Builds the image and boots it for `seconds` of device time at most (a safety net: the
    /// caller stops it sooner). Waits 60 s at most for the pseudo-terminal.
    pub fn boot(seconds: f64) -> Result<PtyBoard> {
        let root = workspace::root();
        install()?;
        let python = python();
        build()?;
        let mut child = Command::new(&python)
            .current_dir(&root)
            .arg("tests/blackpill/run_board.py")
            // What `build` made, wherever cargo put it (CARGO_TARGET_DIR too).
            .arg("--elf")
            .arg(image_path())
            .arg("--plant-lib")
            .arg(workspace::target_dir().join("debug/libplant_ffi.so"))
            .args(["--seconds", &seconds.ceil().to_string()])
            .args(["--defmt-print", &defmt_print(&root)])
            .arg("--control-stdin")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .context("cannot start the Black Pill emulator")?;
        let control = child.stdin.take();
        let stdout = child.stdout.take().ok_or_else(|| anyhow!("no stdout"))?;
        let (tx, rx) = mpsc::channel();
        let process = EmulatorProcess::watch(child, stdout, |l| l.starts_with(PTY_PREFIX), tx);
        let Ok(line) = rx.recv_timeout(Duration::from_secs(60)) else {
            drop(process);
            bail!("the Black Pill emulator did not report its pseudo-terminal within 60 s");
        };
        Ok(PtyBoard {
            port: line[PTY_PREFIX.len()..].to_string(),
            process,
            control,
        })
    }

    /// Injects a fault into the emulated world (`WHAT` as `run_board.py` takes it): the Black
    /// Pill image refuses the protocol's INJECT, so faults come from outside, as on a real rig.
    pub fn inject(&mut self, what: &str) -> Result<()> {
        let stdin = self
            .control
            .as_mut()
            .ok_or_else(|| anyhow!("the emulator's control input is closed"))?;
        writeln!(stdin, "inject {what}")
            .and_then(|()| stdin.flush())
            .context("the emulator's control input is closed")
    }

    /// Waits for the board to end its run by itself; its exit status.
    pub fn wait(&mut self) -> Result<std::process::ExitStatus> {
        self.process
            .child
            .wait()
            .context("waiting for the Black Pill emulator")
    }

    /// Stops the board; returns the last lines of its console.
    pub fn stop(self) -> Vec<String> {
        self.process.stop()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The installer the board runs is the shared one, and every step it names is defined there
    /// (a renamed step would otherwise surface only on a fresh clone).
    #[test]
    fn the_install_steps_are_the_shared_installers() {
        let script =
            std::fs::read_to_string(workspace::root().join("tests/lib/ensure-tools.sh")).unwrap();
        assert!(INSTALL_STEPS.starts_with("source tests/lib/ensure-tools.sh"));
        for step in INSTALL_STEPS.split("&&").skip(1) {
            let name = step.trim();
            assert!(
                script.contains(&format!("{name}() {{")),
                "{name} not in ensure-tools.sh"
            );
        }
        let run = std::fs::read_to_string(workspace::root().join("tests/run")).unwrap();
        assert!(
            run.contains("ensure_blackpill_emulator"),
            "tests/run uses the same installer"
        );
    }
}

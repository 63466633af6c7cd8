//! The demo's rig on the emulated STM32F411: the exact Black Pill image (`cargo fw`) run by
//! tests/blackpill/run_board.py (qiling, the project's peripheral models and plant), USART2 on
//! a pseudo-terminal. The emulator's Python environment is made by `bash tests/run`
//! (`ensure_blackpill_emulator` in tests/lib/ensure-tools.sh).

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use anyhow::{Context, Result, anyhow, bail};

use super::endpoint::{Endpoint, Running, workspace_root};

/// Builds what the emulated board needs: the image and the plant library.
fn build() -> Result<()> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    for args in [
        &[
            "build",
            "--release",
            "-p",
            "firmware",
            "--target",
            "thumbv7em-none-eabihf",
        ][..],
        &["build", "-p", "plant-ffi"][..],
    ] {
        eprintln!("building: cargo {}", args.join(" "));
        let status = Command::new(&cargo)
            .current_dir(workspace_root())
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

fn defmt_print(root: &std::path::Path) -> String {
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

/// Starts the emulated Black Pill for a session of `seconds`.
pub fn start(seconds: f64) -> Result<Endpoint> {
    let root = workspace_root();
    let python: PathBuf = root.join("target/venv-blackpill/bin/python");
    if !python.is_file() {
        bail!(
            "the Black Pill emulator is not installed ({} is missing): run `bash tests/run` once, \
             which installs it",
            python.display()
        );
    }
    build()?;
    // The board ends its run by itself a little after the session (a safety net: we kill it).
    let run_s = (seconds * 1.5 + 60.0).ceil();
    let mut child = Command::new(&python)
        .current_dir(&root)
        .arg("tests/blackpill/run_board.py")
        .args(["--seconds", &run_s.to_string()])
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
    let console = std::thread::spawn(move || {
        let mut keep = Vec::new();
        for line in BufReader::new(stdout).lines().map_while(|l| l.ok()) {
            if let Some(pty) = line.strip_prefix("pty: ") {
                let _ = tx.send(pty.to_string());
            } else {
                keep.push(line);
            }
        }
        keep
    });
    let Ok(port) = rx.recv_timeout(Duration::from_secs(60)) else {
        let _ = child.kill();
        let _ = child.wait();
        bail!("the Black Pill emulator did not report its pseudo-terminal within 60 s");
    };
    Ok(Endpoint {
        description: format!(
            "emulated Black Pill: image target/thumbv7em-none-eabihf/release/firmware on an \
             emulated STM32F411 (tests/blackpill), USART2 on {port}; defmt log in \
             target/test-logs/blackpill-defmt.log"
        ),
        port,
        kind: "blackpill",
        qemu_note: None,
        running: Running::Emulator {
            child,
            console: Some(console),
            control,
        },
    })
}

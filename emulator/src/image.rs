//! Building what runs on and around an emulated board: the firmware's emulator images (the
//! `qemu-*` binaries of the firmware crate, release profile, feature `qemu`) and the `bowl`
//! command the tests drive them with.

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Command, Stdio};

use anyhow::{Context, Result, bail};

use crate::workspace;

/// The firmware image that runs the rig (the firmware's tasks and controller binding with the
/// simulated plant in place of the motors) on the emulated board.
pub const RIG_IMAGE: &str = "qemu-rig";

/// The cargo arguments that build the firmware's emulator image `image`.
pub fn build_args(image: &str) -> [&str; 11] {
    [
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
        image,
    ]
}

/// Builds the firmware's emulator image `image` (e.g. [`RIG_IMAGE`]) and returns its ELF path.
/// Cargo's progress lines are shown on stderr as they come (a first build takes minutes); if the
/// build fails, the error names cargo's first error and the command that shows the rest.
pub fn build(image: &str) -> Result<PathBuf> {
    let args = build_args(image);
    eprintln!("building the emulated board's image {image} (the first build takes minutes)...");
    let mut child = Command::new(workspace::cargo())
        .current_dir(workspace::root())
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .context("cannot run cargo to build the emulated board's image")?;
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
            "the emulated board's image did not build ({image}: {}; to see why: cargo {})",
            first_error.as_deref().unwrap_or("unknown error"),
            args.join(" ")
        );
    }
    let elf = workspace::target_dir()
        .join("thumbv7em-none-eabihf")
        .join("release")
        .join(image);
    if !elf.is_file() {
        bail!("built, but no image at {}", elf.display());
    }
    Ok(elf)
}

/// Builds the `bowl` command (host-tools, debug profile) and returns its path.
pub fn build_bowl() -> Result<PathBuf> {
    let status = Command::new(workspace::cargo())
        .current_dir(workspace::root())
        .args(["build", "-p", "host-tools", "--bin", "bowl"])
        .status()
        .context("cannot run cargo to build bowl")?;
    if !status.success() {
        bail!("building bowl failed (cargo build -p host-tools --bin bowl)");
    }
    Ok(workspace::target_dir().join("debug/bowl"))
}

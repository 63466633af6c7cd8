//! `bowl-emulator`: builds the firmware's emulator images and runs an image on an emulator, the
//! one way the project starts one (scripts and the thumb runner call this command).
//!
//!   bowl-emulator build qemu-rig
//!   bowl-emulator run --profile instruction-count ELF            (what tests/qemu-run does)
//!   bowl-emulator run --image qemu-rig --serial pty -- -append seconds=30
//!   bowl-emulator run --emulator blackpill --timeout-s 60       (the Black Pill image, USART2 on a pty)

use std::path::PathBuf;
use std::process::{ExitCode, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use bowl_emulator::qemu::{self, Profile, Serial};
use bowl_emulator::{Emulator, blackpill, image};
use clap::{Parser, Subcommand, ValueEnum};

/// Builds the firmware's emulator images and runs them on an emulator.
#[derive(Parser)]
#[command(name = "bowl-emulator", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Build a firmware emulator image (release, feature qemu) and print its path.
    Build {
        /// The image, a `qemu-*` binary of the firmware crate (e.g. qemu-rig).
        image: String,
    },
    /// Run an image; the board's console is this command's output and its exit status ours.
    Run(RunArgs),
}

#[derive(clap::Args)]
struct RunArgs {
    /// The ELF to run (QEMU; the Black Pill emulator always runs the board image it builds).
    #[arg(conflicts_with = "image")]
    elf: Option<PathBuf>,
    /// Build this firmware emulator image first and run it (e.g. qemu-rig).
    #[arg(long)]
    image: Option<String>,
    /// The emulator.
    #[arg(long, value_enum, default_value_t = Emulator::Qemu)]
    emulator: Emulator,
    /// How the board's clock runs.
    #[arg(long, value_enum, default_value_t = Profile::InstructionCount)]
    profile: Profile,
    /// Where the board's USART1 goes (with pty, QEMU prints the device's path).
    #[arg(long, value_enum, default_value_t = SerialChoice::None)]
    serial: SerialChoice,
    /// Kill the emulator after this many seconds of wall time (0: never).
    #[arg(long, default_value_t = 0)]
    timeout_s: u64,
    /// Further arguments for the emulator (e.g. `-append seconds=30`, the image's arguments).
    #[arg(last = true)]
    extra: Vec<String>,
}

#[derive(Clone, Copy, ValueEnum)]
enum SerialChoice {
    /// Not connected.
    None,
    /// A new pseudo-terminal.
    Pty,
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("bowl-emulator: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn run(cli: Cli) -> Result<ExitCode> {
    match cli.command {
        Cmd::Build { image } => {
            println!("{}", image::build(&image)?.display());
            Ok(ExitCode::SUCCESS)
        }
        Cmd::Run(args) => match args.emulator {
            Emulator::Qemu => {
                let elf = match (&args.elf, &args.image) {
                    (Some(elf), _) => elf.clone(),
                    (None, Some(image)) => image::build(image)?,
                    (None, None) => bail!("name an ELF or an --image to build"),
                };
                run_qemu(&elf, &args)
            }
            Emulator::Blackpill => run_blackpill(&args),
        },
    }
}

fn run_qemu(elf: &std::path::Path, args: &RunArgs) -> Result<ExitCode> {
    if !qemu::installed() {
        bail!(
            "{} is not installed (`bash tests/run` installs it)",
            qemu::PROGRAM
        );
    }
    let serial = match args.serial {
        SerialChoice::None => Serial::None,
        SerialChoice::Pty => Serial::Pty,
    };
    let mut child = qemu::command(elf, args.profile, &serial)
        .args(&args.extra)
        .stdin(Stdio::null())
        .spawn()
        .with_context(|| format!("cannot start {}", qemu::PROGRAM))?;
    let deadline =
        (args.timeout_s > 0).then(|| Instant::now() + Duration::from_secs(args.timeout_s));
    loop {
        if let Some(status) = child.try_wait().context("waiting for the emulator")? {
            // A board that exits through semihosting with status N: we exit N too.
            let code = status.code().unwrap_or(1);
            return Ok(ExitCode::from(u8::try_from(code).unwrap_or(1)));
        }
        if deadline.is_some_and(|d| Instant::now() >= d) {
            let _ = child.kill();
            let _ = child.wait();
            bail!(
                "{} ran longer than --timeout-s {} and was stopped (a hung image?)",
                elf.display(),
                args.timeout_s
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn run_blackpill(args: &RunArgs) -> Result<ExitCode> {
    if args.elf.is_some() || args.image.is_some() {
        bail!(
            "the Black Pill emulator runs the board image it builds itself ({}): drop the ELF / \
             --image",
            blackpill::image_path().display()
        );
    }
    let seconds = if args.timeout_s > 0 {
        args.timeout_s as f64
    } else {
        3600.0
    };
    let mut board = blackpill::PtyBoard::boot(seconds)?;
    println!("pty: {}", board.port);
    let status = board.wait()?;
    Ok(ExitCode::from(
        u8::try_from(status.code().unwrap_or(1)).unwrap_or(1),
    ))
}

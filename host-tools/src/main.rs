//! `bowl`: the PC side of the bowl granulation rig.

use anyhow::Result;
use clap::{Parser, Subcommand};

mod kinematics;
mod monitor;
mod replay;
mod rig_binding;
mod send;
mod serial;
mod telemetry_csv;
mod virtual_rig;

/// The PC side of the bowl granulation rig.
#[derive(Parser)]
#[command(name = "bowl", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Combined bowl speed from the two motor speeds (paper Eq. 2), or the split of a target speed.
    Kinematics(kinematics::Args),
    /// Live view of the rig's telemetry, with CSV log and frame counters.
    Monitor(monitor::Args),
    /// Send one command to the rig and print its answer.
    Send(send::Args),
    /// Decode a raw capture of the rig's output; print statistics as JSON.
    Replay(replay::Args),
    /// The virtual rig: on a pseudo-terminal (--pty) or into a capture file (--capture).
    Sim(virtual_rig::Args),
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Kinematics(args) => kinematics::run(&args),
        Command::Monitor(args) => monitor::run(&args),
        Command::Send(args) => send::run(&args).map(|code| std::process::exit(code)),
        Command::Replay(args) => replay::run(&args),
        Command::Sim(args) => virtual_rig::run(&args),
    }
}

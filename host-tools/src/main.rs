//! `bowl`: the PC side of the bowl granulation rig.

use anyhow::Result;
use clap::{Parser, Subcommand};

mod kinematics;
mod predict;
mod sim;

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
    /// Residence time and exit velocities of a particle (paper Eq. 5-12, corrected), or a batch CSV.
    Predict(predict::Args),
    /// The controller against the simulated rig: step, family, commission, sweep, stability.
    Sim(sim::Args),
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Kinematics(args) => kinematics::run(&args),
        Command::Predict(args) => predict::run(&args),
        Command::Sim(args) => sim::run(&args),
    }
}

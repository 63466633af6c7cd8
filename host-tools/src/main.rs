//! `bowl`: the PC side of the bowl granulation rig.

use anyhow::Result;
use clap::{Parser, Subcommand};

mod chart;
mod kinematics;
mod predict;

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
    /// Charts: work-precision (error against cost), and the paper's Figures 5-7 redrawn.
    Chart(chart::Args),
    /// Residence time and exit velocities of a particle (paper Eq. 5-12, corrected), or a batch CSV.
    Predict(predict::Args),
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Kinematics(args) => kinematics::run(&args),
        Command::Chart(args) => chart::run(&args),
        Command::Predict(args) => predict::run(&args),
    }
}

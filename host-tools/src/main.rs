//! `bowl`: the PC side of the bowl granulation rig.

use anyhow::Result;
use clap::{Parser, Subcommand};

mod chart;
mod commission;
mod demo;
mod experiment;
mod fit;
mod kinematics;
mod monitor;
mod predict;
mod replay;
mod send;
mod serial;
mod sim;
mod simulated_backend;
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
    /// Charts: work-precision (error against cost), and the paper's Figures 5-7 redrawn.
    Chart(chart::Args),
    /// Residence time and exit velocities of a particle (paper Eq. 5-12, corrected), or a batch CSV.
    Predict(predict::Args),
    /// Live view of the rig's telemetry, with CSV log and frame counters.
    Monitor(monitor::Args),
    /// Send one command to the rig and print its answer.
    Send(send::Args),
    /// Run the motor identification on the rig; print the identified models and gains.
    Commission(commission::Args),
    /// Decode a raw capture of the rig's output; print statistics as JSON.
    Replay(replay::Args),
    /// The simulated rig: serve it on a pseudo-terminal (--pty) or capture its bytes (--capture),
    /// or report on the controller against it (step, family, commission, sweep, stability, trace).
    Sim(SimCommand),
    /// The rig without hardware: a simulated rig, a scripted session, the live view, a summary.
    Demo(demo::Args),
    /// Run a plan of particle releases on a simulated rig and record residence times, or
    /// suggest a plan (--suggest).
    Experiment(experiment::Args),
    /// Fit the rolling resistance of each particle model to measured residence times.
    Fit(fit::Args),
}

/// `bowl sim`: either a report subcommand or the virtual rig's flags.
#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true)]
struct SimCommand {
    #[command(subcommand)]
    report: Option<sim::What>,
    #[command(flatten)]
    rig: virtual_rig::Args,
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Kinematics(args) => kinematics::run(&args),
        Command::Chart(args) => chart::run(&args),
        Command::Predict(args) => predict::run(&args),
        Command::Monitor(args) => monitor::run(&args),
        Command::Send(args) => send::run(&args).map(|code| std::process::exit(code)),
        Command::Commission(args) => commission::run(&args).map(|code| std::process::exit(code)),
        Command::Replay(args) => replay::run(&args),
        Command::Demo(args) => demo::run(&args),
        Command::Experiment(args) => experiment::run(&args),
        Command::Fit(args) => fit::run(&args),
        Command::Sim(args) => match &args.report {
            Some(report) => sim::run(report),
            None => virtual_rig::run(&args.rig),
        },
    }
}

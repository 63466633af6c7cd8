//! `bowl`: the PC side of the bowl granulation rig.

use anyhow::Result;
use clap::{Parser, Subcommand};

mod chart;
mod commission;
#[cfg(unix)]
mod demo;
mod exit_code;
mod kinematics;
mod link;
mod monitor;
mod predict;
mod relay;
mod replay;
mod send;
mod serial;
mod serve;
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
    /// The serial ports on this computer, with their USB descriptions.
    Ports,
    /// Send one command to the rig and print its answer.
    Send(send::Args),
    /// Run the motor identification on the rig; print the identified models and gains.
    Commission(commission::Args),
    /// Decode a raw capture of the rig's output; print statistics as JSON.
    Replay(replay::Args),
    /// A virtual rig (no hardware): serve it on a pseudo-terminal (--pty) or write its bytes to a
    /// file (--capture).
    Serve(serve::Args),
    /// Reports on the controller against the simulated plant (step, family, commission, sweep,
    /// stability, trace).
    #[command(subcommand)]
    Sim(sim::What),
    #[cfg(unix)]
    /// The rig without hardware: a simulated rig, a scripted session, the live view, a summary.
    Demo(demo::Args),
}

fn main() {
    let cli = Cli::parse();
    if let Err(e) = run(cli) {
        eprintln!("error: {e:#}");
        let link = e.chain().any(|c| c.is::<serial::LinkError>());
        std::process::exit(if link {
            exit_code::LINK
        } else {
            exit_code::REFUSED
        });
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Kinematics(args) => kinematics::run(&args),
        Command::Chart(args) => chart::run(&args),
        Command::Predict(args) => predict::run(&args),
        Command::Monitor(args) => monitor::run(&args),
        Command::Ports => serial::run_ports(),
        Command::Send(args) => send::run(&args).map(|code| std::process::exit(code)),
        Command::Commission(args) => commission::run(&args).map(|code| std::process::exit(code)),
        Command::Replay(args) => replay::run(&args),
        #[cfg(unix)]
        Command::Demo(args) => demo::run(&args),
        Command::Serve(args) => serve::run(&args),
        Command::Sim(report) => sim::run(&report),
    }
}

//! `bowl`: the PC side of the bowl granulation rig.

use std::ffi::OsString;
use std::process::ExitCode;

use anyhow::Result;
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

mod cmd;
#[cfg(unix)]
mod demo;
mod exit_code;
mod interrupt;
mod monitor;

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
    Kinematics(cmd::kinematics::Args),
    /// Charts: work-precision (error against cost), and the paper's Figures 5-7 redrawn.
    Chart(cmd::chart::Args),
    /// Residence time and exit velocities of a particle (paper Eq. 5-12, corrected), or a batch CSV.
    Predict(Box<cmd::predict::Args>),
    /// Live view of the rig's telemetry, with CSV log and frame counters.
    Monitor(monitor::Args),
    /// The serial ports on this computer, with their USB descriptions.
    Ports,
    /// Send one command to the rig and print its answer.
    Send(cmd::send::Args),
    /// Run the motor identification on the rig; print the identified models and gains.
    Commission(cmd::commission::Args),
    /// Decode a raw capture of the rig's output; print statistics as JSON.
    Replay(cmd::replay::Args),
    /// A virtual rig (no hardware): serve it on a pseudo-terminal (--pty) or write its bytes to a
    /// file (--capture).
    Serve(cmd::serve::Args),
    /// Reports on the controller against the simulated plant (step, family, commission, sweep,
    /// stability, trace).
    #[command(subcommand)]
    Sim(cmd::sim::What),
    #[cfg(unix)]
    /// The rig without hardware: a simulated rig, a scripted session, the live view, a summary.
    Demo(demo::Args),
    /// Run a plan of particle releases on a simulated rig and record residence times, or
    /// suggest a plan (--suggest).
    Experiment(cmd::experiment::Args),
    /// Fit the rolling resistance of each particle model to measured residence times.
    Fit(cmd::fit::Args),
}

fn main() -> ExitCode {
    restore_default_sigpipe();
    let cli = match negative_numbers(Cli::command())
        .try_get_matches_from(negative_values_joined(std::env::args_os()))
        .and_then(|m| Cli::from_arg_matches(&m))
    {
        Ok(cli) => cli,
        Err(e) => {
            // --help and --version end here too, on standard output and with success.
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() {
                exit_code::USAGE as u8
            } else {
                exit_code::OK as u8
            });
        }
    };
    let code = match run(cli) {
        Ok(code) => code,
        Err(e) if exit_code::is_closed_output(&e) => exit_code::OK,
        Err(e) => {
            eprintln!("error: {e:#}");
            if e.chain().any(|c| c.is::<exit_code::Usage>()) {
                exit_code::USAGE
            } else if e.chain().any(|c| c.is::<rig_client::serial::LinkError>()) {
                exit_code::LINK
            } else {
                exit_code::REFUSED
            }
        }
    };
    ExitCode::from(u8::try_from(code).unwrap_or(1))
}

/// Every command takes negative numbers as values (`--omega-rad-s -3`, `--spin-rad-s -2.7`):
/// each command then judges the value in words by its own limits, instead of clap taking it for
/// an unknown flag.
fn negative_numbers(command: clap::Command) -> clap::Command {
    let command = command.allow_negative_numbers(true);
    let names: Vec<String> = command
        .get_subcommands()
        .map(|s| s.get_name().to_string())
        .collect();
    names
        .iter()
        .fold(command, |c, name| c.mut_subcommand(name, negative_numbers))
}

/// A negative value clap would read as short flags, joined to its flag: clap takes `-3`, `-0.5`
/// and `-2.5e3` after a flag as values, but not `-2.5e-3`, `-.5` or `-inf` (its negative numbers
/// have no sign in the exponent and a digit first): `--spin-rad-s -1e-3` said "unexpected
/// argument '-1' found". Such a value after a `--flag` becomes `--flag=VALUE`, and the flag's own
/// parser judges it in words. Values clap already takes are left as they are.
fn negative_values_joined(args: impl IntoIterator<Item = OsString>) -> Vec<OsString> {
    let mut out: Vec<OsString> = Vec::new();
    for arg in args {
        let flag = out
            .last()
            .and_then(|p| p.to_str())
            .filter(|p| p.len() > 2 && p.starts_with("--") && !p.contains('='));
        if let (Some(flag), Some(value)) = (flag, arg.to_str())
            && value.starts_with('-')
            && !value.starts_with("--")
            && value.split(',').all(|v| v.trim().parse::<f64>().is_ok())
            && !value.split(',').all(clap_takes_as_number)
        {
            let joined = format!("{flag}={value}");
            *out.last_mut().expect("a flag was seen") = joined.into();
        } else {
            out.push(arg);
        }
    }
    out
}

/// Whether clap reads `text` as a number, not as flags: a `-`, then digits with at most one `.`
/// (not first) and at most one `e` followed by digits only (clap_lex's `is_number`).
fn clap_takes_as_number(text: &str) -> bool {
    let Some(rest) = text.strip_prefix('-') else {
        return true;
    };
    let (mantissa, exponent) = match rest.split_once(['e', 'E']) {
        Some((m, e)) => (m, Some(e)),
        None => (rest, None),
    };
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    let mantissa_ok = match mantissa.split_once('.') {
        Some((whole, frac)) => digits(whole) && (frac.is_empty() || digits(frac)),
        None => digits(mantissa),
    };
    mantissa_ok && exponent.is_none_or(digits)
}

/// `bowl ... | head`: when the reader goes away, end quietly the way Unix tools do (the default
/// action of SIGPIPE), instead of failing on the next write to standard output. Logs are flushed
/// as they are written, so nothing already received is lost.
fn restore_default_sigpipe() {
    #[cfg(unix)]
    {
        use nix::sys::signal::{SigHandler, Signal, signal};
        // SAFETY: SIG_DFL installs no handler of ours; nothing else in the process relies on
        // SIGPIPE being ignored (writes to a closed pipe end the process, as for `cat`).
        let _ = unsafe { signal(Signal::SIGPIPE, SigHandler::SigDfl) };
    }
}

/// Runs the command; its exit code (see [`exit_code`]) or the error that ended it.
fn run(cli: Cli) -> Result<i32> {
    let done = |r: Result<()>| r.map(|()| exit_code::OK);
    match cli.command {
        Command::Kinematics(args) => done(cmd::kinematics::run(&args)),
        Command::Chart(args) => done(cmd::chart::run(&args)),
        Command::Predict(args) => done(cmd::predict::run(&args)),
        Command::Monitor(args) => done(monitor::run(&args)),
        Command::Ports => done(cmd::ports::run()),
        Command::Send(args) => cmd::send::run(&args),
        Command::Commission(args) => cmd::commission::run(&args),
        Command::Replay(args) => done(cmd::replay::run(&args)),
        #[cfg(unix)]
        Command::Demo(args) => demo::run(&args),
        Command::Serve(args) => done(cmd::serve::run(&args)),
        Command::Sim(report) => done(cmd::sim::run(&report)),
        Command::Experiment(args) => done(cmd::experiment::run(&args)),
        Command::Fit(args) => done(cmd::fit::run(&args)),
    }
}

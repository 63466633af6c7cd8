//! `bowl experiment PLAN.toml (--rig-file FILE | --port PORT) --out results.csv`: runs a plan of
//! releases on a simulated rig ([`simulated`]) or on a rig over its serial line ([`port`]) and
//! writes one row per release (see [`results`]); `--suggest` prints a plan. Method and limits:
//! docs/experiment.md.

pub mod benchmark;
pub mod plan;
pub mod port;
pub mod simulated;
pub mod suggest;

use std::io::{IsTerminal, Write};
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use model_core::sim::granule::ParticleParams;

use crate::results::{self, Row, Writer};
use simulated::{Release, SimulatedRig};

/// Arguments of `bowl experiment`.
#[derive(clap::Args)]
pub struct Args {
    /// The plan (TOML: settle_s, [[condition]] bowl_rad_s or precession_rad_s + spin_rad_s,
    /// repeats). Not needed with --suggest.
    pub plan: Option<PathBuf>,
    /// Run on a simulated rig described by this rig file (its [particle] table is the truth).
    #[arg(long, required_unless_present = "port", conflicts_with = "port")]
    pub rig_file: Option<PathBuf>,
    /// Run on the rig on this serial port (or a `bowl serve --pty` pseudo-terminal): releases by
    /// RELEASE, residence times from the rig's gate events.
    #[arg(long)]
    pub port: Option<String>,
    /// Baud rate of --port.
    #[arg(long, default_value_t = 115_200, value_parser = clap::value_parser!(u32).range(50..=12_000_000))]
    pub baud: u32,
    /// The results file to write (traces go to `<stem>_traces/` beside it).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print a suggested plan instead of running one.
    #[arg(long)]
    pub suggest: bool,
    /// With --suggest: the guessed mu the plan is designed for.
    #[arg(long, default_value_t = 0.029)]
    pub mu_guess: f64,
    /// With --suggest: number of conditions.
    #[arg(long, default_value_t = 4)]
    pub conditions: usize,
    /// With --suggest: releases per condition.
    #[arg(long, default_value_t = 10)]
    pub repeats: usize,
    /// Run the plan on this many simulated rigs (seeds 1..=N), fit each, and report the
    /// statistics of the fits against the rig file's truth (results under --out's folder).
    #[arg(long)]
    pub benchmark_seeds: Option<u32>,
    /// Seed of the simulated rig (overrides the rig file's `seed`).
    #[arg(long)]
    pub seed: Option<u32>,
}

/// The rig file's one rig: its plant, its `[particle]` truth and its seed.
fn read_rig_file(
    path: &std::path::Path,
) -> Result<(model_core::sim::PlantParams, ParticleParams, u32)> {
    let rigs = rig_file::load(path)?;
    let [rig] = rigs.as_slice() else {
        bail!(
            "{} holds {} rigs ([[plant]] tables); an experiment runs on one: give a rig file \
             with one rig",
            path.display(),
            rigs.len()
        );
    };
    let Some(particle) = rig.particle else {
        bail!(
            "{}: no [particle] table: the simulated rig needs the granules' truth (keys: \
             docs/experiment.md)",
            path.display()
        );
    };
    Ok((rig.params, particle, rig.seed))
}

/// A rig the plan's releases run on.
pub trait ReleaseRig {
    /// The nominal start radius (m), rim radius (m) and k2 of its granules (results columns).
    fn geometry(&self) -> (f64, f64, f64);
    /// Motor speeds for a combined bowl speed by the rig's split rule, rad/s.
    fn split(&self, bowl_rad_s: f64) -> Result<[f64; 2]>;
    /// Sets the motor speeds (starting the loop if idle) and waits until both measured speeds
    /// are within 2 % for a second, then `settle_s` more.
    fn settle(&mut self, targets: [f64; 2], settle_s: f64) -> Result<(), Release>;
    /// Drops one granule and follows it to the exit gate.
    fn release(&mut self) -> Release;
    /// Stops the motors.
    fn stop(&mut self);
}

/// `bowl experiment`.
pub fn run(args: &Args) -> Result<()> {
    if let Some(port) = &args.port {
        if args.suggest || args.benchmark_seeds.is_some() {
            bail!(
                "--suggest and --benchmark-seeds need a simulated rig (--rig-file): the plan is \
                 designed on the rig's known truth"
            );
        }
        let (Some(plan_path), Some(out)) = (&args.plan, &args.out) else {
            bail!("give a plan and --out results.csv");
        };
        let text = std::fs::read_to_string(plan_path)
            .with_context(|| format!("cannot read the plan {}", plan_path.display()))?;
        let plan = plan::parse(&text, &plan_path.display().to_string())?;
        let mut rig = port::PortRig::open(port, args.baud)?;
        let mut writer = Writer::create(out)?;
        let progress = std::io::stderr().is_terminal();
        let run_no = run_plan(&mut rig, &plan, &mut writer, progress)?;
        println!("{run_no} releases written to {}", out.display());
        return Ok(());
    }
    let Some(rig_file) = &args.rig_file else {
        bail!("give --rig-file FILE (a simulated rig) or --port PORT (a rig on a serial line)");
    };
    let (plant, particle, file_seed) = read_rig_file(rig_file)?;
    let seed = args.seed.unwrap_or(file_seed);
    let mut rig = SimulatedRig::new(plant, particle, seed)?;
    if args.suggest {
        let max_bowl = 0.95 * rig.max_bowl_rad_s()?;
        print!(
            "{}",
            suggest::plan_text(
                &particle,
                args.mu_guess,
                max_bowl,
                args.conditions,
                args.repeats
            )
        );
        return Ok(());
    }
    let (Some(plan_path), Some(out)) = (&args.plan, &args.out) else {
        bail!("give a plan and --out results.csv (or --suggest)");
    };
    let text = std::fs::read_to_string(plan_path)
        .with_context(|| format!("cannot read the plan {}", plan_path.display()))?;
    let plan = plan::parse(&text, &plan_path.display().to_string())?;
    if let Some(seeds) = args.benchmark_seeds {
        return benchmark::run(&plan, &plant, &particle, seeds, out);
    }
    let mut writer = Writer::create(out)?;
    let progress = std::io::stderr().is_terminal();
    let run_no = run_plan(&mut rig, &plan, &mut writer, progress)?;
    rig.stop();
    println!("{run_no} releases written to {}", out.display());
    Ok(())
}

/// Runs every release of `plan` on `rig`, writing each row as it is measured; returns the
/// number of releases. A progress bar on standard error when `progress`.
pub fn run_plan(
    rig: &mut impl ReleaseRig,
    plan: &plan::Plan,
    writer: &mut Writer,
    progress: bool,
) -> Result<usize> {
    let (release_radius_m, rim_radius_m, k2) = rig.geometry();
    let total = plan::releases(plan);
    let mut run_no = 0;
    for (ci, c) in plan.condition.iter().enumerate() {
        let targets = match (c.bowl_rad_s, c.precession_rad_s, c.spin_rad_s) {
            (Some(w), _, _) => rig.split(w)?,
            (None, Some(p), Some(s)) => [p, s],
            _ => unreachable!("plan::parse checked the condition"),
        };
        let bowl = c.bowl_rad_s.unwrap_or_else(|| {
            let a = std::f64::consts::FRAC_PI_3;
            ((targets[0] * a.sin()).powi(2) + (targets[0] * a.cos() + targets[1]).powi(2)).sqrt()
        });
        for _ in 0..c.repeats {
            run_no += 1;
            let outcome = match rig.settle(targets, plan.settle_s) {
                Ok(()) => rig.release(),
                Err(e) => e,
            };
            let mut row = Row {
                run: run_no,
                condition: ci + 1,
                bowl_rad_s: bowl,
                precession_rad_s: targets[0],
                spin_rad_s: targets[1],
                release_radius_m,
                rim_radius_m,
                k2,
                status: results::STATUS_OK.into(),
                residence_s: None,
                trace_mean_rad_s: None,
                trace_sd_rad_s: None,
                trace_path: String::new(),
            };
            let trace = match outcome {
                Release::Left(t, trace) => {
                    row.residence_s = Some(t);
                    Some(trace)
                }
                Release::NeverLeft(trace) => {
                    row.status = results::STATUS_NEVER_LEFT.into();
                    Some(trace)
                }
                Release::NotSettled => {
                    row.status = results::STATUS_NOT_SETTLED.into();
                    None
                }
                Release::MotorFault(f) => {
                    row.status = format!("{}: {f}", results::STATUS_MOTOR_FAULT);
                    None
                }
            };
            if let Some(trace) = trace {
                if let Some((m, s)) = results::mean_sd(&trace) {
                    row.trace_mean_rad_s = Some(m);
                    row.trace_sd_rad_s = Some(s);
                }
                row.trace_path = writer.write_trace(run_no, &trace)?;
            }
            writer.push(&row)?;
            if progress {
                let done = run_no * 30 / total;
                eprint!(
                    "\r[{}{}] {run_no}/{total}",
                    "#".repeat(done),
                    ".".repeat(30 - done)
                );
                let _ = std::io::stderr().flush();
            }
        }
    }
    rig.stop();
    if progress {
        eprintln!();
    }
    Ok(run_no)
}

#[cfg(test)]
mod tests;

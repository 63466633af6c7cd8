//! `bowl experiment PLAN.toml (--rig-file FILE | --port PORT) --out results.csv`: runs a plan of
//! releases on a simulated rig or on a rig over its serial line and writes one row per release;
//! `--suggest` prints a plan (`lab::experiment`). Method and limits: docs/experiment.md.

use std::io::IsTerminal;
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use lab::experiment::simulated::BackendRig;
use lab::experiment::{ReleaseRig, benchmark, plan, port, run_plan, suggest};
use lab::results::Writer;
use model_core::sim::granule::ParticleParams;

/// Arguments of `bowl experiment`.
#[derive(clap::Args)]
pub struct Args {
    /// The plan (TOML: settle_s, [[condition]] bowl_rad_s or precession_rad_s + spin_rad_s,
    /// repeats). Not needed with --suggest.
    pub plan: Option<PathBuf>,
    /// Run on a simulated rig described by this rig file (its [particle] table is the truth;
    /// with `model = "bowl"` the granules follow the bowl model in its [bowl] table).
    /// One of --rig-file and --port is needed (refused in words naming both when neither).
    #[arg(long, value_name = "RIG.toml", conflicts_with = "port")]
    pub rig_file: Option<PathBuf>,
    /// Run on the rig on this serial port (or a `bowl serve --pty` pseudo-terminal): releases by
    /// RELEASE, residence times from the rig's gate events.
    #[arg(long)]
    pub port: Option<String>,
    /// Baud rate of --port.
    #[arg(long, default_value_t = 115_200, value_parser = clap::value_parser!(u32).range(50..=12_000_000))]
    pub baud: u32,
    /// The results file to write (traces go to `<stem>_traces/` beside it).
    #[arg(long, value_parser = crate::cmd::file_to_write)]
    pub out: Option<PathBuf>,
    /// Print a suggested plan instead of running one.
    #[arg(long)]
    pub suggest: bool,
    /// With --suggest: the guessed mu the plan is designed for (above 0, at most 1).
    #[arg(long, value_parser = crate::cmd::number, default_value_t = 0.029)]
    pub mu_guess: f64,
    /// With --suggest: number of conditions (1 to 40).
    #[arg(long, default_value_t = 4)]
    pub conditions: usize,
    /// With --suggest: releases per condition (1 to 10000).
    #[arg(long, default_value_t = 10)]
    pub repeats: usize,
    /// Run the plan on this many simulated rigs (seeds 1..=N), fit each, and report the
    /// statistics of the fits against the rig file's truth (results under --out's folder).
    /// At least 1 (0 seeds would give a mean of nothing).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub benchmark_seeds: Option<u32>,
    /// Seed of the simulated rig (overrides the rig file's `seed`).
    #[arg(long)]
    pub seed: Option<u32>,
}

/// The rig file's one rig: its plant, its `[particle]` truth and its seed.
pub fn read_rig_file(
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
        lab::experiment::check_speeds(&rig, &plan)?;
        let mut writer = Writer::create(out)?;
        let progress = std::io::stderr().is_terminal();
        let run_no = run_plan(&mut rig, &plan, &mut writer, progress)?;
        println!(
            "{} written to {}",
            lab::number::count(run_no, "release", "releases"),
            out.display()
        );
        return Ok(());
    }
    let Some(rig_file) = &args.rig_file else {
        return lab::usage::usage(
            "give --rig-file FILE (a simulated rig) or --port PORT (a rig on a serial line)",
        );
    };
    let (plant, particle, file_seed) = read_rig_file(rig_file)?;
    let seed = args.seed.unwrap_or(file_seed);
    let mut rig = BackendRig::new(plant, particle, seed)?;
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
            )?
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
    // Before the results file is made: a plan beyond the motors' limits writes nothing.
    lab::experiment::check_speeds(&rig, &plan)?;
    let mut writer = Writer::create(out)?;
    let progress = std::io::stderr().is_terminal();
    let run_no = run_plan(&mut rig, &plan, &mut writer, progress)?;
    rig.stop();
    println!(
        "{} written to {}",
        lab::number::count(run_no, "release", "releases"),
        out.display()
    );
    Ok(())
}

//! `bowl experiment PLAN --rig-file FILE --out DIR/x.csv --benchmark-seeds N`: the plan on N
//! simulated rigs (seeds 1..=N, each its own noise), each fitted; reports how the fit's
//! statistics hold against the known truth (docs/experiment.md, "Benchmark").

use std::path::Path;
use std::time::Instant;

use anyhow::Result;
use model_core::particle::Model;
use model_core::sim::granule::ParticleParams;

use super::plan::Plan;
use super::run_plan;
use super::simulated::BackendRig;
use crate::fit;
use crate::results::Writer;

/// What one seed gave for the true model.
struct Outcome {
    mu: f64,
    ci: (f64, f64),
    preferred: &'static str,
    excluded: usize,
}

/// Runs the benchmark and prints its summary.
pub fn run(
    plan: &Plan,
    plant: &model_core::sim::PlantParams,
    particle: &ParticleParams,
    seeds: u32,
    out: &Path,
) -> Result<()> {
    if particle.bowl.is_some() {
        anyhow::bail!(
            "--benchmark-seeds scores the paper's models against the rig file's [particle] truth; \
             this rig's granules follow the bowl model ([particle] model = \"bowl\"): run the \
             plan once and fit it with `bowl fit RESULTS --bowl-walls` (docs/experiment.md)"
        );
    }
    let truth = match particle.model {
        Model::Flat => "flat",
        Model::Coriolis => "coriolis",
    };
    let dir = out.parent().unwrap_or(Path::new("."));
    let stem = out
        .file_stem()
        .map_or("bench".into(), |s| s.to_string_lossy());
    let mut outcomes = Vec::new();
    let mut slowest_s: f64 = 0.0;
    for seed in 1..=seeds {
        let path = dir.join(format!("{stem}_seed{seed}.csv"));
        let started = Instant::now();
        let mut rig = BackendRig::new(*plant, *particle, seed)?;
        let mut writer = Writer::create(&path)?;
        run_plan(&mut rig, plan, &mut writer, false)?;
        slowest_s = slowest_s.max(started.elapsed().as_secs_f64());
        let (runs, excluded) = fit::load(&path)?;
        let excluded_n = excluded.len();
        let f = fit::fit(runs, excluded, false)?;
        let m = f
            .models
            .iter()
            .find(|m| m.candidate.name == truth)
            .expect("every candidate is fitted");
        println!(
            "seed {seed:>3}: {truth} mu {:.5} [{:.5}, {:.5}]  flat AIC {:.1}  coriolis AIC {:.1}  preferred {}  excluded {excluded_n}",
            m.mu, m.mu_ci95.0, m.mu_ci95.1, f.models[0].aic, f.models[1].aic, f.preferred
        );
        outcomes.push(Outcome {
            mu: m.mu,
            ci: m.mu_ci95,
            preferred: f.preferred,
            excluded: excluded_n,
        });
    }
    let n = outcomes.len() as f64;
    let covered = outcomes
        .iter()
        .filter(|o| o.ci.0 <= particle.mu && particle.mu <= o.ci.1)
        .count();
    let mean = outcomes.iter().map(|o| o.mu).sum::<f64>() / n;
    let sd = (outcomes.iter().map(|o| (o.mu - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    // The standard error one fit reports: its interval's half-width over 1.96.
    let se_fit = outcomes
        .iter()
        .map(|o| (o.ci.1 - o.ci.0) / (2.0 * 1.96))
        .sum::<f64>()
        / n;
    let count = |p: &str| outcomes.iter().filter(|o| o.preferred == p).count();
    // One seed has no spread: the mean's standard error is not given (it would be NaN).
    let of_mean = if outcomes.len() > 1 {
        format!(
            ", {:+.2} of the mean of {} ({:.5})",
            (mean - particle.mu) / (sd / n.sqrt()),
            outcomes.len(),
            sd / n.sqrt()
        )
    } else {
        " (one seed: no spread between seeds; give --benchmark-seeds 2 or more for the mean's \
         standard error)"
            .into()
    };
    println!(
        "truth {truth} mu {}: interval covers the truth in {covered} of {}; mean estimate {mean:.5}, \
         bias {:+.5} = {:+.2} standard errors of one fit ({se_fit:.5}){of_mean}; preferred flat {}, \
         coriolis {}, undecided {}; runs excluded {}; slowest plan {slowest_s:.2} s",
        particle.mu,
        outcomes.len(),
        mean - particle.mu,
        (mean - particle.mu) / se_fit,
        count("flat"),
        count("coriolis"),
        count("undecided"),
        outcomes.iter().map(|o| o.excluded).sum::<usize>(),
    );
    Ok(())
}

//! `bowl fit results.csv [--json] [--fit-k2] [--models flat,coriolis,rolling]`: the effective rolling resistance `mu` of each
//! candidate model (and with `--fit-k2` the granule's `k2` too) from measured residence times,
//! its 95 % interval, the residuals per condition, and which model the data supports (AIC), by
//! the lab's fit (`lab::fit`). Method and limits: docs/experiment.md.

use std::path::{Path, PathBuf};

use anyhow::Result;
use lab::fit::models::{BOWL_CANDIDATES, CANDIDATES, Method};
use lab::fit::stats::AIC_DECISIVE;
use lab::fit::{
    DEFAULT_AXES_ANGLE_DEG, K2, charts, condition_table, fit_candidates, load, to_json,
};

/// Arguments of `bowl fit`.
#[derive(clap::Args)]
pub struct Args {
    /// The results file written by `bowl experiment`.
    pub results: PathBuf,
    /// Print the fit as JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Folder for the charts and the table (default: `<results stem>_fit` beside the file).
    #[arg(long)]
    pub charts: Option<PathBuf>,
    /// Do not draw charts.
    #[arg(long)]
    pub no_charts: bool,
    /// Angle between the bowl's axis and the vertical during the runs, degrees (the rolling
    /// model's tilt; the results file does not record it).
    #[arg(long, default_value_t = DEFAULT_AXES_ANGLE_DEG)]
    pub axes_angle_deg: f64,
    /// Fit the granule's k2 as well as mu (needs conditions spread over the speed range; the
    /// results file's k2 is the starting point).
    #[arg(long)]
    pub fit_k2: bool,
    /// The models fitted and compared, comma-separated (the rolling model takes by far the
    /// longest to fit: leave it out for a quick look at the paper's two).
    #[arg(
        long,
        value_delimiter = ',',
        value_parser = ["flat", "coriolis", "rolling"],
        default_value = "flat,coriolis,rolling"
    )]
    pub models: Vec<String>,
    /// Also fit the bowl model (docs/model.md section 10) with each of its walls (bare rim,
    /// 60 deg 10 and 20 mm, vertical 20 mm): its parameter is the sliding friction mu_s, and
    /// the AIC says which model and which wall the measured times prefer. Slower (twelve
    /// releases in the real bowl per run and trial).
    #[arg(long)]
    pub bowl_walls: bool,
}

/// `bowl fit`.
pub fn run(args: &Args) -> Result<()> {
    if !(args.axes_angle_deg.is_finite() && (0.0..90.0).contains(&args.axes_angle_deg)) {
        anyhow::bail!(
            "--axes-angle-deg {} is not a tilt the rig can have: give 0 to below 90 degrees",
            args.axes_angle_deg
        );
    }
    let (mut runs, excluded) = load(&args.results)?;
    for r in &mut runs {
        r.axes_angle_rad = args.axes_angle_deg.to_radians();
    }
    let mut candidates: Vec<_> = CANDIDATES
        .iter()
        .filter(|c| args.models.iter().any(|m| m == c.name))
        .copied()
        .collect();
    if args.bowl_walls {
        candidates.extend(BOWL_CANDIDATES);
    }
    let fit = fit_candidates(runs, excluded, &candidates, args.fit_k2)?;
    if !args.no_charts {
        let dir = args.charts.clone().unwrap_or_else(|| {
            let stem = args
                .results
                .file_stem()
                .map_or("results".into(), |s| s.to_string_lossy());
            args.results
                .parent()
                .unwrap_or(Path::new("."))
                .join(format!("{stem}_fit"))
        });
        charts::write(&fit, &dir)?;
        if !args.json {
            println!("charts and table: {}", dir.display());
        }
    }
    if args.json {
        // The terminal hears of every dropped row even when standard output is JSON.
        for e in &fit.excluded {
            eprintln!("bowl fit: excluded line {}: {}", e.row, e.reason);
        }
        for o in &fit.outliers {
            eprintln!("bowl fit: outlier line {}: {}", o.row, o.why);
        }
        for m in fit.models.iter() {
            if let Some(why) = &m.cannot_reproduce {
                eprintln!(
                    "bowl fit: {} model not a candidate: {why}",
                    m.candidate.name
                );
            }
        }
        println!("{}", serde_json::to_string_pretty(&to_json(&fit))?);
        return Ok(());
    }
    let integrated = fit
        .runs
        .iter()
        .filter(|r| r.method == Method::Integrated)
        .count();
    println!(
        "{} runs ({} by the closed form at the mean speed, {} integrated over the speed trace), {} excluded, {} outliers left out",
        fit.runs.len(),
        fit.runs.len() - integrated,
        integrated,
        fit.excluded.len(),
        fit.outliers.len()
    );
    for e in &fit.excluded {
        println!("  excluded line {}: {}", e.row, e.reason);
    }
    for o in &fit.outliers {
        println!("  outlier line {}: {}", o.row, o.why);
    }
    println!("model      mu        95 % interval          rms error %   AIC");
    for m in &fit.models {
        println!(
            "{:<10} {:.5}  [{:.5}, {:.5}]   {:>8.2}   {:>10.2}",
            m.candidate.name, m.mu, m.mu_ci95.0, m.mu_ci95.1, m.rms_error_pct, m.aic
        );
        match &m.k2 {
            K2::Given => {}
            K2::Fitted(k2, ci) => println!("{:<10} k2 {:.4}  [{:.4}, {:.4}]", "", k2, ci.0, ci.1),
            K2::NotFitted(why) => println!("{:<10} k2 not fitted: {why}", ""),
        }
        if let Some(why) = &m.cannot_reproduce {
            println!("{:<10} not a candidate: {why}", "");
        }
    }
    println!(
        "preferred: {} (a model is preferred when its AIC is lower by more than {AIC_DECISIVE})",
        fit.preferred
    );
    if let Some(m) = fit
        .models
        .iter()
        .find(|m| m.candidate.name == fit.preferred)
    {
        println!(
            "apply to the rig: bowl send PORT set MU_PPM {:.0}",
            (m.mu * 1e6).round()
        );
    }
    print!("{}", condition_table(&fit).to_csv());
    Ok(())
}

//! `bowl fit results.csv [--json] [--fit-k2] [--models flat,coriolis,rolling]`: the effective rolling resistance `mu` of each
//! candidate model (and with `--fit-k2` the granule's `k2` too) from measured residence times,
//! its 95 % interval, the residuals per condition, and which model the data supports (AIC), by
//! the lab's fit (`lab::fit`). Method and limits: docs/experiment.md.

use std::path::{Path, PathBuf};

use anyhow::Result;
use lab::fit::models::{BowlBase, CANDIDATES, Equation, Method, Run, Wall, bowl_candidates};
use lab::fit::stats::AIC_DECISIVE;
use lab::fit::{
    DEFAULT_AXES_ANGLE_DEG, K2, charts, condition_table, fit_candidates, load, tilt, to_json,
    undecided_why,
};
use lab::number::count;

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
    /// and bowl models' tilt; the results file does not record it). Default: the rig file's
    /// `[bowl] axes_angle_deg` with --rig-file, else 60.
    #[arg(long, value_parser = crate::cmd::number)]
    pub axes_angle_deg: Option<f64>,
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
    /// The rig file the runs were measured on (the one `bowl experiment --rig-file` used): the
    /// bowl model takes its `[bowl]` table (tilt, bottom radius, fillet, restitution, granule
    /// radius) and, when its `[particle]` follows the bowl model, the rolling resistance `mu`;
    /// its own wall joins the candidate walls. Implies --bowl-walls.
    #[arg(long, value_name = "RIG.toml")]
    pub rig_file: Option<PathBuf>,
}

/// What the rig file gives the bowl fit: the tilt, the shared bowl, the rig's wall and its
/// bottom radius.
struct RigBowl {
    axes_angle_deg: f64,
    base: BowlBase,
    wall: Wall,
    rim_radius_m: f64,
}

/// The rig file's one rig's `[bowl]` table, in plain words when it has none.
fn read_rig_bowl(path: &Path) -> Result<RigBowl> {
    let rigs = rig_file::load(path)?;
    let [rig] = rigs.as_slice() else {
        anyhow::bail!(
            "{} holds {} rigs ([[plant]] tables); the runs were measured on one: give the rig file \
             of that rig",
            path.display(),
            rigs.len()
        );
    };
    let Some(b) = rig.bowl else {
        anyhow::bail!(
            "the rig file {} has no [bowl] table: the bowl fit takes the bowl's shape, tilt and \
             granule from it (keys and how to measure them: docs/rigs/nominal.toml; an example: \
             docs/rigs/bowl-60deg.toml)",
            path.display()
        );
    };
    let rolling_resistance = rig
        .particle
        .filter(|p| p.bowl.is_some())
        .map_or(BowlBase::DEFAULT.rolling_resistance, |p| p.mu);
    Ok(RigBowl {
        axes_angle_deg: b.axes_angle_deg,
        base: BowlBase {
            fillet_radius_m: b.fillet_radius_m,
            restitution: b.restitution,
            particle_radius_m: b.particle_radius_m,
            rolling_resistance,
        },
        wall: Wall {
            angle_deg: b.wall_angle_deg,
            height_m: b.wall_height_m,
        },
        rim_radius_m: b.rim_radius_m,
    })
}

/// Gives every run the rig's bowl; refuses runs measured on another bottom radius.
fn apply_rig_bowl(runs: &mut [Run], rig: &RigBowl, path: &Path) -> Result<()> {
    for r in runs.iter_mut() {
        if (r.rim_radius_m - rig.rim_radius_m).abs() > 1e-9 {
            anyhow::bail!(
                "results line {}: rim radius {} m, but the rig file {} has [bowl] rim_radius_m \
                 = {} m: fit the results with the rig file they were measured on",
                r.row,
                r.rim_radius_m,
                path.display(),
                rig.rim_radius_m
            );
        }
        r.bowl.base = rig.base;
    }
    Ok(())
}

/// `bowl fit`.
pub fn run(args: &Args) -> Result<()> {
    if let Some(a) = args.axes_angle_deg
        && !(a.is_finite() && (0.0..90.0).contains(&a))
    {
        anyhow::bail!(
            "--axes-angle-deg {a} is not a tilt the rig can have: give 0 to below 90 degrees"
        );
    }
    let rig = match &args.rig_file {
        Some(path) => Some(read_rig_bowl(path)?),
        None => None,
    };
    let axes_angle_deg = match (args.axes_angle_deg, &rig) {
        (Some(a), Some(r)) if (a - r.axes_angle_deg).abs() > 1e-9 => anyhow::bail!(
            "--axes-angle-deg {a} but the rig file's [bowl] axes_angle_deg is {}: the runs had \
             one tilt; leave --axes-angle-deg out to use the rig file's",
            r.axes_angle_deg
        ),
        (Some(a), _) => a,
        (None, Some(r)) => r.axes_angle_deg,
        (None, None) => DEFAULT_AXES_ANGLE_DEG,
    };
    let (mut runs, excluded) = load(&args.results)?;
    for r in &mut runs {
        r.axes_angle_rad = axes_angle_deg.to_radians();
    }
    if let (Some(rig), Some(path)) = (&rig, &args.rig_file) {
        apply_rig_bowl(&mut runs, rig, path)?;
    }
    let mut candidates: Vec<_> = CANDIDATES
        .iter()
        .filter(|c| args.models.iter().any(|m| m == c.name))
        .copied()
        .collect();
    if args.bowl_walls || rig.is_some() {
        candidates.extend(bowl_candidates(rig.as_ref().map(|r| r.wall)));
    }
    // The paper's radial models see only the combined speed; the others need the runs' tilt.
    if candidates
        .iter()
        .any(|c| !matches!(c.equation, Equation::Paper(_)))
    {
        let source = match (&args.rig_file, args.axes_angle_deg) {
            (_, Some(_)) => tilt::Source::Flag,
            (Some(path), None) => tilt::Source::RigFile(path),
            (None, None) => tilt::Source::Default,
        };
        tilt::check(&runs, axes_angle_deg, source)?;
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
        "{} ({} by the closed form at the mean speed, {} integrated over the speed trace), {} excluded, {} left out",
        count(fit.runs.len(), "run", "runs"),
        fit.runs.len() - integrated,
        integrated,
        fit.excluded.len(),
        count(fit.outliers.len(), "outlier", "outliers")
    );
    for e in &fit.excluded {
        println!("  excluded line {}: {}", e.row, e.reason);
    }
    for o in &fit.outliers {
        println!("  outlier line {}: {}", o.row, o.why);
    }
    println!("model      mu        95 % interval          rms error %   AIC");
    // A model that cannot reproduce the runs has no finite error or AIC (and an interval
    // may be unbounded): "-" in its cell, the reason on the line below, never "inf".
    let cell = |x: f64, decimals: usize| {
        if x.is_finite() {
            format!("{x:.decimals$}")
        } else {
            "-".into()
        }
    };
    for m in &fit.models {
        println!(
            "{:<10} {}  [{}, {}]   {:>8}   {:>10}",
            m.candidate.name,
            cell(m.mu, 5),
            cell(m.mu_ci95.0, 5),
            cell(m.mu_ci95.1, 5),
            cell(m.rms_error_pct, 2),
            cell(m.aic, 2)
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
    if fit.preferred == "none" {
        println!(
            "  none because no model reproduces these runs (each says why above): check the \
             times' unit and the rig's geometry, or fit one with more of the rig in it \
             (`--models rolling`, `--bowl-walls`)"
        );
    }
    if let Some(why) = undecided_why(&fit) {
        println!("  undecided because {why}");
    }
    // MU_PPM is the paper's and the rolling model's resistance: a bowl wall's mu_s is not it.
    if let Some(m) = fit.models.iter().find(|m| {
        m.candidate.name == fit.preferred && !matches!(m.candidate.equation, Equation::Bowl(_))
    }) {
        println!(
            "apply to the rig: bowl send PORT set MU_PPM {:.0}",
            (m.mu * 1e6).round()
        );
    }
    if let Some(w) = &fit.walls {
        println!("wall: {}", w.text);
    }
    print!("{}", condition_table(&fit).to_csv());
    Ok(())
}

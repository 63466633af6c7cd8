//! `bowl chart`: the speed-against-accuracy chart and the paper-style figures (docs/model.md
//! section 6), drawn by the lab's charts (`lab::chart`).
//!
//! Every chart is written three ways from one `--out FILE.svg`: `FILE.svg`, `FILE.png` (same
//! drawing, text rendered with the embedded DejaVu font) and `FILE.csv` (the numbers behind it).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::cmd::sim::flags as sim_flags;
use clap::Subcommand;
use lab::chart::{
    bowl, chooser, control, costs, error_table, family, figures, hierarchy, log, plot, qemu_log,
    rolling, say, scipy, stability, suffixed, table, timing, workprec,
};

/// Which chart to draw.
#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    which: Which,
}

#[derive(Subcommand)]
enum Which {
    /// Error in the residence time against cost (host ns, RHS evaluations, QEMU instructions)
    /// for every method and setting, on the named scenes.
    WorkPrecision(WorkPrecision),
    /// r(t) at 3.6 rad/s, flat and Coriolis (cf. paper Fig. 5).
    Radial(Out),
    /// Total exit speed against bowl speed for 150-300 mm bowls (cf. paper Fig. 6).
    Velocity(Out),
    /// Residence time against bowl speed for 150-300 mm bowls (cf. paper Fig. 7).
    Residence(Out),
    /// Error against step h*omega for the fixed-step integrators, stability bounds marked.
    Stability(Out),
    /// Draws the scipy side-by-side from tests/scipy/compare.py's CSV (error against RHS
    /// evaluations in FILE.svg, against time in FILE-time.svg; paper scene, Coriolis model).
    Scipy(ScipyArgs),
    /// Settling time of the simulated rig's 0 -> 3 rad/s step against pulses per revolution.
    Settling(ControlArgs),
    /// Limit cycle of the 0.5 rad/s hold against the per-pulse gain, with and without the schedule.
    ControlStability(ControlArgs),
    /// Overshoot against settling of every axis of a rig or family file (a step from rest, or from
    /// --from-rad-s, to the target).
    Family(FamilyArgs),
    /// Rolling model: residence time against bowl speed beside the paper's (cf. paper Fig. 7).
    RollingResidence(RollingResidenceArgs),
    /// Bowl model: residence time against bowl speed for each bowl shape (docs/model.md §10).
    BowlResidence(RollingResidenceArgs),
    /// Bowl model: sliding and leaving against the tilt at 2 rad/s (the regime map).
    BowlRegimes(Out),
    /// Bowl model: what most releases do (roll, slide, fly, held by the wall) over tilt and
    /// speed, on a rod offset of 0.3 m.
    BowlRegimeMap(Out),
    /// Bowl model: work-precision of DP5(4) and RK4 with the wall and with flights.
    BowlWorkPrecision(Out),
    /// The whole hierarchy on the tilted bowl (incline, incline corrected, rolling,
    /// rolling-or-sliding, bowl) and the chooser's picks: error against host time.
    HierarchyWorkPrecision(Out),
    /// Rolling model: the twelve releases' paths on the bowl bottom.
    RollingPaths(Out),
    /// Rolling model: each simpler member's difference from the full model (the hierarchy map).
    RollingHierarchy(RollingHierarchyArgs),
    /// Rolling model: work-precision of DP5(4) and RK4, on the rig and near the stick threshold.
    RollingWorkPrecision(Out),
    /// A logged run (bowl monitor --log, bowl replay --csv, the demo's telemetry.csv): set and
    /// measured speed per axis with link events and faults marked (FILE-precession.svg,
    /// FILE-spin.svg, PNGs beside them).
    Log(LogArgs),
    /// The chooser's cost table (Rust source for model-core) fitted to the work-precision
    /// measurements: per call and per right-hand-side evaluation, host ns and M4F instructions.
    Costs(CostArgs),
    /// The chooser's plans against the cheapest plan meeting the same tolerance, by brute force
    /// on a grid of spin-up scenes (cost ratio per scene; CSV with the plans).
    Chooser(Out),
    /// The chooser's error table (bytes for model-core): RK4's error constant, the Coriolis
    /// effect and T over a spin-up's dimensionless features, each against a tight DP5(4).
    ErrorTable(ErrorTableArgs),
}

/// Options of `bowl chart error-table`.
#[derive(clap::Args)]
struct ErrorTableArgs {
    /// The file to write (model-core/src/choose/error_table.bin).
    #[arg(long, value_parser = crate::cmd::file_to_write)]
    out: PathBuf,
}

/// Options of `bowl chart costs`.
#[derive(clap::Args)]
struct CostArgs {
    /// The work-precision CSV (docs/charts/work-precision.csv).
    #[arg(long)]
    csv: PathBuf,
    /// The Rust file to write (model-core/src/choose/cost_table.rs).
    #[arg(long, value_parser = crate::cmd::file_to_write)]
    out: PathBuf,
}

/// Options of `bowl chart log`.
#[derive(clap::Args)]
struct LogArgs {
    /// The telemetry CSV.
    #[arg(long)]
    csv: PathBuf,
    /// The SVG file name the charts are named after (FILE-precession.svg, FILE-spin.svg).
    #[arg(long, value_parser = crate::cmd::file_to_write)]
    out: PathBuf,
}

/// Options of `bowl chart rolling-residence`.
#[derive(clap::Args)]
struct RollingResidenceArgs {
    #[command(flatten)]
    out: Out,
    /// Tilt of the bowl's axis from the vertical, degrees.
    #[arg(long, value_parser = crate::cmd::number, default_value_t = 60.0)]
    axes_angle_deg: f64,
}

/// Options of `bowl chart rolling-hierarchy`.
#[derive(clap::Args)]
struct RollingHierarchyArgs {
    #[command(flatten)]
    out: Out,
    /// Rolling resistance.
    #[arg(long, value_parser = crate::cmd::number, default_value_t = 0.029)]
    mu: f64,
}

/// Options of `bowl chart family`.
#[derive(clap::Args)]
struct FamilyArgs {
    #[command(flatten)]
    out: Out,
    /// Rig or family file (TOML).
    #[arg(long, value_name = "RIG.toml")]
    rig_file: PathBuf,
    /// Step target, rad/s.
    #[arg(long, value_parser = crate::cmd::number32, default_value_t = 3.0, allow_negative_numbers = true)]
    target_rad_s: f32,
    /// Both axes settle at this speed first, then step to the target (0 = from rest), rad/s.
    #[arg(long, value_parser = crate::cmd::number32, default_value_t = 0.0, allow_negative_numbers = true)]
    from_rad_s: f32,
    /// Give every plant the typical current sense (`current_sense = true`) where its file gave
    /// none (as `bowl sim family --current-sense`).
    #[arg(long)]
    current_sense: bool,
}

/// Options of the control charts (`settling`, `control-stability`).
#[derive(clap::Args)]
struct ControlArgs {
    #[command(flatten)]
    out: Out,
    /// Only a few points, for a quick look (those the tests assert on: settling at 1, 12, 60
    /// and 240 pulses/rev; control-stability at 12 pulses/rev and 1000 Hz, gains 0.5, 1 and 2).
    #[arg(long)]
    quick: bool,
    /// Seed of the simulated rig.
    #[arg(long, default_value_t = 1)]
    seed: u32,
}

/// Options of `bowl chart scipy`.
#[derive(clap::Args)]
struct ScipyArgs {
    /// The comparison CSV written by tests/scipy/compare.py.
    #[arg(long)]
    csv: PathBuf,
    /// The SVG file (PNG beside it; the time chart as FILE-time.svg/png).
    #[arg(long, value_parser = crate::cmd::file_to_write)]
    out: PathBuf,
    /// Scene to draw.
    #[arg(long, default_value = "paper")]
    scene: String,
    /// Model to draw (flat or coriolis).
    #[arg(long, default_value = "coriolis")]
    model: String,
}

fn scipy_charts(a: &ScipyArgs) -> Result<()> {
    for (cost, svg) in [
        (scipy::Cost::RhsEvals, a.out.with_extension("svg")),
        (scipy::Cost::Time, suffixed(&a.out, "time")),
    ] {
        let fig = scipy::figure(&a.csv, &a.scene, &a.model, cost)?;
        let png = svg.with_extension("png");
        fig.write_svg(&svg)?;
        fig.write_png(&png)?;
        report(&[&svg, &png]);
    }
    Ok(())
}

impl ControlArgs {
    fn extent(&self) -> control::Extent {
        if self.quick {
            control::Extent::Quick
        } else {
            control::Extent::Full
        }
    }
}

/// Where to write.
#[derive(clap::Args)]
struct Out {
    /// The SVG file; the PNG and CSV go beside it with the same stem.
    #[arg(long, value_parser = crate::cmd::file_to_write)]
    out: PathBuf,
    /// Write only the CSV (no drawing).
    #[arg(long)]
    csv_only: bool,
}

/// Options of `bowl chart work-precision`.
#[derive(clap::Args)]
struct WorkPrecision {
    #[command(flatten)]
    out: Out,
    /// The QEMU run's output (`target/test-logs/qemu-cases.log` after `tests/run`): adds the
    /// instruction counts of the `cost::` benchmarks to the CSV and draws FILE-qemu.svg.
    #[arg(long)]
    qemu_log: Option<PathBuf>,
    /// Shorter timing (3 batches of 0.2 ms instead of 15 of 2 ms): for tests and quick looks.
    #[arg(long)]
    quick: bool,
    /// Only these method families (comma-separated: closed, euler, semi-implicit-euler, rk4,
    /// dp54); all when omitted.
    #[arg(long, value_delimiter = ',')]
    families: Vec<String>,
}

fn work_precision(args: &WorkPrecision) -> Result<()> {
    use model_core::particle::Model;
    use workprec::CostAxis;
    let qemu = match &args.qemu_log {
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .with_context(|| format!("reading QEMU log {}", p.display()))?;
            qemu_log::parse(&text)?
        }
        None => Default::default(),
    };
    let budget = if args.quick {
        timing::Budget::QUICK
    } else {
        timing::Budget::FULL
    };
    if cfg!(debug_assertions) {
        eprintln!("note: debug build; host times are not representative (use --release)");
    }
    let points = workprec::measure(budget, &qemu, &args.families)?;
    let table = workprec::table(&points);
    // A compact view of the main scene for the terminal (the CSV has everything).
    say("paper scene, Coriolis model:");
    say(&format!(
        "{:<40} {:>10} {:>8} {:>12} {:>10}",
        "method", "rel.error", "RHS", "host ns", "M4F instr"
    ));
    for p in points
        .iter()
        .filter(|p| p.scene == "paper" && p.model == Model::Coriolis)
    {
        say(&format!(
            "{:<40} {:>10} {:>8} {:>12.1} {:>10}",
            p.method.key(),
            p.rel_error
                .map_or_else(|| "-".into(), |e| format!("{e:.2e}")),
            p.run
                .rhs_evals
                .map_or_else(|| "-".into(), |n| n.to_string()),
            p.host_ns,
            p.qemu.map_or_else(|| "-".into(), |c| c.mean.to_string()),
        ));
    }
    let main = workprec::figure(&points, "paper", Model::Coriolis, CostAxis::HostNs);
    write_all(&args.out, &main, &table)?;
    if args.out.csv_only {
        return Ok(());
    }
    let mut extra = vec![
        (
            "near-threshold",
            workprec::figure(&points, "near-threshold", Model::Coriolis, CostAxis::HostNs),
        ),
        (
            "near-rim",
            workprec::figure(&points, "near-rim", Model::Flat, CostAxis::HostNs),
        ),
        (
            "rhs",
            workprec::figure(&points, "paper", Model::Coriolis, CostAxis::RhsEvals),
        ),
    ];
    if points.iter().any(|p| p.qemu.is_some()) {
        extra.push((
            "qemu",
            workprec::figure(
                &points,
                "paper",
                Model::Coriolis,
                CostAxis::QemuInstructions,
            ),
        ));
    }
    for (suffix, fig) in extra {
        if fig.series.is_empty() {
            eprintln!("skipping {suffix}: no points for this cost axis");
            continue;
        }
        let svg = suffixed(&args.out.out, suffix);
        let png = svg.with_extension("png");
        fig.write_svg(&svg)?;
        fig.write_png(&png)?;
        report(&[&svg, &png]);
    }
    Ok(())
}

/// Writes `fig` and `table` as `out` (.svg), .png and .csv.
fn write_all(out: &Out, fig: &plot::Figure, table: &table::Table) -> Result<()> {
    if let Some(dir) = out.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let csv = out.out.with_extension("csv");
    table
        .write(&csv)
        .with_context(|| format!("writing {}", csv.display()))?;
    if !out.csv_only {
        let svg = out.out.with_extension("svg");
        let png = out.out.with_extension("png");
        fig.write_svg(&svg)?;
        fig.write_png(&png)?;
        report(&[&svg, &png, &csv]);
    } else {
        report(&[&csv]);
    }
    Ok(())
}

fn report(paths: &[&Path]) {
    for p in paths {
        say(&format!("wrote {}", p.display()));
    }
}

/// Writes to a closed pipe fail (and [`say`] lets them) instead of ending the process.
fn ignore_sigpipe() {
    #[cfg(unix)]
    {
        use nix::sys::signal::{SigHandler, Signal, signal};
        // SAFETY: SIG_IGN installs no handler of ours; every write of `bowl chart` to standard
        // output goes through `say`, which expects the error.
        let _ = unsafe { signal(Signal::SIGPIPE, SigHandler::SigIgn) };
    }
}

/// Runs `bowl chart ...`.
pub fn run(args: &Args) -> Result<()> {
    ignore_sigpipe();
    match &args.which {
        Which::WorkPrecision(wp) => work_precision(wp),
        Which::Radial(out) => {
            let (f, t) = figures::radial()?;
            write_all(out, &f, &t)
        }
        Which::Velocity(out) => {
            let (f, t) = figures::velocity()?;
            write_all(out, &f, &t)
        }
        Which::Residence(out) => {
            let (f, t) = figures::residence_time()?;
            write_all(out, &f, &t)
        }
        Which::Scipy(a) => scipy_charts(a),
        Which::Costs(a) => costs::write(&a.csv, &a.out),
        Which::ErrorTable(a) => error_table::write(&a.out),
        Which::Chooser(out) => {
            let (f, cost, t) = chooser::chart()?;
            write_all(out, &f, &t)?;
            // What choosing costs, beside it: FILE-cost.svg and .png.
            if !out.csv_only {
                let stem = out.out.file_stem().map_or_else(
                    || "chooser".to_string(),
                    |s| s.to_string_lossy().into_owned(),
                );
                let svg = out.out.with_file_name(format!("{stem}-cost.svg"));
                let png = svg.with_extension("png");
                cost.write_svg(&svg)?;
                cost.write_png(&png)?;
                report(&[&svg, &png]);
            }
            Ok(())
        }
        Which::Log(a) => {
            let written = log::draw(&a.csv, &a.out)?;
            report(&written.iter().map(PathBuf::as_path).collect::<Vec<_>>());
            Ok(())
        }
        Which::RollingResidence(a) => {
            let (f, t) = rolling::residence(a.axes_angle_deg)?;
            write_all(&a.out, &f, &t)
        }
        Which::BowlResidence(a) => {
            let (f, t) = bowl::residence(a.axes_angle_deg)?;
            write_all(&a.out, &f, &t)
        }
        Which::BowlRegimes(out) => {
            let (f, t) = bowl::regimes(2.0)?;
            write_all(out, &f, &t)
        }
        Which::BowlRegimeMap(out) => {
            let (f, t) = bowl::regime_map(0.3)?;
            write_all(out, &f, &t)
        }
        Which::BowlWorkPrecision(out) => {
            let (f, t) = bowl::work_precision()?;
            write_all(out, &f, &t)
        }
        Which::HierarchyWorkPrecision(out) => {
            let (f, t) = hierarchy::work_precision()?;
            write_all(out, &f, &t)
        }
        Which::RollingPaths(out) => {
            let (f, t) = rolling::trajectories()?;
            write_all(out, &f, &t)
        }
        Which::RollingHierarchy(a) => {
            let (f, t) = rolling::hierarchy_map(a.mu)?;
            write_all(&a.out, &f, &t)
        }
        Which::RollingWorkPrecision(out) => {
            let (f, t) = rolling::work_precision()?;
            write_all(out, &f, &t)
        }
        Which::Settling(a) => {
            let (f, t) = control::settling_chart(&control::settling_points(a.extent(), a.seed));
            write_all(&a.out, &f, &t)
        }
        Which::ControlStability(a) => {
            let (f, t) = control::stability_chart(&control::hold_points(a.extent(), a.seed));
            write_all(&a.out, &f, &t)
        }
        Which::Stability(out) => {
            let (f, t) = stability::chart()?;
            write_all(out, &f, &t)
        }
        Which::Family(a) => {
            let mut rigs = rig_file::load(&a.rig_file)?;
            if a.current_sense {
                rigs = rigs
                    .into_iter()
                    .map(rig_file::Rig::with_current_sense)
                    .collect();
            }
            let name = a
                .rig_file
                .file_name()
                .map_or(String::new(), |n| n.to_string_lossy().into_owned());
            let name = if a.current_sense {
                format!("{name}, current sense")
            } else {
                name
            };
            // Judged as `bowl sim family` judges them: a speed no plant can hold drew a chart
            // of never-settled axes (NaN ripple at a target of NaN, false faults at 0).
            let plants: Vec<_> = rigs.iter().map(sim_flags::Plant::of_rig).collect();
            let (from, target) = sim_flags::step(a.from_rad_s, a.target_rad_s, &plants)?;
            let (f, t) = family::chart(&rigs, from, target, &name);
            write_all(&a.out, &f, &t)
        }
    }
}

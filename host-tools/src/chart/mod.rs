//! `bowl chart`: the speed-against-accuracy chart and the paper-style figures (issue 3).
//!
//! Every chart is written three ways from one `--out FILE.svg`: `FILE.svg`, `FILE.png` (same
//! drawing, text rendered with the embedded DejaVu font) and `FILE.csv` (the numbers behind it).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Subcommand;

pub mod figures;
pub mod plot;
pub mod reference;
pub mod table;

/// Which chart to draw.
#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    which: Which,
}

#[derive(Subcommand)]
enum Which {
    /// r(t) at 3.6 rad/s, flat and Coriolis (cf. paper Fig. 5).
    Radial(Out),
    /// Total exit speed against bowl speed for 150-300 mm bowls (cf. paper Fig. 6).
    Velocity(Out),
    /// Residence time against bowl speed for 150-300 mm bowls (cf. paper Fig. 7).
    Residence(Out),
}

/// Where to write.
#[derive(clap::Args)]
struct Out {
    /// The SVG file; the PNG and CSV go beside it with the same stem.
    #[arg(long)]
    out: PathBuf,
    /// Write only the CSV (no drawing).
    #[arg(long)]
    csv_only: bool,
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
        println!("wrote {}", p.display());
    }
}

/// Runs `bowl chart ...`.
pub fn run(args: &Args) -> Result<()> {
    match &args.which {
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
    }
}

//! The results file of `bowl experiment`: one row per release, written and flushed as soon as
//! the release is over (so an interrupted experiment keeps every row measured so far), read back
//! by `bowl fit`. Each row names its speed trace file (`t_s,bowl_rad_s`: time since the release
//! and the measured combined bowl speed), relative to the results file.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};

pub(crate) mod sheet;
use sheet::Sheet;

/// How a release ended.
pub const STATUS_OK: &str = "ok";
/// The granule was still in the bowl when the run gave up.
pub const STATUS_NEVER_LEFT: &str = "never_left";
/// The speeds did not settle (a stalled or too weak motor).
pub const STATUS_NOT_SETTLED: &str = "not_settled";
/// The controller stopped the motors on a fault during the run.
pub const STATUS_MOTOR_FAULT: &str = "motor_fault";

/// One release.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// Release number, from 1.
    pub run: usize,
    /// The plan's condition, from 1.
    pub condition: usize,
    /// Target combined bowl speed (paper Eq. 2), rad/s.
    pub bowl_rad_s: f64,
    /// Target precession speed, rad/s.
    pub precession_rad_s: f64,
    /// Target spin speed, rad/s.
    pub spin_rad_s: f64,
    /// Nominal start radius, m.
    pub release_radius_m: f64,
    /// Rim radius (exit gate), m.
    pub rim_radius_m: f64,
    /// Assumed `k2` of the granules.
    pub k2: f64,
    /// `ok`, `never_left`, `not_settled`, `motor_fault` (with detail after a colon).
    pub status: String,
    /// Release to exit gate, s; empty unless `ok`.
    pub residence_s: Option<f64>,
    /// Mean of the measured combined speed from release to exit, rad/s.
    pub trace_mean_rad_s: Option<f64>,
    /// Its standard deviation, rad/s.
    pub trace_sd_rad_s: Option<f64>,
    /// The trace file, relative to the results file.
    pub trace_path: String,
    /// Where on the bowl the granule was dropped: its azimuth from the downhill direction,
    /// degrees (as `bowl predict --release-azimuth-deg`), when the rig knows it (a simulated rig
    /// in the bowl model does; a rig over its serial line does not report it). Empty otherwise,
    /// and absent from results files written before it existed. The bowl fit then compares the
    /// release with the bowl model at its own azimuth instead of the mean over the azimuths.
    #[serde(default)]
    pub release_azimuth_deg: Option<f64>,
}

/// Appends rows to a results file, flushing each.
pub struct Writer {
    csv: csv::Writer<std::fs::File>,
    dir: PathBuf,
    trace_dir: PathBuf,
}

impl Writer {
    /// Creates `path` and the trace folder `<stem>_traces` beside it.
    pub fn create(path: &Path) -> Result<Self> {
        let dir = path.parent().map_or_else(PathBuf::new, Path::to_path_buf);
        let stem = path
            .file_stem()
            .map_or("results".into(), |s| s.to_string_lossy());
        let trace_dir = PathBuf::from(format!("{stem}_traces"));
        std::fs::create_dir_all(dir.join(&trace_dir))
            .with_context(|| format!("cannot create {}", dir.join(&trace_dir).display()))?;
        let file = std::fs::File::create(path)
            .with_context(|| format!("cannot create {}", path.display()))?;
        Ok(Self {
            csv: csv::Writer::from_writer(file),
            dir,
            trace_dir,
        })
    }

    /// Writes the trace of run `run`, returns its path relative to the results file.
    pub fn write_trace(&self, run: usize, trace: &[(f64, f64)]) -> Result<String> {
        let rel = self.trace_dir.join(format!("run_{run:04}.csv"));
        let mut text = format!("{}\n", TRACE_COLUMNS.join(","));
        for (t, w) in trace {
            text.push_str(&format!("{t:.4},{w:.6}\n"));
        }
        let full = self.dir.join(&rel);
        std::fs::write(&full, text).with_context(|| format!("cannot write {}", full.display()))?;
        Ok(rel.to_string_lossy().into_owned())
    }

    /// Appends one row and flushes it to disk.
    pub fn push(&mut self, row: &Row) -> Result<()> {
        self.csv.serialize(row)?;
        self.csv.flush()?;
        Ok(())
    }
}

/// The columns every results row has (`release_azimuth_deg` may be absent: older files).
const COLUMNS: [&str; 14] = [
    "run",
    "condition",
    "bowl_rad_s",
    "precession_rad_s",
    "spin_rad_s",
    "release_radius_m",
    "rim_radius_m",
    "k2",
    "status",
    "residence_s",
    "trace_mean_rad_s",
    "trace_sd_rad_s",
    "trace_path",
    "release_azimuth_deg",
];

/// Reads a results file: the rows with their line numbers (as the file numbers its lines,
/// header included). The file may have passed through a spreadsheet ([`sheet`]).
pub fn read(path: &Path) -> Result<Vec<(usize, Row)>> {
    // A directory opens like a file on Unix and reads as empty: said, with its name.
    if path.is_dir() {
        anyhow::bail!(
            "{} is a directory, not a results file (the CSV `bowl experiment --out` writes)",
            path.display()
        );
    }
    let what = "a results file of bowl experiment";
    let table = Sheet::read(path, what)?;
    table.require(&COLUMNS[..COLUMNS.len() - 1], what)?;
    let mut rows = Vec::new();
    for cells in table.rows() {
        let c = cells?;
        let row = Row {
            run: c.whole("run")?,
            condition: c.whole("condition")?,
            bowl_rad_s: c.number("bowl_rad_s")?,
            precession_rad_s: c.number("precession_rad_s")?,
            spin_rad_s: c.number("spin_rad_s")?,
            release_radius_m: c.number("release_radius_m")?,
            rim_radius_m: c.number("rim_radius_m")?,
            k2: c.number("k2")?,
            status: c.needed("status")?.to_string(),
            residence_s: c.number_or_empty("residence_s")?,
            trace_mean_rad_s: c.number_or_empty("trace_mean_rad_s")?,
            trace_sd_rad_s: c.number_or_empty("trace_sd_rad_s")?,
            trace_path: c.text("trace_path").to_string(),
            release_azimuth_deg: c.number_or_empty("release_azimuth_deg")?,
        };
        rows.push((c.line, row));
    }
    Ok(rows)
}

/// Reads a trace file (columns `t_s` and `bowl_rad_s`, in any case and order), with
/// the results file's reader.
pub fn read_trace(path: &Path) -> Result<Vec<(f64, f64)>> {
    if path.is_dir() {
        anyhow::bail!(
            "cannot read the speed trace {}: it is a directory",
            path.display()
        );
    }
    let table = Sheet::read(path, "the speed trace")?;
    let [t, w] = TRACE_COLUMNS;
    table.require(&TRACE_COLUMNS, "a speed trace")?;
    let mut out = Vec::new();
    for cells in table.rows() {
        let c = cells?;
        out.push((c.number(t)?, c.number(w)?));
    }
    Ok(out)
}

/// The columns of a speed trace, as [`Writer::write_trace`] names them.
const TRACE_COLUMNS: [&str; 2] = ["t_s", "bowl_rad_s"];

/// Mean and standard deviation of the speeds of a trace.
pub fn mean_sd(trace: &[(f64, f64)]) -> Option<(f64, f64)> {
    if trace.is_empty() {
        return None;
    }
    let n = trace.len() as f64;
    let mean = trace.iter().map(|p| p.1).sum::<f64>() / n;
    let var = trace.iter().map(|p| (p.1 - mean).powi(2)).sum::<f64>() / n;
    Some((mean, var.sqrt()))
}

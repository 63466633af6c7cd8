//! `bowl chart scipy --csv FILE`: draws the side-by-side of `tests/scipy/compare.py` (its CSV:
//! `scene,model,who,method,setting,rel_error,rhs_evals,ns_per_call`) as error against RHS
//! evaluations and error against time, for one scene and model.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result, bail};

use super::plot::{Figure, Mark, Series};
use super::workprec::ERROR_FLOOR;

/// One row of the comparison CSV.
struct Row {
    scene: String,
    model: String,
    who: String,
    method: String,
    rel_error: f64,
    rhs_evals: f64,
    ns_per_call: f64,
}

fn read(path: &Path) -> Result<Vec<Row>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .context("empty comparison CSV")?
        .split(',')
        .collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .with_context(|| format!("{}: no column `{name}`", path.display()))
    };
    let (c_scene, c_model, c_who, c_method) =
        (col("scene")?, col("model")?, col("who")?, col("method")?);
    let (c_err, c_ev, c_ns) = (col("rel_error")?, col("rhs_evals")?, col("ns_per_call")?);
    let mut rows = Vec::new();
    for (n, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != header.len() {
            bail!(
                "{} line {}: {} cells, header has {}",
                path.display(),
                n + 2,
                cells.len(),
                header.len()
            );
        }
        // Empty or unparsable numbers become NaN: a gap in the chart, not an error.
        let num = |c: usize| cells[c].parse::<f64>().unwrap_or(f64::NAN);
        rows.push(Row {
            scene: cells[c_scene].into(),
            model: cells[c_model].into(),
            who: cells[c_who].into(),
            method: cells[c_method].into(),
            rel_error: num(c_err),
            rhs_evals: num(c_ev),
            ns_per_call: num(c_ns),
        });
    }
    Ok(rows)
}

/// Which cost on the x axis.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Cost {
    /// RHS evaluations (the fair comparison of methods).
    RhsEvals,
    /// Time per call (mostly the interpreter's overhead for scipy).
    Time,
}

/// The comparison chart of `scene`/`model` from the CSV at `path`.
pub fn figure(path: &Path, scene: &str, model: &str, cost: Cost) -> Result<Figure> {
    let rows = read(path)?;
    let mut groups: BTreeMap<(String, String), Vec<(f64, f64)>> = BTreeMap::new();
    for r in rows.iter().filter(|r| r.scene == scene && r.model == model) {
        let x = match cost {
            Cost::RhsEvals => r.rhs_evals,
            Cost::Time => r.ns_per_call,
        };
        let y = if r.rel_error.is_nan() {
            f64::NAN
        } else {
            r.rel_error.max(ERROR_FLOOR)
        };
        groups
            .entry((r.who.clone(), r.method.clone()))
            .or_default()
            .push((x, y));
    }
    if groups.is_empty() {
        bail!(
            "{}: no rows for scene `{scene}`, model `{model}`",
            path.display()
        );
    }
    let series = groups
        .into_iter()
        .enumerate()
        .map(|(i, ((who, method), mut pts))| {
            // Settings run from loose to tight: order by error, descending.
            pts.sort_by(|a, b| b.1.total_cmp(&a.1));
            Series {
                name: format!("{who} {method}"),
                points: pts,
                mark: if who == "ours" {
                    Mark::LinePoints
                } else {
                    Mark::DashedPoints
                },
                color: i,
            }
        })
        .collect();
    let (x_label, note) = match cost {
        Cost::RhsEvals => (
            "right-hand-side evaluations",
            "RHS evaluations: the fair comparison of methods",
        ),
        Cost::Time => (
            "time per call (ns)",
            "time: scipy's is mostly Python interpreter overhead",
        ),
    };
    Ok(Figure::error_in_t(
        format!("scipy solve_ivp against ours: scene {scene}, {model} model"),
        x_label,
        series,
        vec![
            note.into(),
            "scipy: rtol = tol, atol = tol R, terminal event r = R".into(),
            "ours: f64 DP5(4) (same tolerances) and RK4".into(),
            "error against the same 256-bit reference".into(),
        ],
    ))
}

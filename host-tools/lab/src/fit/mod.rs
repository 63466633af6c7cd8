//! The effective rolling resistance `mu` of each candidate model (and the granule's `k2` too
//! when asked) from measured residence times, its 95 % interval, the residuals per condition, and
//! which model the data supports (AIC). Method and limits: docs/experiment.md; the command is
//! `bowl fit`.

pub mod charts;
pub mod joint;
pub mod models;
pub mod robust;
pub mod stats;
pub mod tilt;
pub mod walls;

use std::path::Path;

use anyhow::{Result, bail};
use serde::Serialize;
use serde_json::json;

use crate::results::{self, STATUS_OK};
use models::{
    BowlRun, CANDIDATES, Candidate, Equation, Method, Run, STEADY_REL_SD, mu_ceiling_for, predict,
    predict_with_k2,
};
use stats::{AIC_DECISIVE, aic, crossing, minimise, t_quantile_975};

/// The rig's axes angle unless told otherwise, degrees (the controller's default, paper Eq. 2).
pub const DEFAULT_AXES_ANGLE_DEG: f64 = 60.0;

/// A run left out, and why.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Excluded {
    /// Line of the results file (header = 1).
    pub row: usize,
    /// Plain words.
    pub reason: String,
}

/// What the fit did with `k2`.
#[derive(Debug, Clone, PartialEq)]
pub enum K2 {
    /// Taken from the results file.
    Given,
    /// Fitted with `mu`: estimate and 95 % interval.
    Fitted(f64, (f64, f64)),
    /// Asked for, but could not be fitted (plain words); `mu` is the one-parameter fit's.
    NotFitted(String),
}

/// The fit of one model.
#[derive(Debug, Clone)]
pub struct ModelFit {
    /// The candidate.
    pub candidate: Candidate,
    /// Estimate.
    pub mu: f64,
    /// 95 % interval.
    pub mu_ci95: (f64, f64),
    /// Root mean square of the relative errors, %.
    pub rms_error_pct: f64,
    /// Akaike information criterion.
    pub aic: f64,
    /// Relative error of each run, % (prediction minus measurement, over the measurement).
    pub errors_pct: Vec<f64>,
    /// The granule's `k2`.
    pub k2: K2,
    /// The best `mu` is the search's upper limit (the largest at which every run still
    /// leaves): the model does not describe these runs, whatever its interval says.
    pub at_limit: bool,
    /// Why the model cannot reproduce the runs (never preferred then); `None`: it can.
    pub cannot_reproduce: Option<String>,
}

/// The whole fit.
#[derive(Debug, Clone)]
pub struct Fit {
    /// Usable runs.
    pub runs: Vec<Run>,
    /// Runs left out.
    pub excluded: Vec<Excluded>,
    /// Runs left out as outliers.
    pub outliers: Vec<robust::Outlier>,
    /// One per candidate, in [`CANDIDATES`] order.
    pub models: Vec<ModelFit>,
    /// The preferred candidate's name, `undecided`, or `none` (no model reproduces the runs).
    pub preferred: &'static str,
    /// Which bowl wall the times prefer, in words (`None`: no bowl wall fitted).
    pub walls: Option<walls::WallVerdict>,
}

/// Loads the usable runs of a results file; every other row is excluded with its reason.
pub fn load(path: &Path) -> Result<(Vec<Run>, Vec<Excluded>)> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut runs = Vec::new();
    let mut excluded = Vec::new();
    for (line, row) in results::read(path)? {
        let mut exclude = |reason: String| excluded.push(Excluded { row: line, reason });
        // A status typed by hand ("OK", "Ok") means ok: header names match whatever their case too.
        if !row.status.eq_ignore_ascii_case(STATUS_OK) {
            exclude(match row.status.split_once(':') {
                Some((kind, detail)) => format!("{}: {}", words(kind), detail.trim()),
                None => words(&row.status).to_string(),
            });
            continue;
        }
        let t = match row.residence_s {
            None => {
                exclude("no exit gate event (residence time missing)".into());
                continue;
            }
            Some(t) if t.is_nan() => {
                exclude("residence time is not a number (NaN)".into());
                continue;
            }
            Some(t) if t <= 0.0 => {
                exclude(format!(
                    "residence time {t} s: a release takes a positive time (the exit gate fires \
                     after the release gate)"
                ));
                continue;
            }
            Some(t) => t,
        };
        let geometry_ok = row.release_radius_m >= 0.0
            && row.rim_radius_m > row.release_radius_m
            && row.k2 > 0.0
            && row.k2 <= 1.0;
        if !geometry_ok {
            exclude(format!(
                "release radius {} m, rim {} m, k2 {}: need 0 <= release < rim and 0 < k2 <= 1",
                row.release_radius_m, row.rim_radius_m, row.k2
            ));
            continue;
        }
        let trace = match results::read_trace(&dir.join(&row.trace_path)) {
            Ok(t) if !t.is_empty() => t,
            _ => {
                exclude(format!("speed trace {} missing or empty", row.trace_path));
                continue;
            }
        };
        let Some((mean, sd)) = results::mean_sd(&trace).filter(|(m, _)| *m > 0.0) else {
            exclude("the bowl was not turning during the run".into());
            continue;
        };
        let azimuth_rad = match row.release_azimuth_deg {
            Some(deg) if !deg.is_finite() => {
                exclude(format!(
                    "release azimuth {deg} degrees is not a number: give the angle from the \
                     downhill direction in degrees, or leave it empty"
                ));
                continue;
            }
            deg => deg.map(f64::to_radians),
        };
        let method = if sd <= STEADY_REL_SD * mean {
            Method::ClosedForm
        } else {
            Method::Integrated
        };
        runs.push(Run {
            row: line,
            condition: row.condition,
            residence_s: t,
            mean_rad_s: mean,
            release_radius_m: row.release_radius_m,
            rim_radius_m: row.rim_radius_m,
            k2: row.k2,
            trace,
            method,
            axes_angle_rad: DEFAULT_AXES_ANGLE_DEG.to_radians(),
            bowl: BowlRun {
                speeds_rad_s: Some([row.precession_rad_s, row.spin_rad_s]),
                azimuth_rad,
                planned_rad_s: Some(row.bowl_rad_s),
                ..BowlRun::default()
            },
        });
    }
    Ok((runs, excluded))
}

fn words(status: &str) -> String {
    match status {
        results::STATUS_NEVER_LEFT => "the granule never left the bowl".into(),
        results::STATUS_NOT_SETTLED => "the speeds never settled (stalled or weak motor)".into(),
        results::STATUS_MOTOR_FAULT => "the controller stopped the motors on a fault".into(),
        // A word a person typed (e.g. "excluded" to drop a run): quoted, with the rule, so the
        // line says both that it was meant and why it left the fit.
        other => format!(
            "status \"{}\" (only rows whose status is ok are fitted)",
            other.trim()
        ),
    }
}

/// Sum of squared errors of `runs` under `equation` at `mu`, s^2.
pub fn sse(runs: &[Run], equation: Equation, mu: f64) -> f64 {
    let squared = |r: &Run| (predict(r, equation, mu) - r.residence_s).powi(2);
    match equation {
        Equation::Paper(_) => runs.iter().map(squared).sum(),
        // The rolling and bowl models integrate twelve releases per run (milliseconds each):
        // spread the runs over the cores; summed in order, so the same sum as one core's.
        Equation::Rolling | Equation::Bowl(_) => {
            crate::parallel::parallel(runs, squared).iter().sum()
        }
    }
}

/// Fits one model (needs at least 3 runs); with `fit_k2`, `k2` as well (at least 4).
pub fn fit_model(runs: &[Run], candidate: Candidate, fit_k2: bool) -> ModelFit {
    let one = fit_mu(runs, candidate);
    if !fit_k2 {
        return one;
    }
    let model = candidate.equation;
    let ceiling = mu_ceiling(runs, model);
    let k2_start = runs.iter().map(|r| r.k2).sum::<f64>() / runs.len() as f64;
    match joint::fit_mu_k2(runs, model, (one.mu, k2_start), ceiling) {
        Ok(j) => {
            let n = runs.len();
            let errors_pct: Vec<f64> = runs
                .iter()
                .map(|r| {
                    100.0 * (predict_with_k2(r, model, j.mu, j.k2) - r.residence_s) / r.residence_s
                })
                .collect();
            ModelFit {
                candidate,
                mu: j.mu,
                mu_ci95: j.mu_ci95,
                rms_error_pct: rms(&errors_pct),
                // mu, k2 and the noise.
                aic: aic(j.sse, n, 3),
                errors_pct,
                k2: K2::Fitted(j.k2, j.k2_ci95),
                at_limit: at_limit(j.mu, ceiling),
                cannot_reproduce: None,
            }
        }
        Err(e) => ModelFit {
            k2: K2::NotFitted(e.words()),
            ..one
        },
    }
}

/// The largest `mu` at which every run can still leave under `equation`: the fits' search limit.
fn mu_ceiling(runs: &[Run], equation: Equation) -> f64 {
    runs.iter()
        .map(|r| mu_ceiling_for(r, equation))
        .fold(f64::INFINITY, f64::min)
}

/// Whether `mu` sits at the search limit (the model does not describe the runs).
fn at_limit(mu: f64, ceiling: f64) -> bool {
    mu >= ceiling * (1.0 - 1e-9)
}

fn rms(errors_pct: &[f64]) -> f64 {
    (errors_pct.iter().map(|e| e * e).sum::<f64>() / errors_pct.len() as f64).sqrt()
}

/// Fits `mu` alone, `k2` from the results file.
fn fit_mu(runs: &[Run], candidate: Candidate) -> ModelFit {
    let n = runs.len();
    let model = candidate.equation;
    let ceiling = mu_ceiling(runs, model);
    let s = |mu: f64| sse(runs, model, mu);
    let mu = minimise(&s, 0.0, ceiling);
    let s_min = s(mu);
    let t = t_quantile_975(n - 1);
    let level = s_min * (1.0 + t * t / (n - 1) as f64);
    let lo = if s(0.0) <= level {
        0.0
    } else {
        crossing(&s, level, mu, 0.0)
    };
    let hi = crossing(&s, level, mu, ceiling);
    let errors_pct: Vec<f64> = runs
        .iter()
        .map(|r| 100.0 * (predict(r, model, mu) - r.residence_s) / r.residence_s)
        .collect();
    ModelFit {
        candidate,
        mu,
        mu_ci95: (lo, hi),
        rms_error_pct: rms(&errors_pct),
        aic: aic(s_min, n, 2),
        errors_pct,
        k2: K2::Given,
        // The bowl model's T stops depending on mu_s once every release rolls throughout (a
        // plateau up to the search limit): a best mu_s there says "at least the interval's
        // lower end", not that the model fails.
        at_limit: at_limit(mu, ceiling) && !matches!(model, Equation::Bowl(_)),
        cannot_reproduce: None,
    }
}

/// The model whose AIC is lower than every other's by more than [`AIC_DECISIVE`], else
/// "undecided". A model that cannot reproduce the runs takes no part.
fn preferred_by_aic(models: &[ModelFit]) -> &'static str {
    if !models.is_empty() && models.iter().all(|m| m.cannot_reproduce.is_some()) {
        return "none";
    }
    let mut by_aic: Vec<&ModelFit> = models
        .iter()
        .filter(|m| m.aic.is_finite() && m.cannot_reproduce.is_none())
        .collect();
    by_aic.sort_by(|a, b| a.aic.total_cmp(&b.aic));
    match by_aic.as_slice() {
        [best] => best.candidate.name,
        [best, next, ..] if next.aic - best.aic > AIC_DECISIVE => best.candidate.name,
        _ => "undecided",
    }
}

/// Fits every candidate of [`CANDIDATES`] (with `fit_k2`, `k2` too) and decides between them
/// by AIC.
pub fn fit(runs: Vec<Run>, excluded: Vec<Excluded>, fit_k2: bool) -> Result<Fit> {
    fit_candidates(runs, excluded, &CANDIDATES, fit_k2)
}

/// Fits the given candidates and decides between them by AIC.
pub fn fit_candidates(
    runs: Vec<Run>,
    excluded: Vec<Excluded>,
    candidates: &[Candidate],
    fit_k2: bool,
) -> Result<Fit> {
    if let Some(why) = robust::impossible(&runs) {
        bail!("{why}");
    }
    let (runs, outliers) = robust::screen(runs);
    if runs.len() < 3 {
        bail!(
            "{} ({} excluded, {}): the fit needs at least 3 (two parameters, mu and the \
             timing noise, and one degree of freedom for the interval)",
            crate::number::count(runs.len(), "usable run", "usable runs"),
            excluded.len(),
            crate::number::count(outliers.len(), "outlier", "outliers")
        );
    }
    if let Some(why) = robust::one_measurement(&runs) {
        bail!("{why}");
    }
    let mut models: Vec<ModelFit> = candidates
        .iter()
        .map(|&c| fit_model(&runs, c, fit_k2))
        .collect();
    let marks = robust::cannot_reproduce(&models, &runs);
    for (m, why) in models.iter_mut().zip(marks) {
        m.cannot_reproduce = why;
    }
    let preferred = preferred_by_aic(&models);
    let walls = walls::verdict(&runs, &models);
    Ok(Fit {
        runs,
        excluded,
        outliers,
        models,
        preferred,
        walls,
    })
}

/// Why the AIC cannot prefer a model, when the runs themselves say it: all in one condition,
/// where each one-parameter model refits `mu` to the same mean time (the models are told apart
/// by how `T` changes with speed, docs/experiment.md "Design"). `None` when the runs span
/// conditions, or with the bowl walls (a recorded azimuth separates them at one speed).
pub fn undecided_why(fit: &Fit) -> Option<String> {
    let first = fit.runs.first()?;
    let one_condition = fit.runs.iter().all(|r| r.condition == first.condition);
    let bowl = fit
        .models
        .iter()
        .any(|m| matches!(m.candidate.equation, Equation::Bowl(_)));
    if fit.preferred != "undecided" || !one_condition || bowl {
        return None;
    }
    let mean = fit.runs.iter().map(|r| r.mean_rad_s).sum::<f64>() / fit.runs.len() as f64;
    Some(format!(
        "every run is at one condition ({mean:.3} rad/s): refitting mu makes the models agree \
         at one speed, and only how T changes with speed tells them apart; add conditions at \
         other speeds (bowl experiment --suggest chooses them)"
    ))
}

/// The JSON of the fit (the shape docs/experiment.md gives).
pub fn to_json(fit: &Fit) -> serde_json::Value {
    let mut models = serde_json::Map::new();
    for m in &fit.models {
        let mut model = json!({
            "mu": m.mu,
            "mu_ci95": [m.mu_ci95.0, m.mu_ci95.1],
            "rms_error_pct": m.rms_error_pct,
            "aic": m.aic,
        });
        match &m.k2 {
            K2::Given => {}
            K2::Fitted(k2, ci) => {
                model["k2"] = json!(k2);
                model["k2_ci95"] = json!([ci.0, ci.1]);
            }
            K2::NotFitted(why) => model["k2_not_fitted"] = json!(why),
        }
        if m.at_limit {
            model["at_search_limit"] = json!(true);
        }
        if let Some(why) = &m.cannot_reproduce {
            model["cannot_reproduce"] = json!(why);
        }
        models.insert(m.candidate.name.into(), model);
    }
    let mut out = json!({
        "models": models,
        "preferred": fit.preferred,
        "runs": fit.runs.len(),
        "excluded": fit.excluded,
        "outliers": fit.outliers,
    });
    if let Some(v) = &fit.walls {
        out["walls"] = walls::to_json(v);
    }
    out
}

/// Per condition: mean measured speed, mean and standard error of the measured time, and the
/// mean error of each model, %.
pub fn condition_table(fit: &Fit) -> crate::chart::table::Table {
    let mut header = vec!["condition", "runs", "bowl_rad_s", "t_mean_s", "t_se_s"];
    let names: Vec<String> = fit
        .models
        .iter()
        .map(|m| format!("{}_mean_error_pct", m.candidate.name))
        .collect();
    header.extend(names.iter().map(String::as_str));
    let mut table = crate::chart::table::Table::new(&header);
    let mut conditions: Vec<usize> = fit.runs.iter().map(|r| r.condition).collect();
    conditions.sort_unstable();
    conditions.dedup();
    for c in conditions {
        let idx: Vec<usize> = (0..fit.runs.len())
            .filter(|&i| fit.runs[i].condition == c)
            .collect();
        let n = idx.len() as f64;
        let mean = |f: &dyn Fn(usize) -> f64| idx.iter().map(|&i| f(i)).sum::<f64>() / n;
        let t_mean = mean(&|i| fit.runs[i].residence_s);
        let t_se = if idx.len() > 1 {
            (idx.iter()
                .map(|&i| (fit.runs[i].residence_s - t_mean).powi(2))
                .sum::<f64>()
                / (n - 1.0)
                / n)
                .sqrt()
        } else {
            f64::NAN
        };
        let mut row = vec![
            c.to_string(),
            idx.len().to_string(),
            format!("{:.4}", mean(&|i| fit.runs[i].mean_rad_s)),
            format!("{t_mean:.4}"),
            // One run has no standard error, a model that cannot reproduce a run no error:
            // empty cells, never NaN or inf.
            if t_se.is_finite() {
                format!("{t_se:.4}")
            } else {
                String::new()
            },
        ];
        for m in &fit.models {
            let e = mean(&|i| m.errors_pct[i]);
            row.push(if e.is_finite() {
                format!("{e:+.2}")
            } else {
                String::new()
            });
        }
        table.row(row);
    }
    table
}

#[cfg(test)]
pub(crate) mod tests;

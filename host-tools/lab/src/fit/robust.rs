//! What the fit refuses, drops and marks before and after least squares:
//!
//! * **refused**: an `ok` row whose residence time no release can have. Both rigs give a release
//!   up after [`RIG_GIVE_UP_S`] (status `never_left`), so a recorded time above it (1e300 s, a
//!   typing slip of a unit) is not a measurement; nor is one below the time the fastest possible
//!   release takes (`models::shortest_residence_s`: no friction, gravity and the frame's forces
//!   at full strength; a time in ms typed as s). The fit stops and names every such row.
//! * **outliers**: a release far from what the other releases say. Each paper model (flat,
//!   Coriolis) is fitted by least absolute deviations, which one wild value cannot drag; the
//!   model that fits best in that sense gives each run's relative residual; the residuals' scale
//!   is the MAD (`1.4826 median |r - median r|`, floored at [`SCALE_FLOOR`] so noise-free data
//!   do not make every rounding an outlier). A run more than [`OUTLIER_CUT`] scales from the
//!   median is an outlier: reported with its row, value and why, and left out of the fit. For
//!   Gaussian timing noise that cut drops a good run with probability about 6e-7.
//!   A condition all of whose runs (two or more) the screen would leave out is kept whole: runs
//!   that agree among themselves are a measurement, and it is the model that misses them (every
//!   time typed as 5.5 s left a whole condition out as "outliers", one of them "5.5000 s where
//!   the other runs say 5.5000 s").
//! * **cannot reproduce**: a model whose RMS error is over [`REPRODUCE_FLOOR_PCT`] % and over
//!   [`REPRODUCE_RATIO`] times the best model's (the rolling model on Coriolis data: 29 %
//!   against 0.4 %) or the runs' own scatter between repeats of a condition (a lack of fit no
//!   mu can mend: every time 5.5 s, 70 % against none) is marked and never preferred, whatever
//!   its AIC; when every model is, none is preferred.
//! * **one measurement**: every run at one condition with the same time to the microsecond (rows
//!   filled down or pasted over): no scatter between them, so no interval or preference can
//!   be had; the fit used to report `mu_s` 0.379 [0.379, 0.379] and a wall 64 AIC ahead.

use serde::Serialize;

use super::ModelFit;
use super::models::{
    CANDIDATES, Equation, Run, fastest_rad_s, mu_ceiling_for, predict, shortest_residence_s,
};
use super::stats::minimise;

/// The longest a release can last on either rig before it is recorded as `never_left`, s.
pub const RIG_GIVE_UP_S: f64 = 60.0;
/// Robust scales from the median beyond which a run is an outlier.
pub const OUTLIER_CUT: f64 = 5.0;
/// Smallest robust scale of the relative residuals (0.1 %).
pub const SCALE_FLOOR: f64 = 1e-3;
/// Fewest runs for which outliers are looked for (a median of fewer says little).
pub const MIN_RUNS_TO_SCREEN: usize = 5;
/// A model whose RMS error is this many times the best model's ...
pub const REPRODUCE_RATIO: f64 = 5.0;
/// ... and above this, %, cannot reproduce the runs.
pub const REPRODUCE_FLOOR_PCT: f64 = 5.0;

/// A run left out as an outlier.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Outlier {
    /// Line of the results file (header = 1).
    pub row: usize,
    /// Its residence time, s.
    pub value: f64,
    /// Its mean measured combined speed, rad/s (where Fig. 7 draws it).
    pub mean_rad_s: f64,
    /// Plain words.
    pub why: String,
}

/// The rows whose residence time no release can have, in words; `None` when there are none.
pub fn impossible(runs: &[Run]) -> Option<String> {
    let too_long: Vec<String> = runs
        .iter()
        .filter(|r| r.residence_s > RIG_GIVE_UP_S)
        .map(|r| format!("line {}: residence time {:e} s", r.row, r.residence_s))
        .collect();
    let too_short: Vec<String> = runs
        .iter()
        .filter_map(|r| {
            let least = shortest_residence_s(r);
            (r.residence_s < least).then(|| {
                let fastest = fastest_rad_s(r);
                format!(
                    "line {}: residence time {:e} s, under the {least:.3} s that the fastest \
                     possible release takes from rest at {} m to the rim at {} m with the bowl \
                     at up to {fastest:.2} rad/s",
                    r.row, r.residence_s, r.release_radius_m, r.rim_radius_m
                )
            })
        })
        .collect();
    let mut said = Vec::new();
    if !too_long.is_empty() {
        said.push(format!(
            "{}: beyond what the rig can record (a release is given up after {RIG_GIVE_UP_S} s \
             and recorded as never_left, so an ok row's time is at most that)",
            too_long.join("; ")
        ));
    }
    if !too_short.is_empty() {
        said.push(format!(
            "{}: shorter than any release can be (gravity and the turning bowl at full strength, \
             with no friction, cannot bring a granule to the rim sooner; no model the fit \
             compares gives less at any mu)",
            too_short.join("; ")
        ));
    }
    if said.is_empty() {
        return None;
    }
    Some(format!(
        "{}. Correct the value (seconds) or delete the row, then fit again.",
        said.join(". ")
    ))
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Splits `runs` into the runs kept and the outliers (with their reasons).
pub fn screen(runs: Vec<Run>) -> (Vec<Run>, Vec<Outlier>) {
    if runs.len() < MIN_RUNS_TO_SCREEN {
        return (runs, Vec::new());
    }
    let rel = |r: &Run, eq: Equation, mu: f64| (predict(r, eq, mu) - r.residence_s) / r.residence_s;
    // Least absolute deviations of each paper model; the better one judges.
    let best = CANDIDATES
        .iter()
        .filter(|c| matches!(c.equation, Equation::Paper(_)))
        .map(|c| {
            let ceiling = runs
                .iter()
                .map(|r| mu_ceiling_for(r, c.equation))
                .fold(f64::INFINITY, f64::min);
            let l1 = |mu: f64| {
                runs.iter()
                    .map(|r| rel(r, c.equation, mu).abs())
                    .sum::<f64>()
            };
            let mu = minimise(&l1, 0.0, ceiling);
            (c, mu, l1(mu))
        })
        .min_by(|a, b| a.2.total_cmp(&b.2));
    let Some((candidate, mu, _)) = best else {
        return (runs, Vec::new());
    };
    let residuals: Vec<f64> = runs
        .iter()
        .map(|r| rel(r, candidate.equation, mu))
        .collect();
    let centre = median(&mut residuals.clone());
    let mut spread: Vec<f64> = residuals.iter().map(|e| (e - centre).abs()).collect();
    let scale = (1.4826 * median(&mut spread)).max(SCALE_FLOOR);
    let z: Vec<f64> = residuals.iter().map(|e| (e - centre) / scale).collect();
    let off = |z: f64| z.abs() > OUTLIER_CUT || !z.is_finite();
    // A condition whose every run (two or more) is off: kept whole (module docs).
    let whole_condition_off = |c: usize| {
        let mut of_c = runs.iter().zip(&z).filter(|(r, _)| r.condition == c);
        of_c.clone().count() >= 2 && of_c.all(|(_, &z)| off(z))
    };
    let kept_whole: Vec<bool> = runs
        .iter()
        .map(|r| whole_condition_off(r.condition))
        .collect();
    let mut kept = Vec::new();
    let mut outliers = Vec::new();
    for ((run, z), whole) in runs.into_iter().zip(z).zip(kept_whole) {
        if off(z) && !whole {
            let expected = predict(&run, candidate.equation, mu);
            outliers.push(Outlier {
                row: run.row,
                value: run.residence_s,
                mean_rad_s: run.mean_rad_s,
                why: format!(
                    "residence time {:.4} s where the other runs say {:.4} s ({} model, mu \
                     {mu:.4}, fitted robustly): {:.0} robust standard deviations off, the cut is \
                     {OUTLIER_CUT}; left out of the fit",
                    run.residence_s,
                    expected,
                    candidate.name,
                    z.abs()
                ),
            });
        } else {
            kept.push(run);
        }
    }
    (kept, outliers)
}

/// The runs' own scatter: the pooled standard deviation of each run's time about its
/// condition's mean, relative to that mean, %, over the conditions with two runs or more
/// (floored at [`SCALE_FLOOR`]); `None` when no condition has two.
pub fn own_scatter_pct(runs: &[Run]) -> Option<f64> {
    let mut conditions: Vec<usize> = runs.iter().map(|r| r.condition).collect();
    conditions.sort_unstable();
    conditions.dedup();
    let (mut squares, mut dof) = (0.0, 0usize);
    for c in conditions {
        let times: Vec<f64> = runs
            .iter()
            .filter(|r| r.condition == c)
            .map(|r| r.residence_s)
            .collect();
        if times.len() < 2 {
            continue;
        }
        let mean = times.iter().sum::<f64>() / times.len() as f64;
        squares += times.iter().map(|t| (t / mean - 1.0).powi(2)).sum::<f64>();
        dof += times.len() - 1;
    }
    (dof > 0).then(|| 100.0 * (squares / dof as f64).sqrt().max(SCALE_FLOOR))
}

/// For each model, why it cannot reproduce the runs (`None`: it can).
pub fn cannot_reproduce(models: &[ModelFit], runs: &[Run]) -> Vec<Option<String>> {
    let scatter = own_scatter_pct(runs);
    let best = models
        .iter()
        .filter(|m| !m.at_limit && m.rms_error_pct.is_finite())
        .min_by(|a, b| a.rms_error_pct.total_cmp(&b.rms_error_pct));
    models
        .iter()
        .map(|m| {
            if m.at_limit {
                return Some(
                    "its best mu is the largest at which every run still leaves: it does not \
                     describe these runs"
                        .into(),
                );
            }
            if !m.rms_error_pct.is_finite() {
                return Some("some run never leaves under it".into());
            }
            if m.rms_error_pct <= REPRODUCE_FLOOR_PCT {
                return None;
            }
            if let Some(s) = scatter.filter(|s| m.rms_error_pct > REPRODUCE_RATIO * s) {
                return Some(format!(
                    "its RMS error {:.1} % is over {REPRODUCE_RATIO} times the runs' own scatter \
                     between repeats of a condition ({s:.2} %): no mu of it gives these times",
                    m.rms_error_pct
                ));
            }
            let b = best?;
            (m.rms_error_pct > REPRODUCE_RATIO * b.rms_error_pct).then(|| {
                format!(
                    "its RMS error {:.1} % is over {REPRODUCE_RATIO} times the {} model's {:.2} \
                     %: it cannot reproduce these runs",
                    m.rms_error_pct, b.candidate.name, b.rms_error_pct
                )
            })
        })
        .collect()
}

/// Why the runs are one measurement, not several: every run is at one condition with the same
/// residence time to the microsecond. A gate times each release with its own error, so repeats differ; identical
/// times leave the timing noise at zero and every interval and AIC difference without meaning.
pub fn one_measurement(runs: &[Run]) -> Option<String> {
    let first = runs.first()?;
    // Across conditions the same time is a lack of fit, said by `cannot_reproduce` (every
    // time typed as 5.5 s); at one condition it is one release.
    let same = |r: &Run| {
        (r.residence_s - first.residence_s).abs() < 0.5e-6 && r.condition == first.condition
    };
    if runs.len() < 2 || !runs.iter().all(same) {
        return None;
    }
    Some(format!(
        "all {} usable runs are at one condition with the same residence time, {} s, to the \
         microsecond: a gate's \
         timing differs between releases, so these are one measurement repeated (rows filled \
         down or pasted twice?) and cannot say how sure a fit is; check the results file \
         against the rig's record (a simulated rig needs [particle] gate_jitter_s above 0)",
        runs.len(),
        first.residence_s
    ))
}

#[cfg(test)]
mod tests {
    use model_core::particle::Model;

    use super::super::tests::{Truth, synthetic_runs};
    use super::super::{CANDIDATES, K2, ModelFit, fit_candidates};
    use super::*;

    /// The rig in numbers: Coriolis granules at mu 0.15, 2 ms gate jitter, ten releases
    /// at each of three speeds; rows numbered as in a results file (header = line 1).
    fn rig() -> Vec<Run> {
        let k2 = 5.0 / 7.0;
        let truth = Truth {
            model: Model::Coriolis,
            mu: 0.15,
            k2,
        };
        let mut runs = synthetic_runs(truth, k2, &[6.0, 6.5, 7.0], 10, 0.002, 7);
        for (i, r) in runs.iter_mut().enumerate() {
            r.row = i + 2;
        }
        runs
    }

    /// Run 5's time x10: named as an outlier (its line, its value) and left out; mu stays
    /// within 1 % of the truth.
    #[test]
    fn a_run_times_ten_is_named_and_left_out() {
        let mut runs = rig();
        runs[4].residence_s *= 10.0;
        let value = runs[4].residence_s;
        let f = fit_candidates(runs, Vec::new(), &CANDIDATES[..2], false).unwrap();
        assert_eq!(f.outliers.len(), 1, "{:?}", f.outliers);
        assert_eq!(f.outliers[0].row, 6);
        assert_eq!(f.outliers[0].value, value);
        assert!(f.outliers[0].why.contains("robust standard deviations"));
        assert_eq!(f.runs.len(), 29);
        let mu = f.models[1].mu;
        assert!((mu - 0.15).abs() < 0.0015, "coriolis mu {mu}");
    }

    /// Clean runs lose none.
    #[test]
    fn clean_runs_have_no_outliers() {
        for seed in 0..20 {
            let truth = Truth {
                model: Model::Flat,
                mu: 0.03,
                k2: 5.0 / 7.0,
            };
            let runs = synthetic_runs(truth, 5.0 / 7.0, &[2.9, 3.5, 4.2], 10, 0.002, seed);
            let (kept, out) = screen(runs);
            assert!(out.is_empty(), "seed {seed}: {out:?}");
            assert_eq!(kept.len(), 30);
        }
    }

    /// 1e300 s is refused with its line, the limit and what to do.
    #[test]
    fn an_impossible_time_is_refused_with_its_row() {
        let mut runs = rig();
        runs[4].residence_s = 1e300;
        let e = fit_candidates(runs, Vec::new(), &CANDIDATES[..2], false)
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 6: residence time 1e300 s"), "{e}");
        assert!(e.contains("60 s") && e.contains("Correct the value"), "{e}");
    }

    /// 1 ms (a time in ms typed as s) is refused with its line, the bound and what to do; the
    /// rig's own runs are not.
    #[test]
    fn an_impossibly_short_time_is_refused_with_its_row() {
        let mut runs = rig();
        assert_eq!(impossible(&runs), None);
        runs[4].residence_s = 1e-3;
        let least = shortest_residence_s(&runs[4]);
        let e = fit_candidates(runs, Vec::new(), &CANDIDATES[..2], false)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("line 6: residence time 1e-3 s, under the"),
            "{e}"
        );
        assert!(e.contains(&format!("{least:.3} s")), "{e}");
        assert!(
            e.contains("from rest at 0.05 m to the rim at 0.15 m"),
            "{e}"
        );
        assert!(e.contains("shorter than any release can be"), "{e}");
        assert!(e.ends_with("Correct the value (seconds) or delete the row, then fit again."));
        assert!(!e.contains("60 s"), "{e}");
    }

    fn model(name: &'static str, rms: f64, at_limit: bool) -> ModelFit {
        ModelFit {
            candidate: *CANDIDATES.iter().find(|c| c.name == name).unwrap(),
            mu: 0.1,
            mu_ci95: (0.09, 0.11),
            rms_error_pct: rms,
            aic: -100.0,
            errors_pct: Vec::new(),
            k2: K2::Given,
            at_limit,
            cannot_reproduce: None,
        }
    }

    /// The rolling model at 29 % RMS beside Coriolis at 0.37 % is marked; models near the best
    /// are not; a model at the search limit is marked whatever its error.
    #[test]
    fn a_model_that_cannot_reproduce_the_runs_is_marked() {
        // No repeats: the comparison is with the best model alone.
        let marks = cannot_reproduce(
            &[
                model("flat", 0.39, false),
                model("coriolis", 0.37, false),
                model("rolling", 29.2, false),
            ],
            &[],
        );
        assert!(marks[0].is_none() && marks[1].is_none(), "{marks:?}");
        let why = marks[2].as_deref().unwrap();
        assert!(why.contains("29.2 %") && why.contains("coriolis"), "{why}");
        let marks = cannot_reproduce(
            &[model("flat", 0.4, true), model("coriolis", 0.4, false)],
            &[],
        );
        assert!(
            marks[0].as_deref().unwrap().contains("largest"),
            "{marks:?}"
        );
    }

    /// NaN, negative and missing-trace rows are each excluded with their line and own words.
    #[test]
    fn dropped_rows_say_why() {
        use crate::results::{Row, Writer};
        let dir = std::env::temp_dir().join(format!("bowl-fit-dropped-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("r.csv");
        let mut w = Writer::create(&path).unwrap();
        let trace = w.write_trace(1, &[(0.0, 4.0), (0.5, 4.0)]).unwrap();
        let row = |run: usize, t: f64, trace_path: &str| Row {
            run,
            condition: 1,
            bowl_rad_s: 4.0,
            precession_rad_s: 2.3,
            spin_rad_s: 2.3,
            release_radius_m: 0.05,
            rim_radius_m: 0.15,
            k2: 5.0 / 7.0,
            status: "ok".into(),
            residence_s: Some(t),
            trace_mean_rad_s: Some(4.0),
            trace_sd_rad_s: Some(0.0),
            trace_path: trace_path.into(),
            release_azimuth_deg: None,
        };
        w.push(&row(1, f64::NAN, &trace)).unwrap();
        w.push(&row(2, -0.5, &trace)).unwrap();
        w.push(&row(3, 0.6, "r_traces/none.csv")).unwrap();
        w.push(&row(4, 0.6, &trace)).unwrap();
        drop(w);
        let (runs, excluded) = super::super::load(&path).unwrap();
        assert_eq!(runs.len(), 1);
        assert_eq!(runs[0].row, 5);
        let said: Vec<(usize, &str)> = excluded
            .iter()
            .map(|e| (e.row, e.reason.as_str()))
            .collect();
        assert_eq!(said[0], (2, "residence time is not a number (NaN)"));
        assert_eq!(said[1].0, 3);
        assert!(
            said[1]
                .1
                .starts_with("residence time -0.5 s: a release takes a positive time")
        );
        assert_eq!(
            said[2],
            (4, "speed trace r_traces/none.csv missing or empty")
        );
        let _ = std::fs::remove_dir_all(dir);
    }

    /// Four copies of one release (a row filled down): refused in words, not fitted to a
    /// zero-width interval and a wall "preferred" by 64 AIC.
    #[test]
    fn copies_of_one_run_are_refused() {
        let mut runs = rig();
        runs.truncate(4);
        let t = runs[0].residence_s;
        for r in &mut runs {
            r.residence_s = t;
        }
        let e = fit_candidates(runs.clone(), Vec::new(), &CANDIDATES[..2], false)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("all 4 usable runs are at one condition with the same residence time")
                && e.contains("check"),
            "{e}"
        );
        runs[3].residence_s += 1e-6;
        fit_candidates(runs, Vec::new(), &CANDIDATES[..2], false).unwrap();
    }
}

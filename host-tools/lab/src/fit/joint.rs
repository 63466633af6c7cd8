//! `bowl fit --fit-k2`: `mu` and the granule's `k2` together, by Levenberg-Marquardt least
//! squares on the residence times (Marquardt 1963), started from the one-parameter fit and the
//! results file's `k2`.
//!
//! The two are told apart only through the shape of `T(omega)`: `k2` scales how strongly the
//! bowl's speed drives the granule, `mu` how strongly friction holds it, so a plan needs
//! conditions spread in speed (docs/experiment.md). The 95 % intervals are the linearised
//! ones, `estimate +- t(n - 2) se` with the covariance `s^2 (J^T J)^-1`, `s^2 = S / (n - 2)`
//! (Bates and Watts 1988, sec. 2.3): nonlinear models make them approximate, which the
//! coverage test measures.

use super::models::{Equation, Run, predict_with_k2};
use super::stats::t_quantile_975;

/// The smallest `k2` tried (a granule whose rotation takes almost all the energy).
pub const K2_MIN: f64 = 0.05;
/// The largest: a point mass sliding without rotation.
pub const K2_MAX: f64 = 1.0;

/// Iterations allowed; a fit that has not converged by then is reported as not converged.
const ITERATIONS: usize = 200;

/// `mu` and `k2` fitted together.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Joint {
    /// Estimate of `mu`.
    pub mu: f64,
    /// 95 % interval of `mu`.
    pub mu_ci95: (f64, f64),
    /// Estimate of `k2`.
    pub k2: f64,
    /// 95 % interval of `k2`.
    pub k2_ci95: (f64, f64),
    /// Sum of squared errors at the estimate, s^2.
    pub sse: f64,
}

/// Why `k2` could not be fitted.
#[derive(Debug, Clone, PartialEq)]
pub enum JointError {
    /// Fewer than 4 runs: three parameters (mu, k2, the noise) and one degree of freedom.
    TooFewRuns(usize),
    /// Some run never leaves the bowl at the starting point.
    NoStart,
    /// Every speed the same (or nearly): `mu` and `k2` cannot be told apart.
    NotIdentifiable,
}

impl JointError {
    /// Plain words.
    pub fn words(&self) -> String {
        match self {
            Self::TooFewRuns(n) => format!(
                "{}: fitting k2 as well needs at least 4 (mu, k2, the timing noise \
                 and one degree of freedom)",
                crate::number::count(*n, "usable run", "usable runs")
            ),
            Self::NoStart => "some run would never leave at the one-parameter fit's mu".into(),
            Self::NotIdentifiable => {
                "the runs do not tell mu and k2 apart (their speeds are too alike): run \
                 conditions spread over the speed range, or leave k2 at the granule's value"
                    .into()
            }
        }
    }
}

fn residuals(runs: &[Run], equation: Equation, mu: f64, k2: f64) -> Option<Vec<f64>> {
    runs.iter()
        .map(|r| {
            let t = predict_with_k2(r, equation, mu, k2);
            t.is_finite().then_some(t - r.residence_s)
        })
        .collect()
}

fn sum_sq(v: &[f64]) -> f64 {
    v.iter().map(|e| e * e).sum()
}

/// Central differences (one-sided at a bound) of the residuals in `mu` and `k2`.
fn jacobian(
    runs: &[Run],
    equation: Equation,
    mu: f64,
    k2: f64,
    mu_max: f64,
) -> Option<Vec<[f64; 2]>> {
    let h_mu = 1e-5 * mu.max(1e-3);
    let h_k2 = 1e-5;
    let column = |lo: (f64, f64), hi: (f64, f64), h: f64| -> Option<Vec<f64>> {
        let a = residuals(runs, equation, lo.0, lo.1)?;
        let b = residuals(runs, equation, hi.0, hi.1)?;
        Some(a.iter().zip(&b).map(|(a, b)| (b - a) / h).collect())
    };
    let (mu_lo, mu_hi) = ((mu - h_mu).max(0.0), (mu + h_mu).min(mu_max));
    let (k2_lo, k2_hi) = ((k2 - h_k2).max(K2_MIN), (k2 + h_k2).min(K2_MAX));
    let d_mu = column((mu_lo, k2), (mu_hi, k2), mu_hi - mu_lo)?;
    let d_k2 = column((mu, k2_lo), (mu, k2_hi), k2_hi - k2_lo)?;
    Some(d_mu.into_iter().zip(d_k2).map(|(a, b)| [a, b]).collect())
}

/// `J^T J` and `J^T r`.
fn normal_equations(j: &[[f64; 2]], r: &[f64]) -> ([[f64; 2]; 2], [f64; 2]) {
    let mut a = [[0.0; 2]; 2];
    let mut g = [0.0; 2];
    for (row, e) in j.iter().zip(r) {
        for p in 0..2 {
            g[p] += row[p] * e;
            for q in 0..2 {
                a[p][q] += row[p] * row[q];
            }
        }
    }
    (a, g)
}

fn solve2(a: [[f64; 2]; 2], b: [f64; 2]) -> Option<[f64; 2]> {
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    if !(det.is_finite() && det.abs() > 0.0) {
        return None;
    }
    Some([
        (b[0] * a[1][1] - b[1] * a[0][1]) / det,
        (a[0][0] * b[1] - a[1][0] * b[0]) / det,
    ])
}

/// Fits `mu` in `[0, mu_max]` and `k2` in `[K2_MIN, K2_MAX]` from `start` (`mu`, `k2`).
pub fn fit_mu_k2(
    runs: &[Run],
    equation: Equation,
    start: (f64, f64),
    mu_max: f64,
) -> Result<Joint, JointError> {
    let n = runs.len();
    if n < 4 {
        return Err(JointError::TooFewRuns(n));
    }
    let (mut mu, mut k2) = (start.0.clamp(0.0, mu_max), start.1.clamp(K2_MIN, K2_MAX));
    let mut r = residuals(runs, equation, mu, k2).ok_or(JointError::NoStart)?;
    let mut s = sum_sq(&r);
    let mut lambda = 1e-3;
    for _ in 0..ITERATIONS {
        let j = jacobian(runs, equation, mu, k2, mu_max).ok_or(JointError::NoStart)?;
        let (a, g) = normal_equations(&j, &r);
        let mut improved = false;
        while lambda < 1e12 {
            let damped = [
                [a[0][0] * (1.0 + lambda), a[0][1]],
                [a[1][0], a[1][1] * (1.0 + lambda)],
            ];
            let Some(step) = solve2(damped, [-g[0], -g[1]]) else {
                lambda *= 10.0;
                continue;
            };
            let next = (
                (mu + step[0]).clamp(0.0, mu_max),
                (k2 + step[1]).clamp(K2_MIN, K2_MAX),
            );
            match residuals(runs, equation, next.0, next.1) {
                Some(rn) if sum_sq(&rn) < s => {
                    let sn = sum_sq(&rn);
                    let small = s - sn <= 1e-12 * s;
                    (mu, k2, r, s) = (next.0, next.1, rn, sn);
                    lambda = (lambda / 10.0).max(1e-12);
                    improved = !small;
                    break;
                }
                _ => lambda *= 10.0,
            }
        }
        if !improved {
            break;
        }
    }
    let j = jacobian(runs, equation, mu, k2, mu_max).ok_or(JointError::NoStart)?;
    let (a, _) = normal_equations(&j, &r);
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    // Nearly parallel columns: the speeds cannot separate the two effects.
    if !(det.is_finite() && det > 1e-10 * a[0][0] * a[1][1]) {
        return Err(JointError::NotIdentifiable);
    }
    let s2 = s / (n - 2) as f64;
    let t = t_quantile_975(n - 2);
    let se_mu = (s2 * a[1][1] / det).sqrt();
    let se_k2 = (s2 * a[0][0] / det).sqrt();
    Ok(Joint {
        mu,
        mu_ci95: ((mu - t * se_mu).max(0.0), mu + t * se_mu),
        k2,
        k2_ci95: ((k2 - t * se_k2).max(0.0), (k2 + t * se_k2).min(K2_MAX)),
        sse: s,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::tests::{Truth, synthetic_runs};
    use model_core::particle::Model;

    /// The results file's k2 (a solid sphere); the truth below is another granule.
    const K2_FILE: f64 = 5.0 / 7.0;
    const K2_TRUE: f64 = 0.55;
    const MU_TRUE: f64 = 0.03;

    /// `per_speed` releases at each of `speeds` of a granule with [`K2_TRUE`] and [`MU_TRUE`],
    /// timed with Gaussian noise `sigma_s`; the rows say [`K2_FILE`].
    fn runs(model: Model, speeds: &[f64], per_speed: usize, sigma_s: f64, seed: u32) -> Vec<Run> {
        let truth = Truth {
            model,
            mu: MU_TRUE,
            k2: K2_TRUE,
        };
        synthetic_runs(truth, K2_FILE, speeds, per_speed, sigma_s, seed)
    }

    /// Over 100 data sets of 20 runs spread from 2.6 to 5 rad/s the 95 % intervals of both
    /// parameters cover the truth at least 88 times (the binomial(100, 0.95) range holding
    /// 99.7 %), and the mean estimates lie within 3 standard errors of the truth.
    #[test]
    fn k2_and_mu_are_recovered_within_their_intervals() {
        let speeds = [2.6, 3.0, 3.5, 4.2, 5.0];
        for model in [Model::Flat, Model::Coriolis] {
            let (mut covered_mu, mut covered_k2) = (0, 0);
            let (mut mus, mut k2s) = (Vec::new(), Vec::new());
            for seed in 0..100 {
                let data = runs(model, &speeds, 4, 0.002, seed);
                let j = fit_mu_k2(&data, Equation::Paper(model), (0.02, K2_FILE), 0.05).unwrap();
                covered_mu += usize::from(j.mu_ci95.0 <= MU_TRUE && MU_TRUE <= j.mu_ci95.1);
                covered_k2 += usize::from(j.k2_ci95.0 <= K2_TRUE && K2_TRUE <= j.k2_ci95.1);
                mus.push(j.mu);
                k2s.push(j.k2);
            }
            for (name, xs, truth, covered) in [
                ("mu", &mus, MU_TRUE, covered_mu),
                ("k2", &k2s, K2_TRUE, covered_k2),
            ] {
                let n = xs.len() as f64;
                let mean = xs.iter().sum::<f64>() / n;
                let sd = (xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
                println!("{model:?} {name}: covered {covered}/100, mean {mean:.5}, sd {sd:.5}");
                assert!(covered >= 88, "{model:?} {name}: covered {covered} of 100");
                assert!(
                    (mean - truth).abs() < 3.0 * sd / n.sqrt(),
                    "{model:?} {name}: mean {mean}, sd {sd}, truth {truth}"
                );
            }
        }
    }

    /// `bowl fit --fit-k2 --json` adds `k2` and its interval to each model, or why not.
    #[test]
    fn the_json_carries_k2_or_why_not() {
        use crate::fit::{CANDIDATES, fit_candidates, to_json};
        let data = runs(Model::Coriolis, &[2.6, 3.5, 5.0], 3, 0.002, 7);
        let json = to_json(&fit_candidates(data, Vec::new(), &CANDIDATES[..2], true).unwrap());
        let k2 = json["models"]["coriolis"]["k2"].as_f64().unwrap();
        let ci = &json["models"]["coriolis"]["k2_ci95"];
        assert!((k2 - K2_TRUE).abs() < 0.01, "{json}");
        assert!(
            ci[0].as_f64().unwrap() < k2 && k2 < ci[1].as_f64().unwrap(),
            "{json}"
        );
        let one = runs(Model::Coriolis, &[3.5], 5, 0.002, 7);
        let json = to_json(&fit_candidates(one, Vec::new(), &CANDIDATES[..2], true).unwrap());
        let why = json["models"]["flat"]["k2_not_fitted"].as_str().unwrap();
        assert!(why.contains("too alike"), "{json}");
        assert!(json["models"]["flat"].get("k2").is_none(), "{json}");
    }

    /// At one speed the two effects cannot be told apart: said in words, not a wild estimate.
    #[test]
    fn one_speed_cannot_separate_mu_and_k2() {
        let data = runs(Model::Coriolis, &[3.5], 8, 0.002, 1);
        let e = fit_mu_k2(
            &data,
            Equation::Paper(Model::Coriolis),
            (0.03, K2_FILE),
            0.05,
        )
        .unwrap_err();
        assert_eq!(e, JointError::NotIdentifiable);
        assert!(e.words().contains("too alike"), "{}", e.words());
        let few = runs(Model::Flat, &[3.0, 4.0], 1, 0.002, 1);
        let e = fit_mu_k2(&few, Equation::Paper(Model::Flat), (0.03, K2_FILE), 0.05).unwrap_err();
        assert_eq!(e, JointError::TooFewRuns(2));
        assert!(e.words().contains("at least 4"), "{}", e.words());
    }
}

//! `bowl experiment --suggest`: a plan whose conditions separate the two models most, relative
//! to the timing noise, among speeds where granules leave.
//!
//! The fit refits `mu` for each model, so what tells the models apart is not their difference at
//! one `mu` but the difference that survives a refit: the shape of `T(omega)`. For a guessed
//! `mu` we take the flat model's times as the data, fit the Coriolis model's `mu` to them, and
//! count the remaining difference `D = sqrt(sum (T_flat - T_coriolis)^2) / sigma` over the
//! releases (sigma: the gate jitter, at least 1 ms). Conditions are chosen greedily from a grid
//! of speeds between the slowest at which the granule clearly leaves (start radius 1.5 times
//! the equilibrium radius) and the fastest the motors allow, each step adding the speed that
//! raises `D` most. The same `D` decides the AIC (docs/experiment.md): above about 6 the right
//! model is preferred with probability above 98 %.

use model_core::particle::Model;
use model_core::sim::granule::{G_M_S2, ParticleParams};

use crate::fit::models::{Method, Run, closed_form};
use crate::fit::stats::minimise;

/// Speeds tried.
const GRID: usize = 40;

fn run_at(p: &ParticleParams, w: f64) -> Run {
    Run {
        row: 0,
        condition: 0,
        residence_s: 1.0,
        mean_rad_s: w,
        release_radius_m: p.release_radius_m,
        rim_radius_m: p.rim_radius_m,
        k2: p.k2,
        trace: vec![(0.0, w)],
        method: Method::ClosedForm,
        axes_angle_rad: crate::fit::DEFAULT_AXES_ANGLE_DEG.to_radians(),
        bowl: crate::fit::models::BowlRun::default(),
    }
}

/// Separation `D` of a set of speeds (each repeated `repeats` times) for truth flat at `mu`.
pub fn separation(p: &ParticleParams, mu: f64, speeds: &[f64], repeats: usize, sigma: f64) -> f64 {
    let runs: Vec<Run> = speeds.iter().map(|&w| run_at(p, w)).collect();
    let flat: Vec<f64> = runs
        .iter()
        .map(|r| closed_form(r, Model::Flat, mu, r.mean_rad_s))
        .collect();
    let sse = |m: f64| -> f64 {
        runs.iter()
            .zip(&flat)
            .map(|(r, t)| (closed_form(r, Model::Coriolis, m, r.mean_rad_s) - t).powi(2))
            .sum()
    };
    let ceiling = speeds.iter().fold(f64::INFINITY, |c, w| {
        c.min(p.release_radius_m * w * w / G_M_S2)
    });
    let best = minimise(&sse, 0.0, ceiling);
    (repeats as f64 * sse(best)).sqrt() / sigma
}

/// The suggested plan as TOML text, with the reasoning in comments.
pub fn plan_text(
    p: &ParticleParams,
    mu_guess: f64,
    max_bowl_rad_s: f64,
    conditions: usize,
    repeats: usize,
) -> String {
    let sigma = p.gate_jitter_s.max(1e-3);
    let slowest = (1.5 * mu_guess * G_M_S2 / p.release_radius_m).sqrt();
    let grid: Vec<f64> = (0..GRID)
        .map(|i| slowest + (max_bowl_rad_s - slowest) * i as f64 / (GRID - 1) as f64)
        .collect();
    let mut chosen: Vec<f64> = Vec::new();
    while chosen.len() < conditions.min(GRID) {
        let pick = grid
            .iter()
            .filter(|w| !chosen.contains(w))
            .map(|&w| {
                let mut s = chosen.clone();
                s.push(w);
                let d = if s.len() < 2 {
                    w.recip()
                } else {
                    separation(p, mu_guess, &s, repeats, sigma)
                };
                (w, d)
            })
            .max_by(|a, b| a.1.total_cmp(&b.1));
        match pick {
            Some((w, _)) => chosen.push(w),
            None => break,
        }
    }
    chosen.sort_by(f64::total_cmp);
    let d = separation(p, mu_guess, &chosen, repeats, sigma);
    let mut text = format!(
        "# Suggested by bowl experiment --suggest: mu guess {mu_guess}, start {} m, rim {} m, \
         k2 {}, timing noise {sigma} s.\n# Separation of the models after refitting mu: D = \
         {d:.1} (the fit tells them apart reliably above about 6).\nsettle_s = 3.0\n",
        p.release_radius_m, p.rim_radius_m, p.k2
    );
    for w in chosen {
        text.push_str(&format!(
            "\n[[condition]]\nbowl_rad_s = {w:.3}\nrepeats = {repeats}\n"
        ));
    }
    text
}

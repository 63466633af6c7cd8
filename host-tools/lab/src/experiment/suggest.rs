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

use anyhow::{Result, bail};
use model_core::particle::Model;
use model_core::sim::granule::{G_M_S2, ParticleParams};

use crate::experiment::plan;
use crate::fit::models::{Method, Run, closed_form};
use crate::fit::stats::minimise;

/// Speeds tried.
const GRID: usize = 40;

/// The most conditions a suggestion can hold: each is a different speed of the grid.
pub const MAX_CONDITIONS: usize = GRID;

/// The start radius over the equilibrium radius at the slowest speed tried: the granule
/// clearly leaves there under both models.
const SLOWEST_OVER_EQUILIBRIUM: f64 = 1.5;

/// The slowest speed tried for `mu` (rad/s): the one at which the granule starts at 1.5 times
/// its equilibrium radius `mu g / omega^2`.
fn slowest_rad_s(p: &ParticleParams, mu: f64) -> f64 {
    (SLOWEST_OVER_EQUILIBRIUM * mu * G_M_S2 / p.release_radius_m).sqrt()
}

/// The largest `mu` the rig file's `[particle] mu` (and so the simulated rig) accepts.
fn mu_ceiling() -> f64 {
    ParticleParams::default()
        .ranges()
        .iter()
        .find(|r| r.0 == "mu")
        .map_or(1.0, |r| r.3)
}

/// Refuses, in words, every input that would give a plan `bowl experiment` refuses or a
/// non-finite number: checked before any arithmetic, since NaN and infinity pass silently
/// through the search below and come out as `bowl_rad_s = NaN` or `D = inf`.
pub fn check(
    p: &ParticleParams,
    mu_guess: f64,
    max_bowl_rad_s: f64,
    conditions: usize,
    repeats: usize,
) -> Result<()> {
    // The design below is the paper's two models' (flat against Coriolis); on a bowl-model rig
    // it printed a D of 15 between two models that cannot reproduce its times at all, while
    // what tells its walls apart is each release's azimuth (docs/experiment.md).
    if p.bowl.is_some() {
        bail!(
            "--suggest designs a plan that tells the paper's flat and Coriolis models apart; \
             this rig's granules follow the bowl model ([particle] model = \"bowl\"), whose \
             walls the release azimuth tells apart, not the choice of speeds: spread a few \
             conditions over the rig's range (up to {max_bowl_rad_s:.3} rad/s) with ten or more \
             releases each, as docs/experiment/plan-bowl.toml does, and fit the results with \
             `bowl fit RESULTS --rig-file RIG`"
        );
    }
    let mu_max = mu_ceiling();
    // `!(x > 0)` rather than `x <= 0`: NaN fails every comparison and must be refused too.
    if !(mu_guess > 0.0 && mu_guess <= mu_max) {
        let why = if mu_guess == 0.0 {
            ": at 0 the granule leaves at rest, and no range of speeds is left to choose from"
        } else {
            ""
        };
        bail!(
            "--mu-guess {mu_guess}: the guessed rolling resistance must be a number above 0 and \
             at most {mu_max} (the range a rig file's [particle] mu accepts; 0.029 is the \
             paper's){why}"
        );
    }
    if !(max_bowl_rad_s.is_finite() && max_bowl_rad_s > 0.0) {
        bail!(
            "the rig's fastest bowl speed comes out as {max_bowl_rad_s} rad/s: no plan can be \
             suggested for it (check the rig file's motor limits)"
        );
    }
    if p.release_radius_m <= 0.0 {
        bail!(
            "the rig file's [particle] release_radius_m is {} m: a granule at the centre never \
             leaves at any speed, so no plan can be suggested; give a start off the centre",
            p.release_radius_m
        );
    }
    let slowest = slowest_rad_s(p, mu_guess);
    if slowest >= max_bowl_rad_s {
        let mu_fits =
            max_bowl_rad_s.powi(2) * p.release_radius_m / (SLOWEST_OVER_EQUILIBRIUM * G_M_S2);
        bail!(
            "--mu-guess {mu_guess}: the granule would clearly leave only above {slowest:.3} \
             rad/s, beyond the rig's fastest bowl speed ({max_bowl_rad_s:.3} rad/s, 95 % of the \
             motors' limit): give a mu guess below {mu_fits:.4} for this rig (start radius {} m)",
            p.release_radius_m
        );
    }
    if !(1..=MAX_CONDITIONS).contains(&conditions) {
        bail!(
            "--conditions {conditions}: a suggested plan holds 1 to {MAX_CONDITIONS} conditions \
             (each a different one of the {GRID} speeds it tries between {slowest:.3} and \
             {max_bowl_rad_s:.3} rad/s); give a number in that range"
        );
    }
    if !plan::REPEATS.contains(&repeats) {
        bail!(
            "--repeats {repeats}: releases per condition must lie in {} to {} (the range a plan \
             accepts); give a number in that range",
            plan::REPEATS.start(),
            plan::REPEATS.end()
        );
    }
    Ok(())
}

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

/// The suggested plan as TOML text, with the reasoning in comments; the inputs are refused in
/// words first ([`check`]).
pub fn plan_text(
    p: &ParticleParams,
    mu_guess: f64,
    max_bowl_rad_s: f64,
    conditions: usize,
    repeats: usize,
) -> Result<String> {
    check(p, mu_guess, max_bowl_rad_s, conditions, repeats)?;
    let sigma = p.gate_jitter_s.max(1e-3);
    let slowest = slowest_rad_s(p, mu_guess);
    let grid: Vec<f64> = (0..GRID)
        .map(|i| slowest + (max_bowl_rad_s - slowest) * i as f64 / (GRID - 1) as f64)
        .collect();
    let mut chosen: Vec<f64> = Vec::new();
    while chosen.len() < conditions {
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
    // The checks above should leave nothing non-finite; a defect must not print a plan that
    // looks valid.
    if !d.is_finite() {
        bail!(
            "the models' separation came out as D = {d} for --mu-guess {mu_guess}, --conditions \
             {conditions}, --repeats {repeats} (a defect: please report it with the rig file)"
        );
    }
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
    // What is printed must be a plan `bowl experiment` runs (the same reader checks it).
    plan::parse(&text, "the suggested plan")?;
    Ok(text)
}

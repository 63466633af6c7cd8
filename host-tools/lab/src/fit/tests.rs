//! The fit's statistics against known truths: synthetic residence times (closed form plus
//! Gaussian gate noise, no plant) for the statistics, and a small plan on the simulated rig for
//! the whole loop.

use model_core::particle::Model;
use model_core::sim::granule::gaussian;
use model_core::sim::prng::Prng;

use super::models::{Method, Run, closed_form};
use super::*;

const SPEEDS: [f64; 3] = [2.9, 3.5, 4.2];

/// A granule's truth for synthetic runs: its model, `mu` and `k2`.
#[derive(Clone, Copy)]
pub(super) struct Truth {
    pub model: Model,
    pub mu: f64,
    pub k2: f64,
}

/// `per_speed` releases at each of `speeds` of a granule with `truth`, timed with Gaussian noise
/// `sigma_s` (closed form at a steady speed, no plant); the rows say `k2_file`.
pub(super) fn synthetic_runs(
    truth: Truth,
    k2_file: f64,
    speeds: &[f64],
    per_speed: usize,
    sigma_s: f64,
    seed: u32,
) -> Vec<Run> {
    let mut rng = Prng::new(seed);
    let mut runs = Vec::new();
    for (c, &w) in speeds.iter().enumerate() {
        for _ in 0..per_speed {
            let mut run = Run {
                row: 0,
                condition: c + 1,
                residence_s: 0.0,
                mean_rad_s: w,
                release_radius_m: 0.05,
                rim_radius_m: 0.15,
                k2: truth.k2,
                trace: vec![(0.0, w)],
                method: Method::ClosedForm,
                axes_angle_rad: 60f64.to_radians(),
                bowl: models::BowlRun::default(),
            };
            run.residence_s =
                closed_form(&run, truth.model, truth.mu, w) + sigma_s * gaussian(&mut rng);
            run.k2 = k2_file;
            runs.push(run);
        }
    }
    runs
}

/// `per_speed` releases at each of [`SPEEDS`] for the given truth (a solid sphere), noise
/// `sigma_s`.
pub(crate) fn synthetic(
    model: Model,
    mu: f64,
    sigma_s: f64,
    per_speed: usize,
    seed: u32,
) -> Vec<Run> {
    let k2 = 5.0 / 7.0;
    synthetic_runs(
        Truth { model, mu, k2 },
        k2,
        &SPEEDS,
        per_speed,
        sigma_s,
        seed,
    )
}

/// The fit over the paper's two models only: the tests of their behaviour (the rolling model's
/// integration would make a debug build's fits minutes long; [`rolling_truth_is_recognised`]
/// fits all three).
pub(crate) fn fit_paper(runs: Vec<Run>, excluded: Vec<Excluded>) -> anyhow::Result<Fit> {
    super::fit_candidates(runs, excluded, &CANDIDATES[..2], false)
}

pub(crate) fn fitted(fit: &Fit, name: &str) -> ModelFit {
    fit.models
        .iter()
        .find(|m| m.candidate.name == name)
        .unwrap()
        .clone()
}

/// Over 200 synthetic data sets of 12 runs the 95 % interval covers the truth at least 181
/// times (the binomial(200, 0.95) range holding 99.7 %), and the mean estimate lies within
/// 3 standard errors of the mean of the truth (so the bias is well under one standard error
/// of a single fit).
#[test]
fn interval_covers_and_estimate_is_unbiased() {
    for (model, name) in [(Model::Flat, "flat"), (Model::Coriolis, "coriolis")] {
        let mut covered = 0;
        let mut estimates = Vec::new();
        for seed in 0..200 {
            let runs = synthetic(model, 0.03, 0.01, 4, seed);
            let f = fit_paper(runs, Vec::new()).unwrap();
            let m = fitted(&f, name);
            if m.mu_ci95.0 <= 0.03 && 0.03 <= m.mu_ci95.1 {
                covered += 1;
            }
            estimates.push(m.mu);
        }
        let n = estimates.len() as f64;
        let mean = estimates.iter().sum::<f64>() / n;
        let sd = (estimates.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        assert!(covered >= 181, "{name}: covered {covered} of 200");
        assert!(
            (mean - 0.03).abs() < 3.0 * sd / n.sqrt(),
            "{name}: mean {mean}, sd {sd}"
        );
    }
}

/// Where the models differ by several times the noise (2 ms against 8..18 ms at mu 0.03) the
/// fit names the true model; with the truth flat it never prefers Coriolis, at any noise.
#[test]
fn preference_follows_the_truth() {
    for seed in 0..10 {
        let f = fit_paper(synthetic(Model::Coriolis, 0.03, 0.002, 4, seed), Vec::new()).unwrap();
        assert_eq!(f.preferred, "coriolis", "seed {seed}");
        let f = fit_paper(synthetic(Model::Flat, 0.03, 0.002, 4, seed), Vec::new()).unwrap();
        assert_eq!(f.preferred, "flat", "seed {seed}");
        let f = fit_paper(synthetic(Model::Flat, 0.03, 0.02, 4, seed), Vec::new()).unwrap();
        assert_ne!(f.preferred, "coriolis", "seed {seed}");
    }
}

/// Too few runs is a plain error, not a panic.
/// Runs at one speed cannot tell the models apart, and the fit says why; at several speeds it
/// has nothing to explain.
#[test]
fn one_speed_says_why_it_is_undecided() {
    let truth = Truth {
        model: Model::Coriolis,
        mu: 0.03,
        k2: 5.0 / 7.0,
    };
    let one = fit_paper(
        synthetic_runs(truth, truth.k2, &[3.0], 8, 0.002, 3),
        Vec::new(),
    )
    .unwrap();
    assert_eq!(one.preferred, "undecided");
    let why = super::undecided_why(&one).unwrap();
    assert!(why.contains("one condition (3.000 rad/s)"), "{why}");
    let many = fit_paper(synthetic(Model::Coriolis, 0.03, 0.002, 4, 3), Vec::new()).unwrap();
    assert_eq!(super::undecided_why(&many), None);
}

/// Times no mu of either paper model can give (every one typed as 5.5 s, against 0.6-1.1 s):
/// no model is preferred, each says its lack of fit against the runs' own scatter, and no
/// condition is left out whole as "outliers" (10 of 40 were, and the fit then reported a mu).
#[test]
fn times_no_model_gives_are_said_so() {
    let mut runs = synthetic(Model::Coriolis, 0.03, 0.002, 6, 5);
    for r in &mut runs {
        r.residence_s = 5.5;
    }
    let f = fit_paper(runs, Vec::new()).unwrap();
    assert_eq!(f.preferred, "none");
    assert!(f.outliers.is_empty(), "{:?}", f.outliers);
    for m in &f.models {
        let why = m.cannot_reproduce.as_deref().unwrap_or_default();
        assert!(
            why.contains("no mu of it gives these times"),
            "{}: {why}",
            m.candidate.name
        );
    }
    // The same truth timed as measured: one model preferred, none marked.
    let good = fit_paper(synthetic(Model::Coriolis, 0.03, 0.002, 6, 5), Vec::new()).unwrap();
    assert_eq!(good.preferred, "coriolis");
    assert!(good.models.iter().all(|m| m.cannot_reproduce.is_none()));
}

#[test]
fn too_few_runs_is_an_error() {
    let runs = synthetic(Model::Flat, 0.03, 0.01, 1, 1)[..2].to_vec();
    let e = fit_paper(runs, Vec::new()).unwrap_err().to_string();
    assert!(e.contains("needs at least 3"), "{e}");
}

/// Runs whose speed drifts (a 10 % ramp during the residence) are predicted by integrating
/// over the trace, and the fit recovers the truth from them; the closed form at the mean speed
/// would be off by more than the noise.
#[test]
fn drifting_speed_uses_the_integrator() {
    let mut rng = Prng::new(11);
    let mut runs = Vec::new();
    for (c, &w) in SPEEDS.iter().enumerate() {
        for _ in 0..4 {
            let trace: Vec<(f64, f64)> = (0..=300)
                .map(|k| (k as f64 * 0.01, w * (1.0 + 0.1 * k as f64 / 300.0)))
                .collect();
            let truth = model_core::sim::granule::Granule::new(
                Model::Coriolis,
                0.03,
                5.0 / 7.0,
                0.05,
                0.15,
            )
            .residence_over_trace(&trace, 1e-4, 100.0)
            .unwrap();
            let kept: Vec<(f64, f64)> = trace.into_iter().filter(|p| p.0 <= truth).collect();
            runs.push(Run {
                row: 0,
                condition: c + 1,
                residence_s: truth + 0.002 * gaussian(&mut rng),
                mean_rad_s: kept.iter().map(|p| p.1).sum::<f64>() / kept.len() as f64,
                release_radius_m: 0.05,
                rim_radius_m: 0.15,
                k2: 5.0 / 7.0,
                trace: kept,
                method: Method::Integrated,
                axes_angle_rad: 60f64.to_radians(),
                bowl: models::BowlRun::default(),
            });
        }
    }
    let f = fit_paper(runs.clone(), Vec::new()).unwrap();
    let c = fitted(&f, "coriolis");
    assert!(
        c.mu_ci95.0 <= 0.03 && 0.03 <= c.mu_ci95.1,
        "{:?}",
        c.mu_ci95
    );
    for r in &mut runs {
        r.method = Method::ClosedForm;
    }
    let wrong = fitted(&fit_paper(runs, Vec::new()).unwrap(), "coriolis");
    assert!(
        !(wrong.mu_ci95.0 <= 0.03 && 0.03 <= wrong.mu_ci95.1),
        "{:?}",
        wrong.mu_ci95
    );
}

/// Residence times made by the rolling model on the 60-degree rig (each run's time the mean over
/// the release azimuths, plus 2 ms of gate scatter): the rolling model is preferred by AIC and
/// its interval covers the true rolling resistance; the paper's models cannot follow times that
/// hardly change with speed.
#[test]
fn rolling_truth_is_recognised() {
    use super::models::{Equation, predict};
    let mut rng = Prng::new(7);
    let mut runs = Vec::new();
    for (c, &w) in [1.0, 2.2, 3.6].iter().enumerate() {
        for _ in 0..2 {
            let mut run = Run {
                row: 0,
                condition: c + 1,
                residence_s: 0.0,
                mean_rad_s: w,
                release_radius_m: 0.075,
                rim_radius_m: 0.15,
                k2: 5.0 / 7.0,
                trace: vec![(0.0, w)],
                method: Method::ClosedForm,
                axes_angle_rad: 60f64.to_radians(),
                bowl: models::BowlRun::default(),
            };
            run.residence_s = predict(&run, Equation::Rolling, 0.05) + 0.002 * gaussian(&mut rng);
            runs.push(run);
        }
    }
    let f = fit(runs, Vec::new(), false).unwrap();
    assert_eq!(f.preferred, "rolling");
    let r = fitted(&f, "rolling");
    assert!(
        r.mu_ci95.0 <= 0.05 && 0.05 <= r.mu_ci95.1,
        "{:?}",
        r.mu_ci95
    );
}

/// `bowl fit --bowl-walls`: runs made by the bowl model itself with a 60 deg wall 10 mm high at
/// `mu_s` 0.4 on the rig's tilt (75 mm bottom, 60 deg, three speeds, 0.5 ms timing noise) are
/// preferred by that wall over the bare rim and the 20 mm wall, and its `mu_s` interval holds
/// 0.4; the vertical wall, which holds every release, cannot reproduce them (at the limit or
/// never leaving).
#[test]
fn the_bowl_fit_finds_the_wall_and_mu_s() {
    use super::models::{BOWL_CANDIDATES, Equation, predict};
    let mut rng = Prng::new(11);
    let truth = BOWL_CANDIDATES[1];
    let mut runs = Vec::new();
    for (c, &w) in [0.8, 2.0, 3.6].iter().enumerate() {
        let mut run = Run {
            row: 0,
            condition: c + 1,
            residence_s: 0.0,
            mean_rad_s: w,
            release_radius_m: 0.0375,
            rim_radius_m: 0.075,
            k2: 5.0 / 7.0,
            trace: vec![(0.0, w)],
            method: Method::ClosedForm,
            axes_angle_rad: 60f64.to_radians(),
            bowl: models::BowlRun::default(),
        };
        let t = predict(&run, truth.equation, 0.4);
        assert!(t.is_finite() && matches!(truth.equation, Equation::Bowl(_)));
        run.residence_s = t + 0.0005 * gaussian(&mut rng);
        runs.push(run);
    }
    let f = fit_candidates(runs, Vec::new(), &BOWL_CANDIDATES, false).unwrap();
    assert_eq!(f.preferred, truth.name, "{:?}", f.models);
    let m = fitted(&f, truth.name);
    assert!(m.mu_ci95.0 <= 0.4 && 0.4 <= m.mu_ci95.1, "{:?}", m.mu_ci95);
    assert!(m.mu_ci95.1 - m.mu_ci95.0 < 0.1, "{:?}", m.mu_ci95);
    let vertical = fitted(&f, BOWL_CANDIDATES[3].name);
    assert!(
        vertical.cannot_reproduce.is_some() || vertical.at_limit,
        "{vertical:?}"
    );
}

/// A rig file's fillet is shared by every candidate wall: the bare rim has none to round into
/// and a wall lower than the fillet's rise holds the largest fillet it can. The bowl model
/// refuses a fillet above its wall, so without that each such candidate read as a wall that
/// holds every release (an infinite time), and the bare rim lost to any wall.
#[test]
fn a_rigs_fillet_too_tall_for_a_candidate_wall_is_the_largest_it_holds() {
    use super::models::{BOWL_CANDIDATES, BowlBase, Equation, predict};
    let run = |fillet_m: f64| Run {
        row: 2,
        condition: 1,
        residence_s: 0.2,
        mean_rad_s: 2.0,
        release_radius_m: 0.0375,
        rim_radius_m: 0.075,
        k2: 5.0 / 7.0,
        trace: vec![(0.0, 2.0)],
        method: Method::ClosedForm,
        axes_angle_rad: 60f64.to_radians(),
        bowl: models::BowlRun {
            azimuth_rad: Some(0.0),
            base: BowlBase {
                fillet_radius_m: fillet_m,
                ..BowlBase::DEFAULT
            },
            ..models::BowlRun::default()
        },
    };
    let [bare, wall10, ..] = BOWL_CANDIDATES;
    let t = |fillet_m: f64, c: super::models::Candidate| predict(&run(fillet_m), c.equation, 0.4);
    // The bare rim with the rig's 15 mm fillet is the bare rim.
    assert!(t(0.015, bare).is_finite(), "{}", t(0.015, bare));
    assert_eq!(t(0.015, bare), t(0.0, bare));
    // A 30 mm fillet rises 15 mm up a 60 deg wall: the 10 mm wall holds a 20 mm one.
    let Equation::Bowl(w) = wall10.equation else {
        panic!("not a wall")
    };
    let held = w.fillet_held_m(0.03);
    assert!((held - 0.02).abs() < 1e-9, "{held}");
    assert!(t(0.03, wall10).is_finite(), "{}", t(0.03, wall10));
    assert_eq!(t(0.03, wall10), t(held, wall10));
    assert_ne!(t(0.03, wall10), t(0.0, wall10));
}

/// `shortest_residence_s` is a lower bound for every candidate without friction (the fastest
/// each can be), against the models themselves: the paper's closed forms at mu 0 and k2 1, and
/// the rolling model (rolling resistance 0) at each release azimuth, over speeds from 0.3 to 30
/// rad/s, release radii from 5 to 140 mm of a 150 mm rim, axes 0 to 85 degrees apart and k2 from
/// 0.4 to 0.99; and not far below on the rig (within a factor 3 of the fastest).
#[test]
fn the_shortest_residence_time_bounds_every_model_from_below() {
    use model_core::particle::rolling::{self, RollingMethod, RollingScene, SystemLimits};
    let (mut tightest, mut checked) = (f64::INFINITY, 0);
    for w in [0.3, 3.0, 7.0, 30.0] {
        for ri in [0.005, 0.05, 0.14] {
            for angle_deg in [0.0f64, 60.0, 85.0] {
                for k2 in [0.4, 5.0 / 7.0, 0.99] {
                    let run = Run {
                        row: 2,
                        condition: 1,
                        residence_s: 1.0,
                        mean_rad_s: w,
                        release_radius_m: ri,
                        rim_radius_m: 0.15,
                        k2,
                        trace: vec![(0.0, w)],
                        method: Method::ClosedForm,
                        axes_angle_rad: angle_deg.to_radians(),
                        bowl: models::BowlRun::default(),
                    };
                    let bound = models::shortest_residence_s(&run);
                    let mut fastest = f64::INFINITY;
                    for model in [Model::Flat, Model::Coriolis] {
                        fastest = fastest.min(closed_form(
                            &Run {
                                k2: 1.0,
                                ..run.clone()
                            },
                            model,
                            0.0,
                            w,
                        ));
                    }
                    let scene = RollingScene {
                        rolling_resistance: 0.0,
                        k2,
                        ri_m: ri,
                        rim_radius_m: 0.15,
                        ..RollingScene::equal_speeds(w, run.axes_angle_rad, 0.15)
                    };
                    let limits = SystemLimits {
                        horizon_s: 10.0,
                        max_steps: 200_000,
                    };
                    let s = rolling::over_azimuths_within(
                        &scene,
                        RollingMethod::Dp54 { rtol: 1e-10 },
                        limits,
                    )
                    .unwrap_or_else(|e| panic!("w {w} ri {ri} angle {angle_deg} k2 {k2}: {e:?}"));
                    if let Some(min) = s.min_s {
                        fastest = fastest.min(min);
                    }
                    assert!(
                        bound > 0.0 && bound <= fastest,
                        "w {w} ri {ri} angle {angle_deg} k2 {k2}: bound {bound} s, fastest {fastest} s"
                    );
                    if fastest.is_finite() {
                        tightest = tightest.min(fastest / bound);
                        checked += 1;
                    }
                }
            }
        }
    }
    assert!(checked > 80, "{checked} scenes left under some model");
    eprintln!("closest: the fastest model {tightest:.3}x the bound over {checked} scenes");
    // The rig: 7 rad/s, 0.05 m to 0.15 m, 60 degrees.
    let rig = Run {
        row: 2,
        condition: 1,
        residence_s: 1.0,
        mean_rad_s: 7.0,
        release_radius_m: 0.05,
        rim_radius_m: 0.15,
        k2: 5.0 / 7.0,
        trace: vec![(0.0, 7.0)],
        method: Method::ClosedForm,
        axes_angle_rad: 60f64.to_radians(),
        bowl: models::BowlRun::default(),
    };
    let frictionless =
        predict(&rig, models::Equation::Rolling, 0.0).min(closed_form(&rig, Model::Flat, 0.0, 7.0));
    let bound = models::shortest_residence_s(&rig);
    assert!(
        bound > frictionless / 3.0,
        "{bound} s against {frictionless} s"
    );
}

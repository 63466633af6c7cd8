//! The chooser's decisions checked against errors measured independently here.

use super::*;
use crate::ode::{self, SpinUp};

/// The particle tests' scene with the rim at 0.1 m.
pub(super) fn scene(omega: f64, mu: f64, ri: f64) -> Scene<f64> {
    crate::particle::tests::scene(omega, mu, ri, 0.1)
}

/// Measured spread: T over the corners of the uncertainty box (all combinations), relative
/// half-width. Independent of the chooser's one-at-a-time sum.
fn corner_spread(s: &Scene<f64>, k: &Knowledge<f64>) -> f64 {
    let t0 = particle::residence(s, Model::Coriolis)
        .unwrap()
        .residence_time_s();
    let mut worst: f64 = 0.0;
    for &dm in &[-1.0, 1.0] {
        for &dri in &[-1.0, 1.0] {
            for &drim in &[-1.0, 1.0] {
                for &dw in &[-1.0, 1.0] {
                    let p = Scene {
                        mu: s.mu * (1.0 + dm * k.mu_rel),
                        ri_m: s.ri_m + dri * k.radius_m,
                        rim_radius_m: s.rim_radius_m + drim * k.radius_m,
                        omega_rad_s: s.omega_rad_s * (1.0 + dw * k.omega_rel),
                        ..*s
                    };
                    let t = particle::residence(&p, Model::Coriolis)
                        .unwrap()
                        .residence_time_s();
                    worst = worst.max((t - t0).abs() / t0);
                }
            }
        }
    }
    worst
}

#[test]
fn mu_known_to_20_percent_needs_only_the_flat_closed_form() {
    let s = scene(3.0, 0.029, 0.05);
    let k = Knowledge {
        mu_rel: 0.2,
        radius_m: 1e-3,
        omega_rel: 0.01,
    };
    let c = choose_constant(&s, &k).unwrap();
    assert_eq!((c.model, c.plan), (Model::Flat, Plan::ClosedForm));
    // Measured: the spread really is at least 10x the tolerance, and the flat model's error
    // (against the Coriolis closed form) is below the tolerance.
    let measured_spread = corner_spread(&s, &k);
    assert!(
        c.tolerance_rel <= 0.1 * measured_spread * 1.0001,
        "{c:?} vs {measured_spread}"
    );
    let tf = closed_form(&s, Model::Flat);
    let tc = closed_form(&s, Model::Coriolis);
    assert!((tf - tc).abs() / tc <= c.tolerance_rel * 1.05);
}

#[test]
fn precisely_known_resistance_needs_the_coriolis_model() {
    let s = scene(3.6, 0.1, 0.09);
    let k = Knowledge {
        mu_rel: 1e-4,
        radius_m: 1e-7,
        omega_rel: 1e-5,
    };
    let c = choose_constant(&s, &k).unwrap();
    assert_eq!(c.model, Model::Coriolis);
    let tf = closed_form(&s, Model::Flat);
    let tc = closed_form(&s, Model::Coriolis);
    assert!(
        (tf - tc).abs() / tc > c.tolerance_rel,
        "flat would be too far off"
    );
    assert!(c.coriolis_effect_rel > 0.01 && c.coriolis_effect_rel < 0.1);
}

#[test]
fn spin_up_plan_meets_its_tolerance_when_run() {
    let s = scene(0.0, 0.029, 0.05);
    let profile = SpinUp {
        start_rad_s: 0.0,
        final_rad_s: 3.6,
        time_constant_s: 0.3,
    };
    for k in [
        Knowledge {
            mu_rel: 0.2,
            radius_m: 1e-3,
            omega_rel: 0.01,
        },
        Knowledge {
            mu_rel: 1e-5,
            radius_m: 1e-8,
            omega_rel: 1e-7,
        },
    ] {
        let limits = Limits::for_scene(&s, &profile);
        // Truth: the Coriolis model, integrated tightly. The chosen model + method must land
        // within the tolerance of it (model error + method error, each budgeted).
        let truth = run(&s, Model::Coriolis, &profile, dp(1e-12, &s), limits)
            .unwrap()
            .0;
        let need = Need::Uncertainty(k);
        let (p, _) = choose_varying_reading(&s, &need, &profile, false).unwrap();
        let (c, _) = choose_varying_reading(&s, &need, &profile, true).unwrap();
        assert_eq!(
            (p.source, c.source),
            (Source::PilotRuns, Source::Table),
            "{k:?}: {c:?}"
        );
        for choice in [&p, &c] {
            let Plan::Integrate(method) = choice.plan else {
                panic!("{choice:?}")
            };
            let (t, evals) = run(&s, choice.model, &profile, method, limits).unwrap();
            // RK4's plan is run: the pilot's extrapolation does not answer for it.
            assert_eq!(choice.answer_s, None);
            let err = (t - truth).abs() / truth;
            assert!(err <= choice.tolerance_rel, "{choice:?}: error {err:e}");
            let counted = f64::from(choice.rhs_evaluations);
            assert!(
                (counted - f64::from(evals)).abs() <= 0.25 * f64::from(evals) + 4.0,
                "{choice:?}: {evals} evaluations"
            );
        }
        assert_eq!(
            p.rhs_evaluations,
            run(&s, p.model, &profile, plan_method(&p), limits)
                .unwrap()
                .1
        );
        // The table's spread runs at its own step: the same spread within 1 %.
        let (spread_p, spread_c) = (p.spread_rel.unwrap(), c.spread_rel.unwrap());
        assert!(
            (spread_c - spread_p).abs() <= 0.01 * spread_p,
            "{spread_c} {spread_p}"
        );
        // Its runs are only the spread's, fewer than the pilot's, and its plan costs no more.
        assert!(
            c.choosing_evaluations > 0 && c.choosing_evaluations < p.choosing_evaluations,
            "{k:?}: {} against {}",
            c.choosing_evaluations,
            p.choosing_evaluations
        );
        assert!(c.predicted_cost <= 1.05 * p.predicted_cost, "{c:?} {p:?}");
        if k.mu_rel > 0.1 {
            // The pilot measures the effect (0.7 %) within 3/4 of the tolerance (1.25 %): the
            // flat model. The table reads it with a margin of 1.5 and takes the Coriolis model
            // at the same step (its whole tolerance is the method's budget).
            assert_eq!(p.model, Model::Flat, "{p:?}");
            if c.model == Model::Coriolis {
                let read = c.coriolis_effect_rel * table::EFFECT_READING_MARGIN;
                assert!(read > 0.75 * c.tolerance_rel, "{c:?}");
            }
        } else {
            for choice in [&p, &c] {
                assert_eq!(choice.model, Model::Coriolis, "{choice:?}");
                assert!(choice.tolerance_rel < 1e-5);
            }
        }
    }
}

fn plan_method(c: &Choice<f64>) -> Method<f64> {
    match c.plan {
        Plan::Integrate(m) => m,
        _ => panic!("{c:?}"),
    }
}

#[test]
fn bad_knowledge_and_stuck_particles_are_errors() {
    let s = scene(3.0, 0.029, 0.05);
    let bad = Knowledge {
        mu_rel: f64::NAN,
        radius_m: 0.0,
        omega_rel: 0.0,
    };
    assert_eq!(
        choose_constant(&s, &bad),
        Err(ChooseError::InvalidKnowledge)
    );
    let k = Knowledge {
        mu_rel: 0.1,
        radius_m: 0.0,
        omega_rel: 0.0,
    };
    assert_eq!(
        choose_constant(&scene(3.0, 0.4, 0.05), &k),
        Err(ChooseError::DoesNotLeave)
    );
}

/// The closed form's residence time of scene `s`.
pub(super) fn closed_form(s: &Scene<f64>, model: Model) -> f64 {
    particle::residence(s, model).unwrap().residence_time_s()
}

/// The chooser's optimality and its own cost, against an independent brute force: RK4 steps
/// 2^(1/8) apart from the stability margin down, each against a DP5(4) at rtol 1e-13; the
/// coarsest step from which every finer one meets the tolerance is the cheapest dependable
/// RK4 plan (RK4 was the cheapest method on every scene of `bowl chart chooser`). The plan read
/// from the table and the pilot's plan must each meet the tolerance and cost at most 1.25x
/// that plan on the same table (priced at the evaluations the plan ran); the table runs
/// nothing, the pilot fewer than 400 right-hand-side evaluations (290 at most on the chart's
/// grid; 737 before the flat model was probed at the pilot's coarsest steps).
#[test]
fn the_chosen_step_is_within_a_quarter_of_the_cheapest_and_choosing_is_bounded() {
    for (start, end, tau, mu) in [
        (0.0, 3.0, 0.3, 0.029),
        (1.0, 3.0, 2.0, 0.01),
        (0.0, 6.0, 2.0, 0.1),
    ] {
        let s = scene(end, mu, 0.05);
        let profile = SpinUp {
            start_rad_s: start,
            final_rad_s: end,
            time_constant_s: tau,
        };
        let limits = Limits::for_scene(&s, &profile);
        for tolerance in [1e-3, 1e-6] {
            let c = choose_varying_for(&s, &Need::Tolerance(tolerance), &profile).unwrap();
            let Plan::Integrate(method) = c.plan else {
                panic!("{c:?}")
            };
            let truth = run(&s, c.model, &profile, dp(1e-13, &s), limits).unwrap().0;
            let err_of = |m: Method<f64>| {
                let (t, evals) = run(&s, c.model, &profile, m, limits).unwrap();
                ((t - truth).abs() / truth, evals)
            };
            let (err, evals) = err_of(method);
            assert!(err <= tolerance, "{c:?}: error {err:e}");
            // The table's count comes from the T it reads (within 25 %), the pilot's from
            // the T it ran.
            assert_eq!(c.source, Source::Table, "{c:?}");
            let counted = f64::from(c.rhs_evaluations);
            assert!(
                (counted - f64::from(evals)).abs() <= 0.25 * f64::from(evals) + 4.0,
                "{c:?}: {evals} evaluations"
            );
            let steps: [f64; 64] =
                core::array::from_fn(|k| 1.5 / end * 2f64.powf(-(k as f64) / 8.0));
            let runs = steps.map(|h| err_of(Method::Rk4 { step_s: h }));
            let finest_failing = runs.iter().rposition(|(e, _)| *e > tolerance);
            let first_dependable = finest_failing.map_or(0, |k| k + 1);
            assert!(
                first_dependable < steps.len(),
                "no RK4 step met {tolerance:e}"
            );
            let cheapest = plan_cost(
                &Plan::Integrate(Method::Rk4 {
                    step_s: steps[first_dependable],
                }),
                runs[first_dependable].1,
                Target::Host,
            );
            let chosen = plan_cost(&c.plan, evals, Target::Host);
            let ratio = chosen / cheapest;
            assert!(ratio <= 1.25, "{c:?}: {ratio:.3}x the cheapest");
            assert_eq!(c.choosing_evaluations, 0, "{c:?}");
            // The pilot, asked for the same scene, meets the same bounds with fewer than 400
            // evaluations of its own (290 at most on the chart's grid).
            let (p, _) =
                choose_varying_reading(&s, &Need::Tolerance(tolerance), &profile, false).unwrap();
            let Plan::Integrate(by_pilot) = p.plan else {
                panic!("{p:?}")
            };
            let (err, evals) = err_of(by_pilot);
            assert!(err <= tolerance, "{p:?}: error {err:e}");
            assert_eq!(evals, p.rhs_evaluations, "{p:?}");
            let ratio = plan_cost(&p.plan, evals, Target::Host) / cheapest;
            assert!(ratio <= 1.25, "{p:?}: {ratio:.3}x the cheapest");
            assert!(
                p.choosing_evaluations > 0 && p.choosing_evaluations < 400,
                "{p:?}"
            );
        }
    }
}

/// The tolerance on random spin-ups, each plan run against the Coriolis model by DP5(4) at
/// rtol 1e-13 (the flat model's own error counts): 4,000 scenes
/// (mu 0.002 to 0.2, from rest or a random start to 1.5 to 8 rad/s, tau 0.05 to 5 s, ri 0.01
/// to 0.095 m, tolerances 1e-2 to 1e-8; those that leave, about 3,200), each chosen twice:
/// from the table and by the pilot. The table covers nearly all of them and its plans meet
/// the tolerance (28,675 such scenes in a scratch run: none missed, worst 0.87 of it). The
/// pilot's prediction can be off by more than the plan's 2x margin: 2 of them miss, by at most
/// 6 % (before the crossing was located to `O(h^6)` and the pilot resolved the spin-up's time
/// constant: 12 of 1,587 by up to 1.75x). Each held at its level.
#[test]
fn random_spin_ups_meet_their_tolerance_from_the_table_and_nearly_always_by_the_pilot() {
    let mut uniform = crate::particle::tests::uniform_stream(987_654_321);
    let (mut scenes, mut read) = (0, 0);
    // Misses and the worst error over the tolerance: the table's, the pilot's.
    let mut misses = [0usize; 2];
    let mut worst = [0.0f64; 2];
    for _ in 0..4000 {
        let mu = 0.002 * 100f64.powf(uniform());
        let final_rad_s = 1.5 + 6.5 * uniform();
        let start_rad_s = if uniform() < 0.5 {
            0.0
        } else {
            final_rad_s * uniform()
        };
        let profile = SpinUp {
            start_rad_s,
            final_rad_s,
            time_constant_s: 0.05 * 100f64.powf(uniform()),
        };
        let s = scene(final_rad_s, mu, 0.01 + 0.085 * uniform());
        let tolerance = 10f64.powf(-2.0 - 6.0 * uniform());
        let need = Need::Tolerance(tolerance);
        let Ok((c, _)) = choose_varying_reading(&s, &need, &profile, true) else {
            continue;
        };
        let (p, _) = choose_varying_reading(&s, &need, &profile, false).unwrap();
        let limits = ode::Limits::for_scene(&s, &profile);
        let time = |m, model| match particle::integrate(&s, model, &profile, m, limits)
            .unwrap()
            .outcome
        {
            ode::OdeOutcome::Leaves {
                residence_time_s, ..
            } => residence_time_s,
            _ => f64::NAN,
        };
        let reference = ode::Method::Dp54 {
            rtol: 1e-13,
            atol: 1e-18,
        };
        scenes += 1;
        for (k, choice) in [c, p].iter().enumerate() {
            let Plan::Integrate(method) = choice.plan else {
                panic!("{choice:?}")
            };
            // Against the full model: the flat model's own error counts too.
            let truth = time(reference, Model::Coriolis);
            let over = (time(method, choice.model) - truth).abs() / truth / choice.tolerance_rel;
            assert!(over.is_finite(), "{choice:?}");
            misses[k] += usize::from(over > 1.0);
            worst[k] = worst[k].max(over);
        }
        read += usize::from(c.source == Source::Table);
        assert_eq!(p.source, Source::PilotRuns);
    }
    assert!(scenes > 3000, "{scenes}");
    assert!(
        read * 100 > scenes * 95,
        "the table read {read} of {scenes}"
    );
    assert!(
        misses[0] == 0 && worst[0] <= 0.95,
        "the table: {} of {scenes} missed, worst {}",
        misses[0],
        worst[0]
    );
    assert!(
        misses[1] <= 2 && worst[1] <= 1.1,
        "the pilot: {} of {scenes} missed, worst {}",
        misses[1],
        worst[1]
    );
}

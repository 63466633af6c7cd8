//! Integrators in f32 on the target: against the f64 closed form (constant speed) and the
//! stability refusal; benchmarks of each method at a typical setting (no budgets: for the
//! cost chart).

use crate::check::{Bench, Case, Failure, close, ensure};
use model_core::ode::{Method, OdeOutcome};
use model_core::particle::{self, Model, OdeError, Outcome, Scene, residence};

/// Cases of this module.
pub static CASES: &[Case] = &[
    Case {
        name: "ode::f32_methods_vs_f64_closed_form",
        run: methods_vs_closed_form,
    },
    Case {
        name: "ode::f32_step_beyond_stability_refused",
        run: beyond_stability_refused,
    },
];

/// Benchmarks of this module: T by each method, f32, default scene (omega 3, mu 0.029).
pub static BENCHES: &[Bench] = &[
    Bench {
        name: "ode::euler_h0.01_f32",
        inputs: 2,
        run: |i| bench(i, Method::Euler { step_s: 0.01 / 3.0 }),
        budget_instructions: None,
    },
    Bench {
        name: "ode::semi_implicit_h0.01_f32",
        inputs: 2,
        run: |i| bench(i, Method::SemiImplicitEuler { step_s: 0.01 / 3.0 }),
        budget_instructions: None,
    },
    Bench {
        name: "ode::rk4_h0.1_f32",
        inputs: 2,
        run: |i| bench(i, Method::Rk4 { step_s: 0.1 / 3.0 }),
        budget_instructions: None,
    },
    Bench {
        name: "ode::dp54_rtol1e-5_f32",
        inputs: 2,
        run: |i| {
            bench(
                i,
                Method::Dp54 {
                    rtol: 1e-5,
                    atol: 1e-8,
                },
            )
        },
        budget_instructions: None,
    },
];

fn model(i: usize) -> Model {
    if i.is_multiple_of(2) {
        Model::Flat
    } else {
        Model::Coriolis
    }
}

fn bench(i: usize, method: Method<f32>) -> f32 {
    match particle::integrate_constant(&Scene::<f32>::default(), model(i), method) {
        Ok(r) => match r.outcome {
            OdeOutcome::Leaves {
                residence_time_s, ..
            } => residence_time_s,
            _ => f32::NAN,
        },
        Err(_) => f32::NAN,
    }
}

fn methods_vs_closed_form() -> Result<(), Failure> {
    let s64 = Scene::<f64>::default();
    for m in [Model::Flat, Model::Coriolis] {
        let want = match residence(&s64, m) {
            Ok(Outcome::Leaves {
                residence_time_s, ..
            }) => residence_time_s,
            _ => return ensure("f64 closed form leaves", false),
        };
        // (method, relative tolerance): errors of order (h omega)^p, plus f32 round-off.
        let runs: [(Method<f32>, f64); 4] = [
            (
                Method::Euler {
                    step_s: 0.001 / 3.0,
                },
                2e-3,
            ),
            (
                Method::SemiImplicitEuler {
                    step_s: 0.001 / 3.0,
                },
                2e-3,
            ),
            (Method::Rk4 { step_s: 0.05 / 3.0 }, 1e-5),
            (
                Method::Dp54 {
                    rtol: 1e-6,
                    atol: 1e-9,
                },
                2e-5,
            ),
        ];
        for (method, tol) in runs {
            let got = bench(if m == Model::Flat { 0 } else { 1 }, method);
            close(
                "f32 integrator T vs f64 closed form (rel)",
                got as f64 / want,
                1.0,
                tol,
            )?;
        }
    }
    Ok(())
}

fn beyond_stability_refused() -> Result<(), Failure> {
    // omega 3, mu 0: Euler's limit is h = 2 / (k omega) = 0.789 s.
    let s = Scene::<f32> {
        mu: 0.0,
        ..Scene::default()
    };
    ensure(
        "Euler h 0.8 s refused",
        particle::integrate_constant(&s, Model::Flat, Method::Euler { step_s: 0.8 })
            == Err(OdeError::BeyondStabilityLimit),
    )?;
    ensure(
        "RK4 h 1.2 s refused",
        particle::integrate_constant(&s, Model::Flat, Method::Rk4 { step_s: 1.2 })
            == Err(OdeError::BeyondStabilityLimit),
    )
}

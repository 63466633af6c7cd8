//! The integrator methods of `bowl predict`, at the scene's constant speed (model-core `ode`).

use anyhow::{Result, anyhow};
use model_core::ode::{self, Method, OdeOutcome};
use model_core::particle::{self, Model, Outcome, Scene};

use super::{MethodChoice, Prediction};

/// Integrates one scene with a numerical method. The condition number reported is the
/// problem's (from the closed form): it does not depend on the method.
pub fn predict(
    scene: &Scene<f64>,
    model: Model,
    method: MethodChoice,
    step_s: Option<f64>,
    tol: f64,
) -> Result<Prediction> {
    // Default step: a hundredth of the time scale 1/omega.
    let h = step_s.unwrap_or_else(|| {
        if scene.omega_rad_s > 0.0 {
            0.01 / scene.omega_rad_s
        } else {
            0.01
        }
    });
    let m = match method {
        MethodChoice::Euler => Method::Euler { step_s: h },
        MethodChoice::SemiImplicit => Method::SemiImplicitEuler { step_s: h },
        MethodChoice::Rk4 => Method::Rk4 { step_s: h },
        MethodChoice::Dp54 => Method::Dp54 {
            rtol: tol,
            atol: tol * 1e-2,
        },
        MethodChoice::Closed => unreachable!("closed forms are handled by the caller"),
    };
    let closed = particle::residence(scene, model).map_err(|e| anyhow!(super::words::scene(e)))?;
    let report =
        ode::integrate_constant(scene, model, m).map_err(|e| anyhow!(super::words::ode(e)))?;
    let outcome = match report.outcome {
        OdeOutcome::Leaves {
            residence_time_s,
            exit_radial_velocity_m_s,
            exit_total_velocity_m_s,
        } => {
            let (condition_number, ill_conditioned) = match closed {
                Outcome::Leaves {
                    condition_number,
                    ill_conditioned,
                    ..
                } => (condition_number, ill_conditioned),
                _ => (1.0, false),
            };
            Outcome::Leaves {
                residence_time_s,
                exit_radial_velocity_m_s,
                exit_total_velocity_m_s,
                condition_number,
                ill_conditioned,
            }
        }
        OdeOutcome::AlreadyAtRim {
            exit_total_velocity_m_s,
        } => Outcome::AlreadyAtRim {
            exit_total_velocity_m_s,
        },
        OdeOutcome::NeverLeaves | OdeOutcome::NotLeftBy { .. } => Outcome::NeverLeaves {
            equilibrium_radius_m: scene.equilibrium_radius_m(),
            near_threshold: matches!(
                closed,
                Outcome::NeverLeaves {
                    near_threshold: true,
                    ..
                }
            ),
        },
    };
    Ok(Prediction {
        outcome,
        rhs_evaluations: report.rhs_evaluations as u64,
        steps: report.steps as u64,
    })
}

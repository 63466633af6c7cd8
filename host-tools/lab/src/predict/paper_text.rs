//! The paper's level-bowl models in text: the scene and one line per model.

use model_core::particle::{Model, Scene};

use super::{Ends, MethodChoice, Prediction, method_name, model_name, refusals};
use crate::number::{echo, fixed};

pub(super) fn describe_scene(s: &Scene<f64>) -> String {
    let a = s.equilibrium_radius_m();
    // At omega 0 the formula divides by zero: no radius balances friction, said in words.
    let equilibrium = if a.is_finite() {
        format!("equilibrium radius a = mu g / omega^2 = {} m", fixed(a, 6))
    } else {
        "no equilibrium radius: omega is 0, nothing pushes the granule outward".into()
    };
    format!(
        "scene: omega {} rad/s, mu {}, g {} m/s^2, k2 {:.6}, ri {} m, R {} m; {equilibrium}",
        echo(s.omega_rad_s),
        echo(s.mu),
        echo(s.g_m_s2),
        s.k2,
        echo(s.ri_m),
        echo(s.rim_radius_m),
    )
}

pub(super) fn describe(
    scene: &Scene<f64>,
    model: Model,
    method: MethodChoice,
    p: &Prediction,
) -> String {
    let head = format!("{:<8} {:<13}", model_name(model), method_name(method));
    let cost = if p.rhs_evaluations > 0 {
        format!(
            " [{} steps, {} rhs evaluations]",
            p.steps, p.rhs_evaluations
        )
    } else {
        String::new()
    };
    match Ends::from(p.outcome) {
        Ends::Leaves(l) => format!(
            "{head} leaves after T = {} s; exit radial {} m/s, total {} m/s; condition {}{}{cost}",
            fixed(l.residence_time_s, 9),
            fixed(l.exit_radial_velocity_m_s, 6),
            fixed(l.exit_total_velocity_m_s, 6),
            fixed(l.condition_number, 3),
            if l.ill_conditioned {
                " (ILL-CONDITIONED: start just above the threshold a)"
            } else {
                ""
            }
        ),
        Ends::AtRim {
            exit_total_velocity_m_s,
        } => {
            format!(
                "{head} starts at the rim: T = 0, exit total {} m/s",
                fixed(exit_total_velocity_m_s, 6)
            )
        }
        Ends::Never {
            equilibrium_radius_m,
            near_threshold,
        } => format!(
            "{head} NEVER LEAVES: {}{}",
            refusals::what_holds(scene, equilibrium_radius_m),
            if near_threshold {
                " (within rounding of the threshold)"
            } else {
                ""
            }
        ),
    }
}

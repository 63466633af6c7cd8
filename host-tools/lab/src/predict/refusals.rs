//! The particle model's refusals in plain words (a scene, an inverse, an integration it
//! refused): which value, the limit, what to do.

use model_core::particle::OdeError;
use model_core::particle::{Input, InverseError, Scene, SceneError, magnitude_limits};

use crate::number::echo;

/// A `flag` whose value is outside [`magnitude_limits`], in words (the 1-D scene's and the
/// tilted bowl's refusal alike).
pub fn extreme_magnitude(flag: &str) -> String {
    let (low, high) = magnitude_limits::<f64>();
    format!(
        "{flag} is outside the magnitudes the model computes with (0, or {low:e} to {high:e} in \
         size): products of the inputs would underflow or overflow f64 and the answer could \
         come out the wrong way round; rescale the units (or pass 0)"
    )
}

/// Why a scene was refused.
pub fn scene(e: SceneError) -> String {
    match e {
        SceneError::InvalidOmega => "--omega-rad-s must be 0 or more (a bowl speed, rad/s)".into(),
        SceneError::InvalidResistance => "--mu must be 0 or more (0.029 is the paper's)".into(),
        SceneError::InvalidGravity => "--g must be 0 or more (9.81 on Earth)".into(),
        SceneError::InvalidK2 => {
            "--k2 must lie in (0, 1] (5/7 for a solid sphere, 3/5 for a hollow one)".into()
        }
        SceneError::InvalidStartRadius => "--ri-m must be 0 or more (the start radius, m)".into(),
        SceneError::InvalidRimRadius => "--rim-radius-m must be 0 or more (m)".into(),
        SceneError::InvalidTime => "the time must be 0 or more".into(),
        SceneError::ExtremeMagnitude(input) => extreme_magnitude(match input {
            Input::Omega => "--omega-rad-s",
            Input::Resistance => "--mu",
            Input::Gravity => "--g",
            Input::K2 => "--k2",
            Input::StartRadius => "--ri-m",
            Input::RimRadius => "--rim-radius-m",
        }),
        SceneError::OutOfRange => {
            "the numbers overflow the arithmetic for this scene (absurd magnitudes): rescale the \
             units"
                .into()
        }
        SceneError::NoConvergence => {
            "the residence time's root finder did not converge (a defect: please report the scene)"
                .into()
        }
    }
}

/// What each input of the 1-D scene is called where it came from: a flag of `bowl predict`,
/// or a column of a batch file (a row's refusal names the column the user wrote, not a flag
/// they never typed).
pub struct Names {
    pub omega: &'static str,
    pub mu: &'static str,
    pub g: &'static str,
    pub k2: &'static str,
    pub ri: &'static str,
    pub rim: &'static str,
}

/// The flags' names.
pub const FLAGS: Names = Names {
    omega: "--omega-rad-s",
    mu: "--mu",
    g: "--g",
    k2: "--k2",
    ri: "--ri-m",
    rim: "--rim-radius-m",
};

/// The batch file's column names.
pub const COLUMNS: Names = Names {
    omega: "column w_rad_s =",
    mu: "column mu =",
    g: "column g =",
    k2: "column k2 =",
    ri: "column ri_m =",
    rim: "column R_m =",
};

/// Why a scene was refused, with the value given, each input named as in `n`.
pub fn scene_with_values(e: SceneError, s: &Scene<f64>, n: &Names) -> String {
    match e {
        SceneError::InvalidOmega => format!(
            "{} {} rad/s: the paper's models take the bowl's speed as a rate of turning, \
             0 or more (which way it turns is not one of their parameters): give 0 or a positive \
             speed",
            n.omega,
            echo(s.omega_rad_s)
        ),
        SceneError::InvalidResistance => format!(
            "{} {}: the rolling resistance must be 0 or more (0.029 is the paper's)",
            n.mu,
            echo(s.mu)
        ),
        SceneError::InvalidGravity => {
            format!(
                "{} {}: must be above 0 (9.81 on Earth)",
                n.g,
                echo(s.g_m_s2)
            )
        }
        SceneError::InvalidK2 => format!(
            "{} {}: must lie in (0, 1] (5/7 for a solid sphere, 3/5 for a hollow one)",
            n.k2,
            echo(s.k2)
        ),
        SceneError::InvalidStartRadius => {
            format!(
                "{} {} m: the start radius must be 0 or more",
                n.ri,
                echo(s.ri_m)
            )
        }
        SceneError::InvalidRimRadius => format!(
            "{} {} m: the rim radius must be 0 or more",
            n.rim,
            echo(s.rim_radius_m)
        ),
        SceneError::ExtremeMagnitude(input) => extreme_magnitude(match input {
            Input::Omega => n.omega,
            Input::Resistance => n.mu,
            Input::Gravity => n.g,
            Input::K2 => n.k2,
            Input::StartRadius => n.ri,
            Input::RimRadius => n.rim,
        }),
        other => scene(other),
    }
}

/// The scene as the rig would take it: valid, and starting inside the rim (the rig refuses a
/// start at or beyond the rim, so predicting T = 0 there would answer a question it never asks).
pub fn check(s: &Scene<f64>) -> anyhow::Result<()> {
    check_named(s, &FLAGS)
}

/// [`check`], each input named as in `n`.
pub fn check_named(s: &Scene<f64>, n: &Names) -> anyhow::Result<()> {
    s.validate()
        .map_err(|e| anyhow::anyhow!(scene_with_values(e, s, n)))?;
    gravity(s.g_m_s2, n.g)?;
    if s.ri_m >= s.rim_radius_m {
        anyhow::bail!(
            "{} {} m is not inside the rim ({} {} m): the granule must start inside the bowl, \
             as the rig requires",
            n.ri,
            echo(s.ri_m),
            n.rim,
            echo(s.rim_radius_m)
        );
    }
    Ok(())
}

/// Gravity above 0: the models weigh friction against the granule's weight, so g = 0 puts
/// weight in a denominator (friction "of inf of the granule's weight", T without a meaning).
pub fn gravity(g_m_s2: f64, name: &str) -> anyhow::Result<()> {
    if g_m_s2 == 0.0 {
        anyhow::bail!(
            "{name} 0 m/s^2: the models weigh friction against the granule's weight, which needs \
             gravity above 0; give g in m/s^2 (9.81 on Earth)"
        );
    }
    Ok(())
}

/// What keeps a granule that never leaves in the bowl, in words.
pub fn what_holds(scene: &Scene<f64>, equilibrium_radius_m: f64) -> String {
    match (scene.omega_rad_s == 0.0, scene.mu == 0.0) {
        (true, true) => "the bowl is not turning (omega 0) and there is no friction (mu 0): \
                         nothing pushes the granule outward, so it stays where it was put"
            .into(),
        (true, false) => "the bowl is not turning (omega 0): nothing pushes the granule \
                          outward, and friction keeps it where it was put"
            .into(),
        _ => format!(
            "ri <= a = {} m, friction holds it",
            crate::number::fixed(equilibrium_radius_m, 6)
        ),
    }
}

/// Why no bowl speed was found for a target.
pub fn inverse(e: InverseError, target_s: f64) -> String {
    match e {
        InverseError::Scene(s) => scene(s),
        InverseError::InvalidTarget => {
            format!("--target-time-s {target_s} must be a positive number of seconds")
        }
        InverseError::AlreadyAtRim => "the start radius is at the rim: T = 0 at every speed".into(),
        InverseError::NeverLeaves => {
            "a granule at the centre (--ri-m 0) never leaves at any speed".into()
        }
        InverseError::OutOfRange => format!(
            "T = {target_s} s would need a speed beyond the arithmetic's range: give a longer target"
        ),
        InverseError::BeyondPrecision => format!(
            "T = {target_s} s needs a speed within rounding of the threshold speed (below it the \
             granule never leaves): no speed gives it reliably; give a shorter target"
        ),
        InverseError::NotConverged => {
            "the speed search did not converge (a defect: please report the scene)".into()
        }
    }
}

/// Why an integration gave no result.
pub fn ode(e: OdeError) -> String {
    match e {
        OdeError::Scene(s) => scene(s),
        OdeError::InvalidStep => "--step-s and --tol must be positive numbers".into(),
        OdeError::BeyondStabilityLimit => {
            "the step is beyond the method's stability limit for this scene (docs/model.md, \
             Stability): give a smaller --step-s"
                .into()
        }
        OdeError::StepLimit => {
            "the integration took too many steps: give a larger --step-s or a looser --tol".into()
        }
        OdeError::InvalidOmega => "the bowl speed must be 0 or more".into(),
        OdeError::NotFinite => {
            "the integration diverged (a state became infinite): give a smaller --step-s".into()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An extreme magnitude is refused in words: which input (its flag), the limits, what to do.
    #[test]
    fn extreme_magnitudes_are_refused_in_words() {
        let s = Scene {
            mu: 1e-200,
            ..Scene::<f64>::default()
        };
        let said = check(&s).unwrap_err().to_string();
        for part in [
            "--mu",
            "1e-75",
            "1e75",
            "underflow or overflow",
            "rescale the units",
        ] {
            assert!(said.contains(part), "{said:?} lacks {part:?}");
        }
        let said = scene(SceneError::ExtremeMagnitude(Input::Omega));
        assert!(said.starts_with("--omega-rad-s is outside"), "{said}");
    }
}

//! The rolling model's refusals and give-ups in words, with the values given where the scene
//! has them (split from rolling.rs, which passed 500 lines).

use model_core::ode::system::SystemError;
use model_core::particle::rolling::{
    self, RollingError, RollingInput, RollingMethod, RollingScene,
};

/// A refusal of the scene with the values given: `--axes-angle-deg 90` and `--ri-m` equal to
/// `--rim-radius-m` were refused without a word of the value or the limit's.
pub(super) fn given_words(e: RollingError, scene: &RollingScene<f64>, th_deg: f64) -> String {
    let echo = crate::number::echo;
    match e {
        RollingError::InvalidAxesAngle => format!(
            "--axes-angle-deg {}: the angle between the bowl's axis and the vertical must be at \
             least 0 and below 90 degrees (at 90 the bottom stands upright and nothing presses \
             the granule on it); give a tilt below 90",
            echo(th_deg)
        ),
        RollingError::InvalidRimRadius if scene.rim_radius_m.is_finite() => format!(
            "--ri-m {} m is not inside the bottom's radius --rim-radius-m {} m: the granule \
             starts inside the bowl; give a release radius below {} m",
            echo(scene.ri_m),
            echo(scene.rim_radius_m),
            echo(scene.rim_radius_m)
        ),
        e => words(e),
    }
}

pub fn words(e: RollingError) -> String {
    match e {
        RollingError::InvalidPrecession => "--precession-rad-s must be a finite number".into(),
        RollingError::InvalidSpin => "--spin-rad-s must be a finite number".into(),
        RollingError::InvalidAxesAngle => {
            "--axes-angle-deg must be at least 0 and below 90 degrees".into()
        }
        RollingError::InvalidResistance => "--mu must be 0 or more".into(),
        RollingError::InvalidSlidingFriction => "--sliding-mu must be 0 or more".into(),
        RollingError::InvalidGravity => "--g must be 0 or more".into(),
        RollingError::InvalidK2 => {
            "--k2 must lie between 0 and 1 (5/7 for a solid sphere, 3/5 for a hollow one)".into()
        }
        RollingError::InvalidParticleRadius => "--particle-radius-m must be 0 or more".into(),
        RollingError::InvalidRodLength => {
            "--rod-offset-m (the horizontal offset L of the bowl's centre from the precession \
             axis, m) must be 0 or more"
                .into()
        }
        RollingError::InvalidStartRadius => "--ri-m must be 0 or more".into(),
        RollingError::InvalidRimRadius => {
            "--rim-radius-m must be finite and larger than --ri-m (the granule starts inside the bowl)"
                .into()
        }
        RollingError::InvalidAzimuth => "--release-azimuth-deg must be a finite number".into(),
        RollingError::ExtremeMagnitude(input) => super::refusals::extreme_magnitude(match input {
            RollingInput::Precession => "--precession-rad-s",
            RollingInput::Spin => "--spin-rad-s",
            RollingInput::Resistance => "--mu",
            RollingInput::SlidingFriction => "--sliding-mu",
            RollingInput::Gravity => "--g",
            RollingInput::ParticleRadius => "--particle-radius-m",
            RollingInput::RodLength => "--rod-offset-m",
            RollingInput::StartRadius => "--ri-m",
            RollingInput::RimRadius => "--rim-radius-m",
        }),
        RollingError::Integration(SystemError::StepLimit) => {
            "the integration took too many steps: try --method dp54 with a looser --tol, or a \
             larger --step-s"
                .into()
        }
        RollingError::Integration(SystemError::NotFinite) => {
            "the integration diverged (a state became infinite): give a smaller --step-s or a \
             tighter --tol"
                .into()
        }
        RollingError::Integration(SystemError::InvalidStep) => {
            "--step-s and --tol must be positive numbers".into()
        }
        RollingError::Integration(SystemError::Stalled) => {
            "the integration stalled at a roll/slide switch (steps that do not advance the \
             time): give a tighter --tol"
                .into()
        }
    }
}

/// Why a run gave no answer, with the method as set: the step cap said "try --method dp54 with a
/// looser --tol" to a run at `--tol 1e-16` with dp54, without the tolerance or the cap.
pub(super) fn run_words(e: RollingError, method: RollingMethod<f64>) -> String {
    match (e, method) {
        // Looser than the default the cap is met where a granule slows nearly to rest against a
        // resistance that barely holds it (the rolling work-precision chart's near-stick scene,
        // 30 deg, mu_r 0.55: the cap at 1e-4 and 1e-7, an answer at 1e-8): a tighter --tol
        // gets through there, a looser one does not.
        (RollingError::Integration(SystemError::StepLimit), RollingMethod::Dp54 { rtol })
            if rtol > 1e-9 =>
        {
            format!(
                "the integration took more than {} steps at --tol {rtol:e}: give a tighter --tol \
                 (the default, 1e-9): at a loose tolerance a granule that slows nearly to rest \
                 where the rolling resistance barely holds it takes ever shorter steps",
                rolling::MAX_STEPS
            )
        }
        (RollingError::Integration(SystemError::StepLimit), RollingMethod::Dp54 { rtol }) => {
            format!(
                "the integration took more than {} steps at --tol {rtol:e}: give a looser --tol \
                 (the default is 1e-9; below 1e-12 the step's error estimate is f64's rounding \
                 noise)",
                rolling::MAX_STEPS
            )
        }
        (RollingError::Integration(SystemError::StepLimit), RollingMethod::Rk4 { step_s }) => {
            format!(
                "the integration took more than {} steps of --step-s {} s: give a larger \
                 --step-s, or --method dp54 (it takes the steps the scene needs)",
                rolling::MAX_STEPS,
                crate::number::echo(step_s)
            )
        }
        (e, _) => words(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The step cap names the tolerance given and never advises the method in use: at
    /// `--tol 1e-16` with dp54 it said "try --method dp54 with a looser --tol". (The scene that
    /// met the cap end to end, a release that rolls to rest, now answers at 1e-16: its rest is
    /// an event, `predict_bowl_refusals`.)
    #[test]
    fn the_step_cap_names_the_setting_that_met_it() {
        let cap = RollingError::Integration(SystemError::StepLimit);
        let err = run_words(cap, RollingMethod::Dp54 { rtol: 1e-16 });
        assert!(
            err.contains("took more than 2000000 steps at --tol 1e-16: give a looser --tol"),
            "{err}"
        );
        assert!(!err.contains("--method dp54"), "{err}");
        // Looser than the default the way through is a tighter tolerance (it said "looser" at
        // --tol 1e-4 on the near-stick scene, which answers at 1e-8).
        let err = run_words(cap, RollingMethod::Dp54 { rtol: 1e-4 });
        assert!(
            err.contains("steps at --tol 1e-4: give a tighter --tol (the default, 1e-9)"),
            "{err}"
        );
        let err = run_words(cap, RollingMethod::Rk4 { step_s: 1e-9 });
        assert!(
            err.contains("steps of --step-s 1e-9 s: give a larger --step-s"),
            "{err}"
        );
    }
}

//! The integrator methods of `bowl predict`, at the scene's constant speed (model-core `ode`).

use anyhow::{Result, anyhow};
use model_core::ode::{self, Method, OdeOutcome};
use model_core::particle::{self, Model, Outcome, Scene};

use super::{Ends, Leaves, MethodChoice, MethodSettings, Prediction};

/// DP5(4) at tolerance `tol` on scene `s`: relative `tol`, absolute `tol R` (the same for r in
/// m and r' in m/s; r' at the rim is of order omega R). The one rule for `bowl predict --method
/// dp54 --tol`, its suggested tolerance and the work-precision chart, so one tolerance is one
/// plan everywhere (the CLI's absolute tolerance was `tol x 1e-2` whatever the rim: 61
/// evaluations where the chart, at `tol R` with R = 75 mm, took 55).
pub fn dp54<T: model_core::Real>(tol: T, s: &Scene<T>) -> Method<T> {
    Method::Dp54 {
        rtol: tol,
        atol: tol * s.rim_radius_m,
    }
}

/// The integrator `method` with fixed step `step_s` or DP5(4) tolerance `tol`; `None` for the
/// closed form.
pub fn plan(
    method: MethodChoice,
    step_s: f64,
    tol: f64,
    scene: &Scene<f64>,
) -> Option<Method<f64>> {
    Some(match method {
        MethodChoice::Euler => Method::Euler { step_s },
        MethodChoice::SemiImplicit => Method::SemiImplicitEuler { step_s },
        MethodChoice::Rk4 => Method::Rk4 { step_s },
        MethodChoice::Dp54 => dp54(tol, scene),
        MethodChoice::Closed => return None,
    })
}

/// Integrates one scene with a numerical method. The condition number reported is the
/// problem's (from the closed form): it does not depend on the method.
pub fn predict(scene: &Scene<f64>, model: Model, how: &MethodSettings) -> Result<Prediction> {
    let MethodSettings {
        method,
        step_s,
        tol,
    } = *how;
    // Default step: a hundredth of the time scale 1/omega.
    let h = step_s.unwrap_or_else(|| {
        if scene.omega_rad_s > 0.0 {
            0.01 / scene.omega_rad_s
        } else {
            0.01
        }
    });
    let m = plan(method, h, tol, scene)
        .ok_or_else(|| anyhow!("closed forms are not integrated (a bug in bowl)"))?;
    let closed =
        particle::residence(scene, model).map_err(|e| anyhow!(super::refusals::scene(e)))?;
    let report = particle::integrate_constant(scene, model, m).map_err(|e| {
        anyhow!(match (e, m, Ends::from(closed)) {
            (
                particle::OdeError::StepLimit,
                Method::Euler { step_s: h }
                | Method::SemiImplicitEuler { step_s: h }
                | Method::Rk4 { step_s: h },
                Ends::Leaves(c),
            ) => step_cap_words(h, c.residence_time_s, scene),
            _ => super::refusals::ode(e),
        })
    })?;
    let outcome = match report.outcome {
        OdeOutcome::Leaves {
            residence_time_s,
            exit_radial_velocity_m_s,
            exit_total_velocity_m_s,
        } => {
            // The condition is the problem's: the closed form's (well conditioned when that
            // does not leave).
            let (condition_number, ill_conditioned) = match Ends::from(closed) {
                Ends::Leaves(c) => (c.condition_number, c.ill_conditioned),
                _ => (1.0, false),
            };
            Leaves {
                residence_time_s,
                exit_radial_velocity_m_s,
                exit_total_velocity_m_s,
                condition_number,
                ill_conditioned,
            }
            .into()
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
    let relative_error = match (closed, outcome) {
        (
            Outcome::Leaves {
                residence_time_s: exact,
                ..
            },
            Outcome::Leaves {
                residence_time_s: t,
                ..
            },
        ) if exact > 0.0 => Some((t - exact).abs() / exact),
        _ => None,
    };
    let disagrees =
        matches!(closed, Outcome::Leaves { .. }) != matches!(outcome, Outcome::Leaves { .. });
    let off = if disagrees {
        Some(1.0)
    } else {
        relative_error.filter(|&e| e > WARN_RELATIVE_ERROR)
    };
    let check = StepCheck {
        method,
        relative_error,
        disagrees,
        suggested: off.and_then(|err| suggest(scene, model, method, h, tol, err)),
    };
    Ok(Prediction {
        outcome,
        rhs_evaluations: report.rhs_evaluations as u64,
        steps: report.steps as u64,
        check: Some(check),
    })
}

/// Relative error in T above which an integrator's answer gets a warning.
pub const WARN_RELATIVE_ERROR: f64 = 0.01;

/// The step (or DP5(4) tolerance) that brings this scene within half the warning level of its
/// closed form: a first guess from the method's order (error ~ h^p), then halved (or divided by
/// ten) until an actual run meets it.
fn suggest(
    scene: &Scene<f64>,
    model: Model,
    method: MethodChoice,
    h: f64,
    tol: f64,
    err: f64,
) -> Option<f64> {
    let exact = particle::residence(scene, model).ok()?.residence_time_s();
    let aim = 0.5 * WARN_RELATIVE_ERROR;
    let meets = |m: Method<f64>| match particle::integrate_constant(scene, model, m) {
        Ok(r) => match r.outcome {
            OdeOutcome::Leaves {
                residence_time_s, ..
            } => (residence_time_s - exact).abs() <= aim * exact,
            _ => false,
        },
        Err(_) => false,
    };
    let order = match method {
        MethodChoice::Rk4 => 4.0,
        _ => 1.0,
    };
    let mut setting = match method {
        MethodChoice::Dp54 => tol * aim / err,
        _ => h * (aim / err).powf(1.0 / order),
    };
    for _ in 0..40 {
        let m = plan(method, setting, setting, scene)?;
        if meets(m) {
            return Some(setting);
        }
        setting *= if method == MethodChoice::Dp54 {
            0.1
        } else {
            0.5
        };
    }
    None
}

/// An integrator's answer held against the closed form of the same constant-speed scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepCheck {
    method: MethodChoice,
    /// `|T - T_closed| / T_closed` where both leave.
    pub relative_error: Option<f64>,
    /// One says the granule leaves, the other that it does not.
    pub disagrees: bool,
    /// Where the answer is off: the step (or tolerance) found to meet half the warning level.
    pub suggested: Option<f64>,
}

impl StepCheck {
    /// The warning to print, if the step (or tolerance) is too coarse for this scene: how far
    /// off, and the setting found to bring it within half the warning level.
    pub fn warning(&self) -> Option<String> {
        let fix = match (self.method, self.suggested) {
            (MethodChoice::Dp54, Some(tol)) => format!("use --tol {tol:.0e} or tighter"),
            (_, Some(h)) => {
                format!("use --step-s {h:.2e} or less, or the closed form (--method closed)")
            }
            (_, None) => "use the closed form (--method closed)".to_string(),
        };
        if self.disagrees {
            return Some(format!(
                "this setting and the closed form disagree on whether the granule leaves: {fix}"
            ));
        }
        let err = self.relative_error?;
        (err > WARN_RELATIVE_ERROR).then(|| {
            format!(
                "the {} answer is {:.1} % off the closed form of this scene: {fix}",
                super::method_name(self.method),
                100.0 * err
            )
        })
    }
}

/// A fixed step that meets the step cap before the granule leaves: the step, the cap, the time
/// it needs (the closed form's) and the step that gets there. It said "took too many steps: give
/// a larger --step-s or a looser --tol" to `--omega-rad-s 1e-6 --method rk4 --step-s 0.001`,
/// where the granule takes 738 779 s (7e8 steps).
fn step_cap_words(step_s: f64, residence_s: f64, scene: &Scene<f64>) -> String {
    let profile = ode::ConstantOmega(scene.omega_rad_s);
    let cap = ode::Limits::for_scene(scene, &profile).max_steps;
    let echo = crate::number::echo;
    // Two significant figures, rounded up (so the step given does reach the exit), printed
    // through their own decimal: 0.74, not 0.7387791926933908.
    let least = residence_s / f64::from(cap);
    let unit = 10f64.powf(least.log10().floor() - 1.0);
    let at_least: f64 = format!("{:.1e}", (least / unit).ceil() * unit)
        .parse()
        .unwrap_or(least);
    format!(
        "the integration took more than {cap} steps of {} s (--step-s): the granule takes {} s \
         to leave (the closed form), so give --step-s of at least {} s, or --method closed \
         (exact)",
        echo(step_s),
        crate::number::fixed(residence_s, 3),
        echo(at_least)
    )
}

/// `T` of a chosen plan over a varying speed, s: 0 for a particle already at the rim, infinite
/// when it does not leave within the run's horizon.
pub fn plan_time_s<P: model_core::ode::OmegaProfile<f64>>(
    scene: &Scene<f64>,
    model: Model,
    profile: &P,
    method: Method<f64>,
) -> Result<f64> {
    let limits = ode::Limits::for_scene(scene, profile);
    let report = particle::integrate(scene, model, profile, method, limits)
        .map_err(|e| anyhow!(super::refusals::ode(e)))?;
    Ok(match report.outcome {
        OdeOutcome::Leaves {
            residence_time_s, ..
        } => residence_time_s,
        OdeOutcome::AlreadyAtRim { .. } => 0.0,
        _ => f64::INFINITY,
    })
}

/// The line `bowl predict` prints for a chosen plan's `T`.
pub fn plan_time_line(model: Model, time_s: f64) -> String {
    let name = super::model_name(model);
    if time_s.is_finite() {
        format!("{name:<8} leaves after T = {time_s:.9} s")
    } else {
        format!("{name:<8} NEVER LEAVES within the run's horizon")
    }
}

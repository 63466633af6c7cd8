//! "Model no more than a scene needs": pick the model (flat or Coriolis) and the method
//! (closed form, or an integrator with its step or tolerance) from error estimates computed
//! for the scene at hand.
//!
//! 1. **Tolerance from the scene's own spread.** `T` is recomputed with each uncertain parameter
//!    at the ends of its stated range (mu relative, the radii absolute, omega relative); the
//!    spread is the sum of the one-at-a-time relative changes (a first-order worst case). The
//!    tolerance is a tenth of that, clamped to `[64 epsilon, 0.1]`: computing `T` to 1e-12 when
//!    mu is known to 20 % is waste.
//! 2. **Model.** The Coriolis term's effect `|T_coriolis - T_flat| / T_flat` is computed (closed
//!    forms for a constant speed; for a varying one the pilot's Coriolis `T` against the flat
//!    model at the pilot's two coarsest steps, extrapolated, and where that does not settle it,
//!    a flat run whose error is within 1/32 of the tolerance). Within the tolerance, with room
//!    left for the method, the flat model is enough.
//! 3. **Method.** Constant speed: the closed form (exact to rounding, cheapest). A first-order
//!    spin-up (f64): RK4 at the longest step whose error the precomputed table (`table.rs`:
//!    RK4's error constant, the Coriolis effect and `T` measured once over the spin-up's
//!    dimensionless features) predicts within half the tolerance, with no run at all for a
//!    stated tolerance (a derived one runs the spread's scenes only); on `bowl chart
//!    chooser`'s grid that choice costs 0.3x the plan it picks and at most 1.232x the cheapest
//!    plan. Otherwise, time-varying
//!    speed: RK4 at the longest step whose error the pilot (`pilot.rs`: RK4 at `h`, `h/2`, `h/4`,
//!    `h/8` from the release time, `h` resolving both `1/omega` and the speed's own time
//!    scale, where the error follows `C h^p`) predicts within half of what the model leaves of
//!    the tolerance; DP5(4), calibrated by tolerances ten apart, where
//!    RK4 would need more steps than the cap or the speed has kinks (a logged trace). No search
//!    against a tight reference: RK4 was the cheapest plan meeting the tolerance on every scene
//!    of `bowl chart chooser`'s grid, and the step the pilot predicts costs at most 1.24x the
//!    brute force's cheapest there (docs/model.md, the chooser). Explicit and semi-implicit
//!    Euler are not candidates (order 1, more expensive per evaluation on both cost tables).

use crate::Real;
use crate::ode::{Limits, Method, OdeOutcome, OmegaProfile};
use crate::particle::{self, Model, OdeError, Outcome, Scene, SceneError};
use spread::{perturbations, spread};

/// How well the scene's parameters are known.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Knowledge<T> {
    /// Relative uncertainty of the resistance coefficient mu (0.2 = 20 %).
    pub mu_rel: T,
    /// Absolute uncertainty of the start and rim radii, m.
    pub radius_m: T,
    /// Relative uncertainty of the bowl speed.
    pub omega_rel: T,
}

/// What the answer must meet: a tolerance the caller states, or one derived from how well the
/// scene's parameters are known.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Need<T> {
    /// The parameters' uncertainty: the tolerance is a tenth of the spread it causes in `T`.
    Uncertainty(Knowledge<T>),
    /// An explicit relative tolerance on `T` (clamped to `[64 epsilon, 0.1]`).
    Tolerance(T),
}

/// How to compute `T`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Plan<T> {
    /// [`particle::residence`].
    ClosedForm,
    /// [`particle::residence`] at the mean of a varying speed over the residence time: enough
    /// when the speed varies little while the particle is in the bowl.
    ClosedFormAtMeanSpeed {
        /// The mean bowl speed over `[0, T]`, rad/s.
        omega_rad_s: T,
    },
    /// [`particle::integrate`] with this method.
    Integrate(Method<T>),
}

/// The chooser's decision and the numbers it was made from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Choice<T> {
    /// The model to use.
    pub model: Model,
    /// The method to use.
    pub plan: Plan<T>,
    /// Relative tolerance on `T` the scene warrants.
    pub tolerance_rel: T,
    /// Relative spread of `T` over the parameters' uncertainty (infinite if some parameter
    /// set within it never leaves); `None` when the tolerance was given instead.
    pub spread_rel: Option<T>,
    /// `|T_coriolis - T_flat| / T_flat`, computed (or read from the table, where it chose).
    pub coriolis_effect_rel: T,
    /// The plan's relative error as predicted by the pilot runs or the table (0 for the closed
    /// form: rounding; for the closed form at the mean speed, its difference from the pilot's
    /// `T`).
    pub estimated_error_rel: T,
    /// Right-hand-side evaluations the plan costs (0 for the closed form; from the table, counted
    /// from the `T` it reads, within 25 %).
    pub rhs_evaluations: u32,
    /// The plan's measured cost on the target of `T` (f64: host ns; f32: M4F instructions).
    pub predicted_cost: f64,
    /// `T` as the chooser estimated it on the way, s (the closed forms' for a constant speed,
    /// the table's reading, within 25 %, or the pilot's extrapolation for a varying one).
    pub time_estimate_s: T,
    /// Right-hand-side evaluations the choice itself ran (0 for a constant speed).
    pub choosing_evaluations: u32,
    /// `T` the choice already computed, s, within the plan's budget: where the plan is a DP5(4)
    /// run the pilot made, the pilot's finer run (a tenth of the plan's `rtol`, its difference
    /// from the plan's within the budget) is this, and running the plan again adds nothing.
    /// `None` where the plan must run.
    pub answer_s: Option<T>,
    /// What the choice was made from.
    pub source: Source,
}

/// What a choice was made from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// The two closed forms (a constant speed).
    ClosedForms,
    /// The precomputed error table (a first-order spin-up): no run but, for a tolerance derived
    /// from the parameters' uncertainty, the spread's.
    Table,
    /// Pilot runs of the scene itself.
    PilotRuns,
}

impl Source {
    /// In plain words, for `bowl predict`.
    pub fn describe(self) -> &'static str {
        match self {
            Source::ClosedForms => "from the two closed forms",
            Source::Table => "from the precomputed error table",
            Source::PilotRuns => "from pilot runs of the scene",
        }
    }

    /// The JSON name.
    pub fn name(self) -> &'static str {
        match self {
            Source::ClosedForms => "closed-forms",
            Source::Table => "table",
            Source::PilotRuns => "pilot-runs",
        }
    }
}

/// Why no choice was made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ChooseError {
    /// The scene was invalid.
    Scene(SceneError),
    /// An uncertainty was NaN, infinite or negative.
    InvalidKnowledge,
    /// At the nominal parameters the particle does not leave: there is no `T` to compute.
    DoesNotLeave,
    /// An integration failed while calibrating.
    Ode(OdeError),
    /// No integrator met the tolerance within the step cap.
    NoMethodMeetsTolerance,
}

fn check_knowledge<T: Real>(k: &Knowledge<T>) -> Result<(), ChooseError> {
    if k.mu_rel.is_nonneg_finite()
        && k.radius_m.is_nonneg_finite()
        && k.omega_rel.is_nonneg_finite()
    {
        Ok(())
    } else {
        Err(ChooseError::InvalidKnowledge)
    }
}

fn check_need<T: Real>(need: &Need<T>) -> Result<(), ChooseError> {
    match need {
        Need::Uncertainty(k) => check_knowledge(k),
        Need::Tolerance(t) if t.is_nonneg_finite() && *t > T::ZERO => Ok(()),
        Need::Tolerance(_) => Err(ChooseError::InvalidKnowledge),
    }
}

/// The tolerance an explicit need asks for (clamped like a derived one).
fn clamp_tolerance<T: Real>(tolerance: T) -> T {
    let floor = T::from_f64(64.0) * T::EPSILON;
    tolerance.max(floor).min(T::from_f64(0.1))
}

fn tolerance_from<T: Real>(spread: T) -> T {
    clamp_tolerance(spread * T::from_f64(0.1))
}

fn time_of<T: Real>(s: &Scene<T>, m: Model) -> T {
    match particle::residence(s, m) {
        Ok(o) => o.residence_time_s(),
        // An invalid perturbed scene (cannot happen: perturbations stay non-negative) counts
        // as "not determined".
        Err(_) => T::INFINITY,
    }
}

/// Chooses for a constant bowl speed (`scene.omega_rad_s`), the tolerance from the parameters'
/// uncertainty: see [`choose_constant_for`].
pub fn choose_constant<T: Real>(
    scene: &Scene<T>,
    knowledge: &Knowledge<T>,
) -> Result<Choice<T>, ChooseError> {
    choose_constant_for(scene, &Need::Uncertainty(*knowledge))
}

/// Chooses for a constant bowl speed (`scene.omega_rad_s`): always the closed form; the model
/// by the Coriolis effect against the tolerance.
pub fn choose_constant_for<T: Real>(
    scene: &Scene<T>,
    need: &Need<T>,
) -> Result<Choice<T>, ChooseError> {
    scene.validate().map_err(ChooseError::Scene)?;
    check_need(need)?;
    let flat = particle::residence(scene, Model::Flat).map_err(ChooseError::Scene)?;
    let coriolis = particle::residence(scene, Model::Coriolis).map_err(ChooseError::Scene)?;
    let (tf, tc) = match (flat, coriolis) {
        (
            Outcome::Leaves {
                residence_time_s: a,
                ..
            },
            Outcome::Leaves {
                residence_time_s: b,
                ..
            },
        ) => (a, b),
        (Outcome::AlreadyAtRim { .. }, _) => (T::ZERO, T::ZERO),
        _ => return Err(ChooseError::DoesNotLeave),
    };
    let effect = if tf > T::ZERO {
        (tc - tf).abs() / tf
    } else {
        T::ZERO
    };
    // Spread of the more complete model (it carries every parameter's effect).
    let model_for_spread = if scene.mu > T::ZERO {
        Model::Coriolis
    } else {
        Model::Flat
    };
    let nominal = if model_for_spread == Model::Coriolis {
        tc
    } else {
        tf
    };
    let (spread_rel, tolerance) = match need {
        Need::Tolerance(t) => (None, clamp_tolerance(*t)),
        Need::Uncertainty(knowledge) => {
            let spread_rel = if nominal > T::ZERO {
                spread(
                    nominal,
                    &perturbations(scene, knowledge).map(|s| time_of(&s, model_for_spread)),
                )
            } else {
                T::ZERO
            };
            (Some(spread_rel), tolerance_from(spread_rel))
        }
    };
    let (model, time_estimate_s) = if effect <= tolerance {
        (Model::Flat, tf)
    } else {
        (Model::Coriolis, tc)
    };
    Ok(Choice {
        model,
        plan: Plan::ClosedForm,
        tolerance_rel: tolerance,
        spread_rel,
        coriolis_effect_rel: effect,
        estimated_error_rel: T::ZERO,
        rhs_evaluations: 0,
        predicted_cost: plan_cost(&Plan::<T>::ClosedForm, 0, Target::for_precision::<T>()),
        time_estimate_s,
        choosing_evaluations: 0,
        answer_s: None,
        source: Source::ClosedForms,
    })
}

/// `T` from an integration (infinite if it does not leave by the horizon).
fn run<T: Real, P: OmegaProfile<T>>(
    s: &Scene<T>,
    m: Model,
    p: &P,
    method: Method<T>,
    limits: Limits<T>,
) -> Result<(T, u32), ChooseError> {
    let r = particle::integrate(s, m, p, method, limits).map_err(ChooseError::Ode)?;
    let t = match r.outcome {
        OdeOutcome::Leaves {
            residence_time_s, ..
        } => residence_time_s,
        OdeOutcome::AlreadyAtRim { .. } => T::ZERO,
        _ => T::INFINITY,
    };
    Ok((t, r.rhs_evaluations))
}

fn dp<T: Real>(rtol: T, scene: &Scene<T>) -> Method<T> {
    Method::Dp54 {
        rtol,
        atol: rtol * scene.rim_radius_m * T::from_f64(1e-2),
    }
}

pub mod cost;
pub mod incline;
pub mod incline_rotation;
mod pilot;
pub mod rotation_bound;
mod spread;
pub mod table;
mod trace;
mod varying;
pub mod whole;

pub use cost::{MethodCost, Target, plan_cost};
#[cfg(test)]
pub(crate) use varying::choose_varying_reading;
pub(crate) use varying::choose_varying_with_margin;
pub use varying::{choose_varying, choose_varying_for};

pub use trace::{
    LOGGED_SPEED_RESOLUTION_RAD_S, SampledOmega, TraceError, TraceMeasurement, choose_trace,
    mean_omega_rad_s, residence_estimate_s,
};

#[cfg(test)]
mod tests;
#[cfg(test)]
mod trace_tests;

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
//!    spin-up with a stated tolerance (f64): RK4 at the longest step whose error the
//!    precomputed table (`table.rs`: RK4's error constant, the Coriolis effect and `T` measured
//!    once over the spin-up's dimensionless features) predicts within half the tolerance, with
//!    no run at all; on `bowl chart chooser`'s grid that choice costs 0.3x the plan it picks
//!    and at most 1.232x the cheapest plan. Otherwise, time-varying
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
use crate::ode::{self, Limits, Method, OdeError, OdeOutcome, OmegaProfile};
use crate::particle::{self, Model, Outcome, Scene, SceneError};
use spread::{perturbations, spread, spread_at};

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
    /// [`ode::integrate`] with this method.
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
    /// The precomputed error table (a first-order spin-up with a stated tolerance): no run.
    Table,
    /// Pilot runs of the scene itself.
    PilotRuns,
}

impl Source {
    /// In plain words, for `bowl predict`.
    pub fn describe(self) -> &'static str {
        match self {
            Source::ClosedForms => "from the two closed forms",
            Source::Table => "from the precomputed error table, without running the scene",
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
    let r = ode::integrate(s, m, p, method, limits).map_err(ChooseError::Ode)?;
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

/// Chooses for a time-varying bowl speed, the tolerance from the parameters' uncertainty: see
/// [`choose_varying_for`].
pub fn choose_varying<T: Real, P: OmegaProfile<T>>(
    scene: &Scene<T>,
    knowledge: &Knowledge<T>,
    profile: &P,
) -> Result<Choice<T>, ChooseError> {
    choose_varying_for(scene, &Need::Uncertainty(*knowledge), profile)
}

/// Chooses for a time-varying bowl speed (`scene.omega_rad_s` is ignored): RK4 at the longest
/// step whose error a pilot predicts within half the tolerance (see the module docs and
/// `pilot.rs`); DP5(4) where RK4 would need more steps than the cap.
pub fn choose_varying_for<T: Real, P: OmegaProfile<T>>(
    scene: &Scene<T>,
    need: &Need<T>,
    profile: &P,
) -> Result<Choice<T>, ChooseError> {
    choose_varying_with_margin(scene, need, profile).map(|(choice, _)| choice)
}

/// [`choose_varying_for`], and a bound on the relative error of its `time_estimate_s` (the
/// pilot's finest run's estimated error: the extrapolation is better still).
pub(crate) fn choose_varying_with_margin<T: Real, P: OmegaProfile<T>>(
    scene: &Scene<T>,
    need: &Need<T>,
    profile: &P,
) -> Result<(Choice<T>, T), ChooseError> {
    choose_varying_reading(scene, need, profile, true)
}

/// [`choose_varying_with_margin`]; with `read_table` false the pilot chooses even where the
/// table could (the tests hold both to the tolerance).
pub(crate) fn choose_varying_reading<T: Real, P: OmegaProfile<T>>(
    scene: &Scene<T>,
    need: &Need<T>,
    profile: &P,
    read_table: bool,
) -> Result<(Choice<T>, T), ChooseError> {
    scene.validate_except_omega().map_err(ChooseError::Scene)?;
    check_need(need)?;
    let limits = Limits::for_scene(scene, profile);
    let target = Target::for_precision::<T>();
    let w_max = profile.max_omega_rad_s().max(T::EPSILON);
    // The coarsest pilot step: well inside RK4's stability limit (2.785 / |l2|; |l2| <= 1.5
    // k omega here), and no longer than the speed's own time scale (a spin-up faster than
    // 1/omega sets RK4's error by its derivatives; a pilot blind to them found a false C h^p).
    let step_cap = (T::from_f64(1.5) / w_max).min(profile.time_scale_s());
    if scene.ri_m >= scene.rim_radius_m {
        let at_rim = Choice {
            model: Model::Flat,
            plan: Plan::ClosedForm,
            tolerance_rel: tolerance_from(T::ZERO),
            spread_rel: Some(T::ZERO),
            coriolis_effect_rel: T::ZERO,
            estimated_error_rel: T::ZERO,
            rhs_evaluations: 0,
            predicted_cost: plan_cost(&Plan::<T>::ClosedForm, 0, target),
            time_estimate_s: T::ZERO,
            choosing_evaluations: 0,
            answer_s: None,
            source: Source::ClosedForms,
        };
        return Ok((at_rim, T::ZERO));
    }
    // A first-order spin-up with a stated tolerance, inside the table: no run (f64 only: the
    // table holds truncation errors, and f32 adds a rounding error the table does not know).
    if let (Need::Tolerance(t), Some(speed), true) = (
        need,
        profile.spin_up(),
        read_table && T::EPSILON.to_f64() < 1e-12,
    ) {
        let tolerance = clamp_tolerance(*t);
        if let Some(choice) = table::choice(scene, &speed, tolerance, step_cap, limits) {
            return Ok((choice, T::from_f64(table::TIME_READING_ERROR_REL)));
        }
    }
    // A smooth speed: RK4's error model. One with kinks: DP5(4) to a millionth first (the
    // spread and the Coriolis effect need T far better than the tolerance they set), then to
    // the method's budget below.
    let smooth = profile.is_smooth();
    // RK4 where its error settles into C h^p; otherwise (no such regime found) DP5(4). Returns
    // the pilot and every evaluation it took, a failed RK4 pilot's included.
    let pilot_of = |model: Model, budget: T| -> Result<(pilot::Pilot<T>, u32), ChooseError> {
        let mut spent = 0;
        if smooth {
            match pilot::rk4(scene, model, profile, limits, step_cap) {
                Ok(found) => return Ok((found, found.evaluations)),
                Err(evals) => spent = evals,
            }
        }
        let found = pilot::dp54(scene, model, profile, limits, budget)?;
        Ok((found, spent.saturating_add(found.evaluations)))
    };
    // A millionth, or what the precision can verify (f32: 3e-5).
    let first_budget = T::from_f64(1e-6).max(T::from_f64(256.0) * T::EPSILON);
    let (coriolis, mut choosing) = pilot_of(Model::Coriolis, first_budget)?;
    let (spread_rel, tolerance) = match need {
        Need::Tolerance(t) => (None, clamp_tolerance(*t)),
        Need::Uncertainty(knowledge) => {
            // The parameters at the ends of their ranges, at twice the pilot's finest step;
            // where the spread comes out within 100x of the runs' own error there, once more
            // at the step the pilot predicts within a hundredth of it.
            let mut setting = coriolis.step_s * T::TWO;
            let mut spread_rel = T::ZERO;
            for _ in 0..2 {
                let (found, evals) = spread_at(
                    scene,
                    knowledge,
                    profile,
                    coriolis.method(setting, scene),
                    limits,
                );
                choosing = choosing.saturating_add(evals);
                spread_rel = found;
                let noise = coriolis.error_at(setting);
                if found.is_nan() || found >= T::from_f64(100.0) * noise {
                    break;
                }
                setting = coriolis.step_for(found * T::from_f64(0.01));
            }
            (Some(spread_rel), tolerance_from(spread_rel))
        }
    };
    // The flat model's effect: first from a cheap probe, else from a flat run at the step the
    // pilot predicts within 1/32 of the tolerance.
    let (effect, effect_bound, evals) = flat_effect(scene, profile, limits, &coriolis, tolerance)?;
    choosing = choosing.saturating_add(evals);
    // The method's predicted error is kept within half of what the model leaves of the
    // tolerance (the prediction may be off by up to 2x). The flat model leaves the tolerance
    // less its effect (with both runs' errors added): it is taken while that is at least a
    // quarter of the tolerance, so its plan costs at most 2^(1/4) more than the Coriolis one.
    let model = if effect_bound <= tolerance * T::from_f64(0.75) {
        Model::Flat
    } else {
        Model::Coriolis
    };
    let method_budget = if model == Model::Flat {
        (tolerance - effect_bound) * T::HALF
    } else {
        tolerance * T::HALF
    };
    let pilot = if model == Model::Flat || !smooth {
        let (own, evals) = pilot_of(model, method_budget)?;
        choosing = choosing.saturating_add(evals);
        own
    } else {
        coriolis
    };
    let h = pilot.step_for(method_budget);
    let stiff_rate = ode::stiff_rate_per_s(scene, model, w_max);
    let t_start = ode::start_time_s(scene, profile, stiff_rate, limits).unwrap_or(T::ZERO);
    // Steps to the rim: the span over the step, rounded up.
    let span = ((pilot.time_s - t_start) / h).to_f64().max(0.0);
    let whole = span as u64;
    let steps = if (whole as f64) < span {
        whole + 1
    } else {
        whole
    };
    let (plan, evals, estimated, pilot) = if pilot.kind == pilot::Kind::Dp54 {
        (
            Plan::Integrate(pilot.method(h, scene)),
            pilot.plan_evaluations,
            pilot.error_rel,
            pilot,
        )
    } else if steps <= u64::from(limits.max_steps) {
        // RK4: four evaluations a step and one where the rim is crossed.
        let evals = u32::try_from(steps.saturating_mul(4).saturating_add(1)).unwrap_or(u32::MAX);
        (
            Plan::Integrate(Method::Rk4 { step_s: h }),
            evals,
            pilot.error_at(h),
            pilot,
        )
    } else {
        // More RK4 steps than the cap: DP5(4), calibrated to the budget.
        let own = pilot::dp54(scene, model, profile, limits, method_budget)?;
        choosing = choosing.saturating_add(own.evaluations);
        (
            Plan::Integrate(own.method(own.step_s, scene)),
            own.plan_evaluations,
            own.error_rel,
            own,
        )
    };
    let choice = Choice {
        model,
        plan,
        tolerance_rel: tolerance,
        spread_rel,
        coriolis_effect_rel: effect,
        estimated_error_rel: estimated,
        rhs_evaluations: evals,
        predicted_cost: plan_cost(&plan, evals, target),
        time_estimate_s: pilot.time_s,
        choosing_evaluations: choosing,
        answer_s: (pilot.kind == pilot::Kind::Dp54).then_some(pilot.time_s),
        source: Source::PilotRuns,
    };
    Ok((choice, pilot.error_rel))
}

/// The Coriolis term's effect on `T` (`|T_coriolis - T_flat| / T_flat`), an upper bound on it
/// with both runs' errors added, and the evaluations it took.
///
/// Where the Coriolis model is needed the effect is usually far above the tolerance (about 1 %
/// on the rig's scenes), and a precise flat run (its error within 1/32 of the tolerance, twice
/// the evaluations of the plan) only confirms it. So a probe goes first: the flat model at the
/// pilot's two coarsest steps, `h` and `h/2` (a fifth of the pilot), its error at `h/2` taken
/// from their difference at RK4's order 4 (Richardson) and doubled, both extrapolated
/// `T` compared. When even the effect less both errors exceeds what the flat model could
/// use (3/4 of the tolerance), the Coriolis model is settled. Otherwise, and where the precise
/// run would cost less than the probe (loose tolerances, where the plan is a few coarse
/// steps), the precise run decides.
fn flat_effect<T: Real, P: OmegaProfile<T>>(
    scene: &Scene<T>,
    profile: &P,
    limits: Limits<T>,
    coriolis: &pilot::Pilot<T>,
    tolerance: T,
) -> Result<(T, T, u32), ChooseError> {
    let tc = coriolis.time_s;
    let flat_step = coriolis.step_for(tolerance * T::from_f64(1.0 / 32.0));
    let coarse = coriolis.coarsest_step_s;
    let mut spent = 0u32;
    // The probe costs three runs at `h` (one at `h`, one at `h/2`); the precise run
    // `h / flat_step` of them.
    if coriolis.kind == pilot::Kind::Rk4 && flat_step * T::from_f64(3.0) < coarse {
        let flat_at = |step_s| run(scene, Model::Flat, profile, Method::Rk4 { step_s }, limits);
        let half = coarse * T::HALF;
        let ((t_h, e1), (t_half, e2)) = (flat_at(coarse)?, flat_at(half)?);
        spent = e1.saturating_add(e2);
        if t_h.is_finite() && t_half.is_finite() {
            let excess = T::from_f64(15.0);
            let correction = (t_h - t_half) / excess;
            let tf = t_half - correction;
            let flat_error = T::TWO * correction.abs() / tf;
            let effect = (tc - tf).abs() / tf;
            let lower = effect - flat_error - coriolis.error_rel;
            if tf > T::ZERO && lower > tolerance * T::from_f64(0.75) {
                return Ok((effect, effect + flat_error + coriolis.error_rel, spent));
            }
        }
    }
    let flat_error = coriolis.error_at(flat_step);
    let (tf, evals) = run(
        scene,
        Model::Flat,
        profile,
        coriolis.method(flat_step, scene),
        limits,
    )?;
    spent = spent.saturating_add(evals);
    if !tf.is_finite() {
        return Err(ChooseError::DoesNotLeave);
    }
    let effect = (tc - tf).abs() / tf;
    Ok((effect, effect + flat_error + coriolis.error_rel, spent))
}

pub mod cost;
mod pilot;
mod spread;
pub mod table;
mod trace;

pub use cost::{MethodCost, Target, plan_cost};

pub use trace::{
    LOGGED_SPEED_RESOLUTION_RAD_S, SampledOmega, TraceError, TraceMeasurement, choose_trace,
    mean_omega_rad_s, residence_estimate_s,
};

#[cfg(test)]
mod tests;

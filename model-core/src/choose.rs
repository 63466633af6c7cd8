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
//!    forms for a constant speed; loose DP54 runs of both models on the actual omega(t)
//!    otherwise). Below the tolerance the flat model is enough.
//! 3. **Method.** Constant speed: the closed form (exact to rounding, cheapest). Time-varying
//!    speed: each integrator is calibrated on the scene: a run's error is measured against a
//!    tight DP54 reference, its step (or tolerance) rescaled by the method's order to a quarter
//!    of the tolerance, the rescaled run measured again (halving until it meets the tolerance
//!    at that setting *and* at half of it, so a lucky cancellation does not pass), and the one
//!    with the fewest right-hand-side evaluations wins. Explicit Euler is not a candidate:
//!    semi-implicit Euler has the same order and cost per step and no stability limit.

use crate::Real;
use crate::ode::{self, Limits, Method, OdeError, OdeOutcome, OmegaProfile};
use crate::particle::{self, Model, Outcome, Scene, SceneError};

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
    /// `|T_coriolis - T_flat| / T_flat`, computed.
    pub coriolis_effect_rel: T,
    /// The plan's error, measured against a tight reference (0 for the closed form: rounding).
    pub measured_error_rel: T,
    /// Right-hand-side evaluations the plan costs (0 for the closed form).
    pub rhs_evaluations: u32,
    /// The plan's measured cost on the target of `T` (f64: host ns; f32: M4F instructions).
    pub predicted_cost: f64,
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

/// The perturbed scenes: each parameter at both ends of its range, the others nominal.
fn perturbations<T: Real>(s: &Scene<T>, k: &Knowledge<T>) -> [Scene<T>; 8] {
    let lo = |x: T, rel: T| (x * (T::ONE - rel)).max(T::ZERO);
    [
        Scene {
            mu: lo(s.mu, k.mu_rel),
            ..*s
        },
        Scene {
            mu: s.mu * (T::ONE + k.mu_rel),
            ..*s
        },
        Scene {
            ri_m: (s.ri_m - k.radius_m).max(T::ZERO),
            ..*s
        },
        Scene {
            ri_m: s.ri_m + k.radius_m,
            ..*s
        },
        Scene {
            rim_radius_m: (s.rim_radius_m - k.radius_m).max(T::ZERO),
            ..*s
        },
        Scene {
            rim_radius_m: s.rim_radius_m + k.radius_m,
            ..*s
        },
        Scene {
            omega_rad_s: lo(s.omega_rad_s, k.omega_rel),
            ..*s
        },
        Scene {
            omega_rad_s: s.omega_rad_s * (T::ONE + k.omega_rel),
            ..*s
        },
    ]
}

/// Sum over parameters of the larger relative change of `T` at either end of its range.
fn spread<T: Real>(nominal: T, times: &[T; 8]) -> T {
    let mut sum = T::ZERO;
    for pair in times.chunks(2) {
        let d0 = (pair[0] - nominal).abs();
        let d1 = (pair[1] - nominal).abs();
        sum += d0.max(d1) / nominal;
    }
    if sum.is_finite() { sum } else { T::INFINITY }
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
    Ok(Choice {
        model: if effect <= tolerance {
            Model::Flat
        } else {
            Model::Coriolis
        },
        plan: Plan::ClosedForm,
        tolerance_rel: tolerance,
        spread_rel,
        coriolis_effect_rel: effect,
        measured_error_rel: T::ZERO,
        rhs_evaluations: 0,
        predicted_cost: plan_cost(&Plan::<T>::ClosedForm, 0, Target::for_precision::<T>()),
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

/// Chooses for a time-varying bowl speed (`scene.omega_rad_s` is ignored): an integrator,
/// calibrated on this scene and profile (see the module docs).
pub fn choose_varying_for<T: Real, P: OmegaProfile<T>>(
    scene: &Scene<T>,
    need: &Need<T>,
    profile: &P,
) -> Result<Choice<T>, ChooseError> {
    scene.validate_except_omega().map_err(ChooseError::Scene)?;
    check_need(need)?;
    let limits = Limits::for_scene(scene, profile);
    let ref_tol = (T::from_f64(1e-12)).max(T::from_f64(16.0) * T::EPSILON);
    let loose = T::from_f64(1e-7).max(T::from_f64(64.0) * T::EPSILON);
    // Coriolis effect and spread from loose DP54 runs on the actual profile.
    let (tf, _) = run(scene, Model::Flat, profile, dp(loose, scene), limits)?;
    let (tc, _) = run(scene, Model::Coriolis, profile, dp(loose, scene), limits)?;
    if !tc.is_finite() || !tf.is_finite() {
        return Err(ChooseError::DoesNotLeave);
    }
    if tf <= T::ZERO {
        return Ok(Choice {
            model: Model::Flat,
            plan: Plan::ClosedForm,
            tolerance_rel: tolerance_from(T::ZERO),
            spread_rel: Some(T::ZERO),
            coriolis_effect_rel: T::ZERO,
            measured_error_rel: T::ZERO,
            rhs_evaluations: 0,
            predicted_cost: plan_cost(&Plan::<T>::ClosedForm, 0, Target::for_precision::<T>()),
        });
    }
    let effect = (tc - tf).abs() / tf;
    let (spread_rel, tolerance) = match need {
        Need::Tolerance(t) => (None, clamp_tolerance(*t)),
        Need::Uncertainty(knowledge) => {
            let mut times = [T::ZERO; 8];
            let up = T::ONE + knowledge.omega_rel;
            let down = (T::ONE - knowledge.omega_rel).max(T::ZERO);
            for (i, (slot, s)) in times
                .iter_mut()
                .zip(perturbations(scene, knowledge).iter())
                .enumerate()
            {
                // omega's uncertainty scales the whole profile (entries 6 and 7).
                let factor = match i {
                    6 => down,
                    7 => up,
                    _ => T::ONE,
                };
                let scaled = ScaledProfile {
                    inner: profile,
                    factor,
                };
                *slot = run(s, Model::Coriolis, &scaled, dp(loose, scene), limits)
                    .map(|r| r.0)
                    .unwrap_or(T::INFINITY);
            }
            let spread_rel = spread(tc, &times);
            (Some(spread_rel), tolerance_from(spread_rel))
        }
    };
    let model = if effect <= tolerance {
        Model::Flat
    } else {
        Model::Coriolis
    };
    let (t_ref, _) = run(scene, model, profile, dp(ref_tol, scene), limits)?;
    let err_of = |t: T| (t - t_ref).abs() / t_ref;
    let w_max = profile.max_omega_rad_s().max(T::EPSILON);

    // Ranked by measured cost on the target, not by evaluations.
    let target = Target::for_precision::<T>();
    let mut best: Option<(Method<T>, T, u32, f64)> = None;
    let mut consider = |method: Method<T>, err: T, evals: u32| {
        let cost = plan_cost(&Plan::Integrate(method), evals, target);
        if err <= tolerance && best.is_none_or(|(_, _, _, c)| cost < c) {
            best = Some((method, err, evals, cost));
        }
    };
    // Fixed-step methods: calibrate at h0, rescale by the order, verify, halve until it holds.
    type Make<T> = fn(T) -> Method<T>;
    let fixed: [(Make<T>, f64); 2] = [
        (|h| Method::Rk4 { step_s: h }, 4.0),
        (|h| Method::SemiImplicitEuler { step_s: h }, 1.0),
    ];
    let quarter = tolerance * T::from_f64(0.25);
    // A setting is taken when it meets the tolerance and so does the next finer one: a lucky
    // cancellation of errors at one setting (it happens with the kink of a spin-up from rest)
    // does not survive refining. Returns the setting's T and evaluations.
    let robust = |method: Method<T>, finer: Method<T>| -> Option<(T, u32)> {
        let (t, evals) = run(scene, model, profile, method, limits).ok()?;
        let (t2, _) = run(scene, model, profile, finer, limits).ok()?;
        (err_of(t) <= tolerance && err_of(t2) <= tolerance).then_some((t, evals))
    };
    let grow_step = T::from_f64(core::f64::consts::SQRT_2.sqrt());
    let grow_rtol = T::from_f64(1.778_279_410_038_923);
    // Stay well inside RK4's stability limit (2.785 / |l2|; |l2| <= 1.5 k omega here).
    let step_cap = T::from_f64(1.5) / w_max;
    for (make, order) in fixed {
        let h0 = T::from_f64(0.1) / w_max;
        let Ok((t0, _)) = run(scene, model, profile, make(h0), limits) else {
            continue;
        };
        let e0 = err_of(t0);
        let mut h = if e0 > T::ZERO {
            h0 * (quarter / e0).ln().exp_times(1.0 / order)
        } else {
            h0
        };
        h = h.min(step_cap);
        for _ in 0..8 {
            // Skip plans that would need more steps than the cap allows.
            if t_ref / h > T::from_f64(limits.max_steps as f64) {
                break;
            }
            if let Some((t, evals)) = robust(make(h), make(h * T::HALF)) {
                // Then the longest step that is robust too, of the twelve 2^(1/4) apart above
                // it (up to 8x, within the stability margin): the calibration aimed at a
                // quarter of the tolerance, and the error is not monotonic in the step (the
                // kink of a spin-up, the event's interpolation).
                let (mut best_h, mut best) = (h, (t, evals));
                let mut longer = h;
                for _ in 0..12 {
                    longer = (longer * grow_step).min(step_cap);
                    if let Some(found) = robust(make(longer), make(longer * T::HALF)) {
                        (best_h, best) = (longer, found);
                    }
                    if longer >= step_cap {
                        break;
                    }
                }
                consider(make(best_h), err_of(best.0), best.1);
                break;
            }
            h *= T::HALF;
        }
    }
    // DP54: its global error is roughly proportional to rtol; rescale, verify, halve.
    let mut rtol = tolerance;
    for _ in 0..12 {
        if rtol < ref_tol {
            break;
        }
        if let Some((t, evals)) = robust(dp(rtol, scene), dp(rtol * T::HALF, scene)) {
            // Then the loosest robust tolerance of the twelve 10^(1/4) apart above it (up to
            // 1000x, at most 0.1).
            let (mut best_rtol, mut best) = (rtol, (t, evals));
            let mut looser = rtol;
            for _ in 0..12 {
                looser = (looser * grow_rtol).min(T::from_f64(0.1));
                if let Some(found) = robust(dp(looser, scene), dp(looser * T::HALF, scene)) {
                    (best_rtol, best) = (looser, found);
                }
                if looser >= T::from_f64(0.1) {
                    break;
                }
            }
            consider(dp(best_rtol, scene), err_of(best.0), best.1);
            break;
        }
        match run(scene, model, profile, dp(rtol, scene), limits) {
            Ok((t, _)) => {
                let e = err_of(t);
                let factor = (tolerance * T::HALF / e).min(T::HALF);
                rtol *= if factor > T::ZERO { factor } else { T::HALF };
            }
            Err(_) => rtol *= T::HALF,
        }
    }
    let (method, err, evals, cost) = best.ok_or(ChooseError::NoMethodMeetsTolerance)?;
    Ok(Choice {
        model,
        plan: Plan::Integrate(method),
        tolerance_rel: tolerance,
        spread_rel,
        coriolis_effect_rel: effect,
        measured_error_rel: err,
        rhs_evaluations: evals,
        predicted_cost: cost,
    })
}

/// A profile scaled by a constant factor (omega's relative uncertainty).
struct ScaledProfile<'a, T, P> {
    inner: &'a P,
    factor: T,
}

impl<T: Real, P: OmegaProfile<T>> OmegaProfile<T> for ScaledProfile<'_, T, P> {
    fn omega_rad_s(&self, t_s: T) -> T {
        self.inner.omega_rad_s(t_s) * self.factor
    }
    fn max_omega_rad_s(&self) -> T {
        self.inner.max_omega_rad_s() * self.factor
    }
    fn is_constant(&self) -> bool {
        self.inner.is_constant()
    }
}

/// `exp(ln_x * p)`: a power from a logarithm already taken.
trait ExpTimes {
    fn exp_times(self, p: f64) -> Self;
}

impl<T: Real> ExpTimes for T {
    fn exp_times(self, p: f64) -> Self {
        (self * T::from_f64(p)).exp()
    }
}

pub mod cost;
mod trace;

pub use cost::{MethodCost, Target, plan_cost};

pub use trace::{SampledOmega, TraceError, choose_trace, mean_omega_rad_s};

#[cfg(test)]
mod tests;

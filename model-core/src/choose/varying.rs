//! Choosing for a speed that varies in time: from the error table where it holds the scene
//! (`table.rs`), otherwise from pilot runs of the scene itself (`pilot.rs`); the module docs
//! of `choose` say how.

use super::spread::spread_at;
use super::{
    Choice, ChooseError, Knowledge, Need, Plan, Source, Target, check_need, clamp_tolerance, pilot,
    plan_cost, run, table, tolerance_from,
};
use crate::Real;
use crate::ode::{self, Limits, Method, OmegaProfile};
use crate::particle::{Model, Scene, radial};

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
    // A first-order spin-up inside the table (f64 only: the table holds truncation errors,
    // and f32 adds a rounding error the table does not know): the method with no run; a
    // tolerance derived from the parameters' uncertainty needs the spread's runs, at a step
    // the table reads.
    if let (Some(speed), true) = (profile.spin_up(), read_table && T::EPSILON.to_f64() < 1e-12)
        && let Some(found) = from_table(scene, need, profile, &speed, step_cap, limits)
    {
        return Ok((found, T::from_f64(table::TIME_READING_ERROR_REL)));
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
    let stiff_rate = radial::stiff_rate_per_s(scene, model, w_max);
    let t_start = radial::start_time_s(scene, profile, stiff_rate, limits).unwrap_or(T::ZERO);
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

/// The spread runs' own error, relative, at the step the table reads for them: a spread of
/// `T` (a few percent at least, where the tolerance comes from it) is then far above it.
const SPREAD_RUN_ERROR_REL: f64 = 1e-4;

/// The choice from the error table (`table.rs`), `None` where it has no reading. A stated
/// tolerance runs nothing; a derived one runs the spread's nine scenes with RK4 at the step
/// whose error the table reads within [`SPREAD_RUN_ERROR_REL`], and once more within a
/// hundredth of the spread found where that is not 100 times the runs' error.
fn from_table<T: Real, P: OmegaProfile<T>>(
    scene: &Scene<T>,
    need: &Need<T>,
    profile: &P,
    speed: &ode::SpinUp<T>,
    step_cap: T,
    limits: Limits<T>,
) -> Option<Choice<T>> {
    let reading = table::read(scene, speed)?;
    let (w_f, cap) = (speed.final_rad_s.to_f64(), step_cap.to_f64());
    let (spread_rel, tolerance, spent) = match need {
        Need::Tolerance(t) => (None, clamp_tolerance(*t), 0),
        Need::Uncertainty(knowledge) => {
            // Where the spread comes out within 100x of the runs' error, once more with runs
            // within a hundredth of it (taken as found, as the pilot's second pass is).
            let mut step_s = reading.coriolis_step_s(SPREAD_RUN_ERROR_REL, w_f, cap);
            let (mut spent, mut pass) = (0u32, 0);
            let found = loop {
                let method = Method::Rk4 {
                    step_s: T::from_f64(step_s),
                };
                let (spread, evals) = spread_at(scene, knowledge, profile, method, limits);
                spent = spent.saturating_add(evals);
                if pass == 1 || spread >= T::from_f64(100.0 * SPREAD_RUN_ERROR_REL) {
                    break spread;
                }
                let run_error = (spread.to_f64() * 0.01).max(1e-13);
                step_s = reading.coriolis_step_s(run_error, w_f, cap);
                pass += 1;
            };
            (Some(found), tolerance_from(found), spent)
        }
    };
    let choice = table::choice(&reading, speed, tolerance, step_cap, limits)?;
    Some(Choice {
        spread_rel,
        choosing_evaluations: spent,
        ..choice
    })
}

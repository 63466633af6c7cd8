//! What a varying-speed scene needs, from a few coarse RK4 runs instead of a search against a
//! tight reference.
//!
//! Integrated from the release time (`ode`, release.rs) the solution is smooth, so RK4's error
//! in `T` follows `C h^p` with `p = 4` once the step resolves the scene. Four runs at `h`,
//! `h/2`, `h/4`, `h/8` give three differences and two ratios of successive differences, each
//! `2^p` in that regime: when both lie between 2 and 40 (an observed order between 1 and 5.3)
//! and agree within 1.5x, the error of the `h/8` run is `|T(h/4) - T(h/8)| / (2^p - 1)`
//! (Richardson), the extrapolated `T` is better still, and the step that meets a tolerance
//! follows from `C h^p`, never coarser than `h` (the coarsest step the ratios vouch for).
//! Otherwise every step is halved and one finer run added. On `bowl chart chooser`'s grid the
//! pilot and the rest of the choice took 165 to 290 right-hand-side evaluations, where the
//! search it replaces ran a tight DP5(4) reference and dozens of candidate plans. A speed with
//! kinks (a logged trace) has no such regime: [`dp54`] calibrates DP5(4) instead.

use super::{ChooseError, dp, run};
use crate::Real;
use crate::ode::{Limits, Method, OmegaProfile};
use crate::particle::{Model, Scene};

/// Halvings of the pilot's coarsest step before it gives up.
const LEVELS: u32 = 12;

/// Which method a pilot measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    /// RK4 at halving steps: the error model `C h^p`.
    Rk4,
    /// DP5(4) at tolerances ten apart: the error of each from the next.
    Dp54,
}

/// What the pilot runs measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Pilot<T> {
    /// The method measured.
    pub kind: Kind,
    /// The finest pilot step, s (RK4); the tolerance that met the budget (DP5(4)).
    pub step_s: T,
    /// The coarsest step the observed order vouches for (8 x `step_s`), s.
    pub coarsest_step_s: T,
    /// `T` extrapolated from the two finest runs, s.
    pub time_s: T,
    /// Estimated relative error of the run at `step_s`.
    pub error_rel: T,
    /// Observed order `p` of the error in the step.
    pub order: T,
    /// Right-hand-side evaluations of all pilot runs.
    pub evaluations: u32,
    /// Right-hand-side evaluations of the DP5(4) run at `step_s` (0 for RK4).
    pub plan_evaluations: u32,
}

impl<T: Real> Pilot<T> {
    /// The method at `setting` (a step for RK4, a tolerance for DP5(4)).
    pub fn method(&self, setting: T, scene: &Scene<T>) -> Method<T> {
        match self.kind {
            Kind::Rk4 => Method::Rk4 { step_s: setting },
            Kind::Dp54 => dp(setting, scene),
        }
    }

    /// RK4: the longest step, up to [`Pilot::coarsest_step_s`], whose predicted error
    /// `C h^p` is within `target_rel`. DP5(4): the tolerance the pilot validated.
    pub fn step_for(&self, target_rel: T) -> T {
        if self.kind == Kind::Dp54 {
            return self.step_s;
        }
        if self.error_rel <= T::ZERO {
            return self.coarsest_step_s;
        }
        let scale = ((target_rel / self.error_rel).ln() / self.order).exp();
        (self.step_s * scale).min(self.coarsest_step_s)
    }

    /// The predicted relative error at `step_s` (DP5(4): the validated run's).
    pub fn error_at(&self, step_s: T) -> T {
        if self.kind == Kind::Dp54 {
            return self.error_rel;
        }
        self.error_rel * ((step_s / self.step_s).ln() * self.order).exp()
    }
}

/// Runs the pilot of `model` from the step `first_step_s` down (see the module docs). `Err`
/// carries the evaluations spent when no run left the bowl, a run failed or no `C h^p` regime
/// showed within [`LEVELS`] halvings: the caller turns to [`dp54`].
pub(crate) fn rk4<T: Real, P: OmegaProfile<T>>(
    scene: &Scene<T>,
    model: Model,
    profile: &P,
    limits: Limits<T>,
    first_step_s: T,
) -> Result<Pilot<T>, u32> {
    let spent = core::cell::Cell::new(0u32);
    let at = |h: T| -> Result<T, u32> {
        let (t, evals) = run(scene, model, profile, Method::Rk4 { step_s: h }, limits)
            .map_err(|_| spent.get())?;
        spent.set(spent.get().saturating_add(evals));
        if t.is_finite() {
            Ok(t)
        } else {
            Err(spent.get())
        }
    };
    // Runs at h, h/2, h/4, h/8: three differences, two ratios.
    let mut h = first_step_s;
    let mut t = [at(h)?, at(h * T::HALF)?, at(h * T::from_f64(0.25))?];
    for _ in 0..LEVELS {
        let finest = h * T::from_f64(0.125);
        let t3 = at(finest)?;
        let d = [t[0] - t[1], t[1] - t[2], t[2] - t3];
        let rounding = T::from_f64(64.0) * T::EPSILON * t3.abs();
        if d.iter().all(|&x| x.abs() <= rounding) {
            // Within rounding at every step (a scene RK4 integrates to rounding).
            return Ok(Pilot {
                kind: Kind::Rk4,
                plan_evaluations: 0,
                step_s: finest,
                coarsest_step_s: h,
                time_s: t3,
                error_rel: rounding / t3.abs(),
                order: T::from_f64(4.0),
                evaluations: spent.get(),
            });
        }
        let (r1, r2) = (d[0] / d[1], d[1] / d[2]);
        let in_range = |r: T| r >= T::TWO && r <= T::from_f64(40.0);
        // Both ratios in range and within 1.5x of each other: the error follows `C h^p` from
        // `h` down, so the model may be used anywhere in that range.
        if in_range(r1)
            && in_range(r2)
            && r1 <= r2 * T::from_f64(1.5)
            && r2 <= r1 * T::from_f64(1.5)
        {
            let excess = r2 - T::ONE;
            let time_s = t3 - d[2] / excess;
            return Ok(Pilot {
                kind: Kind::Rk4,
                plan_evaluations: 0,
                step_s: finest,
                coarsest_step_s: h,
                time_s,
                error_rel: (d[2] / excess).abs() / time_s,
                order: r2.ln() / T::from_f64(core::f64::consts::LN_2),
                evaluations: spent.get(),
            });
        }
        t = [t[1], t[2], t3];
        h *= T::HALF;
    }
    Err(spent.get())
}

/// Tolerances of DP5(4) tried, each a tenth of the one before.
const DP_TRIES: u32 = 8;

/// For a speed with kinks (a logged trace, linear between samples), where RK4's error does not
/// follow `C h^p`: DP5(4) from a tenth of `budget_rel` down by tenths until a run's difference
/// from the next, its error (the next is about ten times as accurate; `rtol` at least where
/// both took the same steps), is within the budget.
pub(crate) fn dp54<T: Real, P: OmegaProfile<T>>(
    scene: &Scene<T>,
    model: Model,
    profile: &P,
    limits: Limits<T>,
    budget_rel: T,
) -> Result<Pilot<T>, ChooseError> {
    let floor = T::from_f64(1e-13).max(T::from_f64(16.0) * T::EPSILON);
    let mut evaluations = 0u32;
    let mut at = |rtol: T| -> Result<(T, u32), ChooseError> {
        let (t, evals) = run(scene, model, profile, dp(rtol, scene), limits)?;
        evaluations = evaluations.saturating_add(evals);
        if t.is_finite() {
            Ok((t, evals))
        } else {
            Err(ChooseError::DoesNotLeave)
        }
    };
    // At least ten times the floor, so that one tighter run is always possible (f32's floor
    // is 1.9e-6).
    let mut rtol = (budget_rel * T::from_f64(0.1))
        .min(T::from_f64(0.01))
        .max(floor * T::from_f64(10.0));
    let (mut t, mut n) = at(rtol)?;
    for _ in 0..DP_TRIES {
        let finer = rtol * T::from_f64(0.1);
        // (Half the floor: a tenth of ten floors may round just below it.)
        if finer < floor * T::HALF {
            break;
        }
        let (t_fine, n_fine) = at(finer)?;
        // A finer run that took more steps measures the coarser one's error. Where both step
        // from kink to kink (a trace's samples closer than the accuracy needs) they agree to
        // rounding whatever their error: then every step passed the error test at `rtol`, and
        // `rtol` itself is taken as the error (DP5(4)'s global error stayed below 0.4 rtol on
        // 120 measured spin-up scenes).
        let difference = (t - t_fine).abs() / t_fine;
        let error_rel = if n_fine > n {
            difference
        } else {
            difference.max(rtol)
        };
        if error_rel <= budget_rel {
            return Ok(Pilot {
                kind: Kind::Dp54,
                step_s: rtol,
                coarsest_step_s: rtol,
                time_s: t_fine,
                error_rel,
                order: T::ONE,
                evaluations,
                plan_evaluations: n,
            });
        }
        (rtol, t, n) = (finer, t_fine, n_fine);
    }
    Err(ChooseError::NoMethodMeetsTolerance)
}

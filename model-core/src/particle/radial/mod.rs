//! The particle's radial equation of motion (paper Eq. 5 and 9, the hold of static friction of
//! docs/model.md §4) integrated numerically by ode's generic methods: for a constant bowl
//! speed and for one that changes in time, omega(t) (spin-up as the PI loops drive it), where
//! no closed form exists.
//!
//! `r'' = k2 (r omega(t)^2 - mu g - c 2 mu omega(t) r')` with `c = 1` for [`Model::Coriolis`]
//! and 0 for [`Model::Flat`], `r(0) = ri`, `r'(0) = 0`. Static friction holds a particle at rest
//! while `r omega^2 <= mu g` (the closed forms' "never leaves"; the ODE alone would drag it
//! inward, which is unphysical), so the right-hand side is 0 there; a run starts at the release
//! time, where the hold lets go, so that no step straddles that kink (`ode::release`).
//!
//! The equation is ode's [`SecondOrder`] (`Rhs`); the methods, their stability limits and the
//! event location are ode's ([`run_to`]). Every run reports the right-hand-side evaluations.

use super::{Model, Scene, SceneError};
use crate::Real;
use crate::ode::{
    ConstantOmega, Crossing, Limits, Method, OdeOutcome, OmegaProfile, Report, SecondOrder,
    StepError, release_time_s, run_to,
};

impl<T: Real> Limits<T> {
    /// 1000 time constants `1/(k omega_max)` (a constant-speed particle that moves at all
    /// leaves within about 40 in f64), and a million steps.
    pub fn for_scene<P: OmegaProfile<T>>(scene: &Scene<T>, profile: &P) -> Self {
        let rate = scene.k2.sqrt() * profile.max_omega_rad_s();
        let horizon = if rate > T::ZERO {
            T::from_f64(1000.0) / rate
        } else {
            T::from_f64(1000.0)
        };
        Self {
            horizon_s: horizon,
            max_steps: 1_000_000,
        }
    }
}

/// Why a run of [`integrate`] returned no result.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum OdeError {
    /// The scene was invalid.
    Scene(SceneError),
    /// The step (or a tolerance, or the horizon) was NaN, infinite, zero or negative.
    InvalidStep,
    /// The fixed step exceeds the method's stability limit at the fastest speed reached: the
    /// result would be numerical garbage (growing oscillation), so none is returned.
    BeyondStabilityLimit,
    /// The step cap was reached before the rim or the horizon (step too small, or the adaptive
    /// step collapsed).
    StepLimit,
    /// The profile gave a NaN, infinite or negative omega.
    InvalidOmega,
    /// The state overflowed (a speed far outside the scene's scale).
    NotFinite,
}

impl From<StepError> for OdeError {
    fn from(e: StepError) -> Self {
        match e {
            StepError::InvalidStep => Self::InvalidStep,
            StepError::BeyondStabilityLimit => Self::BeyondStabilityLimit,
            StepError::StepLimit => Self::StepLimit,
            StepError::InvalidOmega => Self::InvalidOmega,
            StepError::NotFinite => Self::NotFinite,
        }
    }
}

/// The right-hand side of paper Eq. 5 / 9 with the hold of static friction, as ode's
/// [`SecondOrder`] equation; counts its evaluations.
pub(crate) struct Rhs<'a, T, P> {
    pub k2: T,
    pub mu_g: T,
    /// `2 mu` for Coriolis, 0 for flat.
    pub two_mu_c: T,
    pub profile: &'a P,
    pub evaluations: u32,
}

impl<T: Real, P: OmegaProfile<T>> Rhs<'_, T, P> {
    pub fn omega(&self, t: T) -> Result<T, StepError> {
        let w = self.profile.omega_rad_s(t);
        if w.is_nonneg_finite() {
            Ok(w)
        } else {
            Err(StepError::InvalidOmega)
        }
    }
}

impl<T: Real, P: OmegaProfile<T>> SecondOrder<T> for Rhs<'_, T, P> {
    /// `(r', r'')` at `(t, r, v)`; 0 while friction holds the particle at rest.
    fn eval(&mut self, t: T, r: T, v: T) -> Result<(T, T), StepError> {
        self.evaluations = self.evaluations.saturating_add(1);
        let w = self.omega(t)?;
        let push = r * w * w;
        if v <= T::ZERO && push <= self.mu_g {
            return Ok((T::ZERO, T::ZERO));
        }
        Ok((v, self.k2 * (push - self.mu_g - self.two_mu_c * w * v)))
    }

    /// `v` first with the friction term implicit (stable at every step), then `r` with the
    /// new `v`; held while friction holds the particle at rest.
    fn semi_implicit(&mut self, t: T, r: T, v: T, h: T) -> Result<(T, T), StepError> {
        let w = self.omega(t)?;
        let push = r * w * w;
        if v <= T::ZERO && push <= self.mu_g {
            Ok((r, T::ZERO))
        } else {
            let v1 =
                (v + h * self.k2 * (push - self.mu_g)) / (T::ONE + h * self.k2 * self.two_mu_c * w);
            Ok((r + h * v1, v1))
        }
    }

    fn next_kink_after_s(&self, t: T) -> Option<T> {
        self.profile.next_kink_after_s(t)
    }
}

/// Integrates one scene with a speed profile (`scene.omega_rad_s` is ignored) until the rim,
/// the horizon or a limit.
pub fn integrate<T: Real, P: OmegaProfile<T>>(
    scene: &Scene<T>,
    model: Model,
    profile: &P,
    method: Method<T>,
    limits: Limits<T>,
) -> Result<Report<T>, OdeError> {
    scene.validate_except_omega().map_err(OdeError::Scene)?;
    if !(limits.horizon_s > T::ZERO && limits.horizon_s.is_finite()) {
        return Err(OdeError::InvalidStep);
    }
    let positive = |x: T| x > T::ZERO && x.is_finite();
    let method_ok = match method {
        Method::Euler { step_s }
        | Method::SemiImplicitEuler { step_s }
        | Method::Rk4 { step_s } => positive(step_s),
        Method::Dp54 { rtol, atol } => positive(rtol) && positive(atol),
    };
    if !method_ok {
        return Err(OdeError::InvalidStep);
    }
    let w_max = profile.max_omega_rad_s();
    if !w_max.is_nonneg_finite() {
        return Err(OdeError::InvalidOmega);
    }
    let mut rhs = Rhs {
        k2: scene.k2,
        mu_g: scene.mu * scene.g_m_s2,
        two_mu_c: match model {
            Model::Flat => T::ZERO,
            Model::Coriolis => T::TWO * scene.mu,
        },
        profile,
        evaluations: 0,
    };
    let w0 = rhs.omega(T::ZERO)?;
    let done = |outcome| Report {
        outcome,
        rhs_evaluations: 0,
        steps: 0,
        rejected_steps: 0,
    };
    if scene.ri_m >= scene.rim_radius_m {
        return Ok(done(OdeOutcome::AlreadyAtRim {
            exit_total_velocity_m_s: w0 * scene.rim_radius_m,
        }));
    }
    if profile.is_constant() && scene.ri_m * w0 * w0 <= rhs.mu_g {
        return Ok(done(OdeOutcome::NeverLeaves));
    }
    let stiff_rate = stiff_rate_per_s(scene, model, w_max);
    let Some(t_start) = start_time_s(scene, profile, stiff_rate, limits) else {
        return Ok(done(OdeOutcome::NotLeftBy {
            horizon_s: limits.horizon_s,
            radius_m: scene.ri_m,
        }));
    };
    let run = run_to(
        &mut rhs,
        method,
        stiff_rate,
        limits,
        t_start,
        scene.ri_m,
        scene.rim_radius_m,
    )?;
    let outcome = match run.ended {
        Crossing::Reached { t_s, v } => leaves(&rhs, scene, t_s, v)?,
        Crossing::Horizon { r } => OdeOutcome::NotLeftBy {
            horizon_s: limits.horizon_s,
            radius_m: r,
        },
    };
    Ok(Report {
        outcome,
        rhs_evaluations: rhs.evaluations,
        steps: run.steps,
        rejected_steps: run.rejected_steps,
    })
}

/// The fastest decay rate `|l2|` at the fastest speed `w_max`, 1/s: `k omega (s + k mu)` for
/// the Coriolis model, `k omega` for the flat one (docs/model.md, Stability).
pub(crate) fn stiff_rate_per_s<T: Real>(scene: &Scene<T>, model: Model, w_max: T) -> T {
    let k = scene.k2.sqrt();
    let m = match model {
        Model::Flat => T::ZERO,
        Model::Coriolis => k * scene.mu,
    };
    k * w_max * ((T::ONE + m * m).sqrt() + m)
}

/// Where [`integrate`] starts: static friction holds the particle at `ri` until the push first
/// exceeds it, and the run starts there, where the solution is smooth (release.rs); `None`
/// when that is beyond the horizon. The scan for the crossing looks every tenth of the fastest
/// time scale (`stiff_rate`, 1/s); a closed-form profile needs no scan.
pub(crate) fn start_time_s<T: Real, P: OmegaProfile<T>>(
    scene: &Scene<T>,
    profile: &P,
    stiff_rate: T,
    limits: Limits<T>,
) -> Option<T> {
    let scan_step = if stiff_rate > T::ZERO {
        T::from_f64(0.1) / stiff_rate
    } else {
        limits.horizon_s * T::from_f64(1e-3)
    };
    let mu_g = scene.mu * scene.g_m_s2;
    release_time_s(profile, scene.ri_m, mu_g, limits.horizon_s, scan_step)
}

/// [`integrate`] at the scene's own constant speed with [`Limits::for_scene`].
pub fn integrate_constant<T: Real>(
    scene: &Scene<T>,
    model: Model,
    method: Method<T>,
) -> Result<Report<T>, OdeError> {
    let profile = ConstantOmega(scene.omega_rad_s);
    if !scene.omega_rad_s.is_nonneg_finite() {
        return Err(OdeError::Scene(SceneError::InvalidOmega));
    }
    integrate(
        scene,
        model,
        &profile,
        method,
        Limits::for_scene(scene, &profile),
    )
}

/// The exit record once the crossing is located.
pub(crate) fn leaves<T: Real, P: OmegaProfile<T>>(
    rhs: &Rhs<'_, T, P>,
    scene: &Scene<T>,
    t: T,
    v: T,
) -> Result<OdeOutcome<T>, OdeError> {
    let w = rhs.omega(t).map_err(OdeError::from)?;
    let tangential = w * scene.rim_radius_m;
    let total = (v * v + tangential * tangential).sqrt();
    if !(t.is_finite() && v.is_finite() && total.is_finite()) {
        return Err(OdeError::NotFinite);
    }
    Ok(OdeOutcome::Leaves {
        residence_time_s: t,
        exit_radial_velocity_m_s: v,
        exit_total_velocity_m_s: total,
    })
}

#[cfg(test)]
mod tests;

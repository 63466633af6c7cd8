//! Numerical integration of the particle's equation of motion (paper Eq. 5 and 9), for a
//! constant bowl speed and for a speed that changes in time, omega(t) (spin-up as the PI loops
//! drive it), where no closed form exists.
//!
//! `r'' = k2 (r omega(t)^2 - mu g - c 2 mu omega(t) r')` with `c = 1` for [`Model::Coriolis`]
//! and 0 for [`Model::Flat`], `r(0) = ri`, `r'(0) = 0`. Static friction holds a particle at rest
//! while `r omega^2 <= mu g` (the closed forms' "never leaves"; the ODE alone would drag it
//! inward, which is unphysical), so the right-hand side is 0 there; a run starts at the release
//! time, where the hold lets go, so that no step straddles that kink (release.rs).
//!
//! Methods ([`Method`]): explicit Euler, semi-implicit Euler, RK4 (fixed step, event located by
//! quintic Hermite interpolation) and adaptive Dormand-Prince 5(4) (event located on its dense
//! output). Every run reports the right-hand-side evaluations and steps, refuses a step beyond
//! the method's stability limit instead of returning a wrong number, and stops at a step cap.
//!
//! Stability on this ODE: the fast mode is `l2 = -k omega (s + k mu)` (docs/model.md, Stability; `s + k mu = 1`
//! for the flat model). Explicit Euler is stable for `h |l2| <= 2`, RK4 for `h |l2| <= 2.785`
//! (its real-axis limit); our semi-implicit Euler takes the friction term implicitly and is
//! stable for every step (accuracy, not stability, limits it).

mod dp54;
mod event;
mod fixed;
mod release;
pub mod system;

pub use release::scan_first_time_above;

use crate::Real;
use crate::particle::{Model, Scene, SceneError};

/// A bowl speed that may change in time.
pub trait OmegaProfile<T> {
    /// omega at time `t_s`, rad/s (must be finite and non-negative).
    fn omega_rad_s(&self, t_s: T) -> T;
    /// An upper bound of omega over the run: sets the stability check's reference and the
    /// initial step.
    fn max_omega_rad_s(&self) -> T;
    /// True if omega never changes (then a particle held by friction stays held: the run stops
    /// at once with [`OdeOutcome::NeverLeaves`]).
    fn is_constant(&self) -> bool {
        false
    }
    /// True if omega has continuous derivatives (a fixed-step method keeps its order on it);
    /// false for a logged trace, linear between samples.
    fn is_smooth(&self) -> bool {
        true
    }
    /// The shortest time over which omega changes by a large part of itself, s (a spin-up's
    /// time constant; infinite if unknown or constant): a step must resolve it for the error
    /// to follow `C h^4` (the chooser's pilot starts no coarser).
    fn time_scale_s(&self) -> T
    where
        T: Real,
    {
        T::INFINITY
    }
    /// The profile as a first-order spin-up, where it is one (the chooser's precomputed table
    /// covers those); `None` otherwise.
    fn spin_up(&self) -> Option<SpinUp<T>> {
        None
    }
    /// The first time after `t_s` where omega's derivative jumps (a logged trace's next
    /// sample), `None` if there is none: the adaptive method ends a step there.
    fn next_kink_after_s(&self, _t_s: T) -> Option<T> {
        None
    }
    /// The first time in `[0, horizon_s]` at which omega is above `threshold_rad_s`, `None` if
    /// it never is: where static friction lets a particle go. By default a scan at
    /// `scan_step_s` and bisection ([`scan_first_time_above`]); a profile with a closed form
    /// gives it exactly.
    fn first_time_above_s(&self, threshold_rad_s: T, horizon_s: T, scan_step_s: T) -> Option<T>
    where
        T: Real,
    {
        scan_first_time_above(self, threshold_rad_s, horizon_s, scan_step_s)
    }
}

/// A constant speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstantOmega<T>(pub T);

impl<T: Real> OmegaProfile<T> for ConstantOmega<T> {
    fn omega_rad_s(&self, _t_s: T) -> T {
        self.0
    }
    fn max_omega_rad_s(&self) -> T {
        self.0
    }
    fn is_constant(&self) -> bool {
        true
    }
    fn first_time_above_s(&self, threshold_rad_s: T, _horizon_s: T, _scan_step_s: T) -> Option<T> {
        (self.0 > threshold_rad_s).then_some(T::ZERO)
    }
}

/// First-order spin-up, the step response of a well-tuned PI speed loop:
/// `omega(t) = final + (start - final) e^{-t / tau}`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpinUp<T> {
    /// omega at t = 0, rad/s.
    pub start_rad_s: T,
    /// The setpoint approached, rad/s.
    pub final_rad_s: T,
    /// Time constant tau, s (> 0).
    pub time_constant_s: T,
}

impl<T: Real> OmegaProfile<T> for SpinUp<T> {
    fn omega_rad_s(&self, t_s: T) -> T {
        self.final_rad_s
            + (self.start_rad_s - self.final_rad_s) * (-t_s / self.time_constant_s).exp()
    }
    fn max_omega_rad_s(&self) -> T {
        self.start_rad_s.max(self.final_rad_s)
    }
    fn time_scale_s(&self) -> T {
        if self.start_rad_s == self.final_rad_s
            || self.time_constant_s.is_nan()
            || self.time_constant_s <= T::ZERO
        {
            T::INFINITY
        } else {
            self.time_constant_s
        }
    }
    fn spin_up(&self) -> Option<SpinUp<T>> {
        Some(*self)
    }
    /// `t = tau ln((final - start) / (final - threshold))` on the way up; never on the way
    /// down from at or below it.
    fn first_time_above_s(&self, threshold_rad_s: T, horizon_s: T, scan_step_s: T) -> Option<T> {
        let (start, end, tau) = (self.start_rad_s, self.final_rad_s, self.time_constant_s);
        if start > threshold_rad_s {
            return Some(T::ZERO);
        }
        if end.is_nan() || end <= threshold_rad_s {
            return None;
        }
        if !(tau > T::ZERO && tau.is_finite()) {
            return scan_first_time_above(self, threshold_rad_s, horizon_s, scan_step_s);
        }
        let t = tau * ((end - start) / (end - threshold_rad_s)).ln();
        (t <= horizon_s).then_some(t.max(T::ZERO))
    }
}

/// Any function of time, with the caller's bound on it.
#[derive(Debug, Clone, Copy)]
pub struct FnOmega<F, T> {
    /// omega(t), rad/s.
    pub omega: F,
    /// An upper bound of omega over the run, rad/s.
    pub max_rad_s: T,
}

impl<T: Real, F: Fn(T) -> T> OmegaProfile<T> for FnOmega<F, T> {
    fn omega_rad_s(&self, t_s: T) -> T {
        (self.omega)(t_s)
    }
    fn max_omega_rad_s(&self) -> T {
        self.max_rad_s
    }
}

/// The integration method and its step or tolerance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method<T> {
    /// Explicit Euler, fixed step (s). Order 1; unstable for `h |l2| > 2`.
    Euler {
        /// Step, s.
        step_s: T,
    },
    /// Semi-implicit Euler, fixed step (s): `v` first (friction implicit), then `r` with the new
    /// `v`. Order 1; stable at every step.
    SemiImplicitEuler {
        /// Step, s.
        step_s: T,
    },
    /// Classical Runge-Kutta 4, fixed step (s). Unstable for `h |l2| > 2.785`.
    Rk4 {
        /// Step, s.
        step_s: T,
    },
    /// Adaptive Dormand-Prince 5(4), local error per step below `rtol |y| + atol`.
    Dp54 {
        /// Relative tolerance (> 0).
        rtol: T,
        /// Absolute tolerance, in m for r and m/s for r' (> 0).
        atol: T,
    },
}

/// Limits of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits<T> {
    /// Stop (with [`OdeOutcome::NotLeftBy`]) if the particle is still in the bowl at this time, s.
    pub horizon_s: T,
    /// At most this many steps (accepted and rejected) before [`OdeError::StepLimit`].
    pub max_steps: u32,
}

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

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OdeOutcome<T> {
    /// Reached the rim.
    Leaves {
        /// Residence time T, s (event located by interpolation, not the step end).
        residence_time_s: T,
        /// `r'(T)`, m/s.
        exit_radial_velocity_m_s: T,
        /// `sqrt(r'(T)^2 + (omega(T) R)^2)`, m/s (paper Eq. 12).
        exit_total_velocity_m_s: T,
    },
    /// `ri >= R`: T = 0.
    AlreadyAtRim {
        /// `omega(0) R`, m/s.
        exit_total_velocity_m_s: T,
    },
    /// Constant speed and `ri <= a`: friction holds it for ever.
    NeverLeaves,
    /// Still in the bowl at the horizon.
    NotLeftBy {
        /// The horizon, s.
        horizon_s: T,
        /// Where it was then, m.
        radius_m: T,
    },
}

/// A run's result and what it cost.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Report<T> {
    /// How it ended.
    pub outcome: OdeOutcome<T>,
    /// Right-hand-side evaluations (the fair cost measure across methods).
    pub rhs_evaluations: u32,
    /// Steps taken, accepted and rejected.
    pub steps: u32,
    /// Steps rejected by the error control (DP54 only).
    pub rejected_steps: u32,
}

/// Why a run returned no result.
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

/// The right-hand side, with the model and friction rules; counts its evaluations.
pub(crate) struct Rhs<'a, T, P> {
    pub k2: T,
    pub mu_g: T,
    /// `2 mu` for Coriolis, 0 for flat.
    pub two_mu_c: T,
    pub profile: &'a P,
    pub evaluations: u32,
}

impl<T: Real, P: OmegaProfile<T>> Rhs<'_, T, P> {
    /// `(r', r'')` at `(t, r, v)`; 0 while friction holds the particle at rest.
    pub fn eval(&mut self, t: T, r: T, v: T) -> Result<(T, T), OdeError> {
        self.evaluations = self.evaluations.saturating_add(1);
        let w = self.omega(t)?;
        let push = r * w * w;
        if v <= T::ZERO && push <= self.mu_g {
            return Ok((T::ZERO, T::ZERO));
        }
        Ok((v, self.k2 * (push - self.mu_g - self.two_mu_c * w * v)))
    }

    pub fn omega(&self, t: T) -> Result<T, OdeError> {
        let w = self.profile.omega_rad_s(t);
        if w.is_nonneg_finite() {
            Ok(w)
        } else {
            Err(OdeError::InvalidOmega)
        }
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
    match method {
        Method::Euler { step_s } => fixed::run(
            &mut rhs,
            scene,
            fixed::Scheme::Euler,
            step_s,
            stiff_rate,
            limits,
            t_start,
        ),
        Method::SemiImplicitEuler { step_s } => fixed::run(
            &mut rhs,
            scene,
            fixed::Scheme::SemiImplicit,
            step_s,
            stiff_rate,
            limits,
            t_start,
        ),
        Method::Rk4 { step_s } => fixed::run(
            &mut rhs,
            scene,
            fixed::Scheme::Rk4,
            step_s,
            stiff_rate,
            limits,
            t_start,
        ),
        Method::Dp54 { rtol, atol } => {
            dp54::run(&mut rhs, scene, rtol, atol, stiff_rate, limits, t_start)
        }
    }
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
    release::release_time_s(profile, scene.ri_m, mu_g, limits.horizon_s, scan_step)
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
    let w = rhs.omega(t)?;
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

//! The integrators, generic: they know equations, not particles. The particle models sit above
//! them and implement their traits (`crate::particle::radial` the radial equation of paper
//! Eq. 5 and 9 as a [`SecondOrder`] equation, `crate::particle::rolling` and
//! `crate::particle::bowl` their systems for [`system`]); nothing here imports them.
//!
//! A [`SecondOrder`] equation `r'' = f(t, r, r')` in one coordinate runs from `(t0, r0, 0)`
//! until `r` reaches a target ([`run_to`]), for a bowl speed that may change in time
//! ([`OmegaProfile`]: constant, a spin-up as the PI loops drive it, a logged trace).
//!
//! Methods ([`Method`]): explicit Euler, semi-implicit Euler, RK4 (fixed step, event located by
//! quintic Hermite interpolation) and adaptive Dormand-Prince 5(4) (event located on its dense
//! output). Every run reports its steps, refuses a step beyond the method's stability limit
//! instead of returning a wrong number, and stops at a step cap.
//!
//! Stability on this ODE: the fast mode is `l2 = -k omega (s + k mu)` (docs/model.md, Stability; `s + k mu = 1`
//! for the flat model). Explicit Euler is stable for `h |l2| <= 2`, RK4 for `h |l2| <= 2.785`
//! (its real-axis limit); our semi-implicit Euler takes the friction term implicitly and is
//! stable for every step (accuracy, not stability, limits it).

mod dp54;
pub(crate) mod event;
mod fixed;
mod release;
pub mod system;

pub(crate) use release::release_time_s;
pub use release::scan_first_time_above;

use crate::Real;

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
    /// At most this many steps (accepted and rejected) before [`StepError::StepLimit`].
    pub max_steps: u32,
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

/// Why a run of a [`SecondOrder`] equation returned no result.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StepError {
    /// The step (or a tolerance) was NaN, infinite, zero or negative.
    InvalidStep,
    /// The fixed step exceeds the method's stability limit at the fastest rate: the result
    /// would be numerical garbage (growing oscillation), so none is returned.
    BeyondStabilityLimit,
    /// The step cap was reached before the target or the horizon.
    StepLimit,
    /// The equation's input (the speed profile) gave a NaN, infinite or negative value.
    InvalidOmega,
    /// The state overflowed.
    NotFinite,
}

/// A second-order equation in one coordinate, `r'' = f(t, r, r')`, as [`run_to`] integrates it.
pub trait SecondOrder<T> {
    /// `(r', r'')` at `(t, r, r')`; counts the evaluation.
    fn eval(&mut self, t: T, r: T, v: T) -> Result<(T, T), StepError>;
    /// One semi-implicit Euler step of `h` from `(t, r, v)`: `(r, v)` after it (the velocity
    /// first, with whatever the equation takes implicitly, then the position with the new
    /// velocity).
    fn semi_implicit(&mut self, t: T, r: T, v: T, h: T) -> Result<(T, T), StepError>;
    /// The first time after `t` where the right-hand side has a kink (a logged trace's next
    /// sample): the adaptive method ends a step there.
    fn next_kink_after_s(&self, t: T) -> Option<T>;
}

/// Where a run of [`run_to`] ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Crossing<T> {
    /// `r` reached the target at time `t_s` with velocity `v` (located on the interpolant).
    Reached {
        /// Time, s.
        t_s: T,
        /// `r'` there.
        v: T,
    },
    /// The horizon came first, with `r` there.
    Horizon {
        /// Where `r` was.
        r: T,
    },
}

/// What [`run_to`] returns: the crossing and the steps it took.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stepped<T> {
    /// How it ended.
    pub ended: Crossing<T>,
    /// Steps taken, accepted and rejected.
    pub steps: u32,
    /// Steps rejected by the error control (DP54 only).
    pub rejected_steps: u32,
}

/// Integrates `equation` with `method` from `(t_start, r0, r' = 0)` until `r` reaches `target`
/// or the limits; `stiff_rate` (the fastest decay rate, 1/s) sets the stability check of the
/// fixed-step methods and DP54's first step.
pub fn run_to<T: Real, S: SecondOrder<T>>(
    equation: &mut S,
    method: Method<T>,
    stiff_rate: T,
    limits: Limits<T>,
    t_start: T,
    r0: T,
    target: T,
) -> Result<Stepped<T>, StepError> {
    let start = fixed::Start {
        t_s: t_start,
        r: r0,
        target,
    };
    let (scheme, step_s) = match method {
        Method::Euler { step_s } => (fixed::Scheme::Euler, step_s),
        Method::SemiImplicitEuler { step_s } => (fixed::Scheme::SemiImplicit, step_s),
        Method::Rk4 { step_s } => (fixed::Scheme::Rk4, step_s),
        Method::Dp54 { rtol, atol } => {
            return dp54::run(equation, rtol, atol, stiff_rate, limits, start);
        }
    };
    fixed::run(equation, scheme, step_s, stiff_rate, limits, start)
}

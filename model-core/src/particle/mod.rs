//! A sphere rolling outward in the spinning bowl: paper Eq. 5 to 12, corrected as in
//! docs/model.md.
//!
//! The particle starts at rest at radius `ri_m` on a bowl turning at `omega_rad_s`; the
//! centrifugal term pushes it out, an *effective rolling resistance* `mu` (times `g`) holds it
//! back, and in the [`Model::Coriolis`] model the Coriolis force, pressing the rolling sphere
//! against the bowl, adds a friction `2 mu omega r'`. It leaves at the rim radius
//! `rim_radius_m` after the residence time `T`.
//!
//! * [`residence`]: `T` and the exit velocities, as an explicit [`Outcome`] (leaves / already at
//!   the rim / never leaves) with a condition number, never NaN.
//! * [`residence_time_s`]: `T` alone (telemetry, RTIME); [`residence_times_s`]: the same for a
//!   batch of scenes, at a higher host throughput (`bowl predict --batch --throughput`).
//! * [`position_m`], [`radial_velocity_m_s`]: `r(t)` and `r'(t)` (paper Eq. 6, 7, 10, 11).
//! * [`omega_for_residence_time`]: the inverse, the bowl speed that gives a target `T`.
//!
//! # The resistance coefficient
//! The paper uses a *sliding* friction coefficient 0.4 in a *rolling* model; with it the
//! equilibrium radius `a = mu g / omega^2` exceeds every bowl and nothing ever leaves. We name the
//! coefficient for what the model needs, an effective rolling resistance, and default it to the
//! paper's own "correction factor" 0.029 (docs/model.md §5, "The parameter problem"); 0.4 stays
//! reachable and then gives [`Outcome::NeverLeaves`].

mod batch;
pub mod bowl;
mod coriolis;
mod coriolis_batch;
mod flat;
mod flat_batch;
mod inverse;
pub mod named_scenes;
mod phi;
pub(crate) mod radial;
pub mod rolling;
mod shape;
pub mod speed_table;

pub use inverse::{InverseError, omega_for_residence_time};
pub use radial::{OdeError, integrate, integrate_constant};
pub(crate) use shape::{Shape, ShapeAt};

use crate::Real;
use phi::phi_expm1;

/// Which equation of motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Model {
    /// Paper Eq. 5: `r'' = k2 (r omega^2 - mu g)`; solution Eq. 6, 7 (correct in the paper).
    Flat,
    /// Paper Eq. 9: `r'' = k2 (r omega^2 - mu g - 2 mu omega r')`; solution Eq. 10, 11 with the
    /// corrected coefficients `A = (1 + k mu/s)/2`, `B = (1 - k mu/s)/2` (the paper prints 0.5
    /// and 0.45, which break `r(0) = ri`).
    Coriolis,
}

/// One particle in one bowl: everything the model needs. SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scene<T> {
    /// Combined bowl speed omega (paper Eq. 2), rad/s.
    pub omega_rad_s: T,
    /// Effective rolling resistance coefficient (dimensionless); the paper's `mu`.
    pub mu: T,
    /// Gravity, m/s^2.
    pub g_m_s2: T,
    /// `k2 = m rp^2 / (I + m rp^2)`: 5/7 for a solid sphere, 3/5 for a hollow one. In (0, 1].
    /// (The paper's 0.845 is `sqrt(5/7)`.)
    pub k2: T,
    /// Start radius `ri` (the particle starts at rest), m.
    pub ri_m: T,
    /// Rim radius `R` of the bowl, m.
    pub rim_radius_m: T,
}

impl<T: Real> Default for Scene<T> {
    /// The default scene, chosen so that the particle moves (see the module docs):
    /// omega 3.0 rad/s, mu 0.029, g 9.81 m/s^2, k2 5/7, ri 0.05 m, R 0.1 m.
    ///
    /// R = 0.1 m reads the paper's bowl "sizes" 150 to 300 mm as *diameters* (its conclusion's
    /// reading): 200 mm, the middle of the range. Its nomenclature calls them radii; then pass
    /// `rim_radius_m` 0.15 to 0.3. The start radius is half the rim radius.
    fn default() -> Self {
        Self {
            omega_rad_s: T::from_f64(3.0),
            mu: T::from_f64(0.029),
            g_m_s2: T::from_f64(9.81),
            k2: T::from_f64(5.0 / 7.0),
            ri_m: T::from_f64(0.05),
            rim_radius_m: T::from_f64(0.1),
        }
    }
}

/// What was wrong with a scene (or a time), or why a result cannot be represented.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SceneError {
    /// The bowl speed was NaN, infinite or negative.
    InvalidOmega,
    /// The resistance coefficient mu was NaN, infinite or negative.
    InvalidResistance,
    /// Gravity was NaN, infinite or negative.
    InvalidGravity,
    /// k2 was NaN, infinite, or outside (0, 1] (it is `m rp^2 / (I + m rp^2)`).
    InvalidK2,
    /// The start radius was NaN, infinite or negative.
    InvalidStartRadius,
    /// The rim radius was NaN, infinite or negative.
    InvalidRimRadius,
    /// A valid input outside the magnitudes the model computes with ([`magnitude_limits`]:
    /// nonzero and below `1e-75` or above `1e75` in f64; none in f32): products of
    /// up to four inputs (`mu g / omega^2`, `(omega R)^2`) would underflow or overflow, and the
    /// answer could come out the wrong way round (leaves for never leaves, an exit speed below
    /// the radial one). Refused rather than answered; rescale the units (or pass 0).
    ExtremeMagnitude(Input),
    /// The time was NaN, infinite or negative.
    InvalidTime,
    /// The inputs are valid but a result (or an intermediate of it) overflows the number type,
    /// e.g. `cosh(k omega t)` for a long time in `f32`, or absurd magnitudes. Rescale the units.
    OutOfRange,
    /// The root finder for the residence time did not converge: no result rather than a wrong
    /// one (not seen on any tested input; it would be a defect).
    NoConvergence,
}

/// One input of a [`Scene`], as a refusal names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Input {
    /// `omega_rad_s`.
    Omega,
    /// `mu`.
    Resistance,
    /// `g_m_s2`.
    Gravity,
    /// `k2`.
    K2,
    /// `ri_m`.
    StartRadius,
    /// `rim_radius_m`.
    RimRadius,
}

/// The smallest and the largest nonzero magnitude of a scene's inputs in f64, `1e-75` and
/// `1e75`: products of four of them stay normal numbers (`1e-300` to `1e300`, with room for
/// the rounding of a difference), so the equilibrium radius `a = mu g / omega^2`, `ri omega^2`
/// and the squares of the exit speeds (paper Eq. 12) never underflow or overflow. Zero itself
/// is exact and always accepted.
///
/// In f32 (the MCU) there are no limits: `(0, infinity)`. The rig's scenes come from its wire
/// parameters, held within their ranges (`binding::configure`: micrometres, ppm, a speed limit
/// of a few rad/s), far inside f32's; the test would cost the one-scene forms some 130
/// Cortex-M4F instructions (the flat time alone 150 -> 280), over their budgets.
pub fn magnitude_limits<T: Real>() -> (T, T) {
    if T::is_single_precision() {
        (T::ZERO, T::INFINITY)
    } else {
        (T::from_f64(1e-75), T::from_f64(1e75))
    }
}

/// `x` is 0 or within [`magnitude_limits`] (false for NaN, infinities and negative values).
#[inline(always)]
fn within_magnitudes<T: Real>(x: T) -> bool {
    let (low, high) = magnitude_limits::<T>();
    (x == T::ZERO) | ((x >= low) & (x <= high))
}

/// The result of [`residence`]. Never NaN; the three physical cases are explicit.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Outcome<T> {
    /// The particle reaches the rim.
    Leaves {
        /// Residence time `T`, s.
        residence_time_s: T,
        /// Radial velocity at the rim `r'(T)`, m/s (paper Eq. 7 / 11 at `T`).
        exit_radial_velocity_m_s: T,
        /// Total exit speed `sqrt(r'(T)^2 + (omega R)^2)`, m/s (paper Eq. 12).
        exit_total_velocity_m_s: T,
        /// Relative condition number of `T` with respect to relative perturbations of the
        /// equilibrium radius `a = mu g / omega^2` and of the ratio it enters: about
        /// `1 / (d ln x)` just above the threshold `ri = a (1 + d)`, about 1 to 2 elsewhere.
        /// The achievable relative error is about this times the type's epsilon.
        condition_number: T,
        /// True when `condition_number > 1/sqrt(epsilon)`: more than half the digits of `T` may
        /// be lost (the start radius is very close above the threshold `a`).
        ill_conditioned: bool,
    },
    /// `ri >= R`: the particle starts at (or beyond) the rim, `T = 0`, radial velocity 0.
    AlreadyAtRim {
        /// `omega R`, m/s (paper Eq. 12 with `r' = 0`).
        exit_total_velocity_m_s: T,
    },
    /// `ri <= a`: static friction holds the particle; it never leaves (the ODE would drag it
    /// inward, which is unphysical). Also when `omega = 0`.
    NeverLeaves {
        /// `a = mu g / omega^2`, m (infinite when `omega = 0`).
        equilibrium_radius_m: T,
        /// True when `ri` is within rounding of `a`: the verdict itself is uncertain (in `f32`,
        /// `ri = a (1 + d)` with `d` below about 1e-7 lands here).
        near_threshold: bool,
    },
}

impl<T: Real> Outcome<T> {
    /// `T` in seconds: 0 at the rim, infinity when it never leaves.
    pub fn residence_time_s(&self) -> T {
        match *self {
            Outcome::Leaves {
                residence_time_s, ..
            } => residence_time_s,
            Outcome::AlreadyAtRim { .. } => T::ZERO,
            Outcome::NeverLeaves { .. } => T::INFINITY,
        }
    }

    /// `(radial, total)` exit velocities in m/s, `None` when it never leaves.
    pub fn exit_velocities_m_s(&self) -> Option<(T, T)> {
        match *self {
            Outcome::Leaves {
                exit_radial_velocity_m_s,
                exit_total_velocity_m_s,
                ..
            } => Some((exit_radial_velocity_m_s, exit_total_velocity_m_s)),
            Outcome::AlreadyAtRim {
                exit_total_velocity_m_s,
            } => Some((T::ZERO, exit_total_velocity_m_s)),
            Outcome::NeverLeaves { .. } => None,
        }
    }
}

/// `0 <= x <= MAX`, false for NaN and infinities (one integer compare, see [`Real`]).
fn nonneg_finite<T: Real>(x: T) -> bool {
    x.is_nonneg_finite()
}

impl<T: Real> Scene<T> {
    /// Checks every parameter: finite and non-negative, `k2` in (0, 1], each 0 or within
    /// [`magnitude_limits`].
    pub fn validate(&self) -> Result<(), SceneError> {
        self.validate_except_omega()?;
        if !nonneg_finite(self.omega_rad_s) {
            return Err(SceneError::InvalidOmega);
        }
        if !T::is_single_precision() && !within_magnitudes(self.omega_rad_s) {
            return Err(SceneError::ExtremeMagnitude(Input::Omega));
        }
        Ok(())
    }

    /// All of [`Scene::validate`]'s tests as one value, no branch: the batch's lanes
    /// (`batch.rs`) pass a scene for which it is true on, and hand every other one to the
    /// one-scene path, which names the refusal.
    #[inline(always)]
    pub(crate) fn is_valid(&self) -> bool {
        // `&`, not `&&`: every test on every lane.
        if T::is_single_precision() {
            return nonneg_finite(self.mu)
                & nonneg_finite(self.g_m_s2)
                & self.k2.is_in_unit_interval()
                & nonneg_finite(self.ri_m)
                & nonneg_finite(self.rim_radius_m)
                & nonneg_finite(self.omega_rad_s);
        }
        // The window alone is the test: NaN, infinities and negative values fall outside it
        // (-0 is 0); float compares only.
        let (low, _) = magnitude_limits::<T>();
        within_magnitudes(self.mu)
            & within_magnitudes(self.g_m_s2)
            & (self.k2 >= low)
            & (self.k2 <= T::ONE)
            & within_magnitudes(self.ri_m)
            & within_magnitudes(self.rim_radius_m)
            & within_magnitudes(self.omega_rad_s)
    }

    /// As [`Scene::validate`] but ignores `omega_rad_s` (the inverse solves for it).
    pub fn validate_except_omega(&self) -> Result<(), SceneError> {
        if !nonneg_finite(self.mu) {
            return Err(SceneError::InvalidResistance);
        }
        if !nonneg_finite(self.g_m_s2) {
            return Err(SceneError::InvalidGravity);
        }
        if !self.k2.is_in_unit_interval() {
            return Err(SceneError::InvalidK2);
        }
        if !nonneg_finite(self.ri_m) {
            return Err(SceneError::InvalidStartRadius);
        }
        if !nonneg_finite(self.rim_radius_m) {
            return Err(SceneError::InvalidRimRadius);
        }
        if T::is_single_precision() {
            // No magnitude limits in f32 (see `magnitude_limits`).
            return Ok(());
        }
        for (value, input) in [
            (self.mu, Input::Resistance),
            (self.g_m_s2, Input::Gravity),
            (self.k2, Input::K2),
            (self.ri_m, Input::StartRadius),
            (self.rim_radius_m, Input::RimRadius),
        ] {
            if !within_magnitudes(value) {
                return Err(SceneError::ExtremeMagnitude(input));
            }
        }
        Ok(())
    }

    /// The scene as this number type holds it, read back exactly in f64 (the inputs an f32
    /// computation saw, for a reference to be computed at).
    pub fn to_f64(&self) -> Scene<f64> {
        Scene {
            omega_rad_s: self.omega_rad_s.to_f64(),
            mu: self.mu.to_f64(),
            g_m_s2: self.g_m_s2.to_f64(),
            k2: self.k2.to_f64(),
            ri_m: self.ri_m.to_f64(),
            rim_radius_m: self.rim_radius_m.to_f64(),
        }
    }

    /// The equilibrium radius `a = mu g / omega^2`, m (docs/model.md §4): infinite at `omega = 0`.
    /// Divides twice by omega rather than once by `omega^2` so a large omega cannot overflow.
    pub fn equilibrium_radius_m(&self) -> T {
        if self.omega_rad_s > T::ZERO {
            self.mu * self.g_m_s2 / self.omega_rad_s / self.omega_rad_s
        } else {
            T::INFINITY
        }
    }
}

impl Scene<f64> {
    /// The scene rounded to f32, as the Cortex-M4F holds it.
    pub const fn to_f32(&self) -> Scene<f32> {
        Scene {
            omega_rad_s: self.omega_rad_s as f32,
            mu: self.mu as f32,
            g_m_s2: self.g_m_s2 as f32,
            k2: self.k2 as f32,
            ri_m: self.ri_m as f32,
            rim_radius_m: self.rim_radius_m as f32,
        }
    }
}

/// Residence time `T` and exit velocities (paper Eq. 7, 11, 12; docs/model.md §4, "Residence time T").
///
/// `ri >= R` gives [`Outcome::AlreadyAtRim`], `ri <= a` (or `omega = 0`)
/// [`Outcome::NeverLeaves`]. Flat: `T = log1p(x + sqrt(x (x + 2))) / (k omega)` with
/// `x = (R - ri)/(ri - a)` (the naive `acosh(1 + x)` loses everything near the rim).
/// Coriolis: bracketed monotone Newton from the upper bracket on
/// `A (e^{l1 T} - 1) + B (e^{l2 T} - 1) = x`.
pub fn residence<T: Real>(scene: &Scene<T>, model: Model) -> Result<Outcome<T>, SceneError> {
    scene.validate()?;
    let (ri, rim, omega) = (scene.ri_m, scene.rim_radius_m, scene.omega_rad_s);
    if ri >= rim {
        let v = omega * rim;
        return if v.is_finite() {
            Ok(Outcome::AlreadyAtRim {
                exit_total_velocity_m_s: v,
            })
        } else {
            Err(SceneError::OutOfRange)
        };
    }
    let a = scene.equilibrium_radius_m();
    if ri <= a {
        // a carries about 3 roundings (mu g, two divisions).
        let near = a.is_finite() && a - ri <= T::from_f64(4.0) * T::EPSILON * a;
        return Ok(Outcome::NeverLeaves {
            equilibrium_radius_m: a,
            near_threshold: near,
        });
    }
    let exit = match model {
        Model::Flat => flat::residence(scene, a),
        Model::Coriolis => coriolis::residence(scene, a)?,
    };
    let total = hypot(exit.radial, omega * rim);
    let cond = exit.condition;
    if !(exit.time.is_finite() && exit.radial.is_finite() && total.is_finite() && cond.is_finite())
    {
        return Err(SceneError::OutOfRange);
    }
    Ok(Outcome::Leaves {
        residence_time_s: exit.time,
        exit_radial_velocity_m_s: exit.radial,
        exit_total_velocity_m_s: total,
        condition_number: cond,
        ill_conditioned: cond * cond * T::EPSILON > T::ONE,
    })
}

/// The residence time alone, s (paper Eq. 6 / 10, as [`residence`]): 0 at the rim, infinity
/// when the particle never leaves. What the rig's telemetry and RTIME need: it skips the exit
/// speeds and the condition number, so on the MCU the flat form is about half of
/// [`residence`]'s instructions. The time is bit for bit the one [`residence`] gives.
pub fn residence_time_s<T: Real>(scene: &Scene<T>, model: Model) -> Result<T, SceneError> {
    let a = match before_model(scene)? {
        Before::Answer(time) => return Ok(time),
        Before::Leaves { a } => a,
    };
    finite_time(match model {
        Model::Flat => flat::time(scene, a),
        Model::Coriolis => coriolis::residence(scene, a)?.time,
    })
}

/// [`residence_time_s`] of every scene of `scenes`, in order, into `out` (as many answers as
/// both have). The same answers bit for bit, at a higher throughput on the host: the flat
/// model's arithmetic runs in SIMD lanes, the Coriolis model's root searches interleave (a
/// batch of scenes, `bowl predict --batch`). Inlined so that a caller compiled for wider SIMD
/// gets the flat lanes at that width.
#[inline(always)]
pub fn residence_times_s<T: Real>(
    scenes: &[Scene<T>],
    model: Model,
    out: &mut [Result<T, SceneError>],
) {
    match model {
        Model::Flat => batch::times_s::<T, flat_batch::Flat>(scenes, out),
        // The lanes follow the f64 search (f32 takes no expansion step, see `coriolis`).
        Model::Coriolis if T::is_single_precision() => coriolis::times_s(scenes, out),
        Model::Coriolis => batch::times_s::<T, coriolis_batch::Coriolis>(scenes, out),
    }
}

/// What every model's residence time starts from.
pub(crate) enum Before<T> {
    /// Settled before any model: 0 at the rim, infinity when the particle never leaves.
    Answer(T),
    /// The particle leaves from inside the rim; `a` is the equilibrium radius.
    Leaves { a: T },
}

/// Validates `scene` and settles what needs no model ([`Before`]).
pub(crate) fn before_model<T: Real>(scene: &Scene<T>) -> Result<Before<T>, SceneError> {
    scene.validate()?;
    let (ri, rim) = (scene.ri_m, scene.rim_radius_m);
    if ri >= rim {
        return Ok(Before::Answer(T::ZERO));
    }
    let a = scene.equilibrium_radius_m();
    if ri <= a {
        return Ok(Before::Answer(T::INFINITY));
    }
    Ok(Before::Leaves { a })
}

/// A model's residence time, or `OutOfRange` where it is not finite.
pub(crate) fn finite_time<T: Real>(time: T) -> Result<T, SceneError> {
    if time.is_finite() {
        Ok(time)
    } else {
        Err(SceneError::OutOfRange)
    }
}

/// `sqrt(x^2 + y^2)` (paper Eq. 12's total exit speed) that cannot overflow where the result is
/// representable: the plain form first (cheap on the MCU), scaled by the larger magnitude only
/// when a square overflowed.
fn hypot<T: Real>(x: T, y: T) -> T {
    let plain = (x * x + y * y).sqrt();
    if plain.is_finite() {
        return plain;
    }
    let (x, y) = (x.abs(), y.abs());
    let (big, small) = if x >= y { (x, y) } else { (y, x) };
    if big == T::ZERO || !big.is_finite() {
        return big;
    }
    let r = small / big;
    big * (T::ONE + r * r).sqrt()
}

/// What the per-model solvers return (the caller adds the total speed and checks ranges).
pub(crate) struct Exit<T> {
    pub time: T,
    pub radial: T,
    pub condition: T,
}

/// Condition number of `T` from that of `T(x)`, `kx = x T'(x) / T`: a relative perturbation `e`
/// of `a` moves `x` by `e a / (ri - a)` relatively; one more unit for `x`'s own rounding and one
/// for `omega`.
pub(crate) fn condition<T: Real>(kx: T, a: T, ri: T) -> T {
    // 1 + a / (ri - a) = ri / (ri - a).
    T::ONE + kx * (ri / (ri - a))
}

fn checked_time<T: Real>(t_s: T) -> Result<(), SceneError> {
    if nonneg_finite(t_s) {
        Ok(())
    } else {
        Err(SceneError::InvalidTime)
    }
}

/// Shared set-up of `r(t)` and `r'(t)`: `None` when the particle does not move (`ri <= a`).
fn moving<T: Real>(scene: &Scene<T>, model: Model) -> Result<Option<(Shape<T>, T)>, SceneError> {
    scene.validate()?;
    let a = scene.equilibrium_radius_m();
    if scene.ri_m <= a {
        return Ok(None);
    }
    Ok(Some((Shape::new(scene, model)?, a)))
}

/// `r(t)`, m: paper Eq. 6 (flat) or Eq. 10 (Coriolis, corrected `A`, `B`), written as
/// `ri + (ri - a) F(l1 t)` so that it is accurate at small `t`.
///
/// This is the trajectory of the ODE for every `t >= 0`; the particle physically leaves at the
/// rim at `T` ([`residence`]). When static friction holds it (`ri <= a`) it stays at `ri`.
pub fn position_m<T: Real>(scene: &Scene<T>, model: Model, t_s: T) -> Result<T, SceneError> {
    checked_time(t_s)?;
    let Some((shape, a)) = moving(scene, model)? else {
        return Ok(scene.ri_m);
    };
    let u = shape.c1 * scene.omega_rad_s * t_s;
    let (f, _, _) = shape.eval(u);
    let r = scene.ri_m + (scene.ri_m - a) * f;
    if r.is_finite() {
        Ok(r)
    } else {
        Err(SceneError::OutOfRange)
    }
}

/// `r'(t)`, m/s: paper Eq. 7 (flat) or Eq. 11 (Coriolis):
/// `(ri - a) (k omega / (2 s)) (e^{l1 t} - e^{l2 t})`; 0 when the particle does not move.
pub fn radial_velocity_m_s<T: Real>(
    scene: &Scene<T>,
    model: Model,
    t_s: T,
) -> Result<T, SceneError> {
    checked_time(t_s)?;
    let Some((shape, a)) = moving(scene, model)? else {
        return Ok(T::ZERO);
    };
    let l1 = shape.c1 * scene.omega_rad_s;
    let (_, fp, _) = shape.eval(l1 * t_s);
    let v = (scene.ri_m - a) * l1 * fp;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(SceneError::OutOfRange)
    }
}

#[cfg(test)]
pub(crate) mod tests;

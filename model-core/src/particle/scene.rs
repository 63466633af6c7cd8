//! The scene: one particle in one bowl, everything the closed forms need, and its checks. Every
//! model (flat, Coriolis, their batches, the inverse) takes a [`Scene`] and refuses a bad one the
//! same way ([`SceneError`], naming the [`Input`]), so the checks and the magnitude window that
//! keeps the arithmetic from under- or overflowing ([`magnitude_limits`]) are written once.

use crate::Real;

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
pub(crate) fn within_magnitudes<T: Real>(x: T) -> bool {
    let (low, high) = magnitude_limits::<T>();
    (x == T::ZERO) | ((x >= low) & (x <= high))
}

/// `0 <= x <= MAX`, false for NaN and infinities (one integer compare, see [`Real`]).
pub(super) fn nonneg_finite<T: Real>(x: T) -> bool {
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

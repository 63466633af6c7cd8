//! The granule as it really rolls: a sphere rolling without slip on the flat bottom of the tilted
//! bowl that spins at `w2` about its axis while the axis precesses at `w1` about the vertical
//! (docs/model.md §9). The equations are in [`equations`], the integrated releases in integrate.rs;
//! here are the scene, the release, the outcomes, and the simpler members of the model hierarchy
//! with closed forms:
//!
//! * [`residence`]: one release at azimuth `beta` (from the downhill direction at `t = 0`),
//!   integrated by the project's integrators ([`crate::ode::system`]) with the rim located on
//!   the interpolant; [`residence_over_azimuths`]: mean, min and max over `beta = 0, 30, ...,
//!   330` degrees.
//! * [`incline_residence_s`]: the straight roll down a fixed incline (no rotation).
//! * [`disc_residence_s`]: the horizontal spinning disc without resistance, where the granule
//!   runs on a circle at `(1 - k2) Omega` in the inertial frame.

pub mod equations;
pub mod hierarchy;
pub mod modes;
pub mod slide;

mod integrate;
pub(crate) mod rest;
mod rest_loop;
pub use integrate::{
    AZIMUTHS_DEG, AzimuthSummary, AzimuthTally, over_azimuths_within, residence,
    residence_over_azimuths, residence_within,
};

use crate::Real;
use crate::ode::system::SystemError;
pub use crate::ode::system::SystemLimits;
use crate::particle::scene::within_magnitudes;
use equations::{AT_REST_M_S, State};

/// A scene of the rolling model. SI units; angles in radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RollingScene<T> {
    /// Precession speed `w1` of the bowl's axis about the vertical, rad/s.
    pub precession_rad_s: T,
    /// Spin speed `w2` of the bowl about its own axis, rad/s.
    pub spin_rad_s: T,
    /// Angle `th` between the bowl's axis and the vertical (paper Eq. 2's angle), rad.
    pub axes_angle_rad: T,
    /// Rolling resistance `mu_r`: a torque `mu_r a N`, i.e. a force `mu_r N` against the motion.
    pub rolling_resistance: T,
    /// The friction coefficient the contact can give before it slides (the paper's measured
    /// 0.4): rolling needs `|f_t| <= mu_s N`.
    pub sliding_friction: T,
    /// Gravity, m/s^2.
    pub g_m_s2: T,
    /// `k2 = m a^2 / (I + m a^2)`: 5/7 for a uniform sphere.
    pub k2: T,
    /// Granule radius `a`, m.
    pub particle_radius_m: T,
    /// Distance `L` of the bowl's centre from the precession axis, m.
    pub rod_length_m: T,
    /// Release radius `ri`, m.
    pub ri_m: T,
    /// Rim radius `R`, m.
    pub rim_radius_m: T,
}

impl<T: Real> RollingScene<T> {
    /// The rig's usual scene at the combined speed `omega_rad_s`: `w1 = w2` with
    /// `|w1 e_z + w2 n| = omega`, tilt `th`, `mu_r` 0.029, `mu_s` 0.4, g 9.81, k2 5/7, a 3 mm,
    /// L 0, release at half the rim radius `rim_m`.
    pub fn equal_speeds(omega_rad_s: T, axes_angle_rad: T, rim_m: T) -> Self {
        let w = omega_rad_s / (T::TWO * (T::ONE + axes_angle_rad.cos())).sqrt();
        Self {
            precession_rad_s: w,
            spin_rad_s: w,
            axes_angle_rad,
            rolling_resistance: T::from_f64(0.029),
            sliding_friction: T::from_f64(0.4),
            g_m_s2: T::from_f64(9.81),
            k2: T::from_f64(5.0 / 7.0),
            particle_radius_m: T::from_f64(0.003),
            rod_length_m: T::ZERO,
            ri_m: T::HALF * rim_m,
            rim_radius_m: rim_m,
        }
    }

    /// The motor speeds as given (`precession_rad_s`, `spin_rad_s`), the rest as
    /// [`RollingScene::equal_speeds`] has it: the project's default scene at that tilt and rim.
    pub fn with_speeds(precession_rad_s: T, spin_rad_s: T, axes_angle_rad: T, rim_m: T) -> Self {
        Self {
            precession_rad_s,
            spin_rad_s,
            ..Self::equal_speeds(T::ONE, axes_angle_rad, rim_m)
        }
    }

    /// Checks every input; the first bad one is named.
    pub fn validate(&self) -> Result<(), RollingError> {
        let finite = |v: T| v.is_finite();
        let nonneg = |v: T| v.is_nonneg_finite();
        let checks = [
            (
                finite(self.precession_rad_s),
                RollingError::InvalidPrecession,
            ),
            (finite(self.spin_rad_s), RollingError::InvalidSpin),
            (
                nonneg(self.axes_angle_rad)
                    && self.axes_angle_rad < T::from_f64(core::f64::consts::FRAC_PI_2),
                RollingError::InvalidAxesAngle,
            ),
            (
                nonneg(self.rolling_resistance),
                RollingError::InvalidResistance,
            ),
            (
                nonneg(self.sliding_friction),
                RollingError::InvalidSlidingFriction,
            ),
            (nonneg(self.g_m_s2), RollingError::InvalidGravity),
            (
                self.k2.is_finite() && self.k2 > T::ZERO && self.k2 < T::ONE,
                RollingError::InvalidK2,
            ),
            (
                nonneg(self.particle_radius_m),
                RollingError::InvalidParticleRadius,
            ),
            (nonneg(self.rod_length_m), RollingError::InvalidRodLength),
            (nonneg(self.ri_m), RollingError::InvalidStartRadius),
            (
                nonneg(self.rim_radius_m) && self.rim_radius_m > self.ri_m,
                RollingError::InvalidRimRadius,
            ),
        ];
        if let Some((_, e)) = checks.iter().find(|(ok, _)| !ok) {
            return Err(*e);
        }
        // The 1-D scene's magnitude limits (`SceneError::ExtremeMagnitude`): the rolling model
        // squares the speeds and multiplies them by lengths and times (`omega^2 R`, the step
        // size from `1 / |Omega|`), so a speed of 1e200 rad/s overflowed into a refusal that
        // blamed `--step-s` and `--tol`.
        let magnitudes = [
            (self.precession_rad_s.abs(), RollingInput::Precession),
            (self.spin_rad_s.abs(), RollingInput::Spin),
            (self.rolling_resistance, RollingInput::Resistance),
            (self.sliding_friction, RollingInput::SlidingFriction),
            (self.g_m_s2, RollingInput::Gravity),
            (self.particle_radius_m, RollingInput::ParticleRadius),
            (self.rod_length_m, RollingInput::RodLength),
            (self.ri_m, RollingInput::StartRadius),
            (self.rim_radius_m, RollingInput::RimRadius),
        ];
        match magnitudes.iter().find(|(v, _)| !within_magnitudes(*v)) {
            Some((_, input)) => Err(RollingError::ExtremeMagnitude(*input)),
            None => Ok(()),
        }
    }

    /// The combined rotation speed `|w1 e_z + w2 n|`, rad/s (paper Eq. 2).
    pub fn combined_speed_rad_s(&self) -> T {
        let (w1, w2) = (self.precession_rad_s, self.spin_rad_s);
        let c = self.axes_angle_rad.cos();
        (w1 * w1 + w2 * w2 + T::TWO * w1 * w2 * c)
            .max(T::ZERO)
            .sqrt()
    }

    /// Whether the forces in the bowl's frame are constant in time (no precession and a bowl
    /// that does not spin or spins about the vertical, or a precession about the bowl's own
    /// axis with the bowl on it): then a held granule stays. A tilted bowl that only spins is
    /// not: gravity turns in its frame at the spin (`gB` in [`equations`]), and a granule held
    /// at its release can be let go as it turns (2 deg tilt, 3 rad/s, ri 30 mm, released at
    /// 180 deg: "held" before, now it starts at 0.313 s and leaves at 1.155 s), which a held
    /// segment (`rest`) finds.
    pub(crate) fn stationary(&self) -> bool {
        (self.precession_rad_s == T::ZERO
            && (self.spin_rad_s == T::ZERO || self.axes_angle_rad == T::ZERO))
            || (self.axes_angle_rad == T::ZERO && self.rod_length_m == T::ZERO)
    }
}

/// One input of a [`RollingScene`], as an [`RollingError::ExtremeMagnitude`] refusal names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RollingInput {
    /// `precession_rad_s`.
    Precession,
    /// `spin_rad_s`.
    Spin,
    /// `rolling_resistance`.
    Resistance,
    /// `sliding_friction`.
    SlidingFriction,
    /// `g_m_s2`.
    Gravity,
    /// `particle_radius_m`.
    ParticleRadius,
    /// `rod_length_m`.
    RodLength,
    /// `ri_m`.
    StartRadius,
    /// `rim_radius_m`.
    RimRadius,
}

/// Why the rolling model gave no answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RollingError {
    /// The precession speed was NaN or infinite.
    InvalidPrecession,
    /// The spin speed was NaN or infinite.
    InvalidSpin,
    /// The axes angle was not in [0, 90) degrees.
    InvalidAxesAngle,
    /// The rolling resistance was NaN, infinite or negative.
    InvalidResistance,
    /// The sliding friction coefficient was NaN, infinite or negative.
    InvalidSlidingFriction,
    /// Gravity was NaN, infinite or negative.
    InvalidGravity,
    /// k2 was not in (0, 1).
    InvalidK2,
    /// The granule radius was NaN, infinite or negative.
    InvalidParticleRadius,
    /// The rod length was NaN, infinite or negative.
    InvalidRodLength,
    /// The release radius was NaN, infinite or negative.
    InvalidStartRadius,
    /// The rim radius was not finite and larger than the release radius.
    InvalidRimRadius,
    /// The release azimuth was not finite.
    InvalidAzimuth,
    /// A valid input outside the magnitudes the model computes with
    /// ([`magnitude_limits`](crate::particle::magnitude_limits): nonzero and below `1e-75` or
    /// above `1e75` in f64; none in f32): refused rather than answered; rescale the units.
    ExtremeMagnitude(RollingInput),
    /// The integration failed (step cap, a non-finite state, an invalid step).
    Integration(SystemError),
}

/// What happens to one granule.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RollingOutcome<T> {
    /// It reaches the rim.
    Leaves {
        /// Residence time `T`, s.
        residence_time_s: T,
        /// Speed relative to the bowl at the rim, m/s.
        exit_speed_m_s: T,
        /// The largest friction the contact had to give to keep rolling, as a fraction of the
        /// normal force: above the sliding coefficient the granule slid, and this `T` is the
        /// rolling model's, not the rig's.
        max_friction_ratio: T,
        /// When rolling first needed more friction than the sliding coefficient gives, s.
        first_slip_s: Option<T>,
    },
    /// Released at rest, the resistance holds it, and the forces never change.
    Held,
    /// The normal force fell to zero: the granule leaves the bottom at this time, s.
    LiftsOff {
        /// s.
        time_s: T,
    },
    /// Still in the bowl at the horizon, s.
    NotLeftBy {
        /// s.
        horizon_s: T,
    },
}

/// How the rolling model is integrated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RollingMethod<T> {
    /// Adaptive Dormand-Prince 5(4) at this relative tolerance.
    Dp54 {
        /// Relative tolerance.
        rtol: T,
    },
    /// Classical RK4 at this step, s.
    Rk4 {
        /// s.
        step_s: T,
    },
}

/// One release's outcome and what it cost.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RollingReport<T> {
    /// The outcome.
    pub outcome: RollingOutcome<T>,
    /// Right-hand-side evaluations.
    pub evaluations: u32,
    /// Accepted steps.
    pub steps: u32,
    /// Time held at rest on the way by the rolling resistance (`rest`), s: up to the outcome,
    /// or the horizon.
    pub held_s: T,
}

/// The horizon of a release, s: a granule still in the bowl after this long is reported as such.
pub const HORIZON_S: f64 = 60.0;

/// Step cap of one release.
pub const MAX_STEPS: u32 = 2_000_000;

/// The limits of a release: [`HORIZON_S`] and [`MAX_STEPS`].
pub(crate) fn default_limits<T: Real>() -> SystemLimits<T> {
    SystemLimits {
        horizon_s: T::from_f64(HORIZON_S),
        max_steps: MAX_STEPS,
    }
}

/// The release at azimuth `beta_rad` (measured from the downhill direction at `t = 0`, which is
/// `-e1`, turning towards `-e2`), once the scene and the azimuth are checked:
/// `(x, y) = ri (-cos beta, -sin beta)`, at rest in the bowl.
pub(crate) fn release<T: Real>(
    scene: &RollingScene<T>,
    beta_rad: T,
) -> Result<State<T>, RollingError> {
    scene.validate()?;
    if !beta_rad.is_finite() {
        return Err(RollingError::InvalidAzimuth);
    }
    Ok([
        -scene.ri_m * beta_rad.cos(),
        -scene.ri_m * beta_rad.sin(),
        T::ZERO,
        T::ZERO,
        T::ZERO,
    ])
}

/// The straight roll down a fixed incline at the bowl's tilt, no rotation (the simplest member
/// with gravity): `T(beta) = sqrt(2 s / (k2 g (sin th - mu_r cos th)))` with the path to the rim
/// `s = -ri cos beta + sqrt(R^2 - ri^2 sin^2 beta)`. `None` when the resistance holds it.
pub fn incline_residence_s<T: Real>(scene: &RollingScene<T>, beta_rad: T) -> Option<T> {
    let (st, ct) = (scene.axes_angle_rad.sin(), scene.axes_angle_rad.cos());
    let drive = scene.k2 * scene.g_m_s2 * (st - scene.rolling_resistance * ct);
    // Also catches a NaN drive.
    if drive.is_nan() || drive <= T::ZERO {
        return None;
    }
    let (ri, rim) = (scene.ri_m, scene.rim_radius_m);
    let sb = beta_rad.sin();
    let s = -ri * beta_rad.cos() + (rim * rim - ri * ri * sb * sb).max(T::ZERO).sqrt();
    let t = (T::TWO * s / drive).sqrt();
    t.is_finite().then_some(t)
}

/// The horizontal spinning disc, no resistance, granule released at rest in the disc at `ri`:
/// in the inertial frame it runs on a circle at `nu = (1 - k2) Omega` through the release point,
/// centred `k2 ri / (1 - k2)` on the far side of the axis, so
/// `|r|^2 / ri^2 = ((1 + k2^2) - 2 k2 cos(nu t)) / (1 - k2)^2` (for k2 = 5/7:
/// `37/2 - (35/2) cos(2 Omega t / 7)`, never beyond `6 ri`) and
/// `T = acos(((1 + k2^2) - (1 - k2)^2 (R/ri)^2) / (2 k2)) / nu`. `None` when the circle stays
/// inside the rim or the inputs give no time.
pub fn disc_residence_s<T: Real>(omega_rad_s: T, k2: T, ri_m: T, rim_m: T) -> Option<T> {
    let one_m = T::ONE - k2;
    let nu = one_m * omega_rad_s.abs();
    let ratio = rim_m / ri_m;
    let c = ((T::ONE + k2 * k2) - one_m * one_m * ratio * ratio) / (T::TWO * k2);
    if !(nu > T::ZERO && c.is_finite() && c >= -T::ONE) {
        return None;
    }
    let t = c.min(T::ONE).acos() / nu;
    t.is_finite().then_some(t)
}

/// At rest below this speed (see [`equations::AT_REST_M_S`]), m/s.
pub fn at_rest_threshold_m_s<T: Real>() -> T {
    T::from_f64(AT_REST_M_S)
}

#[cfg(test)]
mod modes_tests;
#[cfg(test)]
mod rest_loop_tests;
#[cfg(test)]
mod rest_tests;
#[cfg(test)]
mod tests;

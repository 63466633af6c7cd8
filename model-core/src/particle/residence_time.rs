//! The residence time `T` and the exit velocities (paper Eq. 6, 7, 10, 11, 12): what every
//! model's answer starts from (the rim, never leaving: [`before_model`]), the models' solvers
//! called and their results checked, one scene ([`residence`], [`residence_time_s`]) or a batch
//! ([`residence_times_s`]), and the [`Outcome`] that says which physical case it is.

use super::{Model, Scene, SceneError};
use super::{batch, coriolis, coriolis_batch, flat, flat_batch};
use crate::Real;

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

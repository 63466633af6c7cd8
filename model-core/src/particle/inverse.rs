//! The inverse problem: the bowl speed omega that gives a target residence time.
//!
//! With `z = c1 omega T` (`c1 = l1 / omega`, see [`Shape`]) the residence condition reads
//! `F(z) = x(omega) = (R - ri) / (ri - mu g / omega^2)`. We solve
//! `Lambda(omega) = ln(F(z) / x(omega)) = 0`, which increases strictly with omega (`F` grows with
//! `z`, `x` falls as `a` does), by Newton in `ln omega`:
//! `d Lambda / d ln omega = z F'(z)/F(z) + 2 a / (ri - a)`, safeguarded by a bracket and geometric
//! bisection. Since `T(omega)` falls from infinity (at the threshold `omega_th = sqrt(mu g / ri)`,
//! where `a = ri`) to 0, every positive target is reachable in exact arithmetic; the errors say
//! why a particular one is not.

use super::flat::acosh_1p_ratio;
use super::{Model, Scene, SceneError, Shape};
use crate::Real;

/// Iterations allowed; the safeguarded Newton needs 4 to 10.
const MAX_ITERATIONS: u32 = 80;

/// Why no bowl speed was returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum InverseError {
    /// A scene parameter (other than omega, which is ignored) was invalid.
    Scene(SceneError),
    /// The target time was NaN, infinite, zero or negative.
    InvalidTarget,
    /// `ri >= R`: the particle starts at the rim, `T = 0` at every speed.
    AlreadyAtRim,
    /// `ri = 0` (the centre): no speed moves it (for `mu > 0` the threshold speed is infinite;
    /// for `mu = 0` the centrifugal force vanishes there).
    NeverLeaves,
    /// The speed needed overflows the number type (a target far too short for the units).
    OutOfRange,
    /// The target lies so close above the threshold speed that the residence time jumps past
    /// it between two adjacent representable speeds (`T` grows like `-ln(omega - omega_th)`):
    /// no speed of this number type gives it. Use a wider type or a shorter target.
    BeyondPrecision,
    /// The iteration did not settle (not expected; reported rather than returning a guess).
    NotConverged,
}

/// Bowl speed omega (rad/s) at which [`super::residence`] gives `target_s`; `scene.omega_rad_s`
/// is ignored. Monotone: a longer target needs a slower bowl, down to (not reaching) the
/// threshold speed `sqrt(mu g / ri)`.
pub fn omega_for_residence_time<T: Real>(
    scene: &Scene<T>,
    model: Model,
    target_s: T,
) -> Result<T, InverseError> {
    scene.validate_except_omega().map_err(InverseError::Scene)?;
    if !(target_s.is_finite() && target_s > T::ZERO) {
        return Err(InverseError::InvalidTarget);
    }
    let (ri, rim) = (scene.ri_m, scene.rim_radius_m);
    if ri >= rim {
        return Err(InverseError::AlreadyAtRim);
    }
    if ri <= T::ZERO {
        return Err(InverseError::NeverLeaves);
    }
    let shape = Shape::new(scene, model).map_err(|_| InverseError::OutOfRange)?;
    let (ac, bc) = (shape.a_coef, shape.b_coef);
    let mu_g = scene.mu * scene.g_m_s2;
    let omega_th = (mu_g / ri).sqrt();
    let l = shape.c1 * target_s; // z = l omega
    let y0 = (rim - ri) / ri;
    let y1 = T::TWO * y0;
    // Bracket. Lower: below omega_th, or where F(z) <= y0 (then x >= y0 >= F). Upper: where
    // a <= ri/2 and F(z) >= 2 y0 >= x. Flat F = cosh z - 1 inverts exactly; for Coriolis
    // A (e^z - 1) - B <= F <= A (e^z - 1) and F >= A z^2 / 2.
    let (z_lo, z_hi) = match model {
        Model::Flat => (
            acosh_1p_ratio(rim - ri, ri),
            acosh_1p_ratio(T::TWO * (rim - ri), ri),
        ),
        Model::Coriolis => (
            (y0 / ac).ln_1p(),
            ((y1 + bc) / ac).ln_1p().min((T::TWO * y1 / ac).sqrt()),
        ),
    };
    let mut lo = omega_th.max(z_lo / l);
    let mut hi = (omega_th * T::from_f64(core::f64::consts::SQRT_2)).max(z_hi / l);
    if !(hi.is_finite() && lo.is_finite()) {
        return Err(InverseError::OutOfRange);
    }
    // Stop when a Newton step moves omega by a few ulps. Near the threshold Lambda bends
    // sharply, so a quadratic-convergence shortcut would stop early: we take the extra step.
    let tol = T::from_f64(8.0) * T::EPSILON;
    // Relative error of T implied by the last Lambda, and its floor (T's jump between adjacent
    // omegas): Lambda / (z F'/F) against epsilon (1 + (2 a/(ri - a)) / (z F'/F)).
    let mut t_err: T;
    let mut t_floor = T::ZERO;
    let mut omega = hi;
    for _ in 0..MAX_ITERATIONS {
        let a = mu_g / omega / omega;
        let step = if a < ri {
            let den = ri - a;
            let x = (rim - ri) / den;
            let z = l * omega;
            let (f, fp, _) = shape.eval(z);
            if f > T::ZERO && f.is_finite() && x.is_finite() && fp.is_finite() {
                let lambda = (f / x).ln();
                if lambda > T::ZERO {
                    hi = omega;
                } else if lambda < T::ZERO {
                    lo = omega;
                } else {
                    return Ok(omega);
                }
                let slope_f = z * fp / f;
                let slope_a = T::TWO * a / den;
                t_err = lambda.abs() / slope_f;
                t_floor = T::EPSILON * (T::ONE + slope_a / slope_f);
                Some(lambda / (slope_f + slope_a))
            } else {
                lo = omega;
                t_err = T::INFINITY;
                None
            }
        } else {
            lo = omega;
            t_err = T::INFINITY;
            None
        };
        let newton = step.map(|d| {
            // omega e^{-d}; the second-order Taylor form for small d saves an exp and keeps
            // the quadratic convergence (its error is O(d^3)).
            let next = if d.abs() < T::from_f64(0.125) {
                omega * (T::ONE - d + T::HALF * d * d)
            } else {
                omega * (-d).exp()
            };
            (d, next)
        });
        match newton {
            Some((d, next)) if next > lo && next < hi => {
                if d.abs() <= tol {
                    return Ok(next);
                }
                omega = next;
            }
            _ => {
                if hi - lo <= tol * hi {
                    return if t_err <= T::from_f64(64.0) * t_floor {
                        Ok(omega)
                    } else {
                        Err(InverseError::BeyondPrecision)
                    };
                }
                omega = (lo * hi).sqrt();
            }
        }
    }
    Err(InverseError::NotConverged)
}

//! The inverse problem: the bowl speed omega that gives a target residence time.
//!
//! With `z = c1 omega T` (`c1 = l1 / omega`, see [`Shape`]) the particle is at the rim at `T`
//! when `F(z) = x = (R - ri) / (ri - a)`, i.e. when
//! `G(omega) = (ri - mu g / omega^2) - (R - ri) / F(c1 T omega) = 0`.
//! `G` increases strictly with omega (both terms do) and is concave (`-1/omega^2` is, and so is
//! `-1/F` for the convex, log-convex `F` of both models), so Newton started *below* the root
//! climbs monotonically onto it. Unlike `ln T` it stays smooth at the threshold
//! `omega_th = sqrt(mu g / ri)`, where `a = ri` and `T` is infinite. We start at a lower bound
//! that is exact for `mu = 0` in the flat model and within `sqrt(q)` for Coriolis, and keep a
//! bracket with bisection as a safeguard. Since `T(omega)` falls from infinity at `omega_th` to
//! 0, every positive target is reachable in exact arithmetic; the errors say why a particular
//! one is not.

use super::flat::acosh_1p_ratio;
use super::{Model, Scene, SceneError, Shape};
use crate::Real;

/// Iterations allowed; Newton from the lower bound needs 2 to 6, bisection at most ~60 more.
const MAX_ITERATIONS: u32 = 100;

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
    /// The target lies so close above the threshold speed that the particle must start within
    /// rounding of the equilibrium radius (`T` grows like `-ln(omega - omega_th)`): no speed
    /// of this number type gives it reliably. Use a wider type or a shorter target.
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
    // Bracket. Lower: omega_th, or where F(z) <= y0 (then x >= y0 >= F, G <= 0). Upper: where
    // a <= ri/2 and F(z) >= 2 y0 >= x. Flat F = cosh z - 1 inverts exactly. Coriolis: from the
    // series F = sum A (1 + (-1)^n q^(n-1)) z^n / n!, F <= A (1 + 1/q)(cosh(q z) - 1) and
    // F <= A (e^z - 1); F >= A (e^z - 1) - B and F >= A z^2 / 2.
    let (z_lo, z_hi) = match model {
        Model::Flat => (
            acosh_1p_ratio(rim - ri, ri),
            acosh_1p_ratio(T::TWO * (rim - ri), ri),
        ),
        Model::Coriolis => {
            let q = shape.q;
            let by_cosh = acosh_1p_ratio(y0 * q, ac * (T::ONE + q)) / q;
            (
                (y0 / ac).ln_1p().max(by_cosh),
                ((y1 + bc) / ac).ln_1p().min((T::TWO * y1 / ac).sqrt()),
            )
        }
    };
    let mut lo = omega_th.max(z_lo / l);
    let mut hi = (omega_th * T::from_f64(core::f64::consts::SQRT_2)).max(z_hi / l);
    if !(hi.is_finite() && lo.is_finite()) {
        return Err(InverseError::OutOfRange);
    }
    let tol = T::from_f64(4.0) * T::EPSILON;
    // Forward would find ri within rounding of a (a target so long that only a speed within
    // rounding of the threshold gives it): T is not determined by this omega.
    let determined = |omega: T| {
        let a = mu_g / omega / omega;
        if a >= ri * (T::ONE - T::from_f64(8.0) * T::EPSILON) {
            Err(InverseError::BeyondPrecision)
        } else {
            Ok(omega)
        }
    };
    // The same, and F must not overflow at the target time (checked where no evaluation near
    // this omega has shown it finite).
    let settle = |omega: T| {
        let (f, _, _) = shape.eval(l * omega);
        if f.is_finite() {
            determined(omega)
        } else {
            Err(InverseError::BeyondPrecision)
        }
    };
    let mut omega = lo;
    // The previous Newton step: in the quadratic regime the next error is about
    // `d^2 |d| / d_prev^2`, which lets the iteration stop one evaluation early.
    let mut d_prev: Option<T> = None;
    for _ in 0..MAX_ITERATIONS {
        let a = mu_g / omega / omega;
        let z = l * omega;
        let (f, fp, _) = shape.eval(z);
        // F may overflow to infinity for a large z: then the particle is long gone by T,
        // gap = 0 and G = ri - a > 0, which is the right sign (omega is too high).
        let step = if f > T::ZERO && !f.is_nan() && !fp.is_nan() {
            let gap = (rim - ri) / f;
            let g = (ri - a) - gap;
            if g < T::ZERO {
                lo = omega;
            } else if g > T::ZERO {
                hi = omega;
            } else {
                return settle(omega);
            }
            // G' = 2 a / omega + (R - ri) c1 T F'(z) / F(z)^2.
            let gp = if gap > T::ZERO {
                T::TWO * a / omega + gap * l * (fp / f)
            } else {
                T::TWO * a / omega
            };
            if gp > T::ZERO && gp.is_finite() {
                Some(g / gp)
            } else {
                None
            }
        } else {
            lo = omega;
            None
        };
        match step {
            // F was finite at omega, and the last step moves it by far less than it could grow.
            Some(d) if d.abs() <= tol * omega => {
                return determined((omega - d).max(lo).min(hi));
            }
            Some(d) if omega - d > lo && omega - d < hi => {
                let next = omega - d;
                if let Some(p) = d_prev
                    && d.abs() < T::from_f64(1e-2) * omega
                    && d.abs() <= T::HALF * p.abs()
                    && d * d * d.abs() <= T::from_f64(0.25) * tol * omega * p * p
                {
                    return determined(next);
                }
                d_prev = Some(d);
                omega = next;
            }
            _ => {
                if hi - lo <= tol * hi {
                    return settle(hi);
                }
                omega = T::HALF * (lo + hi);
            }
        }
    }
    Err(InverseError::NotConverged)
}

//! Residence time of the flat model (paper Eq. 6, 7; correct in the paper).

use super::{Exit, Scene, condition};
use crate::Real;

/// `(acosh(1 + x), den sqrt(x (x + 2)))` for `x = num / den > 0`, the first as
/// `log1p(x + sqrt(x (x + 2)))`.
///
/// The naive `acosh(1 + x)` rounds `1 + x` first and so loses all digits of a small `x` (a start
/// near the rim). For `x > 1/epsilon` (and when `x` overflows) `acosh(1 + x) = ln 2 + ln x` and
/// `sqrt(x (x + 2)) = x + 1` to within epsilon, computed from `num` and `den` so an overflowing
/// quotient does no harm. The second value, `sqrt(num (num + 2 den))`, is `sinh` of the first
/// times `den`: the flat exit velocity needs it.
#[inline(always)]
pub(crate) fn acosh_1p_parts<T: Real>(num: T, den: T) -> (T, T) {
    let x = num / den;
    if x < T::ONE / T::EPSILON {
        let w = (x * (x + T::TWO)).sqrt();
        // x + w is finite and >= 0 here (x below 1/epsilon, and num, den > 0 by the caller).
        ((x + w).ln_1p_in_domain(), den * w)
    } else {
        (
            T::from_f64(core::f64::consts::LN_2) + num.ln() - den.ln(),
            num + den,
        )
    }
}

/// `acosh(1 + num / den)`, see [`acosh_1p_parts`].
#[inline]
pub(crate) fn acosh_1p_ratio<T: Real>(num: T, den: T) -> T {
    acosh_1p_parts(num, den).0
}

/// Flat model, `a < ri < R` (checked by the caller).
///
/// `T = acosh(1 + x) / (k omega)`, `x = (R - ri) / (ri - a)`; exit radial velocity
/// `(ri - a) k omega sinh(k omega T) = k omega sqrt((R - ri)(R - ri + 2 (ri - a)))`, the energy
/// form, without cancellation; condition `kx = x / (sqrt(x (x + 2)) acosh(1 + x))`.
pub(crate) fn residence<T: Real>(scene: &Scene<T>, a: T) -> Exit<T> {
    let (ri, rim) = (scene.ri_m, scene.rim_radius_m);
    let k_omega = scene.k2.sqrt() * scene.omega_rad_s;
    let num = rim - ri;
    let den = ri - a;
    let (z, sinh_den) = acosh_1p_parts(num, den);
    // x / sqrt(x (x + 2)) / z = num / (den sqrt(x (x + 2)) z); tends to 1/2 as x -> 0.
    let kx = if z > T::ZERO && sinh_den > T::ZERO {
        num / (sinh_den * z)
    } else {
        T::HALF
    };
    Exit {
        time: z / k_omega,
        radial: k_omega * sinh_den,
        condition: condition(kx, a, ri),
    }
}

/// The flat model's residence time alone, `a < ri < R` (checked by the caller): the same
/// arithmetic as [`residence`]'s time, none of its exit speed or condition.
#[inline(always)]
pub(crate) fn time<T: Real>(scene: &Scene<T>, a: T) -> T {
    let k_omega = scene.k2.sqrt() * scene.omega_rad_s;
    acosh_1p_ratio(scene.rim_radius_m - scene.ri_m, scene.ri_m - a) / k_omega
}

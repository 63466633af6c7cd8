//! Residence time of the flat model (paper Eq. 6, 7; correct in the paper).

use super::{Exit, Scene, condition};
use crate::Real;

/// `acosh(1 + x)` for `x = num / den > 0`, as `log1p(x + sqrt(x (x + 2)))`.
///
/// The naive `acosh(1 + x)` rounds `1 + x` first and so loses all digits of a small `x` (a start
/// near the rim). For `x > 1/epsilon` (and when `x` overflows) `acosh(1 + x) = ln 2 + ln x` to
/// within epsilon, computed from `num` and `den` so an overflowing quotient does no harm.
#[inline]
pub(crate) fn acosh_1p_ratio<T: Real>(num: T, den: T) -> T {
    let x = num / den;
    if x < T::ONE / T::EPSILON {
        (x + (x * (x + T::TWO)).sqrt()).ln_1p()
    } else {
        T::from_f64(core::f64::consts::LN_2) + num.ln() - den.ln()
    }
}

/// Flat model, `a < ri < R` (checked by the caller).
///
/// `T = acosh(1 + x) / (k omega)`, `x = (R - ri) / (ri - a)`; exit radial velocity
/// `(ri - a) k omega sinh(k omega T) = k omega sqrt((R - ri) ((R - a) + (ri - a)))`, the energy
/// form, which has no cancellation; condition `kx = x / (sqrt(x (x + 2)) acosh(1 + x))`.
pub(crate) fn residence<T: Real>(scene: &Scene<T>, a: T) -> Exit<T> {
    let (ri, rim) = (scene.ri_m, scene.rim_radius_m);
    let k_omega = scene.k2.sqrt() * scene.omega_rad_s;
    let num = rim - ri;
    let den = ri - a;
    let z = acosh_1p_ratio(num, den);
    let radial = k_omega * num.sqrt() * ((rim - a) + den).sqrt();
    // x / sqrt(x (x + 2)) = 1 / sqrt(1 + 2/x), finite for every x > 0 including infinity.
    let kx = if z > T::ZERO {
        T::ONE / ((T::ONE + T::TWO * den / num).sqrt() * z)
    } else {
        T::HALF
    };
    Exit {
        time: z / k_omega,
        radial,
        condition: condition(kx, a, ri),
    }
}

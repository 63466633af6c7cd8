//! `e^z - 1 - z` and `e^z - 1` together, without cancellation.
//!
//! The Coriolis solution (paper Eq. 10, corrected as in docs/model.md §3) is
//! `F(u) = A (e^u - 1) + B (e^{-q u} - 1)`; since `A - B q = 0` this equals
//! `A phi(u) + B phi(-q u)` with `phi(z) = e^z - 1 - z`. For small `z`, `phi(z)` is about `z^2 / 2`
//! and `expm1(z) - z` would cancel all but a few digits, so we sum its Taylor series there.

use crate::Real;
use crate::real::exp::phi_terms_f64;

/// `(phi(z), expm1(z))` with `phi(z) = e^z - 1 - z`.
///
/// For `|z| < 1` the series `z^2/2 (1 + z/3 (1 + z/4 (...)))`, truncated where the next term is
/// below the type's epsilon (10 terms for `f32` by Horner, 18 for `f64` by Estrin's scheme,
/// [`phi_terms_f64`]); `expm1 = phi + z` then has no
/// cancellation worth a bit. Otherwise `e^z - 1` (no cancellation for `|z| >= 1`: `e^z - 1`
/// is at least 0.63 in magnitude; `exp` is also ~25 instructions cheaper than `expm1` in `f32`)
/// and `phi = (e^z - 1) - z`, which loses at most 1.5 bits at `|z| = 1`.
#[inline]
pub(crate) fn phi_expm1<T: Real>(z: T) -> (T, T) {
    if z.abs() < T::ONE {
        let p = if T::is_single_precision() {
            horner_f32_terms(z)
        } else {
            T::from_f64(phi_terms_f64(z.to_f64()))
        };
        let phi = z * z * T::HALF * p;
        (phi, phi + z)
    } else {
        let e = z.exp() - T::ONE;
        (e - z, e)
    }
}

/// `2 phi(z) / z^2 = sum_j 2 z^j / (j + 2)!` to the 11th factorial, by Horner: the fewest
/// instructions, which is what counts on the Cortex-M4F's in-order pipeline.
#[inline]
fn horner_f32_terms<T: Real>(z: T) -> T {
    let mut p = T::ONE;
    let mut n = 11u32;
    while n >= 3 {
        p = T::ONE + z * T::from_f64(1.0 / n as f64) * p;
        n -= 1;
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference: the series summed in f64 to 40 terms (independent of the Horner truncation).
    fn phi_ref(z: f64) -> f64 {
        if z.abs() < 2.0 {
            let (mut term, mut sum) = (z * z / 2.0, 0.0);
            for n in 3..45 {
                sum += term;
                term *= z / n as f64;
            }
            sum
        } else {
            libm::expm1(z) - z
        }
    }

    #[test]
    fn phi_is_accurate_across_the_switch_f64() {
        for &z in &[
            1e-300, -1e-300, 1e-8, -1e-8, 0.01, -0.01, 0.5, -0.5, 0.999, -0.999, 1.0, -1.0, 3.0,
            -3.0, 30.0, -30.0,
        ] {
            let (phi, e) = phi_expm1(z);
            let want = phi_ref(z);
            assert!(
                (phi - want).abs() <= 4.0 * f64::EPSILON * want.abs(),
                "phi({z}) = {phi}, want {want}"
            );
            let want_e = libm::expm1(z);
            assert!((e - want_e).abs() <= 4.0 * f64::EPSILON * want_e.abs());
        }
    }

    #[test]
    fn phi_is_accurate_f32() {
        for &z in &[
            1e-15f32, 1e-4, -1e-4, 0.3, -0.3, 0.99, -0.99, 1.0, -1.0, 5.0, -5.0,
        ] {
            let (phi, _) = phi_expm1(z);
            let want = phi_ref(z as f64);
            let rel = ((phi as f64 - want) / want).abs();
            assert!(rel < 4.0 * f32::EPSILON as f64, "phi({z}) rel err {rel}");
        }
    }
}

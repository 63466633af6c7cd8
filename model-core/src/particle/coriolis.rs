//! Residence time of the Coriolis model (paper Eq. 10, 11 with the corrected A, B of docs/model.md §3).

use super::flat::acosh_1p_ratio;
use super::{Exit, Model, Scene, SceneError, Shape, condition};
use crate::Real;

/// Newton iterations allowed; it needs 2 to 4.
const MAX_NEWTON: u32 = 40;

/// The root `u = l1 T` of `F(u) = x`, with `F` of [`Shape::eval`], and `expm1(-q u)` at the root
/// (for the exit velocity's identity in [`residence`]).
///
/// `F` is convex and increasing with `F'(0) = 0`, so Newton from 0 divides by zero; from any
/// point above the root it decreases monotonically onto it, and from a point below it the first
/// step lands above the root (the tangent of a convex function lies below it). We start at the
/// flat model's closed form scaled to the same curvature at 0,
/// `u0 = acosh(1 + x / (A (1 + q)))` (exact at `mu = 0`, within about `k mu` otherwise), inside
/// the bracket `[0, sqrt(2 x / A)]` (`F >= A u^2 / 2`, docs/model.md §4). Every iterate is
/// clamped to the bracket, which shrinks as Newton learns which side each point is on.
///
/// Where `F` is a factor off `x` with `u > 1` (a large `k mu` with a start far from the rim:
/// `u0` is then far from the root), `F` behaves like `A e^u` and a Newton step moves `u` by
/// about one unit: there we step by `ln(x / F)` instead, which lands within a unit of the root
/// (`F <= A e^u`, docs/model.md §4's `ln((1 + x)/A)` bound). Ordinary scenes never take it, so
/// it costs no logarithm on the MCU where it is not needed.
/// Stop test: after a step `d` the remaining error is about `F''/(2 F') d^2`; we stop when that
/// is below a quarter of an ulp of `u`, which saves the customary extra iteration. An iteration
/// that has not converged is an error, never a result.
pub(crate) fn solve_u<T: Real>(shape: &Shape<T>, x: T) -> Result<(T, T), SceneError> {
    let ac = shape.a_coef;
    let mut lower = T::ZERO;
    let mut upper = (T::TWO * x / ac).sqrt();
    let mut u = acosh_1p_ratio(x, ac * (T::ONE + shape.q)).min(upper);
    let far = T::from_f64(4.0);
    for _ in 0..MAX_NEWTON {
        let (f, fp, fpp, eb) = shape.eval_with_decay(u);
        if !(f.is_finite() && fp.is_finite() && fpp.is_finite()) {
            return Err(SceneError::OutOfRange);
        }
        if fp <= T::ZERO {
            // Only at u = 0, i.e. x = 0 (R - ri underflowed against ri - a): T = 0.
            return Ok((u, eb));
        }
        if f < x {
            lower = u;
        } else {
            upper = u;
        }
        if u > T::ONE && (f > far * x || x > far * f) {
            u = (u - (f / x).ln()).max(lower).min(upper);
            continue;
        }
        let d = (f - x) / fp;
        let next = (u - d).max(lower).min(upper);
        let converged = fpp * d * d <= T::HALF * T::EPSILON * fp * next;
        if converged {
            // expm1(-q next) to first order from expm1(-q u): the step is below sqrt(eps) u.
            let eb_next = eb - (T::ONE + eb) * shape.q * (next - u);
            return Ok((next, eb_next));
        }
        u = next;
    }
    Err(SceneError::NoConvergence)
}

/// The root of `F(u) = x` for `x > 1/eps` (and for an `x` that overflows, e.g. a subnormal
/// `ri - a`): there `e^{-q u}` is below `eps` and `F(u) = A e^u + B e^{-q u} - (A + B)`
/// (docs/model.md §4) gives `u = ln(x / A) + ln(1 + (A + B)/x)` to rounding, with
/// `ln x = ln(R - ri) - ln(ri - a)` so that `x` itself is never formed. No iteration.
fn large_u<T: Real>(shape: &Shape<T>, rise: T, den: T) -> T {
    let sum = shape.a_coef + shape.b_coef;
    (rise.ln() - den.ln()) - shape.a_coef.ln() + sum * (den / rise)
}

/// Coriolis model, `a < ri < R` (checked by the caller). `T = u / l1`, `l1 = k omega/(s + k mu)`.
///
/// Exit velocity `r'(T) = (ri - a) l1 F'(u)` (paper Eq. 11: `(ri - a)(k omega/(2 s))
/// (e^{l1 T} - e^{l2 T})`) through the identity `F'(u) = x - (A + B) expm1(-q u)` (from
/// `F = A e^u + B e^{-q u} - (A + B) = x` and `B q = A`): `F'` from `e^u` would carry `u`'s
/// rounding times `u`; the identity depends on `u` only through a bounded term. Then
/// `r'(T) = l1 ((R - ri) - (ri - a)(A + B) expm1(-q u))`, which never forms `x`.
pub(crate) fn residence<T: Real>(scene: &Scene<T>, a: T) -> Result<Exit<T>, SceneError> {
    let shape = Shape::new(scene, Model::Coriolis)?;
    let (ri, rim) = (scene.ri_m, scene.rim_radius_m);
    let den = ri - a;
    let rise = rim - ri;
    let x = rise / den;
    let (u, eb) = if x.is_finite() && x * T::EPSILON <= T::ONE {
        solve_u(&shape, x)?
    } else {
        (large_u(&shape, rise, den), -T::ONE)
    };
    let l1 = shape.c1 * scene.omega_rad_s;
    // (ri - a) F'(u), finite even where x is not.
    let den_fp = rise - den * (shape.a_coef + shape.b_coef) * eb;
    // kx = x / (u F'(u)); as x -> 0, F ~ A (1 + q) u^2 / 2, so the ratio tends to 1/2.
    let kx = if u * den_fp > T::ZERO {
        rise / (u * den_fp)
    } else {
        T::HALF
    };
    let time = u / l1;
    let radial = l1 * den_fp;
    if !(time.is_finite() && radial.is_finite()) {
        return Err(SceneError::OutOfRange);
    }
    Ok(Exit {
        time,
        radial,
        condition: condition(kx, a, ri),
    })
}

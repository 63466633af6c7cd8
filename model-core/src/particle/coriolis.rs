//! Residence time of the Coriolis model (paper Eq. 10, 11 with the corrected A, B of docs/model.md §3).

use super::flat::{acosh_1p_parts, acosh_1p_ratio};
use super::{Exit, Model, Scene, SceneError, Shape, condition};
use crate::Real;

/// Iterations allowed; it needs 1 or 2 on the rig's scenes (2 or 3 in f64).
const MAX_NEWTON: u32 = 40;

/// Below this `m/s` the start that is first order in `m` is used; above it the
/// curvature-matched one.
const PERTURBATIVE_M: f64 = 0.25;

/// The start of the iteration for `F(u) = x`.
///
/// With `m = k mu`, `F(u) = A e^u + B e^{-q u} - 1` (`A + B = 1`) expands to first order as
/// `cosh u - 1 + m (sinh u - u e^{-u})`, so `u = u0 - m (1 - u0 e^{-u0} / sinh u0)` with
/// `u0 = acosh(1 + x)` (the flat model's root, exact at `mu = 0`). `sinh u0 = sqrt(x (x + 2))`
/// and `e^{-u0} = 1 / (1 + x + sinh u0)` come with `u0` at no further transcendental cost; the
/// start is off by `O(m^2)`, so on the rig's scenes (`m` below 0.03) one Halley step lands within
/// rounding. For larger `m` the flat root scaled to the same curvature at 0,
/// `acosh(1 + x / (A (1 + q)))`, is the better start (docs/model.md §4).
///
/// Returns the start and an upper end for the bracket: the perturbative start is within
/// rounding of the root, so the bracket starts open above (no square root spent on it); the
/// other start comes with `sqrt(2 x / A)` (`F >= A u^2 / 2`, docs/model.md §4).
fn start<T: Real>(shape: &Shape<T>, x: T) -> (T, T) {
    // m / s, which is m to second order.
    let m = T::TWO * shape.a_coef - T::ONE;
    if m < T::from_f64(PERTURBATIVE_M) {
        let (u0, w) = acosh_1p_parts(x, T::ONE);
        let decay = if w > T::ZERO {
            u0 / ((T::ONE + x + w) * w)
        } else {
            T::ONE
        };
        ((u0 - m * (T::ONE - decay)).max(T::ZERO), T::INFINITY)
    } else {
        let upper = (T::TWO * x / shape.a_coef).sqrt();
        let u = acosh_1p_ratio(x, shape.a_coef * (T::ONE + shape.q)).min(upper);
        (u, upper)
    }
}

/// The root `u = l1 T` of `F(u) = x`, with `F` of [`Shape::eval`], and `expm1(-q u)` at the root
/// (for the exit velocity's identity in [`residence`]).
///
/// `F` is convex and increasing with `F'(0) = 0`. Every iterate is clamped to a bracket of the
/// root (from [`start`]), which shrinks as each evaluation tells on which side its point lies.
///
/// Each step is Halley's, `d / (1 - d F'' / (2 F'))` with the Newton step `d = (F - x) / F'`
/// (the derivatives come with `F` from the same two exponentials). Its error is `C h^3` with
/// `C = F''' / (6 F') - (F'' / (2 F'))^2`: we stop when that is below a quarter of an ulp of `u`.
/// Far from the root (`d F'' / F'` not small) it takes Newton's step; where `F` is a factor off
/// `x` with `u > 1`, `F` behaves like `A e^u` and we step by `ln(x / F)` (`F <= A e^u`,
/// docs/model.md §4's `ln((1 + x) / A)` bound). An iteration that has not converged is an
/// error, never a result.
pub(crate) fn solve_u<T: Real>(shape: &Shape<T>, x: T) -> Result<(T, T), SceneError> {
    let mut lower = T::ZERO;
    let (mut u, mut upper) = start(shape, x);
    let far = T::from_f64(4.0);
    let quarter_ulp = T::from_f64(0.25) * T::EPSILON;
    for _ in 0..MAX_NEWTON {
        let e = shape.eval_parts(u);
        let (f, fp, fpp) = (e.f, e.fp, e.fpp);
        // F and F' are below F'' + 1 (both exponentials enter F'' with positive weights), so
        // a finite F'' vouches for all three.
        if !fpp.is_finite() {
            return Err(SceneError::OutOfRange);
        }
        if fp <= T::ZERO {
            // Only at u = 0, i.e. x = 0 (R - ri underflowed against ri - a): T = 0.
            return Ok((u, e.decay_m1));
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
        let half_curv = fpp / (T::TWO * fp);
        let bend = d * half_curv;
        let halley = bend.abs() < T::HALF;
        let step = if halley { d / (T::ONE - bend) } else { d };
        let next = (u - step).max(lower).min(upper);
        let converged = if halley {
            let c = (e.fppp / (T::from_f64(6.0) * fp) - half_curv * half_curv).abs();
            c * step * step * step.abs() <= quarter_ulp * next
        } else {
            fpp * d * d <= T::HALF * T::EPSILON * fp * next
        };
        if converged {
            // expm1(-q next) from expm1(-q u): e^{-q next} = e^{-q u} e^{-q (next - u)}, the
            // last factor to third order (the step is below eps^(1/3) u).
            let z = -shape.q * (next - u);
            let em1 = z * (T::ONE + z * (T::HALF + z * T::from_f64(1.0 / 6.0)));
            return Ok((next, e.decay_m1 + (T::ONE + e.decay_m1) * em1));
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
    // The caller checks that these are finite.
    Ok(Exit {
        time: u / l1,
        radial: l1 * den_fp,
        condition: condition(kx, a, ri),
    })
}

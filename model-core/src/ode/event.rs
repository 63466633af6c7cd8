//! Event location: where, inside a step, does the interpolant of `r` reach the rim?
//!
//! Taking "the step where r > R" would give T only to within a step (first order in h whatever
//! the method's order); the interpolant keeps the method's order.

use crate::Real;

/// The `theta` in `[0, 1]` where `p(theta) = target`, given `p(0) < target <= p(1)`; `p`
/// returns the value and its derivative. Newton safeguarded by bisection on the bracket;
/// at most 60 iterations (bisection alone would reach any precision in that many).
pub(crate) fn locate<T: Real>(p: impl Fn(T) -> (T, T), target: T) -> T {
    let (mut lo, mut hi) = (T::ZERO, T::ONE);
    let (p0, _) = p(T::ZERO);
    let (p1, _) = p(T::ONE);
    // Start at the secant's crossing.
    let mut theta = ((target - p0) / (p1 - p0)).max(T::ZERO).min(T::ONE);
    let tol = T::from_f64(4.0) * T::EPSILON;
    let value_tol = T::TWO * T::EPSILON * target.abs();
    for _ in 0..60 {
        let (value, slope) = p(theta);
        let g = value - target;
        // At the target to rounding: a Newton step would only move within the noise of `g`
        // (when the slope is small, well beyond `tol`).
        if g.abs() <= value_tol {
            return theta;
        }
        if g < T::ZERO {
            lo = theta;
        } else {
            hi = theta;
        }
        let newton = theta - g / slope;
        // Converged: the Newton step is within rounding. (Tested before the bracket: at the
        // root `theta` is one end of the bracket and the step would be taken for leaving it,
        // halving a wide bracket for up to 50 iterations.)
        if slope > T::ZERO && (newton - theta).abs() <= tol {
            return newton.max(lo).min(hi);
        }
        let next = if slope > T::ZERO && newton > lo && newton < hi {
            newton
        } else {
            T::HALF * (lo + hi)
        };
        if (next - theta).abs() <= tol || hi - lo <= tol {
            return next;
        }
        theta = next;
    }
    theta
}

/// Cubic Hermite on `[0, 1]` through `(y0, d0)` and `(y1, d1)` (derivatives per unit theta):
/// value and derivative at `theta`.
pub(crate) fn hermite<T: Real>(y0: T, d0: T, y1: T, d1: T, theta: T) -> (T, T) {
    let t = theta;
    let t2 = t * t;
    let t3 = t2 * t;
    let three = T::from_f64(3.0);
    let h00 = T::TWO * t3 - three * t2 + T::ONE;
    let h10 = t3 - T::TWO * t2 + t;
    let h01 = three * t2 - T::TWO * t3;
    let h11 = t3 - t2;
    let six = T::from_f64(6.0);
    let dh00 = six * (t2 - t);
    let dh10 = three * t2 - T::from_f64(4.0) * t + T::ONE;
    let dh11 = three * t2 - T::TWO * t;
    (
        h00 * y0 + h10 * d0 + h01 * y1 + h11 * d1,
        dh00 * (y0 - y1) + dh10 * d0 + dh11 * d1,
    )
}

/// Quintic Hermite on `[0, 1]` through values, first and second derivatives (per unit theta)
/// at both ends: value and derivative at `theta`. Its interpolation error is `O(h^6)`, so the
/// crossing it locates adds nothing of RK4's order to `T`: with the cubic, the crossing's
/// error was of RK4's own order `h^4` and varied with where in the step the rim fell, which made
/// RK4's error in `T` wander about `C h^4` and the chooser's prediction miss by up to 1.75x.
#[allow(clippy::too_many_arguments)]
pub(crate) fn hermite5<T: Real>(y0: T, d0: T, s0: T, y1: T, d1: T, s1: T, theta: T) -> (T, T) {
    let t = theta;
    let t2 = t * t;
    let t3 = t2 * t;
    let t4 = t3 * t;
    let t5 = t4 * t;
    let c = T::from_f64;
    // Basis for y1 (the one for y0 is 1 minus it) and its derivative.
    let h5 = c(10.0) * t3 - c(15.0) * t4 + c(6.0) * t5;
    let dh5 = c(30.0) * (t2 - T::TWO * t3 + t4);
    let h1 = t - c(6.0) * t3 + c(8.0) * t4 - c(3.0) * t5;
    let dh1 = T::ONE - c(18.0) * t2 + c(32.0) * t3 - c(15.0) * t4;
    let h2 = T::HALF * (t2 - c(3.0) * t3 + c(3.0) * t4 - t5);
    let dh2 = T::HALF * (T::TWO * t - c(9.0) * t2 + c(12.0) * t3 - c(5.0) * t4);
    let h3 = T::HALF * (t3 - T::TWO * t4 + t5);
    let dh3 = T::HALF * (c(3.0) * t2 - c(8.0) * t3 + c(5.0) * t4);
    let h4 = -c(4.0) * t3 + c(7.0) * t4 - c(3.0) * t5;
    let dh4 = -c(12.0) * t2 + c(28.0) * t3 - c(15.0) * t4;
    (
        y0 + (y1 - y0) * h5 + d0 * h1 + s0 * h2 + s1 * h3 + d1 * h4,
        (y1 - y0) * dh5 + d0 * dh1 + s0 * dh2 + s1 * dh3 + d1 * dh4,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Crossings inside a step, as RK4 hands them over (r, h v at both ends): the root is the
    /// one plain bisection finds (100 halvings, independent of Newton) to within what rounding
    /// of `r` moves it, and Newton gets there in a few evaluations. Before the convergence test
    /// came first, a converged Newton step that landed on the bracket's end was taken for
    /// leaving it: 34 and 51 iterations of bisection on two of these.
    #[test]
    fn the_crossing_is_found_in_a_few_newton_steps() {
        for (r0, v0, r1, v1, h) in [
            (0.09, 0.3, 0.105, 0.32, 0.05),
            (0.099, 0.3, 0.1001, 0.3, 0.01),
            (0.05, 0.1, 0.12, 0.4, 0.3),
            (0.0999, 0.01, 0.1002, 0.012, 0.02),
        ] {
            let calls = core::cell::Cell::new(0u32);
            let p = |th: f64| {
                calls.set(calls.get() + 1);
                hermite(r0, h * v0, r1, h * v1, th)
            };
            let theta = locate(p, 0.1);
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            for _ in 0..100 {
                let mid = 0.5 * (lo + hi);
                if hermite(r0, h * v0, r1, h * v1, mid).0 < 0.1 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            // Within what rounding of r (a few units of 0.1) moves the root.
            let slope = hermite(r0, h * v0, r1, h * v1, lo).1;
            let within = 8.0 * f64::EPSILON * (1.0 + 0.1 / slope);
            assert!((theta - lo).abs() <= within, "{theta} vs {lo}");
            assert!(calls.get() <= 8, "{} evaluations on {r0} {r1}", calls.get());
        }
    }
}

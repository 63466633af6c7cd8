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
    for _ in 0..60 {
        let (value, slope) = p(theta);
        let g = value - target;
        if g < T::ZERO {
            lo = theta;
        } else {
            hi = theta;
        }
        let newton = theta - g / slope;
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

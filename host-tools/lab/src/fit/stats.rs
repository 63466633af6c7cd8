//! One-parameter nonlinear least squares for the effective rolling resistance `mu`, with the
//! timing noise Gaussian of unknown standard deviation:
//!
//! * estimate: the `mu` that minimises the sum of squared residence-time errors `S(mu)` (the
//!   maximum-likelihood estimate once sigma is profiled out);
//! * 95 % interval: `{mu : S(mu) <= S_min (1 + t^2 / (n - 1))}`, `t` the 97.5 % quantile of
//!   Student's t with `n - 1` degrees of freedom. This is the profile-likelihood interval in its
//!   small-sample form (the F form of the likelihood-ratio region for one parameter with sigma
//!   unknown; exact when the model is linear in `mu`, Bates and Watts 1988, sec. 6.1); with the
//!   chi-square form `n ln(S/S_min) <= 3.84` it would undercover at ten runs;
//! * AIC: `n ln(S/n) + 2 k` with `k = 2` (mu and sigma).

/// Student's t 97.5 % quantile for `dof` degrees of freedom: the Cornish-Fisher expansion of
/// t in the normal quantile (Abramowitz and Stegun 26.7.5) to the fourth term, exact values
/// below 5 degrees of freedom (where the expansion is poor). Error under 1e-3 for dof >= 5.
pub fn t_quantile_975(dof: usize) -> f64 {
    const SMALL: [f64; 5] = [f64::INFINITY, 12.706, 4.303, 3.182, 2.776];
    if dof < SMALL.len() {
        return SMALL[dof];
    }
    let z: f64 = 1.959_963_984_540_054;
    let n = dof as f64;
    let (z3, z5, z7, z9) = (z.powi(3), z.powi(5), z.powi(7), z.powi(9));
    z + (z3 + z) / (4.0 * n)
        + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * n * n)
        + (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / (384.0 * n.powi(3))
        + (79.0 * z9 + 776.0 * z7 + 1482.0 * z5 - 1920.0 * z3 - 945.0 * z) / (92_160.0 * n.powi(4))
}

/// Minimises `f` on `[lo, hi]`: a grid of `GRID` points, then golden-section search in the
/// two cells around the best grid point. `f` may be infinite (a `mu` at which some run never
/// leaves); it must be unimodal within the bracket found, which holds for `S(mu)` because every
/// predicted time increases with `mu`.
pub fn minimise(f: &dyn Fn(f64) -> f64, lo: f64, hi: f64) -> f64 {
    const GRID: usize = 60;
    let at = |i: usize| lo + (hi - lo) * i as f64 / GRID as f64;
    let best = (0..=GRID)
        .map(|i| (i, f(at(i))))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(0, |(i, _)| i);
    let (mut a, mut b) = (at(best.saturating_sub(1)), at((best + 1).min(GRID)));
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    let mut c = b - phi * (b - a);
    let mut d = a + phi * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..80 {
        if fc <= fd {
            b = d;
            d = c;
            fd = fc;
            c = b - phi * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + phi * (b - a);
            fd = f(d);
        }
        if b - a <= 1e-12 * (1.0 + a.abs()) {
            break;
        }
    }
    let x = 0.5 * (a + b);
    // The grid point can beat the refined one when S is flat or one-sided at an end.
    if f(at(best)) < f(x) { at(best) } else { x }
}

/// The point in `[inside, outside]` where `f` crosses `level`, given `f(inside) <= level <
/// f(outside)` (bisection, 60 halvings).
pub fn crossing(f: &dyn Fn(f64) -> f64, level: f64, mut inside: f64, mut outside: f64) -> f64 {
    for _ in 0..60 {
        let mid = 0.5 * (inside + outside);
        if f(mid) <= level {
            inside = mid;
        } else {
            outside = mid;
        }
    }
    0.5 * (inside + outside)
}

/// Smallest sum of squares the AIC uses: the gate's resolution, 1 microsecond, per run, so an
/// exact fit of noise-free data gives a finite AIC.
pub const SSE_FLOOR_S2_PER_RUN: f64 = 1e-12;

/// AIC of a least-squares fit with Gaussian errors of unknown sigma, `k` = fitted parameters
/// including sigma.
pub fn aic(sse_s2: f64, n: usize, k: usize) -> f64 {
    let n_f = n as f64;
    n_f * (sse_s2.max(SSE_FLOOR_S2_PER_RUN * n_f) / n_f).ln() + 2.0 * k as f64
}

/// AIC difference beyond which a model is preferred. With equal parameter counts the
/// difference is `n ln(S_other / S_this)`; when the two models' predictions differ by a vector
/// `d` (in units of sigma, `D = |d|`) it is about `(2 e.d - D^2)` for the true model's noise `e`,
/// so the chance that the wrong model wins by more than `delta` is `P(Z > (delta + D^2)/(2 D))`,
/// largest at `D = sqrt(delta)`: `P(Z > sqrt(delta))`. At 10 that is 0.08 % (the
/// "essentially no support" level of Burnham and Anderson 2002, sec. 2.6); the right model
/// wins with probability above 98 % once `D >= 6`.
pub const AIC_DECISIVE: f64 = 10.0;

#[cfg(test)]
mod tests {
    use super::*;

    /// Against tabulated t quantiles (Abramowitz and Stegun, Table 26.10).
    #[test]
    fn t_quantiles() {
        for (dof, want) in [
            (5, 2.571),
            (9, 2.262),
            (19, 2.093),
            (39, 2.023),
            (120, 1.980),
        ] {
            let got = t_quantile_975(dof);
            assert!((got - want).abs() < 2e-3, "dof {dof}: {got} vs {want}");
        }
    }

    #[test]
    fn minimise_and_crossing_find_a_parabola() {
        let f = |x: f64| (x - 0.0312).powi(2) + 1.0;
        let x = minimise(&f, 0.0, 0.1);
        // A smooth minimum is located to about sqrt(epsilon) relative: f changes by x^2 there.
        assert!((x - 0.0312).abs() < 1e-7, "{x}");
        let c = crossing(&f, 1.0 + 1e-4, 0.0312, 0.1);
        assert!((c - 0.0412).abs() < 1e-9, "{c}");
        // An infinite wall at the top of the range does not disturb it.
        let g = |x: f64| if x > 0.05 { f64::INFINITY } else { f(x) };
        assert!((minimise(&g, 0.0, 0.06) - 0.0312).abs() < 1e-7);
    }
}

//! When static friction lets go: a particle at rest at `ri` is held while `ri omega(t)^2 <=
//! mu g` (paper Eq. 5 and 9 with the hold of docs/model.md) and moves from the first time the
//! push exceeds friction. The right-hand side has a kink there (zero before, growing after), and
//! a fixed-step method that steps across it loses its order: its error then jumps with where the
//! kink falls inside a step, non-monotone in the step (the chooser's "lucky cancellations").
//! Integrating from the release time instead makes the solution smooth on every step.

use super::OmegaProfile;
use crate::Real;

/// Bisections of the crossing: enough to reach rounding from any scan interval.
const BISECTIONS: u32 = 64;

/// The first time in `[0, horizon_s]` at which `omega(t)` is above `threshold_rad_s` (or not a
/// valid speed, so that the integration starts there and reports it), by a scan at
/// `scan_step_s` and bisection of the first interval that crosses; `None` when it stays at or
/// below the threshold. Profiles with a closed form override
/// [`OmegaProfile::first_time_above_s`] instead.
pub fn scan_first_time_above<T: Real, P: OmegaProfile<T> + ?Sized>(
    profile: &P,
    threshold_rad_s: T,
    horizon_s: T,
    scan_step_s: T,
) -> Option<T> {
    let above = |t: T| {
        let w = profile.omega_rad_s(t);
        !(w.is_nonneg_finite() && w <= threshold_rad_s)
    };
    if above(T::ZERO) {
        return Some(T::ZERO);
    }
    if !(scan_step_s > T::ZERO && scan_step_s.is_finite() && horizon_s.is_finite()) {
        return None;
    }
    let mut k = 0.0f64;
    let mut before = T::ZERO;
    loop {
        k += 1.0;
        // From the count, not a running sum, so round-off does not accumulate.
        let t = (scan_step_s * T::from_f64(k)).min(horizon_s);
        if above(t) {
            // The crossing lies in (before, t]: bisect to rounding.
            let (mut lo, mut hi) = (before, t);
            for _ in 0..BISECTIONS {
                let mid = lo + (hi - lo) * T::HALF;
                if mid <= lo || mid >= hi {
                    break;
                }
                if above(mid) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            return Some(hi);
        }
        if t >= horizon_s {
            return None;
        }
        before = t;
    }
}

/// The release time of a particle at rest at `ri_m` with friction `mu_g` (`mu g`, m/s^2):
/// the first time `ri omega^2 > mu g`, 0 when it is already so, `None` when it never is by
/// the horizon.
pub(crate) fn release_time_s<T: Real, P: OmegaProfile<T>>(
    profile: &P,
    ri_m: T,
    mu_g: T,
    horizon_s: T,
    scan_step_s: T,
) -> Option<T> {
    if ri_m <= T::ZERO {
        // No push at the centre: the hold decides at every step, as before any release.
        return Some(T::ZERO);
    }
    let w0 = profile.omega_rad_s(T::ZERO);
    if !(w0.is_nonneg_finite()) || ri_m * w0 * w0 > mu_g {
        return Some(T::ZERO);
    }
    let threshold = (mu_g / ri_m).sqrt();
    let t = profile.first_time_above_s(threshold, horizon_s, scan_step_s)?;
    // The closed forms and the bisection land within rounding of the crossing; step past it so
    // that the hold's own test (the same product as the right-hand side's) lets go at the start.
    let mut t = t;
    for _ in 0..4 {
        let w = profile.omega_rad_s(t);
        if !w.is_nonneg_finite() || ri_m * w * w > mu_g || t >= horizon_s {
            break;
        }
        t = (t + (t.abs() + T::ONE) * T::EPSILON * T::from_f64(4.0)).min(horizon_s);
    }
    Some(t)
}

//! The spread of `T` over the parameters' uncertainty: each parameter at both ends of its
//! range, the others nominal, and the sum of the larger relative changes (a first-order worst
//! case). The chooser's tolerance is a tenth of it.

use super::run;
use crate::Real;
use crate::ode::{Limits, Method, OmegaProfile};
use crate::particle::{Model, Scene};

use super::Knowledge;

/// The perturbed scenes: each parameter at both ends of its range, the others nominal.
pub(super) fn perturbations<T: Real>(s: &Scene<T>, k: &Knowledge<T>) -> [Scene<T>; 8] {
    let lo = |x: T, rel: T| (x * (T::ONE - rel)).max(T::ZERO);
    [
        Scene {
            mu: lo(s.mu, k.mu_rel),
            ..*s
        },
        Scene {
            mu: s.mu * (T::ONE + k.mu_rel),
            ..*s
        },
        Scene {
            ri_m: (s.ri_m - k.radius_m).max(T::ZERO),
            ..*s
        },
        Scene {
            ri_m: s.ri_m + k.radius_m,
            ..*s
        },
        Scene {
            rim_radius_m: (s.rim_radius_m - k.radius_m).max(T::ZERO),
            ..*s
        },
        Scene {
            rim_radius_m: s.rim_radius_m + k.radius_m,
            ..*s
        },
        Scene {
            omega_rad_s: lo(s.omega_rad_s, k.omega_rel),
            ..*s
        },
        Scene {
            omega_rad_s: s.omega_rad_s * (T::ONE + k.omega_rel),
            ..*s
        },
    ]
}

/// Sum over parameters of the larger relative change of `T` at either end of its range.
pub(super) fn spread<T: Real>(nominal: T, times: &[T; 8]) -> T {
    let mut sum = T::ZERO;
    for pair in times.chunks(2) {
        let d0 = (pair[0] - nominal).abs();
        let d1 = (pair[1] - nominal).abs();
        sum += d0.max(d1) / nominal;
    }
    if sum.is_finite() { sum } else { T::INFINITY }
}

/// The spread of `T` over the parameters' uncertainty (see [`spread`]) from runs of `method`
/// on the Coriolis model, the nominal scene's included (so that the runs' common error
/// cancels), and the evaluations they took.
pub(super) fn spread_at<T: Real, P: OmegaProfile<T>>(
    scene: &Scene<T>,
    knowledge: &Knowledge<T>,
    profile: &P,
    method: Method<T>,
    limits: Limits<T>,
) -> (T, u32) {
    let (nominal, mut evaluations) = match run(scene, Model::Coriolis, profile, method, limits) {
        Ok(found) => found,
        Err(_) => return (T::INFINITY, 0),
    };
    let mut times = [T::ZERO; 8];
    let up = T::ONE + knowledge.omega_rel;
    let down = (T::ONE - knowledge.omega_rel).max(T::ZERO);
    for (i, (slot, s)) in times
        .iter_mut()
        .zip(perturbations(scene, knowledge).iter())
        .enumerate()
    {
        // omega's uncertainty scales the whole profile (entries 6 and 7).
        let factor = match i {
            6 => down,
            7 => up,
            _ => T::ONE,
        };
        let scaled = ScaledProfile {
            inner: profile,
            factor,
        };
        *slot = match run(s, Model::Coriolis, &scaled, method, limits) {
            Ok((t, evals)) => {
                evaluations = evaluations.saturating_add(evals);
                t
            }
            Err(_) => T::INFINITY,
        };
    }
    (spread(nominal, &times), evaluations)
}

/// A profile scaled by a constant factor (omega's relative uncertainty).
struct ScaledProfile<'a, T, P> {
    inner: &'a P,
    factor: T,
}

impl<T: Real, P: OmegaProfile<T>> OmegaProfile<T> for ScaledProfile<'_, T, P> {
    fn omega_rad_s(&self, t_s: T) -> T {
        self.inner.omega_rad_s(t_s) * self.factor
    }
    fn max_omega_rad_s(&self) -> T {
        self.inner.max_omega_rad_s() * self.factor
    }
    fn is_constant(&self) -> bool {
        self.inner.is_constant()
    }
    fn is_smooth(&self) -> bool {
        self.inner.is_smooth()
    }
    fn next_kink_after_s(&self, t_s: T) -> Option<T> {
        self.inner.next_kink_after_s(t_s)
    }
    fn time_scale_s(&self) -> T {
        self.inner.time_scale_s()
    }
}

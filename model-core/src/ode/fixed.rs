//! Fixed-step methods: explicit Euler, semi-implicit Euler, RK4; the crossing of the rim located
//! by quintic Hermite interpolation of `r` (with `r'` and `r''` at both ends: error `O(h^6)`,
//! below RK4's own), the exit speed by cubic Hermite interpolation of `r'` (with `r''`).

use super::event::{hermite, hermite5, locate};
use super::{Limits, OdeError, OdeOutcome, OmegaProfile, Report, Rhs, leaves};
use crate::Real;
use crate::particle::Scene;

/// Which fixed-step scheme.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scheme {
    Euler,
    SemiImplicit,
    Rk4,
}

impl Scheme {
    /// Largest stable `h |lambda|` on the negative real axis (None: unconditionally stable).
    fn stability_limit(self) -> Option<f64> {
        match self {
            Scheme::Euler => Some(2.0),
            Scheme::SemiImplicit => None,
            // The real-axis extent of RK4's stability region, 2.7853.
            Scheme::Rk4 => Some(2.785),
        }
    }
}

pub(crate) fn run<T: Real, P: OmegaProfile<T>>(
    rhs: &mut Rhs<'_, T, P>,
    scene: &Scene<T>,
    scheme: Scheme,
    h: T,
    stiff_rate: T,
    limits: Limits<T>,
    t_start: T,
) -> Result<Report<T>, OdeError> {
    if !(h > T::ZERO && h.is_finite()) {
        return Err(OdeError::InvalidStep);
    }
    if let Some(limit) = scheme.stability_limit()
        && h * stiff_rate > T::from_f64(limit)
    {
        return Err(OdeError::BeyondStabilityLimit);
    }
    let rim = scene.rim_radius_m;
    let (mut r, mut v) = (scene.ri_m, T::ZERO);
    let mut steps: u32 = 0;
    while steps < limits.max_steps {
        // t from the step count, not a running sum, so round-off does not accumulate.
        let t = t_start + h * T::from_f64(steps as f64);
        if t >= limits.horizon_s {
            return Ok(Report {
                outcome: OdeOutcome::NotLeftBy {
                    horizon_s: limits.horizon_s,
                    radius_m: r,
                },
                rhs_evaluations: rhs.evaluations,
                steps,
                rejected_steps: 0,
            });
        }
        let (_, a0) = rhs.eval(t, r, v)?;
        let (r1, v1) = match scheme {
            Scheme::Euler => (r + h * v, v + h * a0),
            Scheme::SemiImplicit => {
                // v first with the friction term implicit, then r with the new v.
                let w = rhs.omega(t)?;
                let push = r * w * w;
                if v <= T::ZERO && push <= rhs.mu_g {
                    (r, T::ZERO)
                } else {
                    let v1 = (v + h * rhs.k2 * (push - rhs.mu_g))
                        / (T::ONE + h * rhs.k2 * rhs.two_mu_c * w);
                    (r + h * v1, v1)
                }
            }
            Scheme::Rk4 => {
                let half = T::HALF * h;
                let (dr1, dv1) = (v, a0);
                let (dr2, dv2) = rhs.eval(t + half, r + half * dr1, v + half * dv1)?;
                let (dr3, dv3) = rhs.eval(t + half, r + half * dr2, v + half * dv2)?;
                let (dr4, dv4) = rhs.eval(t + h, r + h * dr3, v + h * dv3)?;
                let sixth = h / T::from_f64(6.0);
                (
                    r + sixth * (dr1 + T::TWO * (dr2 + dr3) + dr4),
                    v + sixth * (dv1 + T::TWO * (dv2 + dv3) + dv4),
                )
            }
        };
        steps += 1;
        if !(r1.is_finite() && v1.is_finite()) {
            return Err(OdeError::NotFinite);
        }
        if r1 >= rim {
            let t1 = t + h;
            let (_, a1) = rhs.eval(t1, r1, v1)?;
            let h2 = h * h;
            let theta = locate(
                |th| hermite5(r, h * v, h2 * a0, r1, h * v1, h2 * a1, th),
                rim,
            );
            let (v_exit, _) = hermite(v, h * a0, v1, h * a1, theta);
            let outcome = leaves(rhs, scene, t + theta * h, v_exit)?;
            return Ok(Report {
                outcome,
                rhs_evaluations: rhs.evaluations,
                steps,
                rejected_steps: 0,
            });
        }
        r = r1;
        v = v1;
    }
    Err(OdeError::StepLimit)
}

//! Fixed-step methods: explicit Euler, semi-implicit Euler, RK4; the crossing of the rim located
//! by quintic Hermite interpolation of `r` (with `r'` and `r''` at both ends: error `O(h^6)`,
//! below RK4's own), the exit speed by cubic Hermite interpolation of `r'` (with `r''`).

use super::event::{hermite, hermite5, locate};
use super::{Crossing, Limits, SecondOrder, StepError, Stepped};
use crate::Real;

/// Where a run starts (at rest) and the value of `r` it runs to.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Start<T> {
    pub t_s: T,
    pub r: T,
    pub target: T,
}

/// The run's end at the horizon (both methods), with `r` there.
pub(crate) fn at_horizon<T>(r: T, steps: u32, rejected_steps: u32) -> Stepped<T> {
    Stepped {
        ended: Crossing::Horizon { r },
        steps,
        rejected_steps,
    }
}

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

pub(crate) fn run<T: Real, S: SecondOrder<T>>(
    equation: &mut S,
    scheme: Scheme,
    h: T,
    stiff_rate: T,
    limits: Limits<T>,
    start: Start<T>,
) -> Result<Stepped<T>, StepError> {
    if !(h > T::ZERO && h.is_finite()) {
        return Err(StepError::InvalidStep);
    }
    if let Some(limit) = scheme.stability_limit()
        && h * stiff_rate > T::from_f64(limit)
    {
        return Err(StepError::BeyondStabilityLimit);
    }
    let (t_start, rim) = (start.t_s, start.target);
    let (mut r, mut v) = (start.r, T::ZERO);
    let mut steps: u32 = 0;
    while steps < limits.max_steps {
        // t from the step count, not a running sum, so round-off does not accumulate.
        let t = t_start + h * T::from_f64(steps as f64);
        if t >= limits.horizon_s {
            return Ok(at_horizon(r, steps, 0));
        }
        let (_, a0) = equation.eval(t, r, v)?;
        let (r1, v1) = match scheme {
            Scheme::Euler => (r + h * v, v + h * a0),
            Scheme::SemiImplicit => equation.semi_implicit(t, r, v, h)?,
            Scheme::Rk4 => {
                let half = T::HALF * h;
                let (dr1, dv1) = (v, a0);
                let (dr2, dv2) = equation.eval(t + half, r + half * dr1, v + half * dv1)?;
                let (dr3, dv3) = equation.eval(t + half, r + half * dr2, v + half * dv2)?;
                let (dr4, dv4) = equation.eval(t + h, r + h * dr3, v + h * dv3)?;
                let sixth = h / T::from_f64(6.0);
                (
                    r + sixth * (dr1 + T::TWO * (dr2 + dr3) + dr4),
                    v + sixth * (dv1 + T::TWO * (dv2 + dv3) + dv4),
                )
            }
        };
        steps += 1;
        if !(r1.is_finite() && v1.is_finite()) {
            return Err(StepError::NotFinite);
        }
        if r1 >= rim {
            let t1 = t + h;
            let (_, a1) = equation.eval(t1, r1, v1)?;
            let h2 = h * h;
            let theta = locate(
                |th| hermite5(r, h * v, h2 * a0, r1, h * v1, h2 * a1, th),
                rim,
            );
            let (v_exit, _) = hermite(v, h * a0, v1, h * a1, theta);
            return Ok(Stepped {
                ended: Crossing::Reached {
                    t_s: t + theta * h,
                    v: v_exit,
                },
                steps,
                rejected_steps: 0,
            });
        }
        r = r1;
        v = v1;
    }
    Err(StepError::StepLimit)
}

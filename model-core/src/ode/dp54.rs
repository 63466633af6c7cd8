//! Adaptive Dormand-Prince 5(4) (Dormand & Prince 1980; the step control and the 4th-order
//! dense output of Hairer, Norsett & Wanner, "Solving ODEs I", as in their DOPRI5). FSAL: six new
//! right-hand sides per step. The rim crossing is located on the dense output.

use super::event::locate;
use super::fixed::{Start, at_horizon};
use super::{Crossing, Limits, SecondOrder, StepError, Stepped};
use crate::Real;

pub(super) const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
pub(super) const A2: [f64; 1] = [1.0 / 5.0];
pub(super) const A3: [f64; 2] = [3.0 / 40.0, 9.0 / 40.0];
pub(super) const A4: [f64; 3] = [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0];
pub(super) const A5: [f64; 4] = [
    19372.0 / 6561.0,
    -25360.0 / 2187.0,
    64448.0 / 6561.0,
    -212.0 / 729.0,
];
pub(super) const A6: [f64; 5] = [
    9017.0 / 3168.0,
    -355.0 / 33.0,
    46732.0 / 5247.0,
    49.0 / 176.0,
    -5103.0 / 18656.0,
];
/// 5th-order weights (also the 7th stage's row: FSAL).
pub(super) const B: [f64; 7] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
    0.0,
];
/// 5th minus 4th order weights: the local error estimate.
pub(super) const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
/// Dense output (continuous extension of order 4).
pub(super) const D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

pub(super) fn t_of<T: Real>(x: f64) -> T {
    T::from_f64(x)
}

/// The dense-output polynomial of one component on `[0, 1]`:
/// `y(theta) = c1 + theta (c2 + (1 - theta)(c3 + theta (c4 + (1 - theta) c5)))`.
#[derive(Clone, Copy)]
pub(super) struct Dense<T> {
    c: [T; 5],
}

impl<T: Real> Dense<T> {
    pub(super) fn new(y0: T, y1: T, hk: &[T; 7]) -> Self {
        let diff = y1 - y0;
        let bspl = hk[0] - diff;
        let mut c5 = T::ZERO;
        for i in 0..7 {
            c5 += t_of::<T>(D[i]) * hk[i];
        }
        Self {
            c: [y0, diff, bspl, diff - hk[6] - bspl, c5],
        }
    }

    /// Value and derivative with respect to theta.
    pub(super) fn at(&self, th: T) -> (T, T) {
        let [c1, c2, c3, c4, c5] = self.c;
        let one_m = T::ONE - th;
        let q = c4 + one_m * c5;
        let dq = -c5;
        let p = c3 + th * q;
        let dp = q + th * dq;
        let s = c2 + one_m * p;
        let ds = one_m * dp - p;
        (c1 + th * s, s + th * ds)
    }
}

pub(crate) fn run<T: Real, S: SecondOrder<T>>(
    equation: &mut S,
    rtol: T,
    atol: T,
    stiff_rate: T,
    limits: Limits<T>,
    start: Start<T>,
) -> Result<Stepped<T>, StepError> {
    if !(rtol > T::ZERO && rtol.is_finite() && atol > T::ZERO && atol.is_finite()) {
        return Err(StepError::InvalidStep);
    }
    let rim = start.target;
    let (mut t, mut r, mut v) = (start.t_s, start.r, T::ZERO);
    // Initial step: a fifth of the tolerance's fifth root in units of the fastest time scale.
    let mut h = if stiff_rate > T::ZERO {
        T::from_f64(0.2) * rtol.ln().exp_scaled(0.2) / stiff_rate
    } else {
        limits.horizon_s * T::from_f64(1e-3)
    };
    h = h.min(limits.horizon_s);
    let (mut steps, mut rejected) = (0u32, 0u32);
    let mut k1 = equation.eval(t, r, v)?;
    while steps < limits.max_steps {
        if t >= limits.horizon_s {
            return Ok(at_horizon(r, steps, rejected));
        }
        if h <= T::EPSILON * t {
            // The step has collapsed below the time's resolution.
            return Err(StepError::StepLimit);
        }
        steps += 1;
        // A step never crosses a kink of the speed (a logged trace's samples): it ends on it,
        // so every step's error estimate sees a smooth right-hand side.
        let proposed = h;
        let clipped = match equation.next_kink_after_s(t) {
            Some(kink) if t + h > kink => {
                h = kink - t;
                true
            }
            _ => false,
        };
        let mut kr = [T::ZERO; 7];
        let mut kv = [T::ZERO; 7];
        (kr[0], kv[0]) = k1;
        let rows: [&[f64]; 5] = [&A2, &A3, &A4, &A5, &A6];
        for (s, row) in rows.iter().enumerate() {
            let (mut yr, mut yv) = (r, v);
            for (j, &a) in row.iter().enumerate() {
                yr += h * t_of::<T>(a) * kr[j];
                yv += h * t_of::<T>(a) * kv[j];
            }
            (kr[s + 1], kv[s + 1]) = equation.eval(t + t_of::<T>(C[s + 1]) * h, yr, yv)?;
        }
        let (mut r1, mut v1) = (r, v);
        for i in 0..6 {
            r1 += h * t_of::<T>(B[i]) * kr[i];
            v1 += h * t_of::<T>(B[i]) * kv[i];
        }
        let k7 = equation.eval(t + h, r1, v1)?;
        (kr[6], kv[6]) = k7;
        let (mut er, mut ev) = (T::ZERO, T::ZERO);
        for i in 0..7 {
            er += h * t_of::<T>(E[i]) * kr[i];
            ev += h * t_of::<T>(E[i]) * kv[i];
        }
        if !(r1.is_finite() && v1.is_finite() && er.is_finite() && ev.is_finite()) {
            return Err(StepError::NotFinite);
        }
        let sr = atol + rtol * r.abs().max(r1.abs());
        let sv = atol + rtol * v.abs().max(v1.abs());
        let err = ((er / sr) * (er / sr) + (ev / sv) * (ev / sv)) * T::HALF;
        let err = err.sqrt();
        let factor = step_factor(err);
        if err <= T::ONE {
            if r1 >= rim {
                let hkr = kr.map(|k| h * k);
                let hkv = kv.map(|k| h * k);
                let dr = Dense::new(r, r1, &hkr);
                let dv = Dense::new(v, v1, &hkv);
                let theta = locate(|th| dr.at(th), rim);
                let (v_exit, _) = dv.at(theta);
                return Ok(Stepped {
                    ended: Crossing::Reached {
                        t_s: t + theta * h,
                        v: v_exit,
                    },
                    steps,
                    rejected_steps: rejected,
                });
            }
            t += h;
            r = r1;
            v = v1;
            k1 = k7;
            // After a step shortened to a kink, the controller goes on from what it proposed.
            let next = h * factor;
            h = if clipped { next.max(proposed) } else { next }.min(limits.horizon_s);
        } else {
            rejected += 1;
            h *= factor.min(T::ONE);
        }
    }
    Err(StepError::StepLimit)
}

/// The step-size controller: the next step is `factor` times this one for a scaled error
/// `err`, the classic `0.9 err^(-1/5)` kept within [0.2, 5].
pub(super) fn step_factor<T: Real>(err: T) -> T {
    if err > T::ZERO {
        (T::from_f64(0.9) * err.ln().exp_scaled(-0.2))
            .max(T::from_f64(0.2))
            .min(T::from_f64(5.0))
    } else {
        T::from_f64(5.0)
    }
}

/// `exp(p * x)` for the controller's powers, on the `ln` already taken.
pub(super) trait ExpScaled {
    fn exp_scaled(self, p: f64) -> Self;
}

impl<T: Real> ExpScaled for T {
    fn exp_scaled(self, p: f64) -> Self {
        (self * T::from_f64(p)).exp()
    }
}

//! The project's integrators for a system of `N` first-order equations `y' = f(t, y)` (the
//! rolling granule of `particle::rolling`, which implements it): adaptive Dormand-Prince 5(4) with its dense
//! output (the same tableau and step control as the radial model's, `ode/dp54.rs`) and classical
//! RK4 at a fixed step with cubic Hermite interpolation (shortened where the caller grades it
//! towards a singularity of its solution: `rk4_graded`). Both stop at the first zero of an event
//! function (the rim), located on the interpolant, so `T` keeps the method's order; a check
//! after every accepted step can end the run early (lift-off, slip, a held granule).

use core::ops::ControlFlow;

use super::dp54::{A2, A3, A4, A5, A6, B, C, Dense, E, step_factor, t_of};
use super::event::{hermite, locate};
use crate::Real;

/// How a system run ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Ended<T, const N: usize, S> {
    /// The event function reached zero (from below) at `t`, with the state `y` there.
    Event {
        /// Time, s.
        t: T,
        /// State at `t`.
        y: [T; N],
    },
    /// The check after a step stopped the run.
    Stopped {
        /// Time of that step's end, s.
        t: T,
        /// State there.
        y: [T; N],
        /// Why.
        why: S,
    },
    /// The time horizon was reached first.
    Horizon {
        /// State at the horizon.
        y: [T; N],
    },
}

/// Why a system run gave no result.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SystemError {
    /// The step cap was reached before an event or the horizon.
    StepLimit,
    /// A state or error estimate was not finite.
    NotFinite,
    /// A step size or tolerance was not positive and finite.
    InvalidStep,
    /// A run watched for stalls took steps in a row that do not advance the time (the
    /// roll/slide switch stalling at a loose tolerance: `particle::rolling::modes::StallWatch`).
    Stalled,
}

/// What a run did besides its ending: its cost.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Run<T, const N: usize, S> {
    /// How it ended.
    pub ended: Ended<T, N, S>,
    /// Right-hand-side evaluations.
    pub evaluations: u32,
    /// Accepted steps.
    pub steps: u32,
}

/// The event: `(g(y), g'(y) dy)` for a state `y` and a state increment `dy` (the directional
/// derivative), so that its zero can be located on an interpolant.
pub type EventFn<T, const N: usize> = fn(&[T; N], &[T; N]) -> (T, T);

/// Limits of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SystemLimits<T> {
    /// Stop at this time, s.
    pub horizon_s: T,
    /// Stop after this many steps (accepted and rejected).
    pub max_steps: u32,
}

fn axpy<T: Real, const N: usize>(y: &[T; N], h: T, terms: &[(f64, &[T; N])]) -> [T; N] {
    let mut out = *y;
    for (a, k) in terms {
        let ha = h * t_of::<T>(*a);
        for i in 0..N {
            out[i] += ha * k[i];
        }
    }
    out
}

/// A state-only event as one of the time, the state and the step's direction.
fn on_state<T: Real, const N: usize>(
    event: EventFn<T, N>,
) -> impl Fn(T, &[T; N], T, &[T; N]) -> (T, T) {
    move |_: T, y: &[T; N], _: T, dy: &[T; N]| event(y, dy)
}

/// A run's end with what it cost.
fn run_ended<T, const N: usize, S>(
    ended: Ended<T, N, S>,
    evaluations: u32,
    steps: u32,
) -> Result<Run<T, N, S>, SystemError> {
    Ok(Run {
        ended,
        evaluations,
        steps,
    })
}

fn finite<T: Real, const N: usize>(y: &[T; N]) -> bool {
    y.iter().all(|v| v.is_finite())
}

/// Where in the step `[t, t + h]` the event reaches zero, located on the step's interpolant
/// (`component(i, theta)`: component `i`'s value and derivative per unit theta), and the
/// state there.
fn event_in_step<T: Real, const N: usize>(
    component: impl Fn(usize, T) -> (T, T),
    event: &impl Fn(T, &[T; N], T, &[T; N]) -> (T, T),
    t: T,
    h: T,
) -> (T, [T; N]) {
    let at = |th: T| -> ([T; N], [T; N]) {
        let mut v = [T::ZERO; N];
        let mut d = [T::ZERO; N];
        for i in 0..N {
            (v[i], d[i]) = component(i, th);
        }
        (v, d)
    };
    let theta = locate(
        |th| {
            let (v, d) = at(th);
            event(t + th * h, &v, h, &d)
        },
        T::ZERO,
    );
    (t + theta * h, at(theta).0)
}

/// Adaptive Dormand-Prince 5(4) from `(t0, y0)` until `event` crosses zero from below, `check`
/// breaks, or the horizon. `scale[i]` is the absolute tolerance of component `i` (a state's
/// typical size times `rtol` where it may pass through zero); `h0` the first step.
#[allow(clippy::too_many_arguments)]
pub fn dp54<T: Real, const N: usize, S>(
    f: impl FnMut(T, &[T; N]) -> [T; N],
    t0: T,
    y0: [T; N],
    rtol: T,
    atol: [T; N],
    h0: T,
    event: EventFn<T, N>,
    check: impl FnMut(T, &[T; N]) -> ControlFlow<S>,
    limits: SystemLimits<T>,
) -> Result<Run<T, N, S>, SystemError> {
    dp54_with(
        f,
        t0,
        y0,
        (rtol, atol),
        h0,
        &on_state(event),
        check,
        |_: &[T; N], _: &[T; N], _: &[T; N]| T::ZERO,
        limits,
    )
}

/// A value-only event as `(g, g')` along `(dt, dy)` (per unit theta of a step), for
/// [`dp54_with`] and [`rk4_with`]: an event that depends on the time and on the caller's data (a
/// mode switch of the granule: the friction it needs reaching what the contact gives, its slip
/// reversing), given by its value alone; the crossing is located on the interpolant as the
/// rim's is, with the slope by a central difference over `sqrt(eps)` of the step (Newton is
/// safeguarded by bisection, so an approximate slope costs iterations, not accuracy).
pub(crate) fn timed<T: Real, const N: usize>(
    g: impl Fn(T, &[T; N]) -> T,
) -> impl Fn(T, &[T; N], T, &[T; N]) -> (T, T) {
    move |t: T, y: &[T; N], dt: T, dy: &[T; N]| {
        let value = g(t, y);
        let e = T::EPSILON.sqrt();
        let shifted = |sign: T| {
            let mut ys = *y;
            for i in 0..N {
                ys[i] += sign * e * dy[i];
            }
            g(t + sign * e * dt, &ys)
        };
        let slope = (shifted(T::ONE) - shifted(-T::ONE)) / (T::TWO * e);
        (value, slope)
    }
}

/// [`dp54`] with an event of the time, the state and the step's direction (as [`timed`] makes),
/// and a further error measure `extra(e, y, y1)` of a step from `y` to `y1` with the error
/// estimate `e` (already divided by its tolerance, 0 for none): the step is accepted where both
/// it and the components' error norm are within 1, and its size follows the larger.
#[allow(clippy::too_many_arguments)]
pub(crate) fn dp54_with<T: Real, const N: usize, S>(
    mut f: impl FnMut(T, &[T; N]) -> [T; N],
    t0: T,
    y0: [T; N],
    (rtol, atol): (T, [T; N]),
    h0: T,
    event: &impl Fn(T, &[T; N], T, &[T; N]) -> (T, T),
    mut check: impl FnMut(T, &[T; N]) -> ControlFlow<S>,
    extra: impl Fn(&[T; N], &[T; N], &[T; N]) -> T,
    limits: SystemLimits<T>,
) -> Result<Run<T, N, S>, SystemError> {
    if !(rtol > T::ZERO && rtol.is_finite() && h0 > T::ZERO && h0.is_finite()) {
        return Err(SystemError::InvalidStep);
    }
    let (mut t, mut y, mut h) = (t0, y0, h0.min(limits.horizon_s - t0));
    let mut evaluations = 1u32;
    let mut steps = 0u32;
    let mut k1 = f(t, &y);
    while steps < limits.max_steps {
        if t >= limits.horizon_s {
            return run_ended(Ended::Horizon { y }, evaluations, steps);
        }
        if h <= T::EPSILON * t.abs() {
            return Err(SystemError::StepLimit);
        }
        steps += 1;
        let mut k = [[T::ZERO; N]; 7];
        k[0] = k1;
        let rows: [&[f64]; 5] = [&A2, &A3, &A4, &A5, &A6];
        for (s, row) in rows.iter().enumerate() {
            let mut yi = y;
            for (j, &a) in row.iter().enumerate() {
                let ha = h * t_of::<T>(a);
                for i in 0..N {
                    yi[i] += ha * k[j][i];
                }
            }
            k[s + 1] = f(t + t_of::<T>(C[s + 1]) * h, &yi);
        }
        let mut y1 = y;
        for (s, &b) in B.iter().enumerate().take(6) {
            let hb = h * t_of::<T>(b);
            for i in 0..N {
                y1[i] += hb * k[s][i];
            }
        }
        k[6] = f(t + h, &y1);
        evaluations += 6;
        let mut err2 = T::ZERO;
        let mut errs = [T::ZERO; N];
        for i in 0..N {
            let mut e = T::ZERO;
            for s in 0..7 {
                e += h * t_of::<T>(E[s]) * k[s][i];
            }
            errs[i] = e;
            let sc = atol[i] + rtol * y[i].abs().max(y1[i].abs());
            err2 += (e / sc) * (e / sc);
        }
        let more = extra(&errs, &y, &y1);
        if !(finite(&y1) && err2.is_finite() && more.is_finite()) {
            return Err(SystemError::NotFinite);
        }
        let err = (err2 / T::from_f64(N as f64)).sqrt().max(more);
        let factor = step_factor(err);
        if err > T::ONE {
            h *= factor.min(T::ONE);
            continue;
        }
        let (g1, _) = event(t + h, &y1, T::ZERO, &[T::ZERO; N]);
        if g1 >= T::ZERO {
            let dense: [Dense<T>; N] = core::array::from_fn(|i| {
                let hk: [T; 7] = core::array::from_fn(|s| h * k[s][i]);
                Dense::new(y[i], y1[i], &hk)
            });
            let (te, ye) = event_in_step(|i, th| dense[i].at(th), event, t, h);
            return run_ended(Ended::Event { t: te, y: ye }, evaluations, steps);
        }
        // The step to the horizon ends on it: `t + (horizon - t)` can round to one below it, and
        // the step left, one rounding long, is below the time's resolution (a give-up).
        t = if h >= limits.horizon_s - t {
            limits.horizon_s
        } else {
            t + h
        };
        y = y1;
        k1 = k[6];
        if let ControlFlow::Break(why) = check(t, &y) {
            return run_ended(Ended::Stopped { t, y, why }, evaluations, steps);
        }
        h = (h * factor).min(limits.horizon_s - t).max(T::EPSILON * t);
    }
    Err(SystemError::StepLimit)
}

/// Classical RK4 at the fixed step `h` from `(t0, y0)`, the event located on the cubic Hermite
/// interpolant of each component (its slopes are the right-hand sides at the step's ends).
pub fn rk4<T: Real, const N: usize, S>(
    f: impl FnMut(T, &[T; N]) -> [T; N],
    t0: T,
    y0: [T; N],
    h: T,
    event: EventFn<T, N>,
    check: impl FnMut(T, &[T; N]) -> ControlFlow<S>,
    limits: SystemLimits<T>,
) -> Result<Run<T, N, S>, SystemError> {
    rk4_with(f, t0, y0, h, &on_state(event), check, limits)
}

/// [`rk4`] with an event of the time, the state and the step's direction (as [`timed`] makes).
pub(crate) fn rk4_with<T: Real, const N: usize, S>(
    f: impl FnMut(T, &[T; N]) -> [T; N],
    t0: T,
    y0: [T; N],
    h: T,
    event: &impl Fn(T, &[T; N], T, &[T; N]) -> (T, T),
    check: impl FnMut(T, &[T; N]) -> ControlFlow<S>,
    limits: SystemLimits<T>,
) -> Result<Run<T, N, S>, SystemError> {
    rk4_graded(f, t0, y0, h, |_, _, _| h, event, check, limits)
}

/// [`rk4_with`] whose step from `(t, y)` with the slope `y'` there is `step(t, y, y')` where
/// that is shorter than `h` (a segment that ends at a singularity of its solution grades its
/// steps down to it: a slide's end, `particle::rolling::modes`); `h` elsewhere.
#[allow(clippy::too_many_arguments)]
pub(crate) fn rk4_graded<T: Real, const N: usize, S>(
    mut f: impl FnMut(T, &[T; N]) -> [T; N],
    t0: T,
    y0: [T; N],
    h: T,
    step: impl Fn(T, &[T; N], &[T; N]) -> T,
    event: &impl Fn(T, &[T; N], T, &[T; N]) -> (T, T),
    mut check: impl FnMut(T, &[T; N]) -> ControlFlow<S>,
    limits: SystemLimits<T>,
) -> Result<Run<T, N, S>, SystemError> {
    if !(h > T::ZERO && h.is_finite()) {
        return Err(SystemError::InvalidStep);
    }
    let (mut t, mut y) = (t0, y0);
    // The time as `anchor + n h`, not a running sum: no rounding accumulates in it. A shortened
    // step moves the anchor to its end.
    let (mut anchor, mut n) = (t0, 0u32);
    let mut evaluations = 1u32;
    let mut steps = 0u32;
    let mut k1 = f(t, &y);
    let half = T::HALF;
    while steps < limits.max_steps {
        if t >= limits.horizon_s {
            return run_ended(Ended::Horizon { y }, evaluations, steps);
        }
        steps += 1;
        let graded = step(t, &y, &k1);
        // A step below the time's resolution would not advance it.
        let floor = T::from_f64(16.0) * T::EPSILON * t.abs();
        let hs = if graded < h && graded.is_finite() {
            graded.max(floor)
        } else {
            h
        };
        let k2 = f(t + half * hs, &axpy(&y, hs, &[(0.5, &k1)]));
        let k3 = f(t + half * hs, &axpy(&y, hs, &[(0.5, &k2)]));
        let k4 = f(t + hs, &axpy(&y, hs, &[(1.0, &k3)]));
        let y1 = axpy(
            &y,
            hs,
            &[
                (1.0 / 6.0, &k1),
                (1.0 / 3.0, &k2),
                (1.0 / 3.0, &k3),
                (1.0 / 6.0, &k4),
            ],
        );
        let k1_next = f(t + hs, &y1);
        evaluations += 4;
        if !finite(&y1) {
            return Err(SystemError::NotFinite);
        }
        let (g1, _) = event(t + hs, &y1, T::ZERO, &[T::ZERO; N]);
        if g1 >= T::ZERO {
            let (te, ye) = event_in_step(
                |i, th| hermite(y[i], hs * k1[i], y1[i], hs * k1_next[i], th),
                event,
                t,
                hs,
            );
            return run_ended(Ended::Event { t: te, y: ye }, evaluations, steps);
        }
        if hs < h {
            anchor = t + hs;
            n = 0;
        } else {
            n += 1;
        }
        t = anchor + T::from_f64(f64::from(n)) * h;
        y = y1;
        k1 = k1_next;
        if let ControlFlow::Break(why) = check(t, &y) {
            return run_ended(Ended::Stopped { t, y, why }, evaluations, steps);
        }
    }
    Err(SystemError::StepLimit)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run ends at its horizon however the horizon rounds. The step that reaches it is
    /// `horizon - t`, and `t + (horizon - t)` rounds to one below the horizon for some `t` (below
    /// half the horizon: a smooth run whose steps grew fast); the next step, one rounding long,
    /// was below the time's resolution and the run gave up (`StepLimit`): a still-cone incline
    /// integrated to 0.17364774274691488 s did (particle::bowl::incline_tests).
    #[test]
    fn a_run_ends_at_a_horizon_it_does_not_hit_exactly() {
        let mut gave_up = 0;
        for k in 0..400 {
            let horizon = 0.1 + 0.000_737_3 * f64::from(k);
            let run = dp54(
                |_, _: &[f64; 1]| [1.0],
                0.0,
                [0.0],
                1e-9,
                [1e-12],
                1e-5,
                |_, _| (-1.0, 0.0),
                |_, _| ControlFlow::<()>::Continue(()),
                SystemLimits {
                    horizon_s: horizon,
                    max_steps: 1000,
                },
            );
            match run {
                Ok(Run {
                    ended: Ended::Horizon { y },
                    ..
                }) => assert!((y[0] - horizon).abs() <= 4.0 * f64::EPSILON * horizon),
                _ => gave_up += 1,
            }
        }
        assert_eq!(gave_up, 0, "{gave_up} of 400 horizons gave up");
    }
}

//! A logged speed trace (the console's CSV): the bowl speed sampled in time, and the choice
//! between the closed form at the trace's mean speed and an integrator over the trace.
//!
//! The closed form (paper Eq. 5 to 11, docs/model.md §2 to §4) assumes a constant speed. On a
//! rig the speed ripples and drifts; when it varies little while the particle is in the bowl,
//! the closed form at the mean speed over `[0, T]` is within the tolerance and costs a
//! fraction of an integration. The chooser measures that on the trace itself: it computes `T`
//! with a tight DP5(4) over the trace, the mean speed over `[0, T]`, and the closed form's error
//! at that mean; within the tolerance the closed form wins, otherwise the integrator the
//! varying-speed chooser calibrated.

use super::{Choice, ChooseError, Need, Plan, choose_varying_with_margin};
use crate::Real;
use crate::ode::OmegaProfile;
use crate::particle::{self, Scene};

/// A bowl speed sampled in time, linear between samples and held after the last one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampledOmega<'a, T> {
    times_s: &'a [T],
    omega_rad_s: &'a [T],
    max_rad_s: T,
}

/// Why a trace cannot be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TraceError {
    /// No samples, or the two columns differ in length.
    Empty,
    /// Sample `index`'s time is not finite or not after the one before.
    TimeNotIncreasing {
        /// The sample (0-based).
        index: usize,
    },
    /// Sample `index`'s speed is negative, NaN or infinite.
    BadSpeed {
        /// The sample (0-based).
        index: usize,
    },
}

impl<'a, T: Real> SampledOmega<'a, T> {
    /// The trace `(times_s[i], omega_rad_s[i])`; time 0 is the release.
    pub fn new(times_s: &'a [T], omega_rad_s: &'a [T]) -> Result<Self, TraceError> {
        if times_s.is_empty() || times_s.len() != omega_rad_s.len() {
            return Err(TraceError::Empty);
        }
        let mut max_rad_s = T::ZERO;
        for (index, (&t, &w)) in times_s.iter().zip(omega_rad_s).enumerate() {
            let after_previous = index == 0 || t > times_s[index - 1];
            if !(t.is_finite() && after_previous) {
                return Err(TraceError::TimeNotIncreasing { index });
            }
            if !w.is_nonneg_finite() {
                return Err(TraceError::BadSpeed { index });
            }
            max_rad_s = max_rad_s.max(w);
        }
        Ok(Self {
            times_s,
            omega_rad_s,
            max_rad_s,
        })
    }
}

impl<T: Real> OmegaProfile<T> for SampledOmega<'_, T> {
    fn omega_rad_s(&self, t_s: T) -> T {
        let (ts, ws) = (self.times_s, self.omega_rad_s);
        let last = ts.len() - 1;
        // Before the first sample (or a NaN time): the first speed.
        if t_s.is_nan() || t_s <= ts[0] {
            return ws[0];
        }
        if t_s >= ts[last] {
            return ws[last];
        }
        // The first sample after t_s (binary search; ts is strictly increasing).
        let (mut lo, mut hi) = (0, last);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if ts[mid] <= t_s {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let f = (t_s - ts[lo]) / (ts[hi] - ts[lo]);
        ws[lo] + (ws[hi] - ws[lo]) * f
    }
    fn max_omega_rad_s(&self) -> T {
        self.max_rad_s
    }
    fn is_smooth(&self) -> bool {
        // Linear between samples: a kink at every sample.
        false
    }
    fn next_kink_after_s(&self, t_s: T) -> Option<T> {
        // The first sample beyond t_s by more than rounding (so no step shrinks to nothing).
        let beyond = t_s + T::from_f64(16.0) * T::EPSILON * (t_s.abs() + T::ONE);
        let ts = self.times_s;
        let (mut lo, mut hi) = (0, ts.len());
        while lo < hi {
            let mid = (lo + hi) / 2;
            if ts[mid] <= beyond {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        ts.get(lo).copied()
    }
}

/// The mean of omega(t) over `[0, t_end_s]` (composite Simpson, 1,024 intervals), rad/s.
pub fn mean_omega_rad_s<T: Real, P: OmegaProfile<T>>(profile: &P, t_end_s: T) -> T {
    if t_end_s.is_nan() || t_end_s <= T::ZERO || !t_end_s.is_finite() {
        return profile.omega_rad_s(T::ZERO);
    }
    const N: u32 = 1024;
    let h = t_end_s / T::from_f64(f64::from(N));
    let mut sum = profile.omega_rad_s(T::ZERO) + profile.omega_rad_s(t_end_s);
    for i in 1..N {
        let weight = if i % 2 == 1 { 4.0 } else { 2.0 };
        sum += T::from_f64(weight) * profile.omega_rad_s(h * T::from_f64(f64::from(i)));
    }
    // The integral h/3 * sum over the interval's length.
    sum * h / T::from_f64(3.0) / t_end_s
}

/// Chooses for a logged speed trace: the closed form at the mean speed over the residence
/// time if it meets the tolerance there, otherwise the integrator [`choose_varying_for`]
/// picks. The closed form is judged against the pilot's `T` (`time_estimate_s`), whose own
/// estimated error is added to the difference; `estimated_error_rel` is that difference.
pub fn choose_trace<T: Real, P: OmegaProfile<T>>(
    scene: &Scene<T>,
    need: &Need<T>,
    profile: &P,
) -> Result<Choice<T>, ChooseError> {
    let (integrated, margin_rel) = choose_varying_with_margin(scene, need, profile)?;
    if integrated.plan == Plan::ClosedForm {
        // The particle starts at the rim: nothing to integrate.
        return Ok(integrated);
    }
    let t_pilot = integrated.time_estimate_s;
    let mean = mean_omega_rad_s(profile, t_pilot);
    let at_mean = Scene {
        omega_rad_s: mean,
        ..*scene
    };
    let closed = particle::residence(&at_mean, integrated.model)
        .ok()
        .map(|o| o.residence_time_s())
        .filter(|t| t.is_finite());
    match closed {
        Some(t)
            if (t - t_pilot).abs() + margin_rel * t_pilot <= integrated.tolerance_rel * t_pilot =>
        {
            let plan = Plan::ClosedFormAtMeanSpeed { omega_rad_s: mean };
            Ok(Choice {
                plan,
                estimated_error_rel: (t - t_pilot).abs() / t_pilot,
                rhs_evaluations: 0,
                predicted_cost: super::plan_cost(&plan, 0, super::Target::for_precision::<T>()),
                ..integrated
            })
        }
        _ => Ok(integrated),
    }
}

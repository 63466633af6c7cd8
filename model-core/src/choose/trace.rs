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

/// The wire's bowl speed is whole mrad/s (`Telemetry::bowl_mrad_s`): a logged sample is within
/// half of that of the speed the rig measured, rad/s.
pub const LOGGED_SPEED_RESOLUTION_RAD_S: f64 = 1e-3;

/// How well a logged trace knows the bowl speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TraceMeasurement<T> {
    /// Half the logged resolution, rad/s.
    pub rounding_rad_s: T,
    /// RMS scatter of the samples about the straight line through their neighbours, rad/s.
    pub scatter_rad_s: T,
    /// Time-weighted mean speed of the trace, rad/s.
    pub mean_rad_s: T,
    /// `(rounding + scatter) / mean`, at most 1: the relative uncertainty of the speed the
    /// particle saw, as far as the trace itself can tell.
    pub relative: T,
}

impl<T: Real> SampledOmega<'_, T> {
    /// The trace's own measurement uncertainty over `[0, until_s]` (the residence time: the
    /// speed after the particle left does not matter; at least three samples are used), the
    /// samples logged to `resolution_rad_s`.
    ///
    /// The scatter is measured on the trace: each inner sample's distance from the straight
    /// line through its two neighbours, whose RMS is `sqrt(1 + a^2 + b^2)` (`a + b = 1`, the
    /// neighbours' weights) times the noise of independent samples; that factor is divided
    /// out. A real ripple or a bend of the speed counts as scatter too (an upper bound: the
    /// trace cannot tell its own noise from a speed that varies faster than it samples).
    pub fn measurement(&self, resolution_rad_s: T, until_s: T) -> TraceMeasurement<T> {
        let within = self.times_s.iter().take_while(|&&t| t <= until_s).count();
        let used = within.max(3).min(self.times_s.len());
        let (ts, ws) = (&self.times_s[..used], &self.omega_rad_s[..used]);
        let rounding_rad_s = resolution_rad_s.abs() * T::HALF;
        let (mut sum_sq, mut inner) = (T::ZERO, 0u32);
        for i in 1..ts.len().saturating_sub(1) {
            let span = ts[i + 1] - ts[i - 1];
            let b = (ts[i] - ts[i - 1]) / span;
            let a = T::ONE - b;
            let line = ws[i - 1] * a + ws[i + 1] * b;
            let off = (ws[i] - line) / (T::ONE + a * a + b * b).sqrt();
            sum_sq += off * off;
            inner += 1;
        }
        let scatter_rad_s = if inner > 0 {
            (sum_sq / T::from_f64(f64::from(inner))).sqrt()
        } else {
            T::ZERO
        };
        // Trapezoids between samples; one sample is its own mean.
        let duration = ts[ts.len() - 1] - ts[0];
        let mean_rad_s = if duration > T::ZERO {
            let mut area = T::ZERO;
            for i in 1..ts.len() {
                area += (ws[i] + ws[i - 1]) * T::HALF * (ts[i] - ts[i - 1]);
            }
            area / duration
        } else {
            ws[0]
        };
        let uncertain = rounding_rad_s + scatter_rad_s;
        let relative = if uncertain >= mean_rad_s || !(uncertain / mean_rad_s).is_finite() {
            T::ONE
        } else {
            uncertain / mean_rad_s
        };
        TraceMeasurement {
            rounding_rad_s,
            scatter_rad_s,
            mean_rad_s,
            relative,
        }
    }
}

/// A first estimate of the residence time on a varying speed, s: the flat closed form at the
/// mean speed over the time it gives, iterated from the trace's top speed (a few closed forms,
/// no integration). `None` when it does not settle within a few percent or the particle does
/// not leave; it only sets the window over which a trace's measurement is judged.
pub fn residence_estimate_s<T: Real, P: OmegaProfile<T>>(
    scene: &Scene<T>,
    profile: &P,
) -> Option<T> {
    let flat_at = |omega_rad_s: T| {
        let at = Scene {
            omega_rad_s,
            ..*scene
        };
        particle::residence(&at, particle::Model::Flat)
            .ok()
            .map(|o| o.residence_time_s())
            .filter(|t| t.is_finite())
    };
    let mut t = flat_at(profile.max_omega_rad_s())?;
    for _ in 0..8 {
        let next = flat_at(mean_omega_rad_s(profile, t))?;
        if (next - t).abs() <= T::from_f64(0.02) * t {
            return Some(next);
        }
        t = next;
    }
    None
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
/// time if it meets the tolerance there, otherwise the integrator
/// [`choose_varying_for`](super::choose_varying_for) picks. The closed form is judged against the pilot's `T` (`time_estimate_s`), whose own
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
                answer_s: None,
                ..integrated
            })
        }
        _ => Ok(integrated),
    }
}

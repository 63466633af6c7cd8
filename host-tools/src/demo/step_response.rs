//! One motor's response to one step of the demo, measured from its telemetry frames with the
//! project's one step-response definition (`model_core::sim::StepMetrics`: rise from 10 % to 90 %
//! of the change, overshoot past the setpoint, last time outside the settling band, steady
//! error and ripple over the end of the window).

use model_core::sim::StepMetrics;
use model_core::wire::Telemetry;

use super::frames::{AXES, measured, seconds, set};
use super::report::{AxisStep, Tolerances};

/// Steps smaller than this, rad/s, get no rise time or overshoot (the pulse-based reading's
/// resolution would dominate them).
const SMALLEST_RESOLVED_STEP_RAD_S: f64 = 0.05;

/// Step measures of one axis over the window that starts at the step (`frames`, the first at or
/// after `at_ms`): from the first frame's measured speed to the last frame's setpoint.
pub(super) fn axis_step(
    frames: &[Telemetry],
    at_ms: u32,
    axis: usize,
    tol: &Tolerances,
) -> Option<AxisStep> {
    let first = frames.first()?;
    let last = frames.last()?;
    let y0 = measured(first, axis);
    let y1 = set(last, axis);
    let change = y1 - y0;
    let since = |t: &Telemetry| seconds(t.time_ms.wrapping_sub(at_ms));
    let steady_from = frames.len()
        - ((frames.len() as f64 * tol.steady_fraction).ceil() as usize).clamp(1, frames.len());
    let steady = &frames[steady_from..];
    let mut metrics = StepMetrics::between(
        y0 as f32,
        y1 as f32,
        tol.settle_band as f32,
        since(&steady[0]) as f32,
    );
    for t in frames {
        metrics.add(since(t) as f32, measured(t, axis) as f32);
    }
    let report = metrics.report();
    let resolved = change.abs() >= SMALLEST_RESOLVED_STEP_RAD_S;
    // Both crossings in the same frame: the reading jumped, the rise is not resolved.
    let rise_time_s = (resolved && report.rise_time_s.is_finite() && report.rise_time_s > 0.0)
        .then_some(f64::from(report.rise_time_s));
    let first_reading_s = (y0 == 0.0)
        .then(|| frames.iter().find(|t| measured(t, axis) != 0.0).map(since))
        .flatten();
    let settling_time_s = report.settled.then_some(f64::from(report.settling_time_s));
    let steady_error_pct = 100.0 * f64::from(report.steady_state_error);
    let tracked = settling_time_s.is_some_and(|s| s <= tol.settle_within_s)
        && steady_error_pct <= tol.steady_error * 100.0;
    Some(AxisStep {
        axis: AXES[axis],
        from_rad_s: y0,
        set_rad_s: y1,
        rise_time_s,
        first_reading_s,
        settling_time_s,
        overshoot_pct: if resolved {
            100.0 * f64::from(report.overshoot)
        } else {
            0.0
        },
        steady_mean_rad_s: steady.iter().map(|t| measured(t, axis)).sum::<f64>()
            / steady.len() as f64,
        steady_error_pct,
        steady_ripple_pct: 100.0 * f64::from(report.half_peak_to_peak),
        tracked,
    })
}

#[cfg(test)]
mod tests {
    use super::super::frames::fixtures::sampled;
    use super::super::report::TOLERANCES;
    use super::*;

    /// A first-order response: 10-90 % rise tau ln 9, settling into the +/-2 % band tau ln 50,
    /// no overshoot, within the frame spacing (20 ms).
    #[test]
    fn first_order_step_measures_match_the_closed_forms() {
        let (tau, set) = (0.4, 2.0);
        let frames = sampled(|t| set * (1.0 - (-t / tau).exp()), set, 6.0);
        let a = axis_step(&frames, 0, 0, &TOLERANCES).unwrap();
        let rise = a.rise_time_s.unwrap();
        assert!((rise - tau * 9f64.ln()).abs() <= 0.021, "rise {rise}");
        let settle = a.settling_time_s.unwrap();
        // One frame, plus one more where the mrad/s rounding of the wire sits on the band edge.
        assert!(
            (settle - tau * (1.0 / TOLERANCES.settle_band).ln()).abs() <= 0.041,
            "settle {settle}"
        );
        assert_eq!(a.overshoot_pct, 0.0);
        assert!(a.steady_error_pct < 0.1);
        assert!(a.tracked);
    }

    /// A first-order step down, 3 -> 1 rad/s: rise (10 % to 90 % of the change) tau ln 9; the
    /// band is 2 % of the setpoint, 1 % of the change, so settling takes tau ln 100.
    #[test]
    fn a_step_down_is_measured_against_its_change() {
        let (tau, from, set) = (0.3, 3.0, 1.0);
        let frames = sampled(|t| set + (from - set) * (-t / tau).exp(), set, 6.0);
        let a = axis_step(&frames, 0, 0, &TOLERANCES).unwrap();
        let rise = a.rise_time_s.unwrap();
        assert!((rise - tau * 9f64.ln()).abs() <= 0.021, "rise {rise}");
        let settle = a.settling_time_s.unwrap();
        let expected = tau * ((from - set) / (TOLERANCES.settle_band * set)).ln();
        assert!(
            (settle - expected).abs() <= 0.041,
            "settle {settle} vs {expected}"
        );
        assert_eq!(a.overshoot_pct, 0.0);
        assert!(a.tracked);
    }

    /// A second-order response with damping 0.5 overshoots by exp(-zeta pi / sqrt(1 - zeta^2))
    /// = 16.3 % of the step.
    #[test]
    fn underdamped_overshoot_matches_the_closed_form() {
        let (zeta, wn, from, set) = (0.5f64, 6.0f64, 1.0, 3.0);
        let wd = wn * (1.0 - zeta * zeta).sqrt();
        let y = |t: f64| {
            let e = (-zeta * wn * t).exp();
            from + (set - from)
                * (1.0 - e * ((wd * t).cos() + zeta / (1.0 - zeta * zeta).sqrt() * (wd * t).sin()))
        };
        let frames = sampled(y, set, 6.0);
        let a = axis_step(&frames, 0, 0, &TOLERANCES).unwrap();
        let expected = 100.0 * (-zeta * std::f64::consts::PI / (1.0 - zeta * zeta).sqrt()).exp();
        assert!(
            (a.overshoot_pct - expected).abs() < 0.5,
            "{} vs {expected}",
            a.overshoot_pct
        );
        assert_eq!(a.from_rad_s, from);
    }

    /// A response that never gets within the band is not tracked (the check can fail).
    #[test]
    fn a_motor_that_stays_short_of_its_setpoint_is_not_tracked() {
        let frames = sampled(|t| 1.8 * (1.0 - (-t / 0.2).exp()), 2.0, 6.0);
        let a = axis_step(&frames, 0, 0, &TOLERANCES).unwrap();
        assert_eq!(a.settling_time_s, None);
        assert!(a.steady_error_pct > 9.0);
        assert!(!a.tracked);
    }
}

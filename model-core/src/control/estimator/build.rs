//! The estimator's construction: the timer and wheel constants a configuration gives (the
//! lockout, the counting window, the stall time of the module's "Stall bound", [`super`]) and
//! the state at rest.

use super::{Gap, PulseSpeedEstimator, STALL_PITCHES, WINDOW_S, lowest_speed_rad_s};
use crate::control::config::{AxisConfig, ControllerConfig};
use crate::control::teeth::ToothMap;

impl PulseSpeedEstimator {
    /// An estimator for `axis` of a validated configuration.
    pub const fn new(cfg: &ControllerConfig, axis: &AxisConfig) -> Self {
        let ticks_per_s = cfg.timer_hz as f32;
        let rad_per_pulse = core::f32::consts::TAU / axis.pulses_per_rev as f32;
        let min_period_s = rad_per_pulse / axis.overspeed_rad_s;
        let stall_s = STALL_PITCHES * rad_per_pulse / lowest_speed_rad_s(axis);
        Self {
            mask: cfg.timer_mask(),
            rad_per_pulse,
            ticks_per_s,
            s_per_tick: 1.0 / ticks_per_s,
            rad_ticks_per_pulse_s: rad_per_pulse * ticks_per_s,
            lockout_ticks: (0.5 * min_period_s * ticks_per_s) as u32,
            window_ticks: (WINDOW_S * ticks_per_s) as u32,
            stall_ticks: (stall_s * ticks_per_s).min(4.0e9) as u32,
            filter_weight: axis.filter_weight,
            prev_now: 0,
            clock: 0,
            has_edge: false,
            last_edge: 0,
            last_interval: 0,
            prev_interval: 0,
            win_start: 0,
            win_pulses: 0,
            win_pitches: 0.0,
            teeth: ToothMap::new(axis.pulses_per_rev, ticks_per_s),
            learn_teeth: false,
            valid: false,
            raw_period_ticks: 0.0,
            lockout_now: (0.5 * min_period_s * ticks_per_s) as u32,
            missing_from: u32::MAX,
            observed: false,
            expect_pitches: 0.0,
            expect_pitches_per_tick: 0.0,
            tick_restarted: false,
            tick_pitches: 0.0,
            tick_edges: 0,
            speed_filt: 0.0,
            speed: 0.0,
            bound_active: false,
            bound_pitches: 1,
            restart_at: None,
            closed_at: None,
            closed_span: 0,
            closed_raw: 0.0,
            accepted: 0,
            rejected: 0,
            missing: 0,
            drop_memory: 0,
            late_edges: 0,
            last_gap: Gap {
                serial: 0,
                index: 0,
                pitches: 0.0,
                ticks: 0,
                end: 0,
            },
        }
    }
}

//! The loop's per-axis constants (gains per bandwidth, the gain schedule's ceiling, the
//! kick's and the push's rates, the runaway rule's arming speed), precomputed once from the
//! configuration so that the tick only multiplies.

use super::{LEAD_MARGIN_DUTY, PUSH_SPAN_DUTY, REFERENCE_TAU_S, STUCK_PITCHES};
use crate::control::config::AxisConfig;
use crate::control::supervisor::{
    PAIR_RUNAWAY_ARMED_SHARE, RUNAWAY_MARGIN_RAD_S, RUNAWAY_RATIO, WATCH_PITCHES,
};

/// Per-axis constants of the loop, precomputed from the configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopConstants {
    pub(super) dt_s: f32,
    pub(super) duty_per_rad_s: f32,
    pub(super) pair_runaway_above_rad_s: f32,
    pub(super) friction_duty: f32,
    pub(super) model_alpha: f32,
    pub(super) kp_per_wc: f32,
    pub(super) ki_dt_per_wc: f32,
    pub(super) bandwidth_rad_s: f32,
    pub(super) per_pulse_bw_times_pulses_per_rad: f32,
    pub(super) filter_weight: f32,
    pub(super) push_per_rad_tick: f32,
    pub(super) kick_excess: f32,
    pub(super) kick_gain_per_tick: f32,
    pub(super) stuck_angle_rad: f32,
    pub(super) duty_limit: f32,
    pub(super) slew_per_tick: f32,
    /// The reference's lead per rad/s of the model's lag behind it (`lead` in
    /// [`SpeedLoop::step`](super::SpeedLoop::step)): `tau / REFERENCE_TAU_S - 1`, at least 0.
    pub(super) lead_gain: f32,
    /// The speed whose feedforward reaches the duty limit less [`LEAD_MARGIN_DUTY`], rad/s:
    /// the lead stays below it less the reference.
    pub(super) lead_room_rad_s: f32,
}

/// The model speed above which a bridge stuck on may stay below the single-interval runaway
/// threshold (`RUNAWAY_RATIO m + RUNAWAY_MARGIN`, controller) because the identified model's
/// full-duty speed `(1 - friction_duty) V / volts_per_rad_s` is within reach of it (80 % of it:
/// material poured in since commissioning lowers the true one). Above it the controller also
/// judges the last two intervals together.
const fn pair_runaway_above_rad_s(axis: &AxisConfig, supply_v: f32) -> f32 {
    let full = (1.0 - axis.model.friction_duty) * supply_v / axis.model.volts_per_rad_s;
    (PAIR_RUNAWAY_ARMED_SHARE * full - RUNAWAY_MARGIN_RAD_S) / RUNAWAY_RATIO
}

/// The speed above which the gain schedule stops raising the loop's bandwidth with the pulse
/// rate, rad/s. The tooth map leaves the wheel's once-per-revolution pattern visible (it cannot
/// be told from an eccentric load, teeth.rs), so the loop sees it as a speed error at the
/// revolution frequency; a loop as fast as the revolution (the schedule gives `0.95 omega` on
/// 12 teeth) chases it. Measured on the 60-plant family and six unseen ones at 3 rad/s, 12
/// teeth: scheduled up to 3 rad/s (2.9 rad/s of bandwidth) the true speed rippled up to 2.06 %;
/// held from 2.1 rad/s on (2.0 rad/s of bandwidth), 1.84 % at most, overshoot and 3 s settling
/// unchanged or better. The pattern shrinks as the teeth multiply (as `N^-1.5` for random
/// offsets) while the bandwidth held grows with them: at 60 teeth it (10 rad/s) lies above the
/// configured ceiling, and those loops are unchanged.
pub const SCHEDULE_TOP_RAD_S: f32 = 2.1;

/// The loop's bandwidth ceiling on `axis`: the configured one, or the schedule's value at
/// [`SCHEDULE_TOP_RAD_S`] where that is lower.
pub const fn bandwidth_ceiling_rad_s(axis: &AxisConfig) -> f32 {
    let pulses_per_rad = axis.pulses_per_rev as f32 / core::f32::consts::TAU;
    let at_top = axis.per_pulse_bandwidth * pulses_per_rad * SCHEDULE_TOP_RAD_S;
    if at_top < axis.bandwidth_rad_s {
        at_top
    } else {
        axis.bandwidth_rad_s
    }
}

impl LoopConstants {
    /// Constants for `axis` at tick period `dt_s` and supply `supply_v`.
    pub const fn new(axis: &AxisConfig, dt_s: f32, supply_v: f32) -> Self {
        let pulses_per_rad = axis.pulses_per_rev as f32 / core::f32::consts::TAU;
        let w = axis.filter_weight;
        Self {
            dt_s,
            duty_per_rad_s: axis.model.volts_per_rad_s / supply_v,
            pair_runaway_above_rad_s: pair_runaway_above_rad_s(axis, supply_v),
            friction_duty: axis.model.friction_duty,
            // Backward-Euler step of the first-order plant model, precomputed.
            model_alpha: dt_s / (axis.model.time_constant_s + dt_s),
            kp_per_wc: axis.model.time_constant_s * axis.model.volts_per_rad_s / supply_v,
            ki_dt_per_wc: dt_s * axis.model.volts_per_rad_s / supply_v,
            bandwidth_rad_s: bandwidth_ceiling_rad_s(axis),
            per_pulse_bw_times_pulses_per_rad: axis.per_pulse_bandwidth * pulses_per_rad,
            filter_weight: w,
            // Per tick and per rad/s of reference: the model covers the push's pitches in
            // `pitches / (r pulses_per_rad)` seconds.
            push_per_rad_tick: PUSH_SPAN_DUTY * dt_s * pulses_per_rad
                / (WATCH_PITCHES - STUCK_PITCHES),
            kick_excess: if axis.model.breakaway_duty > axis.model.friction_duty {
                axis.model.breakaway_duty - axis.model.friction_duty
            } else {
                0.0
            },
            // The model's speed gain per tick and per duty above friction:
            // `tau dw/dt = (d - friction) / duty_per_rad_s - w` (Backward Euler like the model).
            kick_gain_per_tick: dt_s
                / ((axis.model.time_constant_s + dt_s) * axis.model.volts_per_rad_s / supply_v),
            stuck_angle_rad: STUCK_PITCHES / pulses_per_rad,
            duty_limit: axis.duty_limit,
            slew_per_tick: axis.duty_slew_per_s * dt_s,
            lead_gain: if axis.model.time_constant_s > REFERENCE_TAU_S {
                axis.model.time_constant_s / REFERENCE_TAU_S - 1.0
            } else {
                0.0
            },
            lead_room_rad_s: (axis.duty_limit - LEAD_MARGIN_DUTY - axis.model.friction_duty)
                * supply_v
                / axis.model.volts_per_rad_s,
        }
    }

    /// Duty above friction the identified stiction needs at reference speed `r_abs` (none once
    /// the reference's own feedforward gives it).
    #[inline]
    pub(super) fn kick_level(&self, r_abs: f32) -> f32 {
        let level = self.kick_excess - r_abs * self.duty_per_rad_s;
        if level > 0.0 { level } else { 0.0 }
    }

    /// The reference `r` (magnitude `r_abs`, sign `direction`) led for a model at `r_p`: a
    /// shaft slower than [`REFERENCE_TAU_S`] gets, while its model is behind the reference in
    /// the commanded direction, the feedforward of a reference ahead of it by
    /// `(tau / REFERENCE_TAU_S - 1) (r - r_p)`, so it follows a model of that lag instead of
    /// its own. Below the duty limit (less [`LEAD_MARGIN_DUTY`]); none on the way down, where
    /// the shaft coasts as its inertia lets it.
    #[inline(always)]
    pub(super) fn led_reference(&self, r: f32, r_abs: f32, r_p: f32, direction: f32) -> f32 {
        let lead = self.lead_gain * (r - r_p);
        let room = self.lead_room_rad_s - r_abs;
        if lead * direction <= 0.0 || room <= 0.0 {
            r
        } else if lead.abs() > room {
            r + room * direction
        } else {
            r + lead
        }
    }

    /// Closed-loop bandwidth the schedule picks at reference speed `r_abs`, rad/s.
    #[inline]
    pub fn scheduled_bandwidth(&self, r_abs: f32) -> f32 {
        let by_pulses = self.per_pulse_bw_times_pulses_per_rad * r_abs;
        if by_pulses < self.bandwidth_rad_s {
            by_pulses
        } else {
            self.bandwidth_rad_s
        }
    }

    /// Proportional gain at loop bandwidth `wc_rad_s`, duty per rad/s of speed error
    /// (`tau * Ke / V * wc`: the PI zero cancels the model's pole).
    pub fn kp(&self, wc_rad_s: f32) -> f32 {
        self.kp_per_wc * wc_rad_s
    }

    /// Integral gain at loop bandwidth `wc_rad_s`, duty per rad of accumulated speed error
    /// (`Ke / V * wc`).
    pub fn ki_per_s(&self, wc_rad_s: f32) -> f32 {
        self.ki_dt_per_wc / self.dt_s * wc_rad_s
    }

    /// Duty per rad/s of the identified model (`volts_per_rad_s / V`).
    pub fn duty_per_rad_s(&self) -> f32 {
        self.duty_per_rad_s
    }

    /// Model speed above which the two-interval runaway rule is armed, rad/s (the free
    /// function of the same name in this module says how it is set).
    pub fn pair_runaway_above_rad_s(&self) -> f32 {
        self.pair_runaway_above_rad_s
    }

    /// The largest duty the loop gives, in magnitude.
    pub fn duty_limit(&self) -> f32 {
        self.duty_limit
    }

    /// Steady-state duty of the model at `r` rad/s (signed).
    #[inline]
    pub fn feedforward(&self, r: f32) -> f32 {
        if r > 0.0 {
            self.friction_duty + r * self.duty_per_rad_s
        } else if r < 0.0 {
            -self.friction_duty + r * self.duty_per_rad_s
        } else {
            0.0
        }
    }
}

//! The speed loop of one axis: feedforward from the identified motor model plus a discrete PI
//! on the measured speed, with gain scheduling, anti-windup, clamp and slew limit.
//!
//! # Structure (two degrees of freedom)
//! `duty = ff(r) + Kp e + I`, with `e = r_m - y`:
//! - `ff(r) = sign(r) (friction_duty + |r| volts_per_rad_s / V)`: the steady-state duty of the
//!   identified model, so the loop only corrects the model's error.
//! - `r_m` is the ramped reference `r` delayed by what the plant and the measurement add (plant
//!   time constant, half a pulse interval, the estimator filter's lag). The pulse estimate of a
//!   speed that follows `r` lags it by about that much; comparing it with `r` itself would wind
//!   the integral up on every ramp and overshoot afterwards.
//!
//! # Gains
//! The plant from duty to speed is `K / (tau s + 1)` with `K = V / volts_per_rad_s`. The PI zero
//! cancels the pole (`Ti = tau`) and `Kp = wc tau / K`, `Ki = wc / K` give a first-order closed
//! loop of bandwidth `wc`. `wc = min(bandwidth, per_pulse_bandwidth * pulse_rate)`, with the pulse
//! rate at the reference speed: sparse pulses sample the speed slowly, and a loop faster than
//! about a fifth of the sample rate rings or limit-cycles (see docs/control.md's stability map).
//!
//! # Anti-windup, bumpless changes, zero setpoint
//! The integral stores its *output* (duty), so changing `Ki` never moves the duty; when `Kp`
//! changes the integral absorbs `(Kp_old - Kp_new) e`, so neither does that. Integration stops
//! (conditional integration) while the output is clamped or slew-limited in the direction the
//! error pushes, which holds a blocked motor's integral instead of letting it run away, and while
//! the estimator has no valid measurement (no pulse interval yet). At a zero reference the output
//! is exactly zero and the integral is cleared: no hum, no creep.

use super::config::AxisConfig;

/// State of one axis's loop.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SpeedLoop {
    integral: f32,
    duty: f32,
    ref_model: f32,
    kp_prev: f32,
}

/// Inputs of one loop step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopInput {
    /// Ramped reference, rad/s (signed: the commanded direction).
    pub reference_rad_s: f32,
    /// Measured speed with the commanded sign, rad/s.
    pub measured_rad_s: f32,
    /// The estimator has a valid measurement.
    pub measurement_valid: bool,
    /// Feedback on (false only in the open-loop test of the feedback's necessity).
    pub feedback: bool,
}

/// Per-axis constants of the loop, precomputed from the configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopConstants {
    dt_s: f32,
    duty_per_rad_s: f32,
    friction_duty: f32,
    tau_s: f32,
    bandwidth_rad_s: f32,
    per_pulse_bw_times_pulses_per_rad: f32,
    meas_lag_pulses: f32,
    rad_per_pulse: f32,
    max_meas_lag_s: f32,
    duty_limit: f32,
    slew_per_tick: f32,
}

impl LoopConstants {
    /// Constants for `axis` at tick period `dt_s` and supply `supply_v`.
    pub fn new(axis: &AxisConfig, dt_s: f32, supply_v: f32) -> Self {
        let pulses_per_rad = axis.pulses_per_rev as f32 / core::f32::consts::TAU;
        let w = axis.filter_weight;
        Self {
            dt_s,
            duty_per_rad_s: axis.model.volts_per_rad_s / supply_v,
            friction_duty: axis.model.friction_duty,
            tau_s: axis.model.time_constant_s,
            bandwidth_rad_s: axis.bandwidth_rad_s,
            per_pulse_bw_times_pulses_per_rad: axis.per_pulse_bandwidth * pulses_per_rad,
            // Half an interval of sampling delay plus the exponential filter's mean lag.
            meas_lag_pulses: 0.5 + (1.0 - w) / w,
            rad_per_pulse: 1.0 / pulses_per_rad,
            max_meas_lag_s: 2.0,
            duty_limit: axis.duty_limit,
            slew_per_tick: axis.duty_slew_per_s * dt_s,
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

impl SpeedLoop {
    /// One fixed-rate step; returns the duty in `[-duty_limit, duty_limit]`.
    #[inline]
    pub fn step(&mut self, k: &LoopConstants, input: LoopInput) -> f32 {
        let r = input.reference_rad_s;
        if r == 0.0 {
            *self = Self::default();
            return 0.0;
        }
        let r_abs = r.abs();
        // Reference model: the lag the measurement will show.
        let mut lag_s = k.meas_lag_pulses * k.rad_per_pulse / r_abs;
        if lag_s > k.max_meas_lag_s {
            lag_s = k.max_meas_lag_s;
        }
        let tc = k.tau_s + lag_s;
        self.ref_model += (r - self.ref_model) * (k.dt_s / (tc + k.dt_s));

        let wc = k.scheduled_bandwidth(r_abs);
        let ki_dt = wc * k.duty_per_rad_s * k.dt_s;
        let kp = wc * k.tau_s * k.duty_per_rad_s;
        let e = if input.feedback && input.measurement_valid {
            self.ref_model - input.measured_rad_s
        } else {
            0.0
        };
        // Bumpless gain change: the proportional jump is absorbed by the integral.
        self.integral += (self.kp_prev - kp) * e;
        self.kp_prev = kp;

        let ff = k.feedforward(r);
        let candidate_i = self.integral + ki_dt * e;
        let unclamped = ff + kp * e + candidate_i;
        let lim = k.duty_limit;
        let saturating = (unclamped > lim && e > 0.0) || (unclamped < -lim && e < 0.0);
        let slew_pushing = (unclamped - self.duty > k.slew_per_tick && e > 0.0)
            || (unclamped - self.duty < -k.slew_per_tick && e < 0.0);
        if !saturating && !slew_pushing {
            self.integral = candidate_i.clamp(-lim, lim);
        }
        let target = (ff + kp * e + self.integral).clamp(-lim, lim);
        let step = (target - self.duty).clamp(-k.slew_per_tick, k.slew_per_tick);
        self.duty += step;
        self.duty
    }

    /// The last output duty.
    pub fn duty(&self) -> f32 {
        self.duty
    }
    /// The integral term (duty).
    pub fn integral(&self) -> f32 {
        self.integral
    }
    /// Back to rest (zero output, zero integral).
    pub fn reset(&mut self) {
        *self = Self::default();
    }
}

//! The controller's configuration: rates, per-axis sensor and motor model, limits, safety.
//!
//! Everything is checked once by [`ControllerConfig::validate`]; the controller only ever runs
//! on a validated configuration, so the control tick needs no defensive checks.

/// Index of the precession axis (the rod about the vertical, omega1) in per-axis arrays.
pub const PRECESSION: usize = 0;
/// Index of the spin axis (the bowl about its own axis, omega2) in per-axis arrays.
pub const SPIN: usize = 1;

/// What a configuration check found wrong. The first problem found is reported.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ConfigError {
    /// The control tick rate is outside 100 Hz ..= 10 kHz.
    TickRate,
    /// The capture timer's rate is below 10 kHz or not a multiple of the tick rate's order
    /// (it must be at least 10 ticks per control tick), or its width is not 16 or 32 bits.
    Timer,
    /// The supply voltage is not finite or outside 1 ..= 60 V.
    SupplyVoltage,
    /// Pulses per revolution of this axis (0 = precession, 1 = spin) is 0 or above 1000.
    PulsesPerRev(u8),
    /// The speed limits of this axis are inconsistent: need
    /// `0 < min_speed < max_speed < overspeed`, all finite.
    SpeedLimits(u8),
    /// The motor model of this axis is implausible: volts per rad/s must be in (0, 100],
    /// friction duty in [0, 0.9], time constant in (0, 10] s.
    MotorModel(u8),
    /// A loop parameter of this axis is out of range (bandwidth, per-pulse bandwidth,
    /// acceleration limit, duty limit, duty slew, filter weight).
    LoopParameter(u8),
    /// The supervisor's thresholds are out of range (stall duty, sensor timeout floor,
    /// host timeout).
    Supervisor,
    /// The spin/precession ratio or the angle between the axes is invalid.
    Geometry,
    /// A commissioning parameter is out of range (duties, step time, timeout).
    Commissioning,
}

/// The identified model of one axis, as the feedforward and the gain design need it.
///
/// Steady state of a DC motor with friction, seen from the bridge:
/// `duty * V = volts_per_rad_s * |omega| + friction_duty * V`, and the step response from duty
/// to speed is first order with `time_constant_s`. Without a current measurement the back-EMF
/// constant cannot be separated from viscous friction: `volts_per_rad_s` is the back-EMF
/// constant plus `R * viscous / k_t`, which is exactly what the feedforward needs.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MotorModel {
    /// Effective back-EMF constant at the output shaft, V per rad/s (includes viscous friction).
    pub volts_per_rad_s: f32,
    /// Duty that balances Coulomb friction while turning (fraction of full duty).
    pub friction_duty: f32,
    /// Mechanical time constant of the duty-to-speed step response, s.
    pub time_constant_s: f32,
    /// Duty that started the shaft from rest (stiction; fraction of full duty): the breakaway
    /// search's duty at the first edge, an upper bound (the duty kept rising while the shaft
    /// travelled to the edge, up to a pitch; edges alone cannot tell how far). At or below
    /// `friction_duty` (the nominal model) the loop knows no stiction and starts without a
    /// kick.
    pub breakaway_duty: f32,
    /// Duty this axis needs per rad/s^2 of the other axis's acceleration to cancel its
    /// reaction torque (the spin's reaction on the precession axis, measured by commissioning;
    /// duty s^2/rad). 0 means not measured: the controller then estimates it from the axes'
    /// geometry and the spin model, assuming the same motor type on both axes.
    pub reaction_duty_s2_per_rad: f32,
}

/// Configuration of one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AxisConfig {
    /// Proximity pulses per output revolution (teeth of the target wheel; 1 is valid).
    pub pulses_per_rev: u16,
    /// Lowest nonzero speed a command may ask for, rad/s. The estimator reads zero once no
    /// pulse has come for one pulse period at this speed (the stall bound).
    pub min_speed_rad_s: f32,
    /// Highest speed a command may ask for, rad/s.
    pub max_speed_rad_s: f32,
    /// Measured speed above this latches an over-speed fault, rad/s.
    pub overspeed_rad_s: f32,
    /// Identified motor model (from commissioning, or nominal values).
    pub model: MotorModel,
    /// Upper bound of the closed-loop bandwidth, rad/s.
    pub bandwidth_rad_s: f32,
    /// Bandwidth allowed per pulse per second: `wc <= per_pulse_bandwidth * pulse_rate_hz`.
    /// Sparse pulses are a sampled measurement; this keeps the loop well inside it.
    pub per_pulse_bandwidth: f32,
    /// Setpoint ramp, rad/s^2.
    pub accel_limit_rad_s2: f32,
    /// Largest duty magnitude the loop may command (0..=1).
    pub duty_limit: f32,
    /// Largest duty change per second.
    pub duty_slew_per_s: f32,
    /// Weight of a new raw speed sample in the estimator's exponential filter, (0, 1].
    pub filter_weight: f32,
}

/// The open-loop identification routine's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CommissioningConfig {
    /// First duty step (from rest), fraction.
    pub low_duty: f32,
    /// Second duty step (from the first), fraction.
    pub high_duty: f32,
    /// Minimum time each step is held, s. The fit uses the second half.
    pub step_time_s: f32,
    /// Minimum edges in the second half of each step before it ends.
    pub min_fit_edges: u16,
    /// The whole routine fails (invalid-configuration fault) after this long, s.
    pub timeout_s: f32,
}

/// The whole controller's configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ControllerConfig {
    /// Control tick rate, Hz (the firmware calls [`crate::control::Controller::tick`] at it).
    pub tick_hz: u32,
    /// Capture timer rate, Hz (the unit of edge timestamps).
    pub timer_hz: u32,
    /// Capture timer width: 16 or 32 bits (timestamps wrap at `2^bits`).
    pub timer_bits: u8,
    /// H-bridge supply voltage, V.
    pub supply_v: f32,
    /// Per-axis settings, indexed by [`PRECESSION`] and [`SPIN`].
    pub axes: [AxisConfig; 2],
    /// Angle between the spin and the precession axis, rad (see `crate::bowl`).
    pub axes_angle_rad: f32,
    /// Spin speed per precession speed used when a combined bowl speed is split (Eq. 2).
    pub spin_per_precession: f32,
    /// Duty magnitude above which "no pulses" counts as a lost sensor or a stalled shaft.
    pub stall_duty: f32,
    /// Floor of the sensor-lost timeout, s (the timeout is
    /// `max(this, 3 expected pulse periods)`).
    pub sensor_timeout_floor_s: f32,
    /// Host link silence that faults while driving, s; 0 disables the check (the default).
    pub host_timeout_s: f32,
    /// Identification settings.
    pub commissioning: CommissioningConfig,
}

impl AxisConfig {
    /// A small 12 V gearmotor with a 12-tooth target (see docs/control.md for the numbers).
    pub const fn nominal() -> Self {
        Self {
            pulses_per_rev: 12,
            min_speed_rad_s: 0.2,
            max_speed_rad_s: 4.0,
            overspeed_rad_s: 5.5,
            model: MotorModel {
                volts_per_rad_s: 1.75,
                friction_duty: 0.06,
                time_constant_s: 0.06,
                breakaway_duty: 0.06,
                reaction_duty_s2_per_rad: 0.0,
            },
            bandwidth_rad_s: 8.0,
            per_pulse_bandwidth: 0.5,
            accel_limit_rad_s2: 6.0,
            duty_limit: 0.95,
            duty_slew_per_s: 4.0,
            filter_weight: 0.7,
        }
    }
}

impl Default for ControllerConfig {
    fn default() -> Self {
        Self::nominal()
    }
}

impl ControllerConfig {
    /// The nominal rig: 1 kHz tick, 1 MHz 32-bit capture timer, 12 V, 12 pulses per revolution.
    pub const fn nominal() -> Self {
        Self {
            tick_hz: 1000,
            timer_hz: 1_000_000,
            timer_bits: 32,
            supply_v: 12.0,
            axes: [AxisConfig::nominal(), AxisConfig::nominal()],
            axes_angle_rad: core::f32::consts::FRAC_PI_3,
            spin_per_precession: 1.0,
            stall_duty: 0.15,
            sensor_timeout_floor_s: 0.2,
            host_timeout_s: 0.0,
            commissioning: CommissioningConfig {
                low_duty: 0.25,
                high_duty: 0.45,
                step_time_s: 2.0,
                min_fit_edges: 8,
                timeout_s: 120.0,
            },
        }
    }

    /// Checks every field; the controller only accepts a configuration that passes.
    ///
    /// A `const fn`, so a configuration fixed at build time is checked by the compiler.
    pub const fn validate(&self) -> Result<(), ConfigError> {
        if self.tick_hz < 100 || self.tick_hz > 10_000 {
            return Err(ConfigError::TickRate);
        }
        if (self.timer_bits != 16 && self.timer_bits != 32)
            || self.timer_hz < 10_000
            || self.timer_hz / self.tick_hz < 10
        {
            return Err(ConfigError::Timer);
        }
        if !in_range(self.supply_v, 1.0, 60.0) {
            return Err(ConfigError::SupplyVoltage);
        }
        let mut i = 0;
        while i < 2 {
            if let Err(e) = self.axes[i].validate(i as u8) {
                return Err(e);
            }
            i += 1;
        }
        let geometry_ok = self.axes_angle_rad.is_finite()
            && self.axes_angle_rad >= 0.0
            && self.axes_angle_rad < core::f32::consts::PI
            && in_range(self.spin_per_precession, 0.0, 1000.0);
        if !geometry_ok {
            return Err(ConfigError::Geometry);
        }
        if !in_range(self.stall_duty, 0.01, 0.9)
            || !in_range(self.sensor_timeout_floor_s, 0.01, 10.0)
            || !in_range(self.host_timeout_s, 0.0, 3600.0)
        {
            return Err(ConfigError::Supervisor);
        }
        let c = &self.commissioning;
        if !in_range(c.low_duty, 0.05, 0.9)
            || !in_range(c.high_duty, 0.05, 0.95)
            || c.high_duty < c.low_duty + 0.05
            || !in_range(c.step_time_s, 0.2, 60.0)
            || c.min_fit_edges < 2
            || c.min_fit_edges > 1000
            || !in_range(c.timeout_s, 1.0, 3600.0)
        {
            return Err(ConfigError::Commissioning);
        }
        Ok(())
    }

    /// Timestamps wrap at `2^timer_bits`; differences are taken with this mask.
    pub(crate) const fn timer_mask(&self) -> u32 {
        if self.timer_bits >= 32 {
            u32::MAX
        } else {
            (1u32 << self.timer_bits) - 1
        }
    }
}

impl AxisConfig {
    const fn validate(&self, axis: u8) -> Result<(), ConfigError> {
        if self.pulses_per_rev < 1 || self.pulses_per_rev > 1000 {
            return Err(ConfigError::PulsesPerRev(axis));
        }
        let speeds_ok = in_range(self.min_speed_rad_s, 1e-3, 1e3)
            && in_range(self.max_speed_rad_s, 1e-3, 1e3)
            && in_range(self.overspeed_rad_s, 1e-3, 1e3)
            && self.min_speed_rad_s < self.max_speed_rad_s
            && self.max_speed_rad_s < self.overspeed_rad_s;
        if !speeds_ok {
            return Err(ConfigError::SpeedLimits(axis));
        }
        if let Err(e) = self.model.validate(axis) {
            return Err(e);
        }
        let loop_ok = in_range(self.bandwidth_rad_s, 0.01, 1000.0)
            && in_range(self.per_pulse_bandwidth, 0.01, 10.0)
            && in_range(self.accel_limit_rad_s2, 0.01, 1000.0)
            && in_range(self.duty_limit, 0.05, 1.0)
            && in_range(self.duty_slew_per_s, 0.1, 1000.0)
            && self.filter_weight > 0.0
            && self.filter_weight <= 1.0;
        if !loop_ok {
            return Err(ConfigError::LoopParameter(axis));
        }
        Ok(())
    }
}

impl MotorModel {
    /// Checks the model's plausibility; `axis` names the axis in the error.
    pub const fn validate(&self, axis: u8) -> Result<(), ConfigError> {
        let ok = self.volts_per_rad_s > 0.0
            && self.volts_per_rad_s <= 100.0
            && in_range(self.friction_duty, 0.0, 0.9)
            && in_range(self.breakaway_duty, 0.0, 1.0)
            && in_range(self.reaction_duty_s2_per_rad, -1.0, 1.0)
            && self.time_constant_s > 0.0
            && self.time_constant_s <= 10.0;
        if ok {
            Ok(())
        } else {
            Err(ConfigError::MotorModel(axis))
        }
    }
}

/// `lo <= x <= hi` and finite (NaN fails).
pub(crate) const fn in_range(x: f32, lo: f32, hi: f32) -> bool {
    x.is_finite() && x >= lo && x <= hi
}

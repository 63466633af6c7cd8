//! The rig's controller: pulse speed estimation, a PI speed loop per motor, setpoints from the
//! particle model, a supervisor with latched faults, and open-loop commissioning. `no_std`, no
//! heap, `f32` (the Cortex-M4F's FPU), no panics on any input.
//!
//! # The contract the firmware and the serial protocol bind to
//!
//! ```text
//! Controller::new(cfg: ControllerConfig) -> Result<Controller, ConfigError>
//! Controller::new_or_faulted(cfg: ControllerConfig) -> Controller   // boots faulted if invalid
//!
//! // at exactly cfg.tick_hz (1 kHz nominal), from the control task:
//! Controller::tick(&mut self, now_ticks: u32, edges: [&[u32]; 2]) -> [f32; 2]
//!
//! // commands (each returns Ok or a Rejection; a rejected command changes nothing;
//! // out-of-range values are rejected, never clamped):
//! Controller::set_motor_speeds(&mut self, precession_rad_s: f32, spin_rad_s: f32) -> Result<(), Rejection>
//! Controller::set_target_residence_time(&mut self, target_s: f32, model: &dyn BowlSpeedForResidence)
//!     -> Result<[f32; 2], Rejection>
//! Controller::start(&mut self) -> Result<(), Rejection>
//! Controller::stop(&mut self) -> Result<(), Rejection>
//! Controller::clear_fault(&mut self) -> Result<(), Rejection>
//! Controller::set_parameters(&mut self, cfg: ControllerConfig) -> Result<(), Rejection>
//! Controller::set_loop_tuning(&mut self, axis: usize, bandwidth_rad_s: f32, per_pulse_bandwidth: f32)
//!     -> Result<(), Rejection>
//! Controller::start_commissioning(&mut self) -> Result<(), Rejection>
//! Controller::host_heartbeat(&mut self)
//!
//! // telemetry (at the telemetry rate, not in the tick):
//! Controller::status(&self) -> Status
//! Controller::predicted_residence_time_s(&self, model: &dyn ResidenceForBowlSpeed) -> Option<f32>
//! Controller::identified(&self) -> [Option<Identified>; 2]
//! ```
//!
//! - Axis order everywhere: `[PRECESSION, SPIN]` = `[0, 1]` (omega1, omega2).
//! - `now_ticks`: the capture timer (`timer_hz`, 16 or 32 bits, wrapping) read *after* the
//!   edges were drained. `edges[axis]`: capture timestamps of that axis's sensor since the last
//!   tick, oldest first (the input-capture ISR queues them; the queue must report overflow to the
//!   host itself: the controller cannot see edges it was never given).
//! - Duties: `-1..=1`, sign = direction; `0` means the bridge *coasts* (both half-bridges
//!   off). The firmware maps `|duty|` to the PWM compare value (20 kHz PWM, nominal) and the
//!   sign to the bridge's direction input.
//! - One proximity sensor per shaft gives no direction: the measured speed takes the sign of the
//!   commanded (ramped) direction, and a reversal ramps to zero and waits until the estimator
//!   reads zero before ramping the other way.
//! - Faults: any fault zeroes both duties in the tick it is detected and latches until
//!   `clear_fault`; [`Fault::code`] gives telemetry's number (0 = none).
//!
//! # Rates and limits (nominal configuration, see docs/control.md)
//! Tick 1 kHz; capture timer 1 MHz; PWM 20 kHz. The lowest holdable speed is the configured
//! `min_speed_rad_s` (0.2 rad/s nominal; at N pulses per revolution one pulse then takes
//! `2 pi / (N * 0.2)` s: 31 s at N = 1, 2.6 s at N = 12); commands below it (except zero) are
//! refused.
//!
//! # Modules
//! - [`config`], the configuration and its validation.
//! - [`estimator`], speed from edge timestamps.
//! - [`pi`], feedforward + PI per axis.
//! - [`breakaway`], the breakaway seen in the motor current, for the loop.
//! - [`load_pattern`], the once-per-revolution load, learned and fed forward.
//! - [`planner`], setpoints, Eq. 2 split, ramps, the particle-model traits.
//! - [`supervisor`], states and faults.
//! - [`commission`], identification.

pub mod breakaway;
pub mod commission;
pub mod config;
mod const_trig;
mod controller;
pub mod estimator;
pub mod load_pattern;
pub mod observer;
pub mod pi;
pub mod planner;
pub mod supervisor;
pub mod teeth;

pub use commission::{Identified, IdentifyError};
pub use config::{
    AxisConfig, CommissioningConfig, ConfigError, ControllerConfig, MotorModel, PRECESSION, SPIN,
};
pub use controller::{AxisStatus, Controller, Rejection, Status};
pub use planner::{BowlSpeedForResidence, InverseFailure, ResidenceForBowlSpeed};
pub use supervisor::{CurrentTrip, CurrentWatch, DetectedBy, Fault, State};

//! A simulated rig for the controller, `no_std` and allocation-free so the same code runs in
//! `bowl sim` on the host and on the emulated Cortex-M4F: two brushed 12 V gearmotors with
//! their loads ([`motor`]), the spin motor's reaction torque on the precession axis, proximity
//! sensors with tooth-spacing error and jitter, once-per-revolution load ripple and injectable
//! faults ([`plant`]), a seeded generator ([`prng`]), and the closed loop with step-response
//! measures ([`harness`]). Nominal parameters and why they are plausible: docs/control.md.
//!
//! Left out on purpose: PWM ripple (20 kHz, averaged), gyroscopic torques between the axes
//! (second order at these speeds), gearbox backlash.

pub mod assembly;
pub mod bowl_granule;
pub mod experiments;
pub mod gates;
pub mod granule;
pub mod harness;
pub mod motor;
pub mod plant;
pub mod prng;
pub mod restart;

pub use assembly::{ASSEMBLY_COMMISSION_MAX_S, AssemblyError, commission_on_plant};
pub use harness::{ClosedLoop, SETTLING_BAND, StepMetrics, StepReport};
pub use motor::{MotorParams, MotorState};
pub use plant::{AxisFaults, AxisParams, CurrentSense, Plant, PlantParams, SensorParams};

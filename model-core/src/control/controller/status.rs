//! What the controller tells the firmware, the virtual rig and the tests: its state, fault,
//! configuration, identified models and loop gains, and the status snapshot telemetry is made
//! from. Read-only.

use super::Controller;
use crate::bowl::{MotorSpeeds, combined_speed_from_trig};
use crate::control::commission::{Identified, IdentifyError};
use crate::control::config::ControllerConfig;
use crate::control::planner::ResidenceForBowlSpeed;
use crate::control::supervisor::{Fault, State, fault_code};

/// Per-axis part of the status snapshot.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AxisStatus {
    /// Commanded target, rad/s (signed).
    pub target_rad_s: f32,
    /// Ramped reference the loop follows now, rad/s.
    pub reference_rad_s: f32,
    /// Measured speed with the commanded sign, rad/s.
    pub measured_rad_s: f32,
    /// Duty applied, -1..=1 (0 = bridge coasting).
    pub duty: f32,
    /// Edges accepted since start (wrapping).
    pub pulses: u32,
    /// Edges rejected as bounces.
    pub rejected_edges: u32,
    /// Pulses inferred as missing.
    pub inferred_missing: u32,
    /// The estimator has a valid measurement.
    pub measurement_valid: bool,
}

/// A snapshot of the controller for telemetry.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Status {
    /// Operating state.
    pub state: State,
    /// Latched fault, if any.
    pub fault: Option<Fault>,
    /// Fault code (0 = none), see [`Fault::code`].
    pub fault_code: u8,
    /// Per axis, indexed by `PRECESSION` and `SPIN`.
    pub axes: [AxisStatus; 2],
    /// Combined bowl speed of the targets (Eq. 2), rad/s.
    pub combined_target_rad_s: f32,
    /// Combined bowl speed of the measured speeds (Eq. 2), rad/s.
    pub combined_measured_rad_s: f32,
}

impl Controller {
    /// Operating state.
    pub fn state(&self) -> State {
        self.state
    }

    /// Latched fault, if any.
    pub fn fault(&self) -> Option<Fault> {
        self.fault
    }

    /// The configuration in force (with identified models after commissioning).
    pub fn config(&self) -> &ControllerConfig {
        &self.cfg
    }

    /// The speed loop's gains on `axis` at its bandwidth ceiling (the schedule lowers both in
    /// proportion at sparse pulses): `(kp, ki)` in duty per rad/s and duty per rad.
    pub fn loop_gains(&self, axis: usize) -> Option<(f32, f32)> {
        let k = &self.axes.get(axis)?.k;
        let wc = crate::control::pi::bandwidth_ceiling_rad_s(self.cfg.axes.get(axis)?);
        Some((k.kp(wc), k.ki_per_s(wc)))
    }

    /// The once-per-revolution load learned on `axis` (0 = precession, 1 = spin): revolutions
    /// learned since it was last forgotten and the pattern's amplitude, duty (see
    /// [`crate::control::load_pattern`]). `(0, 0.0)` for an axis out of range.
    pub fn load_pattern(&self, axis: usize) -> (u16, f32) {
        self.axes.get(axis).map_or((0, 0.0), |a| {
            (a.load.revolutions_learned(), a.load.amplitude_duty())
        })
    }

    /// Revolutions of the sensor wheel's tooth offsets learned on `axis` (teeth.rs; from 2
    /// the estimator counts each gap at its learned length). 0 for an axis out of range.
    pub fn wheel_revolutions_learned(&self, axis: usize) -> u16 {
        self.axes
            .get(axis)
            .map_or(0, |a| a.est.teeth_revolutions_learned())
    }

    /// Results of the last commissioning run, per axis.
    pub fn identified(&self) -> [Option<Identified>; 2] {
        self.identified
    }

    /// Why the last commissioning run failed, if it did.
    pub fn identify_error(&self) -> Option<IdentifyError> {
        self.identify_error
    }

    /// Status snapshot for telemetry (computes Eq. 2; call at telemetry rate, not per tick).
    pub fn status(&self) -> Status {
        let targets = self.planner.targets();
        let ramped = self.planner.ramped();
        let mut axes = [AxisStatus::default(); 2];
        for (i, (out, a)) in axes.iter_mut().zip(&self.axes).enumerate() {
            *out = AxisStatus {
                target_rad_s: targets[i],
                reference_rad_s: ramped[i],
                measured_rad_s: a.measured,
                duty: a.duty,
                pulses: a.est.accepted_edges(),
                rejected_edges: a.est.rejected_edges(),
                inferred_missing: a.est.inferred_missing(),
                measurement_valid: a.est.is_valid(),
            };
        }
        let combined = |w: [f32; 2]| {
            combined_speed_from_trig(
                self.cos_axes,
                self.sin_axes,
                MotorSpeeds {
                    precession_rad_s: w[0],
                    spin_rad_s: w[1],
                },
            )
            .unwrap_or(0.0)
        };
        Status {
            state: self.state,
            fault: self.fault,
            fault_code: fault_code(self.fault),
            axes,
            combined_target_rad_s: combined(targets),
            combined_measured_rad_s: combined([self.axes[0].measured, self.axes[1].measured]),
        }
    }

    /// Predicted residence time at the measured combined bowl speed, s, from a forward particle
    /// model (flat or Coriolis). For telemetry: call at the telemetry rate, never per tick.
    pub fn predicted_residence_time_s(&self, model: &dyn ResidenceForBowlSpeed) -> Option<f32> {
        let w = self.status().combined_measured_rad_s;
        if w > 0.0 {
            model.residence_time_s(w)
        } else {
            None
        }
    }
}

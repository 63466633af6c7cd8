//! Setpoints: motor speeds asked for directly, or a target residence time turned into motor
//! speeds through the particle model's inverse and paper Eq. 2; then ramps.
//!
//! The residence-time inverse is behind [`BowlSpeedForResidence`] so the controller does not
//! depend on which particle model (flat Eq. 6/7 or Coriolis Eq. 10/11, with the corrections of
//! docs/model.md) or which scene (bowl radius, start radius, resistance coefficient) is in use:
//! the caller passes the model in with the command.

use crate::bowl::split_from_trig;

/// Why the particle model's inverse gave no bowl speed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum InverseFailure {
    /// No bowl speed gives this residence time in this scene (for example, the particle never
    /// leaves, or the time is shorter than the fastest allowed speed gives).
    Unreachable,
    /// The model rejected its inputs (scene or target invalid).
    ModelRejected,
}

/// The particle model's inverse: the combined bowl speed that gives a residence time.
pub trait BowlSpeedForResidence {
    /// Combined bowl speed (paper Eq. 2's omega), rad/s, for the residence time `target_s`.
    fn omega_rad_s(&self, target_s: f32) -> Result<f32, InverseFailure>;
}

/// The particle model's forward direction, used for telemetry's predicted residence time.
pub trait ResidenceForBowlSpeed {
    /// Residence time, s, at combined bowl speed `omega_rad_s`; `None` if the particle never
    /// leaves (or the model rejects the inputs).
    fn residence_time_s(&self, omega_rad_s: f32) -> Option<f32>;
}

/// Combined bowl speed split into motor speeds by Eq. 2 at a fixed spin/precession ratio.
/// Returns `[precession, spin]`, rad/s, or `None` if the geometry rejects the split.
/// `cos_axes`, `sin_axes`: of the angle between the axes.
pub fn split_combined(
    omega_rad_s: f32,
    cos_axes: f32,
    sin_axes: f32,
    spin_per_precession: f32,
) -> Option<[f32; 2]> {
    let s = split_from_trig(cos_axes, sin_axes, omega_rad_s, spin_per_precession).ok()?;
    Some([s.precession_rad_s, s.spin_rad_s])
}

/// Ramps both axes' references toward their targets.
///
/// Two rules beyond the ramps, both because the sensors cannot see direction:
/// - A reversal ramps to zero and holds there until the axis's estimator reads zero.
/// - The spin axis starts ramping only once the precession axis has started (its reference
///   is off zero: its kick, the identified breakaway duty, is on from that tick), if
///   precession is asked to turn at all. The spin motor rides on the rod: its accelerating
///   torque reacts on the precession axis, and a rod whose motor had not yet got going could
///   be dragged *backwards*, which a direction-blind loop would read as forward motion. With
///   the rod's motor kicked to its breakaway, that reaction would have to exceed the kick and
///   the rod's stiction together; on 600 family starts it reached at most 0.62 of the stiction
///   alone while the rod was held, no rod turned backwards, and the rod's decoupling feeds it
///   forward (docs/control.md, "The spin starts with the rod"). Waiting for the rod's first
///   edge held the spin 0.05-0.8 s from rest.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SetpointPlanner {
    target: [f32; 2],
    ramped: [f32; 2],
    steady_s: [f32; 2],
    reversing: [bool; 2],
}

impl SetpointPlanner {
    /// Everything at rest.
    pub const REST: Self = Self {
        target: [0.0; 2],
        ramped: [0.0; 2],
        steady_s: [0.0; 2],
        reversing: [false; 2],
    };

    /// Sets the targets (already validated), rad/s.
    pub const fn set_targets(&mut self, target: [f32; 2]) {
        self.target = target;
    }

    /// Targets, rad/s.
    pub fn targets(&self) -> [f32; 2] {
        self.target
    }

    /// Ramped references, rad/s.
    pub fn ramped(&self) -> [f32; 2] {
        self.ramped
    }

    /// Seconds since each axis's ramp last moved.
    pub fn steady_s(&self) -> [f32; 2] {
        self.steady_s
    }

    /// True once the spin axis may ramp: the precession axis has started, or is not asked to
    /// turn (see the type's docs).
    fn spin_released(&self) -> bool {
        self.ramped[0] != 0.0 || self.target[0] == 0.0
    }

    /// Drops everything to rest at once (fault, abort).
    pub fn reset(&mut self) {
        *self = Self::REST;
    }

    /// Advances the ramps by `dt_s`. `max_step` is the largest change per step of each axis,
    /// `stopped` says whether each axis's estimator reads zero.
    #[inline(always)]
    pub fn step(&mut self, dt_s: f32, max_step: [f32; 2], stopped: [bool; 2]) -> [f32; 2] {
        for i in 0..2 {
            let (t, r) = (self.target[i], self.ramped[i]);
            let d = t - r;
            let m = max_step[i];
            let mut next = if d > m {
                r + m
            } else if d < -m {
                r - m
            } else {
                t
            };
            if r * next < 0.0 {
                // Crossing zero (a reversal): stop at zero first.
                next = 0.0;
                self.reversing[i] = true;
            }
            if r == 0.0 {
                if self.reversing[i] {
                    if stopped[i] {
                        self.reversing[i] = false;
                    } else {
                        next = 0.0;
                    }
                }
                // The precession's ramp has stepped already this tick (`i` = 0 first).
                if i == 1 && !self.spin_released() {
                    next = 0.0;
                }
            }
            if next == r {
                self.steady_s[i] += dt_s;
            } else {
                self.steady_s[i] = 0.0;
            }
            self.ramped[i] = next;
        }
        self.ramped
    }
}

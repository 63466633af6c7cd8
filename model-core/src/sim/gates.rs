//! The simulated rig's release solenoid and gates: one granule at a time is dropped at the
//! start radius, follows its equation of motion ([`super::granule`]) under the plant's true
//! combined bowl speed (paper Eq. 2 from the two true shaft speeds) one step at a time, and the
//! exit gate fires when it reaches the rim, with the gate's timing error, to the microsecond.
//! Every simulated rig uses this one: the host's virtual rig, the QEMU board's plant task.

use super::granule::{Granule, ParticleParams};
use super::prng::Prng;
use crate::bowl::{MotorSpeeds, combined_speed_from_trig};

/// The granule in the bowl and its release time on the capture clock, us.
#[derive(Debug, Clone, Copy)]
struct InFlight {
    granule: Granule,
    released_us: u32,
}

/// Granules, the release and the exit gate of one simulated rig.
#[derive(Debug, Clone, Copy)]
pub struct Gates {
    particle: ParticleParams,
    rng: Prng,
    cos_sin: (f64, f64),
    in_flight: Option<InFlight>,
}

impl Gates {
    /// Granules drawn from `particle` with a generator seeded by `seed`, in a bowl whose axes
    /// are `axes_rad` apart (paper Eq. 2).
    pub fn new(particle: ParticleParams, seed: u32, axes_rad: f64) -> Self {
        Self {
            particle,
            rng: Prng::new(seed ^ 0x6772_616e),
            cos_sin: (libm::cos(axes_rad), libm::sin(axes_rad)),
            in_flight: None,
        }
    }

    /// The granules' truth.
    pub fn particle(&self) -> &ParticleParams {
        &self.particle
    }

    /// A granule is in the bowl.
    pub fn in_bowl(&self) -> bool {
        self.in_flight.is_some()
    }

    /// Takes the granule out of the bowl without an exit (one that never leaves).
    pub fn clear_bowl(&mut self) {
        self.in_flight = None;
    }

    /// Drops a granule at capture time `now_us` (the release gate's time); a granule already
    /// in the bowl is replaced.
    pub fn drop_granule(&mut self, now_us: u32) {
        self.in_flight = Some(InFlight {
            granule: self.particle.release(&mut self.rng),
            released_us: now_us,
        });
    }

    /// One step of `dt_s`, the shafts turning at `speeds_rad_s` (true, `[precession, spin]`)
    /// over it. Returns the exit gate's capture time, us, in the step the granule reaches the
    /// rim.
    pub fn step(&mut self, speeds_rad_s: [f64; 2], dt_s: f64) -> Option<u32> {
        let f = self.in_flight.as_mut()?;
        let bowl_rad_s = combined_speed_from_trig(
            self.cos_sin.0,
            self.cos_sin.1,
            MotorSpeeds {
                precession_rad_s: speeds_rad_s[0],
                spin_rad_s: speeds_rad_s[1],
            },
        )
        .unwrap_or(0.0);
        let exit_s = f.granule.step(bowl_rad_s, dt_s)?;
        let released_us = f.released_us;
        self.in_flight = None;
        let error_s = self.particle.gate_error_s(&mut self.rng);
        let after_us = libm::round((exit_s + error_s).clamp(0.0, 4.0e9) * 1e6) as u64;
        Some(released_us.wrapping_add((after_us & 0xFFFF_FFFF) as u32))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::particle::{self, Model, Scene};

    #[test]
    fn a_granule_at_a_constant_speed_leaves_when_the_closed_form_says() {
        let particle = ParticleParams {
            model: Model::Flat,
            ..ParticleParams::default()
        };
        // Axes at right angles: the bowl turns at the spin speed alone.
        let mut gates = Gates::new(particle, 1, core::f64::consts::FRAC_PI_2);
        assert_eq!(gates.step([0.0, 4.0], 1e-3), None, "no granule yet");
        gates.drop_granule(2_000_000);
        assert!(gates.in_bowl());
        let mut exit = None;
        for _ in 0..10_000 {
            if let Some(at) = gates.step([0.0, 4.0], 1e-3) {
                exit = Some(at);
                break;
            }
        }
        let measured = f64::from(exit.unwrap() - 2_000_000) * 1e-6;
        let scene = Scene {
            omega_rad_s: 4.0,
            mu: particle.mu,
            g_m_s2: 9.81,
            k2: particle.k2,
            ri_m: particle.release_radius_m,
            rim_radius_m: particle.rim_radius_m,
        };
        let want = particle::residence(&scene, Model::Flat)
            .unwrap()
            .residence_time_s();
        // RK4 at 1 ms with the exit interpolated in the step, rounded to the microsecond.
        assert!((measured - want).abs() < 2e-6, "{measured} vs {want}");
        assert!(!gates.in_bowl());
    }
}

//! The simulated rig's release solenoid and gates: one granule at a time is dropped at the
//! start radius, follows its equation of motion ([`super::granule`]) under the plant's true
//! combined bowl speed (paper Eq. 2 from the two true shaft speeds) one step at a time, and the
//! exit gate fires when it reaches the rim, with the gate's timing error, to the microsecond.
//! A granule in the bowl model ([`super::bowl_granule`], `[particle] model = "bowl"`) is
//! followed once, at the shaft speeds of the moment it drops ([`Gates::drop_granule_at`]), and
//! its exit gate fires when that time has passed.
//! Every simulated rig uses this one: the host's virtual rig, the QEMU board's plant task.

use super::bowl_granule::BowlRelease;
use super::granule::{Granule, ParticleParams};
use super::prng::Prng;
use crate::bowl::{MotorSpeeds, combined_speed_from_trig};

/// How the granule in the bowl moves.
#[derive(Debug, Clone, Copy)]
enum Motion {
    /// Stepped under the speed of each step (the paper's radial equations).
    Stepped(Granule),
    /// Its exit known at the release (the bowl model): seconds from the release to the exit
    /// (`None`: never), and the time since the release.
    Timed { exit_s: Option<f64>, elapsed_s: f64 },
}

/// The granule in the bowl and its release time on the capture clock, us.
#[derive(Debug, Clone, Copy)]
struct InFlight {
    motion: Motion,
    released_us: u32,
}

/// Granules, the release and the exit gate of one simulated rig.
#[derive(Debug, Clone, Copy)]
pub struct Gates {
    particle: ParticleParams,
    rng: Prng,
    cos_sin: (f64, f64),
    in_flight: Option<InFlight>,
    last_bowl_release: Option<BowlRelease>,
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
            last_bowl_release: None,
        }
    }

    /// The granules' truth.
    pub fn particle(&self) -> &ParticleParams {
        &self.particle
    }

    /// The last granule dropped in the bowl model: its azimuth, friction, start and exit (the
    /// hidden truth a fit of the gate times should find; `None` before the first).
    pub fn last_bowl_release(&self) -> Option<BowlRelease> {
        self.last_bowl_release
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
    /// in the bowl is replaced. It follows the paper's radial equation (`particle.model`); a
    /// rig whose granules follow the bowl model drops them with [`Gates::drop_granule_at`].
    pub fn drop_granule(&mut self, now_us: u32) {
        self.in_flight = Some(InFlight {
            motion: Motion::Stepped(self.particle.release(&mut self.rng)),
            released_us: now_us,
        });
    }

    /// As [`Gates::drop_granule`], the shafts turning at `speeds_rad_s` (true,
    /// `[precession, spin]`): with a bowl truth (`particle.bowl`) the granule follows the bowl
    /// model at these speeds from a random azimuth, its exit computed now (milliseconds of
    /// CPU on a PC: the firmware's QEMU plant, whose granules follow the radial equations,
    /// calls [`Gates::drop_granule`] and never links the bowl model).
    pub fn drop_granule_at(&mut self, now_us: u32, speeds_rad_s: [f64; 2]) {
        let Some(truth) = self.particle.bowl else {
            return self.drop_granule(now_us);
        };
        let r = truth.release(&self.particle, &mut self.rng, speeds_rad_s);
        self.last_bowl_release = Some(r);
        self.in_flight = Some(InFlight {
            motion: Motion::Timed {
                exit_s: r.exit_s,
                elapsed_s: 0.0,
            },
            released_us: now_us,
        });
    }

    /// One step of `dt_s`, the shafts turning at `speeds_rad_s` (true, `[precession, spin]`)
    /// over it. Returns the exit gate's capture time, us, in the step the granule reaches the
    /// rim.
    pub fn step(&mut self, speeds_rad_s: [f64; 2], dt_s: f64) -> Option<u32> {
        let f = self.in_flight.as_mut()?;
        let exit_s = match &mut f.motion {
            Motion::Stepped(granule) => {
                let bowl_rad_s = combined_speed_from_trig(
                    self.cos_sin.0,
                    self.cos_sin.1,
                    MotorSpeeds {
                        precession_rad_s: speeds_rad_s[0],
                        spin_rad_s: speeds_rad_s[1],
                    },
                )
                .unwrap_or(0.0);
                granule.step(bowl_rad_s, dt_s)?
            }
            Motion::Timed { exit_s, elapsed_s } => {
                if dt_s.is_finite() && dt_s > 0.0 {
                    *elapsed_s += dt_s;
                }
                // The gate fires in the step within which the exit falls.
                let exit = (*exit_s)?;
                if *elapsed_s < exit {
                    return None;
                }
                exit
            }
        };
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

    /// A granule in the bowl model: the exit gate fires at the release plus the bowl model's
    /// time for the drawn azimuth at the speeds of the drop (no jitter), to the microsecond;
    /// one held by a vertical wall never fires.
    #[test]
    fn a_granule_in_the_bowl_leaves_when_the_bowl_model_says() {
        use crate::particle::bowl::BowlShape;
        use crate::sim::bowl_granule::{BowlTruth, rig};
        let (truth, particle) = rig();
        let speeds = [1.3, 1.1];
        let mut gates = Gates::new(particle, 9, 60f64.to_radians());
        // The same draw, made again from the same generator state.
        let mut rng = gates.rng;
        let want = truth.release(&particle, &mut rng, speeds).exit_s.unwrap();
        gates.drop_granule_at(1_000_000, speeds);
        let mut exit = None;
        for _ in 0..10_000 {
            if let Some(at) = gates.step(speeds, 1e-3) {
                exit = Some(at);
                break;
            }
        }
        let got = f64::from(exit.unwrap() - 1_000_000) * 1e-6;
        assert!((got - want).abs() <= 0.5e-6, "{got} vs {want}");
        let mut held = particle;
        held.bowl = Some(BowlTruth {
            shape: BowlShape {
                wall_angle_rad: core::f64::consts::FRAC_PI_2,
                wall_height_m: 0.02,
                ..truth.shape
            },
            ..truth
        });
        let mut gates = Gates::new(held, 9, 60f64.to_radians());
        gates.drop_granule_at(0, speeds);
        for _ in 0..5_000 {
            assert_eq!(gates.step(speeds, 1e-3), None);
        }
        assert!(gates.in_bowl(), "held by the wall: still in the bowl");
    }
}

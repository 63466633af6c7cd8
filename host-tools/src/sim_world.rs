//! What the virtual rig's plant does not hold and a real rig's world does: injected faults
//! (INJECT) and granules (RELEASE) with the two gates that time them.
//!
//! A lost sensor withholds the plant's edges from the controller, a stalled motor gets no drive.
//! A RELEASE drops a granule (`model_core::sim::granule`, drawn from the rig file's `[particle]`
//! truth) at the next control period: the release gate fires then, the granule follows its
//! equation of motion under the plant's true combined bowl speed (paper Eq. 2 from the two true
//! shaft speeds) one control period at a time, and the exit gate fires when it reaches the rim,
//! with the gate's timing error, to the microsecond, as the firmware's capture would report it.

use std::collections::VecDeque;

use model_core::binding::Injector;
use model_core::sim::granule::{Granule, ParticleParams};
use model_core::sim::prng::Prng;
use model_core::wire::{GateEvent, GateKind, Injection, Reason};

/// Gate events kept for the link (a real rig's capture buffer is as small).
const EVENT_QUEUE: usize = 16;

/// A granule in the bowl and the device time of its release, s.
#[derive(Debug, Clone, Copy)]
struct InFlight {
    granule: Granule,
    released_s: f64,
}

/// The simulated world around the virtual rig's controller.
#[derive(Debug, Clone)]
pub struct SimWorld {
    injection: Injection,
    particle: ParticleParams,
    rng: Prng,
    release_asked: bool,
    in_flight: Option<InFlight>,
    events: VecDeque<GateEvent>,
    /// Events the queue had no room for (the link was not read).
    pub events_lost: u32,
}

impl Injector for SimWorld {
    fn inject(&mut self, what: Injection) -> Result<(), Reason> {
        self.injection = what;
        Ok(())
    }

    /// One granule at a time: a release while one is in the bowl is refused (`STATE`).
    fn release(&mut self) -> Result<(), Reason> {
        if self.release_asked || self.in_flight.is_some() {
            return Err(Reason::State);
        }
        self.release_asked = true;
        Ok(())
    }

    fn gate_event(&mut self) -> Option<GateEvent> {
        self.events.pop_front()
    }
}

impl SimWorld {
    /// No fault, no granule; granules drawn from `particle` with a generator seeded by `seed`.
    pub fn new(particle: ParticleParams, seed: u32) -> Self {
        Self {
            injection: Injection::None,
            particle,
            rng: Prng::new(seed ^ 0x6772_616e),
            release_asked: false,
            in_flight: None,
            events: VecDeque::with_capacity(EVENT_QUEUE),
            events_lost: 0,
        }
    }

    /// The granules' truth.
    pub fn particle(&self) -> &ParticleParams {
        &self.particle
    }

    /// The sensor of `axis` is lost (its edges do not reach the controller).
    pub fn sensor_lost(&self, axis: usize) -> bool {
        matches!(
            (self.injection, axis),
            (Injection::SensorLostPrecession, 0) | (Injection::SensorLostSpin, 1)
        )
    }

    /// The motor of `axis` gets no drive.
    pub fn stalled(&self, axis: usize) -> bool {
        matches!(
            (self.injection, axis),
            (Injection::StallPrecession, 0) | (Injection::StallSpin, 1)
        )
    }

    /// Takes the granule out of the bowl without an exit event (one that never leaves).
    pub fn clear_bowl(&mut self) {
        self.release_asked = false;
        self.in_flight = None;
    }

    fn push(&mut self, kind: GateKind, at_s: f64) {
        if self.events.len() == EVENT_QUEUE {
            self.events_lost = self.events_lost.saturating_add(1);
            return;
        }
        // Device time in microseconds, modulo 2^32, as the capture timer counts.
        let time_us = ((at_s.max(0.0) * 1e6).round() as u64 & 0xFFFF_FFFF) as u32;
        self.events.push_back(GateEvent {
            kind,
            time_us,
            boot: 0,
        });
    }

    /// One control period from device time `now_s`, the bowl turning at `bowl_rad_s` (true).
    pub fn step(&mut self, bowl_rad_s: f64, now_s: f64, dt_s: f64) {
        if self.release_asked {
            self.release_asked = false;
            self.in_flight = Some(InFlight {
                granule: self.particle.release(&mut self.rng),
                released_s: now_s,
            });
            self.push(GateKind::Release, now_s);
        }
        let Some(f) = &mut self.in_flight else {
            return;
        };
        if let Some(exit_s) = f.granule.step(bowl_rad_s, dt_s) {
            let released_s = f.released_s;
            self.in_flight = None;
            let error_s = self.particle.gate_error_s(&mut self.rng);
            self.push(GateKind::Exit, released_s + (exit_s + error_s).max(0.0));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use model_core::particle::{self, Model, Scene};

    #[test]
    fn a_granule_at_a_constant_speed_leaves_when_the_closed_form_says() {
        let particle = ParticleParams {
            model: Model::Flat,
            ..ParticleParams::default()
        };
        let mut world = SimWorld::new(particle, 1);
        assert_eq!(world.gate_event(), None);
        world.release().unwrap();
        assert_eq!(world.release(), Err(Reason::State), "one granule at a time");
        let (w, dt) = (4.0, 1e-3);
        let mut t = 2.0;
        for _ in 0..10_000 {
            world.step(w, t, dt);
            t += dt;
        }
        let release = world.gate_event().unwrap();
        let exit = world.gate_event().unwrap();
        assert_eq!(
            (release.kind, exit.kind),
            (GateKind::Release, GateKind::Exit)
        );
        assert_eq!(release.time_us, 2_000_000);
        let measured = f64::from(exit.time_us.wrapping_sub(release.time_us)) * 1e-6;
        let scene = Scene {
            omega_rad_s: w,
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
        // The granule has left: the next one may drop.
        world.release().unwrap();
    }
}

//! What the virtual rig's plant does not hold and a real rig's world does: injected faults
//! (INJECT) and granules (RELEASE) with the two gates that time them.
//!
//! A lost sensor withholds the plant's edges from the controller, a stalled motor gets no drive.
//! A RELEASE drops a granule (`model_core::sim::granule`, drawn from the rig file's `[particle]`
//! truth) at the next control period: the release gate fires then, the granule follows its
//! equation of motion under the plant's true combined bowl speed (paper Eq. 2 from the two true
//! shaft speeds) one control period at a time, and the exit gate fires when it reaches the rim,
//! with the gate's timing error, to the microsecond, as the firmware's capture would report it.
//! A granule in the bowl model (`[particle] model = "bowl"`) follows that model at the true
//! shaft speeds of the period it drops in, from a random azimuth, and the exit gate fires when
//! its centre passes the lip (`model_core::sim::bowl_granule`).

use std::collections::VecDeque;

use model_core::binding::Injector;
use model_core::sim::gates::Gates;
use model_core::sim::granule::ParticleParams;
use model_core::wire::{GateEvent, GateKind, Injection, Reason};

/// Gate events kept for the link (a real rig's capture buffer is as small).
const EVENT_QUEUE: usize = 16;

/// The simulated world around the virtual rig's controller.
#[derive(Debug, Clone)]
pub struct World {
    injection: Injection,
    gates: Gates,
    release_asked: bool,
    events: VecDeque<GateEvent>,
    /// Events the queue had no room for (the link was not read).
    pub events_lost: u32,
}

impl Injector for World {
    fn inject(&mut self, what: Injection) -> Result<(), Reason> {
        self.injection = what;
        Ok(())
    }

    /// One granule at a time: a release while one is in the bowl is refused (`STATE`).
    fn release(&mut self) -> Result<(), Reason> {
        if self.release_asked || self.gates.in_bowl() {
            return Err(Reason::State);
        }
        self.release_asked = true;
        Ok(())
    }

    fn gate_event(&mut self) -> Option<GateEvent> {
        self.events.pop_front()
    }
}

impl World {
    /// No fault, no granule; granules drawn from `particle` with a generator seeded by `seed`,
    /// in a bowl whose axes are `axes_rad` apart.
    pub fn new(particle: ParticleParams, seed: u32, axes_rad: f64) -> Self {
        Self {
            injection: Injection::None,
            gates: Gates::new(particle, seed, axes_rad),
            release_asked: false,
            events: VecDeque::with_capacity(EVENT_QUEUE),
            events_lost: 0,
        }
    }

    /// The granules' truth.
    pub fn particle(&self) -> &ParticleParams {
        self.gates.particle()
    }

    /// The last granule dropped in the bowl model, as drawn (azimuth, `mu_s`, start, exit).
    pub fn last_bowl_release(&self) -> Option<model_core::sim::bowl_granule::BowlRelease> {
        self.gates.last_bowl_release()
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
        self.gates.clear_bowl();
    }

    fn push(&mut self, kind: GateKind, time_us: u32) {
        if self.events.len() == EVENT_QUEUE {
            self.events_lost = self.events_lost.saturating_add(1);
            return;
        }
        self.events.push_back(GateEvent {
            kind,
            time_us,
            boot: 0,
        });
    }

    /// One control period from device time `now_us`, the shafts turning at `speeds_rad_s`
    /// (true) over it.
    pub fn step(&mut self, speeds_rad_s: [f64; 2], now_us: u32, dt_s: f64) {
        if self.release_asked {
            self.release_asked = false;
            self.gates.drop_granule_at(now_us, speeds_rad_s);
            self.push(GateKind::Release, now_us);
        }
        if let Some(exit_us) = self.gates.step(speeds_rad_s, dt_s) {
            self.push(GateKind::Exit, exit_us);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn releases_are_one_at_a_time_and_timed_by_both_gates() {
        let mut world = World::new(ParticleParams::default(), 1, core::f64::consts::FRAC_PI_2);
        assert_eq!(world.gate_event(), None);
        world.release().unwrap();
        assert_eq!(world.release(), Err(Reason::State), "one granule at a time");
        let mut now_us = 2_000_000u32;
        for _ in 0..10_000 {
            world.step([0.0, 4.0], now_us, 1e-3);
            now_us += 1000;
        }
        let release = world.gate_event().unwrap();
        let exit = world.gate_event().unwrap();
        assert_eq!(
            (release.kind, exit.kind),
            (GateKind::Release, GateKind::Exit)
        );
        assert_eq!(release.time_us, 2_000_000);
        assert!(exit.time_us > release.time_us);
        // The granule has left: the next one may drop.
        world.release().unwrap();
    }
}

//! The virtual rig behind `bowl serve --pty` / `--capture`: the simulated plant
//! (`model_core::sim::Plant`) in place of the motors and sensors, and in front of it the same
//! binding of the controller and the particle model to the protocol that the firmware runs
//! (`model_core::binding::ControllerBackend`).
//!
//! Only the simulated world is particular to it ([`World`]): injected faults sit between the
//! plant and the controller (a lost sensor withholds the plant's edges, a stalled motor gets no
//! drive), and granules dropped by RELEASE move under the plant's true bowl speed, timed by the
//! gates.

use anyhow::{Result, anyhow};
use model_core::binding::{ControllerBackend, Record, default_params, persisted};
use model_core::control::ControllerConfig;
use model_core::sim::granule::ParticleParams;
use model_core::sim::{AssemblyError, PlantParams, commission_on_plant};
use model_core::wire::{Hello, ParamId, ResetCause};

use crate::world::World;

/// The plant, and the controller bound to the protocol.
#[derive(Clone)]
pub struct SimulatedBackend {
    plant: model_core::sim::Plant,
    rig: ControllerBackend<World>,
    ticks: u64,
    total_ms: u64,
    now_ms: u32,
}

impl SimulatedBackend {
    /// The nominal plant (seeded noise) and the nominal controller, commissioned on it.
    #[cfg(test)]
    pub fn new(seed: u32) -> Result<Self> {
        Self::with_plant(PlantParams::nominal(), ParticleParams::default(), seed)
    }

    /// The plant (seeded noise) and the nominal controller (told the plant's teeth),
    /// commissioned on the plant as the real rig is once after assembly (through the same
    /// COMMISSION path the wire uses), then at rest at device time 0.
    pub fn with_plant(
        plant_params: PlantParams,
        particle: ParticleParams,
        seed: u32,
    ) -> Result<Self> {
        let base = ControllerConfig::nominal();
        let mut params = default_params();
        for (id, axis) in [(ParamId::Teeth1, 0), (ParamId::Teeth2, 1)] {
            params[id.index()] = i32::from(plant_params.axes[axis].sensor.pulses_per_rev);
        }
        particle.describe_bowl(&mut params);
        // The rig as built: granules in a rig file's bowl feel its tilt, and the controller
        // is told the same angle (AXES_MDEG, as set once on a real rig), so that its split of
        // the bowl speed and the granules agree (both paper Eq. 2).
        let axes_rad = particle
            .bowl
            .map_or(f64::from(base.axes_angle_rad), |b| b.axes_angle_rad);
        let (lo, hi) = ParamId::AxesMdeg.range();
        params[ParamId::AxesMdeg.index()] =
            ((axes_rad.to_degrees() * 1e3).round() as i32).clamp(lo, hi);
        let hello = Hello {
            reset_cause: ResetCause::Unknown,
            reset_count: 0,
        };
        let models = [base.axes[0].model, base.axes[1].model];
        let (rig, checked) = ControllerBackend::new(
            base,
            persisted(&Record {
                params,
                models,
                identified: [false; 2],
            }),
            hello,
            World::new(particle, seed, axes_rad),
        );
        checked.map_err(|r| anyhow!("rig parameters refused: {}", r.token()))?;
        let mut sim = Self {
            plant: model_core::sim::Plant::new(plant_params, seed),
            rig,
            ticks: 0,
            total_ms: 0,
            now_ms: 0,
        };
        commission_on_plant(&mut sim.rig, &mut sim.plant).map_err(|e| match e {
            AssemblyError::Refused(r) => anyhow!("commissioning refused: {}", r.token()),
            AssemblyError::Ended(state, why) => anyhow!(
                "commissioning on the simulated plant ended {} ({}): check the rig's motor, \
                 supply and friction values",
                model_core::wire::DeviceState::from(state).words(),
                why.map_or("no reason given", |e| e.reason())
            ),
        })?;
        sim.ticks = 0;
        sim.rig.set_now_ms(0);
        Ok(sim)
    }

    /// The controller and particle model behind the protocol.
    pub fn bound(&self) -> &ControllerBackend<World> {
        &self.rig
    }

    /// The same, to hand to the protocol device.
    pub fn bound_mut(&mut self) -> &mut ControllerBackend<World> {
        &mut self.rig
    }

    fn dt_s(&self) -> f32 {
        1.0 / self.rig.controller().config().tick_hz as f32
    }

    /// Runs the control ticks up to device time `now_ms`.
    pub fn advance_to_ms(&mut self, now_ms: u32) {
        let tick_hz = u64::from(self.rig.controller().config().tick_hz);
        let dt_s = self.dt_s();
        // Device time counts up from 0 and wraps after 49 days; the tick count does not.
        self.total_ms += u64::from(now_ms.wrapping_sub(self.now_ms));
        self.now_ms = now_ms;
        self.rig.set_now_ms(now_ms);
        let target = self.total_ms * tick_hz / 1000;
        while self.ticks < target {
            self.tick(dt_s);
        }
    }

    fn tick(&mut self, dt_s: f32) {
        let now = self.plant.now_ticks();
        let world = self.rig.injector();
        let (lost, stalled) = (
            [0, 1].map(|a| world.sensor_lost(a)),
            [0, 1].map(|a| world.stalled(a)),
        );
        let plant = &self.plant;
        let edges = |axis: usize| -> &[u32] { if lost[axis] { &[] } else { plant.edges(axis) } };
        let duties = self.rig.controller_mut().tick(now, [edges(0), edges(1)]);
        let driven = [0, 1].map(|axis| if stalled[axis] { 0.0 } else { duties[axis] });
        // A granule moves during the period under the speeds the shafts have over it; gate
        // times are device time in us (0 when commissioning at boot ended).
        let tick_hz = u64::from(self.rig.controller().config().tick_hz);
        let now_us = ((self.ticks * 1_000_000 / tick_hz) & 0xFFFF_FFFF) as u32;
        let speeds = [0, 1].map(|a| f64::from(self.plant.speed_rad_s(a)));
        self.plant.advance(driven, dt_s);
        self.rig
            .injector_mut()
            .step(speeds, now_us, f64::from(dt_s));
        self.ticks += 1;
    }

    /// The simulated world: faults, granules and gates.
    pub fn world_mut(&mut self) -> &mut World {
        self.rig.injector_mut()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use model_core::wire::Reason;
    use model_core::wire::device::Backend as _;

    /// The nominal parameters are all inside their wire ranges (else PARAMS would fail).
    #[test]
    fn nominal_parameters_fit_the_wire() {
        let rig = SimulatedBackend::new(1).unwrap();
        for id in ParamId::ALL {
            if id == ParamId::TelemetryHz {
                continue;
            }
            let (lo, hi) = id.range();
            let v = rig.bound().param(id);
            assert!((lo..=hi).contains(&v), "{} = {v}", id.token());
        }
    }

    /// A rig whose granules sit in a bowl tilted 30 deg tells its controller 30 deg
    /// (AXES_MDEG): the split of a bowl speed into motor speeds and the granules use one angle.
    #[test]
    fn the_controller_is_told_the_tilt_its_granules_feel() {
        use model_core::particle::bowl::BowlShape;
        use model_core::sim::bowl_granule::BowlTruth;
        let truth = BowlTruth {
            shape: BowlShape {
                wall_angle_rad: 60f64.to_radians(),
                wall_height_m: 0.01,
                fillet_radius_m: 0.0,
                restitution: 0.0,
            },
            axes_angle_rad: 30f64.to_radians(),
            particle_radius_m: 0.003,
            sliding_mu: 0.4,
            sliding_mu_spread: 0.0,
        };
        let particle = ParticleParams {
            mu: 0.029,
            release_radius_m: 0.0375,
            rim_radius_m: 0.075,
            bowl: Some(truth),
            ..ParticleParams::default()
        };
        let rig = SimulatedBackend::with_plant(PlantParams::nominal(), particle, 1).unwrap();
        assert_eq!(rig.bound().param(ParamId::AxesMdeg), 30_000);
        let cfg = rig.bound().controller().config();
        assert!((cfg.axes_angle_rad - 30f32.to_radians()).abs() < 1e-6);
        // Without a bowl the nominal 60 deg, as before.
        let plain = SimulatedBackend::new(1).unwrap();
        assert_eq!(plain.bound().param(ParamId::AxesMdeg), 60_000);
    }

    /// Setting a parameter and reading it back gives the value (a round trip through the
    /// controller's float configuration).
    #[test]
    fn parameters_round_trip() {
        let mut rig = SimulatedBackend::new(1).unwrap();
        for (id, v) in [
            (ParamId::RimUm, 150_000),
            (ParamId::StartUm, 40_000),
            (ParamId::MuPpm, 20_000),
            (ParamId::AxesMdeg, 30_000),
            (ParamId::Bandwidth2MradS, 6_000),
            (ParamId::SpeedMax1MradS, 3_500),
            (ParamId::Teeth2, 24),
            (ParamId::RatioPpm, 1_500_000),
        ] {
            rig.bound_mut().set_param(id, v).unwrap();
            assert_eq!(rig.bound().param(id), v, "{}", id.token());
        }
        // A start radius beyond the rim is refused and changes nothing.
        assert_eq!(
            rig.bound_mut().set_param(ParamId::StartUm, 200_000),
            Err(Reason::Range)
        );
        assert_eq!(rig.bound().param(ParamId::StartUm), 40_000);
    }

    use model_core::wire::device::Device;
    use model_core::wire::{Command, Frame};
    use proptest::prelude::*;

    /// Commissioning at boot dominates a debug-build test: do it once.
    fn commissioned() -> &'static SimulatedBackend {
        static RIG: std::sync::OnceLock<SimulatedBackend> = std::sync::OnceLock::new();
        RIG.get_or_init(|| SimulatedBackend::new(3).unwrap())
    }

    fn all_params(rig: &SimulatedBackend) -> Vec<i32> {
        ParamId::ALL
            .iter()
            .map(|&id| rig.bound().param(id))
            .collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// Through the real controller: a SET that is rejected changes no parameter, and one that
        /// is accepted changes exactly that parameter (to the value sent).
        #[test]
        fn a_rejected_set_changes_nothing(
            i in 0..ParamId::ALL.len(),
            frac in 0.0f64..=1.0,
            running in any::<bool>(),
        ) {
            let id = ParamId::ALL[i];
            // The telemetry rate lives in the protocol device, not behind the backend.
            prop_assume!(id != ParamId::TelemetryHz);
            let (lo, hi) = id.range();
            let value = lo + ((f64::from(hi) - f64::from(lo)) * frac) as i32;
            let mut rig = commissioned().clone();
            let mut device = Device::new();
            if running {
                prop_assert_eq!(rig.bound_mut().set_speeds(1500, 1500), Ok(()));
                prop_assert_eq!(rig.bound_mut().start(), Ok(()));
                rig.advance_to_ms(200);
            }
            let before = all_params(&rig);
            let answer = device.execute(rig.bound_mut(), 9, Command::SetParam { id, value });
            let after = all_params(&rig);
            match answer {
                Frame::Ack { id: 9 } => {
                    for (k, (b, a)) in before.iter().zip(&after).enumerate() {
                        if k == id.index() {
                            prop_assert_eq!(*a, value, "{} set", id.token());
                        } else {
                            prop_assert_eq!(a, b, "{} changed {}", id.token(), ParamId::ALL[k].token());
                        }
                    }
                }
                Frame::Reject { id: 9, .. } => prop_assert_eq!(before, after),
                other => prop_assert!(false, "unexpected answer {:?}", other),
            }
        }
    }
}

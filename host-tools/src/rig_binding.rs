//! The virtual rig behind `bowl sim --pty` / `--capture`: the real controller
//! (`model_core::control::Controller`) ticking against the simulated plant
//! (`model_core::sim::Rig`), bound to the protocol's [`Rig`] trait in wire units.
//!
//! The same binding, with the hardware in place of the plant, is what the firmware needs; only
//! the fault injection (INJECT) is particular to the simulation. It sits between the plant and
//! the controller: a lost sensor withholds the plant's edges from the controller, a stalled
//! motor gets no drive (its duty never reaches the plant).
//!
//! Residence-time predictions and the RTIME inverse use `model_core::particle` (paper Eq. 6/7
//! flat, Eq. 10/11 with the MODEL-NOTES coefficients) on the scene set by RIM_UM, START_UM,
//! MU_PPM, K2_PPM, at the controller's combined bowl speed (paper Eq. 2).

use anyhow::{Result, anyhow};
use model_core::control::{
    BowlSpeedForResidence, Controller, ControllerConfig, InverseFailure, Rejection, State,
};
use model_core::particle::{self, InverseError, Model, Outcome, Scene};
use model_core::sim::{ClosedLoop, RigParams};
use model_core::wire::device::Rig;
use model_core::wire::{
    DUTY_MAX_BP, DeviceState, FaultCode, Hello, Injection, MotorTelemetry, ParamId, Reason,
    ResetCause, Residence, ResidenceModel, Telemetry,
};

/// Simulated seconds of the identification run at boot (it ends much sooner).
const COMMISSION_MAX_S: f32 = 300.0;

/// The controller, the plant, the particle scene and the injected faults.
#[derive(Clone)]
pub struct SimulatedRig {
    plant: model_core::sim::Rig,
    ctrl: Controller,
    scene: Scene<f32>,
    injected: Injection,
    ticks: u64,
    total_ms: u64,
    now_ms: u32,
}

/// The particle model's inverse for one scene and model, as the controller wants it.
struct Inverse {
    scene: Scene<f32>,
    model: Model,
}

impl BowlSpeedForResidence for Inverse {
    fn omega_rad_s(&self, target_s: f32) -> Result<f32, InverseFailure> {
        particle::omega_for_residence_time(&self.scene, self.model, target_s).map_err(|e| match e {
            InverseError::AlreadyAtRim
            | InverseError::NeverLeaves
            | InverseError::BeyondPrecision => InverseFailure::Unreachable,
            _ => InverseFailure::ModelRejected,
        })
    }
}

fn model_of(m: ResidenceModel) -> Model {
    match m {
        ResidenceModel::Flat => Model::Flat,
        ResidenceModel::Coriolis => Model::Coriolis,
    }
}

/// How a controller refusal reads on the wire.
fn reason(r: Rejection) -> Reason {
    match r {
        Rejection::WrongState(_) | Rejection::Faulted(_) | Rejection::NotFaulted => Reason::State,
        Rejection::Inverse(_) | Rejection::SplitFailed => Reason::Infeasible,
        Rejection::NotFinite
        | Rejection::AboveMaxSpeed(_)
        | Rejection::BelowMinSpeed(_)
        | Rejection::InvalidResidenceTime
        | Rejection::InvalidConfig(_)
        | Rejection::InvalidTuning => Reason::Range,
    }
}

/// A float in `unit`s per wire step (1000 for milli, 1e6 for ppm), rounded and saturated to
/// the i32 range (the controller's values are validated, so saturation does not happen).
fn scaled(x: f32, per_unit: f32) -> i32 {
    (f64::from(x) * f64::from(per_unit)).round() as i32
}

fn mrad_s_i16(x_rad_s: f32) -> i16 {
    (f64::from(x_rad_s) * 1000.0)
        .round()
        .clamp(f64::from(i16::MIN), f64::from(i16::MAX)) as i16
}

impl SimulatedRig {
    /// The nominal plant (seeded noise) and the nominal controller, commissioned on the plant
    /// as the real rig is once after assembly, then at rest at device time 0.
    pub fn new(seed: u32) -> Result<Self> {
        let plant_params = RigParams::nominal();
        let mut cfg = ControllerConfig::nominal();
        for (axis, p) in cfg.axes.iter_mut().zip(plant_params.axes.iter()) {
            axis.pulses_per_rev = p.sensor.pulses_per_rev;
        }
        let ctrl = Controller::new(cfg).map_err(|e| anyhow!("controller config: {e:?}"))?;
        let mut cl = ClosedLoop::new(model_core::sim::Rig::new(plant_params, seed), ctrl);
        let end = cl.commission(COMMISSION_MAX_S);
        if end != State::Idle {
            return Err(anyhow!(
                "commissioning on the simulated plant ended in {end:?} ({:?})",
                cl.ctrl.identify_error()
            ));
        }
        Ok(Self {
            plant: cl.rig,
            ctrl: cl.ctrl,
            scene: Scene::default(),
            injected: Injection::None,
            ticks: 0,
            total_ms: 0,
            now_ms: 0,
        })
    }

    /// Runs the control ticks up to device time `now_ms`.
    pub fn advance_to_ms(&mut self, now_ms: u32) {
        let tick_hz = u64::from(self.ctrl.config().tick_hz);
        let dt_s = 1.0 / tick_hz as f32;
        // Device time counts up from 0 and wraps after 49 days; the tick count does not.
        self.total_ms += u64::from(now_ms.wrapping_sub(self.now_ms));
        self.now_ms = now_ms;
        let target = self.total_ms * tick_hz / 1000;
        while self.ticks < target {
            self.tick(dt_s);
        }
    }

    fn sensor_lost(&self, axis: usize) -> bool {
        matches!(
            (self.injected, axis),
            (Injection::SensorLostPrecession, 0) | (Injection::SensorLostSpin, 1)
        )
    }

    fn stalled(&self, axis: usize) -> bool {
        matches!(
            (self.injected, axis),
            (Injection::StallPrecession, 0) | (Injection::StallSpin, 1)
        )
    }

    fn tick(&mut self, dt_s: f32) {
        let now = self.plant.now_ticks();
        let lost = [self.sensor_lost(0), self.sensor_lost(1)];
        let edges = |axis: usize| -> &[u32] {
            if lost[axis] {
                &[]
            } else {
                self.plant.edges(axis)
            }
        };
        let duties = self.ctrl.tick(now, [edges(0), edges(1)]);
        let driven = [
            if self.stalled(0) { 0.0 } else { duties[0] },
            if self.stalled(1) { 0.0 } else { duties[1] },
        ];
        self.plant.advance(driven, dt_s);
        self.ticks += 1;
    }

    fn predicted(&self, omega_rad_s: f32, model: Model) -> Residence {
        if omega_rad_s <= 0.0 {
            return Residence::Unavailable;
        }
        let scene = Scene {
            omega_rad_s,
            ..self.scene
        };
        match particle::residence(&scene, model) {
            Ok(Outcome::Leaves {
                residence_time_s, ..
            }) => Residence::from_seconds(Some(residence_time_s)),
            Ok(Outcome::AlreadyAtRim { .. }) => Residence::Ms(0),
            Ok(Outcome::NeverLeaves { .. }) => Residence::NeverLeaves,
            Err(_) => Residence::Unavailable,
        }
    }

    /// Applies a changed configuration through the controller's own validation.
    fn reconfigure(&mut self, change: impl FnOnce(&mut ControllerConfig)) -> Result<(), Reason> {
        let mut cfg = *self.ctrl.config();
        change(&mut cfg);
        self.ctrl.set_parameters(cfg).map_err(reason)
    }

    fn set_scene(&mut self, change: impl FnOnce(&mut Scene<f32>)) -> Result<(), Reason> {
        let mut scene = self.scene;
        change(&mut scene);
        if scene.validate_except_omega().is_err() || scene.ri_m >= scene.rim_radius_m {
            return Err(Reason::Range);
        }
        self.scene = scene;
        Ok(())
    }
}

impl Rig for SimulatedRig {
    fn telemetry(&self) -> Telemetry {
        let s = self.ctrl.status();
        let motor = |axis: usize| {
            let a = &s.axes[axis];
            MotorTelemetry {
                set_mrad_s: mrad_s_i16(a.target_rad_s),
                measured_mrad_s: mrad_s_i16(a.measured_rad_s),
                duty_bp: (f64::from(a.duty) * 10_000.0)
                    .round()
                    .clamp(-f64::from(DUTY_MAX_BP), f64::from(DUTY_MAX_BP))
                    as i16,
                // The wire carries the count modulo 2^16.
                pulses: a.pulses as u16,
            }
        };
        let omega = s.combined_measured_rad_s;
        Telemetry {
            time_ms: self.now_ms,
            seq: 0,
            state: DeviceState::from_code(i64::from(s.state as u8)).unwrap_or(DeviceState::Faulted),
            fault: FaultCode::from_code(i64::from(s.fault_code))
                .unwrap_or(FaultCode::InvalidConfiguration),
            precession: motor(0),
            spin: motor(1),
            bowl_mrad_s: (f64::from(omega) * 1000.0).round().clamp(0.0, 65_535.0) as u16,
            residence_flat: self.predicted(omega, Model::Flat),
            residence_coriolis: self.predicted(omega, Model::Coriolis),
        }
    }

    fn reset_info(&self) -> Hello {
        Hello {
            reset_cause: ResetCause::Unknown,
            reset_count: 0,
        }
    }

    fn set_speeds(&mut self, precession_mrad_s: i16, spin_mrad_s: i16) -> Result<(), Reason> {
        self.ctrl
            .set_motor_speeds(
                f32::from(precession_mrad_s) / 1000.0,
                f32::from(spin_mrad_s) / 1000.0,
            )
            .map_err(reason)
    }

    fn set_residence(&mut self, model: ResidenceModel, time_ms: u32) -> Result<(), Reason> {
        let inverse = Inverse {
            scene: self.scene,
            model: model_of(model),
        };
        match self
            .ctrl
            .set_target_residence_time(time_ms as f32 / 1000.0, &inverse)
        {
            Ok(_) => Ok(()),
            // The speed that gives this time is outside the motors' range.
            Err(Rejection::AboveMaxSpeed(_) | Rejection::BelowMinSpeed(_)) => {
                Err(Reason::Infeasible)
            }
            Err(e) => Err(reason(e)),
        }
    }

    fn start(&mut self) -> Result<(), Reason> {
        self.ctrl.start().map_err(reason)
    }

    fn stop(&mut self) {
        // Never refused: in Idle or Fault it does nothing.
        let _ = self.ctrl.stop();
    }

    fn clear_fault(&mut self) -> Result<(), Reason> {
        self.ctrl.clear_fault().map_err(reason)
    }

    fn set_param(&mut self, id: ParamId, value: i32) -> Result<(), Reason> {
        let v = value as f32;
        let milli = v / 1000.0;
        let micro = v / 1_000_000.0;
        let axis = match id {
            ParamId::Bandwidth2MradS
            | ParamId::PerPulse2Milli
            | ParamId::SpeedMax2MradS
            | ParamId::Accel2MradS2
            | ParamId::DutyMax2Bp
            | ParamId::Teeth2 => 1,
            _ => 0,
        };
        match id {
            ParamId::RimUm => self.set_scene(|s| s.rim_radius_m = micro),
            ParamId::StartUm => self.set_scene(|s| s.ri_m = micro),
            ParamId::MuPpm => self.set_scene(|s| s.mu = micro),
            ParamId::K2Ppm => self.set_scene(|s| s.k2 = micro),
            ParamId::AxesMdeg => self.reconfigure(|c| c.axes_angle_rad = (milli).to_radians()),
            ParamId::Bandwidth1MradS | ParamId::Bandwidth2MradS => {
                let per_pulse = self.ctrl.config().axes[axis].per_pulse_bandwidth;
                self.ctrl
                    .set_loop_tuning(axis, milli, per_pulse)
                    .map_err(reason)
            }
            ParamId::PerPulse1Milli | ParamId::PerPulse2Milli => {
                let bandwidth = self.ctrl.config().axes[axis].bandwidth_rad_s;
                self.ctrl
                    .set_loop_tuning(axis, bandwidth, milli)
                    .map_err(reason)
            }
            ParamId::SpeedMax1MradS | ParamId::SpeedMax2MradS => {
                self.reconfigure(|c| c.axes[axis].max_speed_rad_s = milli)
            }
            ParamId::Accel1MradS2 | ParamId::Accel2MradS2 => {
                self.reconfigure(|c| c.axes[axis].accel_limit_rad_s2 = milli)
            }
            ParamId::DutyMax1Bp | ParamId::DutyMax2Bp => {
                self.reconfigure(|c| c.axes[axis].duty_limit = v / 10_000.0)
            }
            ParamId::Teeth1 | ParamId::Teeth2 => {
                // In range 1..=255 by the wire's check.
                self.reconfigure(|c| c.axes[axis].pulses_per_rev = value as u16)
            }
            ParamId::RatioPpm => self.reconfigure(|c| c.spin_per_precession = micro),
            // Owned by the protocol layer (Device), never passed here.
            ParamId::TelemetryHz => Err(Reason::Internal),
        }
    }

    fn param(&self, id: ParamId) -> i32 {
        let c = self.ctrl.config();
        match id {
            ParamId::RimUm => scaled(self.scene.rim_radius_m, 1e6),
            ParamId::StartUm => scaled(self.scene.ri_m, 1e6),
            ParamId::MuPpm => scaled(self.scene.mu, 1e6),
            ParamId::K2Ppm => scaled(self.scene.k2, 1e6),
            ParamId::AxesMdeg => scaled(c.axes_angle_rad.to_degrees(), 1000.0),
            ParamId::Bandwidth1MradS => scaled(c.axes[0].bandwidth_rad_s, 1000.0),
            ParamId::Bandwidth2MradS => scaled(c.axes[1].bandwidth_rad_s, 1000.0),
            ParamId::PerPulse1Milli => scaled(c.axes[0].per_pulse_bandwidth, 1000.0),
            ParamId::PerPulse2Milli => scaled(c.axes[1].per_pulse_bandwidth, 1000.0),
            ParamId::SpeedMax1MradS => scaled(c.axes[0].max_speed_rad_s, 1000.0),
            ParamId::SpeedMax2MradS => scaled(c.axes[1].max_speed_rad_s, 1000.0),
            ParamId::Accel1MradS2 => scaled(c.axes[0].accel_limit_rad_s2, 1000.0),
            ParamId::Accel2MradS2 => scaled(c.axes[1].accel_limit_rad_s2, 1000.0),
            ParamId::DutyMax1Bp => scaled(c.axes[0].duty_limit, 10_000.0),
            ParamId::DutyMax2Bp => scaled(c.axes[1].duty_limit, 10_000.0),
            ParamId::Teeth1 => i32::from(c.axes[0].pulses_per_rev),
            ParamId::Teeth2 => i32::from(c.axes[1].pulses_per_rev),
            ParamId::RatioPpm => scaled(c.spin_per_precession, 1e6),
            ParamId::TelemetryHz => 0,
        }
    }

    fn heartbeat(&mut self) {
        self.ctrl.host_heartbeat();
    }

    fn commission(&mut self) -> Result<(), Reason> {
        self.ctrl.start_commissioning().map_err(reason)
    }

    fn inject(&mut self, what: Injection) -> Result<(), Reason> {
        self.injected = what;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every controller state and fault has its wire code (the wire enums follow the
    /// controller's numbering); a mismatch would show up as a wrong name in telemetry.
    #[test]
    fn controller_codes_map_onto_wire_codes() {
        use model_core::control::Fault;
        for (state, wire) in [
            (State::Idle, DeviceState::Idle),
            (State::Commissioning, DeviceState::Commissioning),
            (State::SpinningUp, DeviceState::SpinningUp),
            (State::Running, DeviceState::Running),
            (State::Stopping, DeviceState::Stopping),
            (State::Fault, DeviceState::Faulted),
        ] {
            assert_eq!(DeviceState::from_code(i64::from(state as u8)), Some(wire));
        }
        for (fault, wire) in [
            (
                Fault::SensorLostOrStall(0),
                FaultCode::SensorLostOrStallPrecession,
            ),
            (
                Fault::SensorLostOrStall(1),
                FaultCode::SensorLostOrStallSpin,
            ),
            (Fault::Overspeed(0), FaultCode::OverspeedPrecession),
            (Fault::Overspeed(1), FaultCode::OverspeedSpin),
            (Fault::HostSilent, FaultCode::HostSilent),
            (Fault::InvalidConfiguration, FaultCode::InvalidConfiguration),
        ] {
            assert_eq!(FaultCode::from_code(i64::from(fault.code())), Some(wire));
        }
    }

    /// The nominal parameters are all inside their wire ranges (else PARAMS would fail).
    #[test]
    fn nominal_parameters_fit_the_wire() {
        let rig = SimulatedRig::new(1).unwrap();
        for id in ParamId::ALL {
            if id == ParamId::TelemetryHz {
                continue;
            }
            let (lo, hi) = id.range();
            let v = rig.param(id);
            assert!((lo..=hi).contains(&v), "{} = {v}", id.token());
        }
    }

    /// Setting a parameter and reading it back gives the value (a round trip through the
    /// controller's float configuration).
    #[test]
    fn parameters_round_trip() {
        let mut rig = SimulatedRig::new(1).unwrap();
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
            rig.set_param(id, v).unwrap();
            assert_eq!(rig.param(id), v, "{}", id.token());
        }
        // A start radius beyond the rim is refused and changes nothing.
        assert_eq!(rig.set_param(ParamId::StartUm, 200_000), Err(Reason::Range));
        assert_eq!(rig.param(ParamId::StartUm), 40_000);
    }

    use model_core::wire::device::Device;
    use model_core::wire::{Command, Frame};
    use proptest::prelude::*;

    /// Commissioning at boot dominates a debug-build test: do it once.
    fn commissioned() -> &'static SimulatedRig {
        static RIG: std::sync::OnceLock<SimulatedRig> = std::sync::OnceLock::new();
        RIG.get_or_init(|| SimulatedRig::new(3).unwrap())
    }

    fn all_params(rig: &SimulatedRig) -> Vec<i32> {
        ParamId::ALL.iter().map(|&id| rig.param(id)).collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// Through the real controller: a SET that is rejected changes no parameter, and one that
        /// is accepted changes exactly that parameter (to the value sent).
        #[test]
        fn a_rejected_set_changes_nothing(
            i in 0..ParamId::ALL.len() - 1,
            frac in 0.0f64..=1.0,
            running in any::<bool>(),
        ) {
            let id = ParamId::ALL[i];
            let (lo, hi) = id.range();
            let value = lo + ((f64::from(hi) - f64::from(lo)) * frac) as i32;
            let mut rig = commissioned().clone();
            let mut device = Device::new();
            if running {
                prop_assert_eq!(rig.set_speeds(1500, 1500), Ok(()));
                prop_assert_eq!(rig.start(), Ok(()));
                rig.advance_to_ms(200);
            }
            let before = all_params(&rig);
            let answer = device.execute(&mut rig, 9, Command::SetParam { id, value });
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

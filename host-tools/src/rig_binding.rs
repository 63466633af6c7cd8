//! The rig behind the virtual transport.
//!
//! INTERIM: until `model_core::control` (the controller) and `model_core::sim` (the plant) are
//! on main, this is a first-order speed response with no controller; it exists only so the
//! transport and the end-to-end tests can run. It is replaced by the binding of the real
//! Controller + simulated plant as soon as those land.

use anyhow::Result;
use model_core::bowl::{BowlGeometry, MotorSpeeds};
use model_core::wire::device::Rig;
use model_core::wire::{
    DeviceState, FaultCode, Hello, Injection, MotorTelemetry, ParamId, Reason, ResetCause,
    Residence, ResidenceModel, Telemetry,
};

/// The simulated rig.
pub struct SimulatedRig {
    now_ms: u32,
    state: DeviceState,
    fault: FaultCode,
    set_mrad_s: [i16; 2],
    speed_rad_s: [f64; 2],
    pulses: [u16; 2],
    phase_rev: [f64; 2],
    params: [i32; model_core::wire::PARAM_COUNT],
    injected: Injection,
}

impl SimulatedRig {
    /// A rig at rest.
    pub fn new(_seed: u32) -> Result<Self> {
        let mut params = [0; model_core::wire::PARAM_COUNT];
        for (slot, (id, v)) in params.iter_mut().zip([
            (ParamId::RimUm, 150_000),
            (ParamId::StartUm, 20_000),
            (ParamId::MuPpm, 29_000),
            (ParamId::K2Ppm, 714_286),
            (ParamId::AxesMdeg, 60_000),
            (ParamId::Bandwidth1MradS, 10_000),
            (ParamId::Bandwidth2MradS, 10_000),
            (ParamId::PerPulse1Ppm, 500_000),
            (ParamId::PerPulse2Ppm, 500_000),
            (ParamId::SpeedMax1MradS, 5_000),
            (ParamId::SpeedMax2MradS, 5_000),
            (ParamId::Accel1MradS2, 2_000),
            (ParamId::Accel2MradS2, 2_000),
            (ParamId::DutyMax1Bp, 9_500),
            (ParamId::DutyMax2Bp, 9_500),
            (ParamId::Teeth1, 1),
            (ParamId::Teeth2, 1),
            (ParamId::RatioPpm, 1_000_000),
            (ParamId::TelemetryHz, 50),
        ]) {
            debug_assert_eq!(id.index(), params_index(id));
            *slot = v;
        }
        Ok(Self {
            now_ms: 0,
            state: DeviceState::Idle,
            fault: FaultCode::None,
            set_mrad_s: [0; 2],
            speed_rad_s: [0.0; 2],
            pulses: [0; 2],
            phase_rev: [0.0; 2],
            params,
            injected: Injection::None,
        })
    }

    /// Runs the rig up to `now_ms`.
    pub fn advance_to_ms(&mut self, now_ms: u32) {
        while self.now_ms != now_ms {
            self.now_ms = self.now_ms.wrapping_add(1);
            for axis in 0..2 {
                let target = match self.state {
                    DeviceState::SpinningUp | DeviceState::Running => {
                        f64::from(self.set_mrad_s[axis]) / 1000.0
                    }
                    _ => 0.0,
                };
                let stalled = matches!(
                    (self.injected, axis),
                    (Injection::StallPrecession, 0) | (Injection::StallSpin, 1)
                );
                let target = if stalled { 0.0 } else { target };
                self.speed_rad_s[axis] += (target - self.speed_rad_s[axis]) * 0.001 / 0.3;
                let lost = matches!(
                    (self.injected, axis),
                    (Injection::SensorLostPrecession, 0) | (Injection::SensorLostSpin, 1)
                );
                self.phase_rev[axis] += self.speed_rad_s[axis] * 0.001 / std::f64::consts::TAU;
                if self.phase_rev[axis] >= 1.0 {
                    self.phase_rev[axis] -= 1.0;
                    if !lost {
                        self.pulses[axis] = self.pulses[axis].wrapping_add(1);
                    }
                }
            }
            if self.state == DeviceState::Stopping
                && self.speed_rad_s.iter().all(|s| s.abs() < 0.01)
            {
                self.state = DeviceState::Idle;
            }
            if self.state == DeviceState::SpinningUp {
                self.state = DeviceState::Running;
            }
        }
    }

    fn measured_mrad_s(&self, axis: usize) -> i16 {
        let lost = matches!(
            (self.injected, axis),
            (Injection::SensorLostPrecession, 0) | (Injection::SensorLostSpin, 1)
        );
        if lost {
            0
        } else {
            (self.speed_rad_s[axis] * 1000.0)
                .round()
                .clamp(-32768.0, 32767.0) as i16
        }
    }
}

fn params_index(id: ParamId) -> usize {
    id.index()
}

impl Rig for SimulatedRig {
    fn telemetry(&self) -> Telemetry {
        let motor = |axis: usize| MotorTelemetry {
            set_mrad_s: self.set_mrad_s[axis],
            measured_mrad_s: self.measured_mrad_s(axis),
            duty_bp: 0,
            pulses: self.pulses[axis],
        };
        let geometry = BowlGeometry::<f64>::default();
        let bowl = geometry
            .combined_speed_rad_s(MotorSpeeds {
                precession_rad_s: f64::from(self.measured_mrad_s(0)) / 1000.0,
                spin_rad_s: f64::from(self.measured_mrad_s(1)) / 1000.0,
            })
            .unwrap_or(0.0);
        Telemetry {
            time_ms: self.now_ms,
            seq: 0,
            state: self.state,
            fault: self.fault,
            precession: motor(0),
            spin: motor(1),
            bowl_mrad_s: (bowl * 1000.0).round().clamp(0.0, 65535.0) as u16,
            residence_flat: Residence::Unavailable,
            residence_coriolis: Residence::Unavailable,
        }
    }

    fn reset_info(&self) -> Hello {
        Hello {
            reset_cause: ResetCause::Unknown,
            reset_count: 0,
        }
    }

    fn set_speeds(&mut self, precession_mrad_s: i16, spin_mrad_s: i16) -> Result<(), Reason> {
        self.set_mrad_s = [precession_mrad_s, spin_mrad_s];
        Ok(())
    }

    fn set_residence(&mut self, _model: ResidenceModel, _time_ms: u32) -> Result<(), Reason> {
        Err(Reason::Unsupported)
    }

    fn start(&mut self) -> Result<(), Reason> {
        if self.state == DeviceState::Faulted {
            return Err(Reason::State);
        }
        self.state = DeviceState::SpinningUp;
        Ok(())
    }

    fn stop(&mut self) {
        if self.state != DeviceState::Faulted {
            self.state = DeviceState::Stopping;
        }
    }

    fn clear_fault(&mut self) -> Result<(), Reason> {
        if self.state != DeviceState::Faulted {
            return Err(Reason::State);
        }
        self.state = DeviceState::Idle;
        self.fault = FaultCode::None;
        Ok(())
    }

    fn set_param(&mut self, id: ParamId, value: i32) -> Result<(), Reason> {
        self.params[id.index()] = value;
        Ok(())
    }

    fn param(&self, id: ParamId) -> i32 {
        self.params[id.index()]
    }

    fn inject(&mut self, what: Injection) -> Result<(), Reason> {
        self.injected = what;
        Ok(())
    }
}

//! [`ControllerBackend`]: the controller and the particle scene behind the protocol's
//! [`Backend`] trait. It keeps the parameters in wire units and the motor models to persist,
//! and turns the controller's states, faults and refusals into the wire's codes.

use super::configure::{AxisSetting, ParamRole, derive, table_from_params, with_models};
use super::record::{Persisted, Record, persisted, split_persisted};
use super::{AXES, Injector, default_params};
use crate::control::{
    BowlSpeedForResidence, Controller, ControllerConfig, Fault, InverseFailure, MotorModel,
    Rejection, State,
};
use crate::particle::speed_table::SpeedTable;
use crate::particle::{self, InverseError, Model, Scene};
use crate::wire::device::{Backend, ResidenceChoice};
use crate::wire::{
    AxisModel, DeviceState, FaultCode, GateEvent, Hello, Injection, MODEL_FIELD_MAX,
    MotorTelemetry, ParamId, ParamValues, Reason, Residence, ResidenceModel, Telemetry,
};

/// Nearest integer as f32 (ties away from zero); a cast after it saturates and maps NaN to 0.
fn round(x: f32) -> f32 {
    libm::roundf(x)
}

/// The particle scene as the controller's model traits.
#[derive(Clone, Copy)]
struct SceneModel {
    scene: Scene<f32>,
    model: Model,
}

impl BowlSpeedForResidence for SceneModel {
    fn omega_rad_s(&self, target_s: f32) -> Result<f32, InverseFailure> {
        use InverseError as E;
        particle::omega_for_residence_time(&self.scene, self.model, target_s).map_err(|e| match e {
            E::Scene(_) | E::InvalidTarget => InverseFailure::ModelRejected,
            _ => InverseFailure::Unreachable,
        })
    }
}

/// The stored residence-time table as the controller's inverse (`RTIME TABLE`): refused when
/// flat or outside its times (docs/model.md §11).
impl BowlSpeedForResidence for SpeedTable {
    fn omega_rad_s(&self, target_s: f32) -> Result<f32, InverseFailure> {
        self.omega_for_s(target_s)
            .map_err(|_| InverseFailure::Unreachable)
    }
}

impl SceneModel {
    /// The predicted residence time at bowl speed `omega_rad_s`, as telemetry carries it.
    fn predicted(&self, omega_rad_s: f32) -> Residence {
        if omega_rad_s.is_nan() || omega_rad_s <= 0.0 {
            return Residence::Unavailable;
        }
        let scene = Scene {
            omega_rad_s,
            ..self.scene
        };
        // The time alone: telemetry carries nothing else, and on the MCU it is half the work.
        match particle::residence_time_s(&scene, self.model) {
            Ok(t) if t.is_infinite() => Residence::NeverLeaves,
            Ok(t) => Residence::from_seconds(Some(t)),
            Err(_) => Residence::Unavailable,
        }
    }
}

fn reason(r: Rejection) -> Reason {
    use Rejection as R;
    match r {
        R::NotFinite => Reason::Malformed,
        R::AboveMaxSpeed(_) | R::BelowMinSpeed(_) | R::InvalidResidenceTime => Reason::Range,
        R::Inverse(_) | R::SplitFailed => Reason::Infeasible,
        R::WrongState(_) | R::Faulted(_) | R::NotFaulted => Reason::State,
        R::InvalidConfig(_) | R::InvalidTuning => Reason::Range,
    }
}

/// The controller's fault as the wire carries it: its telemetry code ([`Fault::code`], the one
/// numbering) read as the wire's [`FaultCode`] (no fault is [`FaultCode::None`]). Every fault's
/// code is one the wire names (`state_and_fault_names_keep_the_controller_codes`); a code it
/// did not name would still say the rig faulted, as [`FaultCode::InvalidConfiguration`] does
/// for a fault state without a latched fault (`Controller`'s `latched`).
impl From<Option<Fault>> for FaultCode {
    fn from(f: Option<Fault>) -> Self {
        FaultCode::from_code(crate::control::supervisor::fault_code(f).into())
            .unwrap_or(FaultCode::InvalidConfiguration)
    }
}

/// The controller's state as the wire carries it (the same states; the wire says `Faulted`).
impl From<State> for DeviceState {
    fn from(s: State) -> Self {
        match s {
            State::Idle => DeviceState::Idle,
            State::Commissioning => DeviceState::Commissioning,
            State::ChangingSpeed => DeviceState::ChangingSpeed,
            State::Running => DeviceState::Running,
            State::Stopping => DeviceState::Stopping,
            State::Fault => DeviceState::Faulted,
        }
    }
}

fn mrad(x: f32) -> i16 {
    // `as` saturates and maps NaN to 0.
    round(x * 1000.0) as i16
}

/// The controller and the particle scene behind the wire protocol's [`Backend`] trait.
#[derive(Clone)]
pub struct ControllerBackend<I: Injector> {
    ctrl: Controller,
    base: ControllerConfig,
    scene: Scene<f32>,
    params: ParamValues,
    hello: Hello,
    now_ms: u32,
    params_dirty: bool,
    saved_models: [MotorModel; AXES],
    saved_identified: [bool; AXES],
    /// Axes whose model in force came identified from the stored record.
    stored_identified: [bool; AXES],
    /// Board conditions for STATUS (`wire::status_flags`), set by the board.
    status_flags: u8,
    injector: I,
}

impl<I: Injector> ControllerBackend<I> {
    /// A controller for a persisted record (checked: parameters or motor models that fail
    /// validation give the defaults, and `Err` says why, so the board still boots and reports
    /// it). `base` supplies what the wire does not carry (tick rate, timer, supervisor limits).
    pub fn new(
        base: ControllerConfig,
        stored: Persisted,
        hello: Hello,
        injector: I,
    ) -> (Self, Result<(), Reason>) {
        let record = split_persisted(&stored);
        let stored_base = with_models(&base, &record.models);
        let (base, params, stored_identified, outcome) = match derive(&stored_base, &record.params)
        {
            Ok(_) => (stored_base, record.params, record.identified, Ok(())),
            Err(r) => (base, default_params(), [false; AXES], Err(r)),
        };
        let (cfg, scene) = match derive(&base, &params) {
            Ok(x) => x,
            // The defaults are derived from the nominal configuration and always pass; if
            // they somehow do not, the controller boots faulted instead of trusting them.
            Err(_) => (base, Scene::default()),
        };
        let rig = Self {
            ctrl: Controller::new_or_faulted(cfg),
            base,
            scene,
            params,
            hello,
            now_ms: 0,
            params_dirty: false,
            saved_models: [cfg.axes[0].model, cfg.axes[1].model],
            saved_identified: stored_identified,
            stored_identified,
            status_flags: 0,
            injector,
        };
        (rig, outcome)
    }

    fn models(&self) -> [MotorModel; AXES] {
        let a = &self.ctrl.config().axes;
        [a[0].model, a[1].model]
    }

    /// Per axis: the model in force was identified by commissioning, on this boot or on the
    /// one that stored it.
    pub fn identified(&self) -> [bool; AXES] {
        let now = self.ctrl.identified();
        [
            now[0].is_some() || self.stored_identified[0],
            now[1].is_some() || self.stored_identified[1],
        ]
    }

    /// Sets and clears board conditions STATUS reports (`wire::status_flags` bits).
    pub fn update_status_flags(&mut self, set: u8, clear: u8) {
        self.status_flags = (self.status_flags & !clear) | set;
    }

    /// The controller (diagnostics).
    pub fn controller(&self) -> &Controller {
        &self.ctrl
    }

    /// The controller, to run its control tick.
    pub fn controller_mut(&mut self) -> &mut Controller {
        &mut self.ctrl
    }

    /// Where injections go (the simulated plant reads its faults from here).
    pub fn injector(&self) -> &I {
        &self.injector
    }

    /// The same, for the simulation to take releases from and hand gate events to.
    pub fn injector_mut(&mut self) -> &mut I {
        &mut self.injector
    }

    /// The device time telemetry frames carry, ms (set before each telemetry poll).
    pub fn set_now_ms(&mut self, now_ms: u32) {
        self.now_ms = now_ms;
    }

    /// The motor models in force (nominal, stored, or identified by commissioning).
    pub fn motor_models(&self) -> [MotorModel; AXES] {
        self.models()
    }

    /// Parameters and motor models as one record, for persisting (`telemetry_hz` is the
    /// protocol device's rate, which the device owns).
    pub fn to_persist(&self, telemetry_hz: u8) -> Persisted {
        let mut params = self.params;
        params[ParamId::TelemetryHz.index()] = i32::from(telemetry_hz);
        persisted(&Record {
            params,
            models: self.models(),
            identified: self.identified(),
        })
    }

    /// The parameters in force, wire units.
    pub fn params(&self) -> &ParamValues {
        &self.params
    }

    /// Whether parameters or motor models (after commissioning) changed since the last call
    /// and should be persisted now (only while idle: a flash erase stalls the CPU).
    pub fn take_params_to_save(&mut self) -> bool {
        let idle = matches!(self.ctrl.state(), State::Idle | State::Fault);
        let models = self.models();
        let identified = self.identified();
        let due = idle
            && (self.params_dirty
                || models != self.saved_models
                || identified != self.saved_identified);
        if due {
            self.params_dirty = false;
            self.saved_models = models;
            self.saved_identified = identified;
        }
        due
    }

    /// One of the paper's 1-D models on the scene in force.
    fn model(&self, m: Model) -> SceneModel {
        SceneModel {
            scene: self.scene,
            model: m,
        }
    }
}

impl<I: Injector> Backend for ControllerBackend<I> {
    fn telemetry(&self) -> Telemetry {
        let s = self.ctrl.status();
        let motor = |i: usize| {
            let a = s.axes[i];
            MotorTelemetry {
                set_mrad_s: mrad(a.target_rad_s),
                measured_mrad_s: mrad(a.measured_rad_s),
                // The controller keeps |duty| <= 1, inside the wire's +-10 000 bp.
                duty_bp: round(a.duty * 10_000.0) as i16,
                pulses: a.pulses as u16,
            }
        };
        let predicted = |m| self.model(m).predicted(s.combined_measured_rad_s);
        Telemetry {
            time_ms: self.now_ms,
            seq: 0,
            state: s.state.into(),
            fault: s.fault.into(),
            precession: motor(0),
            spin: motor(1),
            bowl_mrad_s: round(s.combined_measured_rad_s * 1000.0) as u16,
            residence_flat: predicted(Model::Flat),
            residence_coriolis: predicted(Model::Coriolis),
        }
    }

    fn reset_info(&self) -> Hello {
        self.hello
    }

    fn status_flags(&self) -> u8 {
        self.status_flags
    }

    fn set_speeds(&mut self, precession_mrad_s: i16, spin_mrad_s: i16) -> Result<(), Reason> {
        self.ctrl
            .set_motor_speeds(
                f32::from(precession_mrad_s) * 1e-3,
                f32::from(spin_mrad_s) * 1e-3,
            )
            .map_err(reason)
    }

    fn set_residence(
        &mut self,
        model: ResidenceModel,
        time_ms: u32,
    ) -> Result<ResidenceChoice, Reason> {
        let target_s = time_ms as f32 * 1e-3;
        let chosen = match model {
            ResidenceModel::Flat => self
                .ctrl
                .set_target_residence_time(target_s, &self.model(Model::Flat)),
            ResidenceModel::Coriolis => self
                .ctrl
                .set_target_residence_time(target_s, &self.model(Model::Coriolis)),
            // The table in force (checked when it was set); none stored: nothing to answer with.
            ResidenceModel::Table => match table_from_params(&self.params) {
                Ok(Some(table)) => self.ctrl.set_target_residence_time(target_s, &table),
                Ok(None) | Err(_) => return Err(Reason::Infeasible),
            },
        };
        match chosen {
            // Within the motors' range (checked), so the casts cannot saturate.
            Ok(speeds) => Ok(ResidenceChoice {
                model,
                precession_mrad_s: round(speeds[0] * 1e3) as i16,
                spin_mrad_s: round(speeds[1] * 1e3) as i16,
            }),
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
        // Stop is always possible: in Idle or Fault it does nothing.
        let _ = self.ctrl.stop();
    }

    fn clear_fault(&mut self) -> Result<(), Reason> {
        self.ctrl.clear_fault().map_err(reason)
    }

    fn set_param(&mut self, id: ParamId, value: i32) -> Result<(), Reason> {
        let mut next = self.params;
        next[id.index()] = value;
        // The motor models in force (perhaps from commissioning) stay as they are.
        let (cfg, scene) = derive(&with_models(&self.base, &self.models()), &next)?;
        match ParamRole::of(id) {
            // Owned by the protocol device, never passed here.
            ParamRole::TelemetryRate => return Err(Reason::Internal),
            // The scene and the residence-time table only feed RTIME and the predictions: any
            // time.
            ParamRole::Scene | ParamRole::ResidenceTable => {}
            // Loop tuning: also while running, bumpless.
            ParamRole::Axis(axis, AxisSetting::Bandwidth | AxisSetting::PerPulseBandwidth) => {
                let a = cfg.axes.get(axis).ok_or(Reason::Internal)?;
                self.ctrl
                    .set_loop_tuning(axis, a.bandwidth_rad_s, a.per_pulse_bandwidth)
                    .map_err(reason)?;
            }
            // Everything else rebuilds the controller: idle or faulted only.
            ParamRole::AxesAngle
            | ParamRole::SplitRatio
            | ParamRole::LinkTimeout
            | ParamRole::CurrentSense
            | ParamRole::Axis(..) => self.ctrl.set_parameters(cfg).map_err(reason)?,
        }
        self.scene = scene;
        self.params = next;
        self.params_dirty = true;
        Ok(())
    }

    fn param(&self, id: ParamId) -> i32 {
        self.params[id.index()]
    }

    fn telemetry_hz_set(&mut self, hz: u8) {
        // Only a change is saved: the board sets its stored rate at every boot.
        let stored = &mut self.params[ParamId::TelemetryHz.index()];
        if *stored != i32::from(hz) {
            *stored = i32::from(hz);
            self.params_dirty = true;
        }
    }

    fn heartbeat(&mut self) {
        self.ctrl.host_heartbeat();
    }

    fn commission(&mut self) -> Result<(), Reason> {
        self.ctrl.start_commissioning().map_err(reason)
    }

    fn inject(&mut self, what: Injection) -> Result<(), Reason> {
        self.injector.inject(what)
    }

    fn release(&mut self) -> Result<(), Reason> {
        self.injector.release()
    }

    fn next_gate_event(&mut self) -> Option<GateEvent> {
        self.injector.gate_event()
    }

    fn models(&self) -> Result<[AxisModel; AXES], Reason> {
        let identified = self.identified();
        let mut out = [AxisModel::default(); AXES];
        for (axis, slot) in out.iter_mut().enumerate() {
            let m = self.ctrl.config().axes[axis].model;
            let (kp, ki) = self.ctrl.loop_gains(axis).ok_or(Reason::Internal)?;
            let mut v = [0u32; 5];
            for (out, x) in v.iter_mut().zip([
                m.volts_per_rad_s,
                m.friction_duty,
                m.time_constant_s,
                kp,
                ki,
            ]) {
                // Every field is in millionths. A value the wire cannot carry (negative, not
                // finite, too large) would be a bug here: INTERNAL, never a wrong number.
                let scaled = round(x * 1e6);
                if !(scaled >= 0.0 && scaled <= MODEL_FIELD_MAX as f32) {
                    return Err(Reason::Internal);
                }
                *out = scaled as u32;
            }
            *slot = AxisModel {
                identified: identified[axis],
                back_emf_uv_per_rad_s: v[0],
                friction_ppm: v[1],
                time_constant_us: v[2],
                kp_ppm_per_rad_s: v[3],
                ki_ppm_per_rad: v[4],
            };
        }
        Ok(out)
    }
}

#[cfg(test)]
mod rtime_tests;
#[cfg(test)]
mod tests;

//! The one binding of the controller ([`crate::control`]) and the particle model
//! ([`crate::particle`]) to the serial protocol's rig interface ([`crate::wire::device::Backend`]).
//! No heap, no hardware: the Black Pill firmware, the emulated board under QEMU and the host's
//! virtual rig (`bowl serve --pty/--capture`) all run this code; each supplies only what is its
//! own (the motors and sensors or a simulated plant, and an [`Injector`] for INJECT).
//!
//! The parameters in force are kept in wire units (what SET sent is what PARAMS reports,
//! exactly), and the controller's configuration is derived from them:
//! - `RIM_UM`, `START_UM`, `MU_PPM`, `K2_PPM`: the particle scene for `RTIME` and the predicted
//!   residence times (paper Eq. 6/7 flat, Eq. 10/11 with the MODEL-NOTES coefficients) at the
//!   controller's combined bowl speed (paper Eq. 2); gravity 9.81 m/s^2.
//! - `AXES_MDEG`: `axes_angle_rad` (paper Eq. 2); `RATIO_PPM`: `spin_per_precession`.
//! - per axis n: `BWn_MRAD_S` `bandwidth_rad_s`, `PER_PULSEn_MILLI` `per_pulse_bandwidth`
//!   (both changeable while running, bumpless), `SPEED_MAXn_MRAD_S` `max_speed_rad_s` (the
//!   over-speed fault limit follows at [`OVERSPEED_PER_MAX`] times it), `ACCELn_MRAD_S2`
//!   `accel_limit_rad_s2`, `DUTY_MAXn_BP` `duty_limit`, `TEETHn` `pulses_per_rev` (these only
//!   while idle or faulted).
//!
//! A value the scene check or the controller's validation refuses is rejected with `RANGE`
//! (or `STATE` when the controller is busy) and changes nothing.

use crate::control::{
    BowlSpeedForResidence, Controller, ControllerConfig, Fault, InverseFailure, MotorModel,
    Rejection, State,
};
use crate::particle::{self, InverseError, Model, Outcome, Scene};
use crate::wire::device::{Backend, DEFAULT_TELEMETRY_HZ};
use crate::wire::{
    AxisModel, DeviceState, FaultCode, Hello, Injection, MODEL_FIELD_MAX, MotorTelemetry,
    PARAM_COUNT, ParamId, ParamValues, Reason, Residence, ResidenceModel, Telemetry,
};

/// Motor axes: precession (0) and spin (1).
pub const AXES: usize = 2;

/// Over-speed fault limit as a multiple of `SPEED_MAX` (the nominal 5.5 / 4.0 rad/s).
pub const OVERSPEED_PER_MAX: f32 = 1.375;
const GRAVITY_M_S2: f32 = 9.81;

/// Nearest integer as f32 (ties away from zero); a cast after it saturates and maps NaN to 0.
fn round(x: f32) -> f32 {
    libm::roundf(x)
}

/// Where fault injections go: the emulated board's plant, or nowhere on real hardware.
pub trait Injector {
    /// Applies `what` or says why not.
    fn inject(&mut self, what: Injection) -> Result<(), Reason>;
}

/// Real hardware: nothing can be injected.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoInjection;

impl Injector for NoInjection {
    fn inject(&mut self, _what: Injection) -> Result<(), Reason> {
        Err(Reason::Unsupported)
    }
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
        match particle::residence(&scene, self.model) {
            Ok(Outcome::Leaves {
                residence_time_s, ..
            }) => Residence::from_seconds(Some(residence_time_s)),
            Ok(Outcome::AlreadyAtRim { .. }) => Residence::Ms(0),
            Ok(Outcome::NeverLeaves { .. }) => Residence::NeverLeaves,
            Err(_) => Residence::Unavailable,
        }
    }
}

/// The parameter values a new board starts with (wire units, wire order): the controller's
/// nominal configuration and the particle model's default scene.
pub fn default_params() -> ParamValues {
    let cfg = ControllerConfig::nominal();
    let scene = Scene::<f32>::default();
    let milli = |x: f32| round(x * 1000.0) as i32;
    let micro = |x: f32| round(x * 1e6) as i32;
    let mut v = [0i32; PARAM_COUNT];
    for id in ParamId::ALL {
        let (a, b) = (&cfg.axes[0], &cfg.axes[1]);
        v[id.index()] = match id {
            ParamId::RimUm => micro(scene.rim_radius_m),
            ParamId::StartUm => micro(scene.ri_m),
            ParamId::MuPpm => micro(scene.mu),
            ParamId::K2Ppm => micro(scene.k2),
            ParamId::AxesMdeg => milli(cfg.axes_angle_rad.to_degrees()),
            ParamId::Bandwidth1MradS => milli(a.bandwidth_rad_s),
            ParamId::Bandwidth2MradS => milli(b.bandwidth_rad_s),
            ParamId::PerPulse1Milli => milli(a.per_pulse_bandwidth),
            ParamId::PerPulse2Milli => milli(b.per_pulse_bandwidth),
            ParamId::SpeedMax1MradS => milli(a.max_speed_rad_s),
            ParamId::SpeedMax2MradS => milli(b.max_speed_rad_s),
            ParamId::Accel1MradS2 => milli(a.accel_limit_rad_s2),
            ParamId::Accel2MradS2 => milli(b.accel_limit_rad_s2),
            ParamId::DutyMax1Bp => round(a.duty_limit * 10_000.0) as i32,
            ParamId::DutyMax2Bp => round(b.duty_limit * 10_000.0) as i32,
            ParamId::Teeth1 => i32::from(a.pulses_per_rev),
            ParamId::Teeth2 => i32::from(b.pulses_per_rev),
            ParamId::RatioPpm => micro(cfg.spin_per_precession),
            ParamId::TelemetryHz => i32::from(DEFAULT_TELEMETRY_HZ),
        };
    }
    v
}

/// Values persisted in flash: the wire parameters (wire order), then per axis the motor model
/// in force (identified by commissioning, or nominal): back-EMF constant, friction duty, time
/// constant, as f32 bit patterns.
pub const PERSISTED_COUNT: usize = PARAM_COUNT + 3 * AXES;
/// One persisted record's values.
pub type Persisted = [i32; PERSISTED_COUNT];

/// Joins parameters and motor models into a record.
pub fn persisted(params: &ParamValues, models: &[MotorModel; AXES]) -> Persisted {
    let mut v = [0i32; PERSISTED_COUNT];
    v[..PARAM_COUNT].copy_from_slice(params);
    for (i, m) in models.iter().enumerate() {
        let at = PARAM_COUNT + 3 * i;
        v[at] = m.volts_per_rad_s.to_bits() as i32;
        v[at + 1] = m.friction_duty.to_bits() as i32;
        v[at + 2] = m.time_constant_s.to_bits() as i32;
    }
    v
}

/// Splits a record into parameters and motor models.
pub fn split_persisted(v: &Persisted) -> (ParamValues, [MotorModel; AXES]) {
    let mut params = [0i32; PARAM_COUNT];
    params.copy_from_slice(&v[..PARAM_COUNT]);
    let f = |k: usize| f32::from_bits(v[k] as u32);
    let model = |i: usize| {
        let at = PARAM_COUNT + 3 * i;
        MotorModel {
            volts_per_rad_s: f(at),
            friction_duty: f(at + 1),
            time_constant_s: f(at + 2),
        }
    };
    (params, [model(0), model(1)])
}

/// The record a new board starts with: [`default_params`] and the nominal motor models.
pub fn default_persisted() -> Persisted {
    let cfg = ControllerConfig::nominal();
    persisted(&default_params(), &[cfg.axes[0].model, cfg.axes[1].model])
}

fn with_models(base: &ControllerConfig, models: &[MotorModel; AXES]) -> ControllerConfig {
    let mut cfg = *base;
    for (a, m) in cfg.axes.iter_mut().zip(models) {
        a.model = *m;
    }
    cfg
}

/// Controller configuration and scene for a set of wire parameters, or why they do not fit.
fn derive(
    base: &ControllerConfig,
    v: &ParamValues,
) -> Result<(ControllerConfig, Scene<f32>), Reason> {
    let p = |id: ParamId| v[id.index()] as f32;
    let scene = Scene {
        omega_rad_s: 0.0,
        mu: p(ParamId::MuPpm) * 1e-6,
        g_m_s2: GRAVITY_M_S2,
        k2: p(ParamId::K2Ppm) * 1e-6,
        ri_m: p(ParamId::StartUm) * 1e-6,
        rim_radius_m: p(ParamId::RimUm) * 1e-6,
    };
    if scene.validate_except_omega().is_err() || scene.ri_m >= scene.rim_radius_m {
        return Err(Reason::Range);
    }
    let mut cfg = *base;
    cfg.axes_angle_rad = (p(ParamId::AxesMdeg) * 1e-3).to_radians();
    cfg.spin_per_precession = p(ParamId::RatioPpm) * 1e-6;
    let per_axis = [
        [
            ParamId::Bandwidth1MradS,
            ParamId::PerPulse1Milli,
            ParamId::SpeedMax1MradS,
            ParamId::Accel1MradS2,
            ParamId::DutyMax1Bp,
            ParamId::Teeth1,
        ],
        [
            ParamId::Bandwidth2MradS,
            ParamId::PerPulse2Milli,
            ParamId::SpeedMax2MradS,
            ParamId::Accel2MradS2,
            ParamId::DutyMax2Bp,
            ParamId::Teeth2,
        ],
    ];
    for (a, [bw, per_pulse, max, accel, duty, teeth]) in cfg.axes.iter_mut().zip(per_axis) {
        a.bandwidth_rad_s = p(bw) * 1e-3;
        a.per_pulse_bandwidth = p(per_pulse) * 1e-3;
        a.max_speed_rad_s = p(max) * 1e-3;
        a.overspeed_rad_s = a.max_speed_rad_s * OVERSPEED_PER_MAX;
        a.accel_limit_rad_s2 = p(accel) * 1e-3;
        a.duty_limit = p(duty) * 1e-4;
        a.pulses_per_rev = u16::try_from(v[teeth.index()]).map_err(|_| Reason::Range)?;
    }
    cfg.validate().map_err(|_| Reason::Range)?;
    Ok((cfg, scene))
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

fn fault_code(f: Option<Fault>) -> FaultCode {
    match f {
        None => FaultCode::None,
        Some(Fault::SensorLostOrStall(0)) => FaultCode::SensorLostOrStallPrecession,
        Some(Fault::SensorLostOrStall(_)) => FaultCode::SensorLostOrStallSpin,
        Some(Fault::Overspeed(0)) => FaultCode::OverspeedPrecession,
        Some(Fault::Overspeed(_)) => FaultCode::OverspeedSpin,
        Some(Fault::HostSilent) => FaultCode::HostSilent,
        Some(Fault::InvalidConfiguration) => FaultCode::InvalidConfiguration,
    }
}

fn device_state(s: State) -> DeviceState {
    match s {
        State::Idle => DeviceState::Idle,
        State::Commissioning => DeviceState::Commissioning,
        State::SpinningUp => DeviceState::SpinningUp,
        State::Running => DeviceState::Running,
        State::Stopping => DeviceState::Stopping,
        State::Fault => DeviceState::Faulted,
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
        let (params, models) = split_persisted(&stored);
        let stored_base = with_models(&base, &models);
        let (base, params, outcome) = match derive(&stored_base, &params) {
            Ok(_) => (stored_base, params, Ok(())),
            Err(r) => (base, default_params(), Err(r)),
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
            injector,
        };
        (rig, outcome)
    }

    fn models(&self) -> [MotorModel; AXES] {
        let a = &self.ctrl.config().axes;
        [a[0].model, a[1].model]
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
        persisted(&params, &self.models())
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
        let due = idle && (self.params_dirty || models != self.saved_models);
        if due {
            self.params_dirty = false;
            self.saved_models = models;
        }
        due
    }

    fn model(&self, m: ResidenceModel) -> SceneModel {
        SceneModel {
            scene: self.scene,
            model: match m {
                ResidenceModel::Flat => Model::Flat,
                ResidenceModel::Coriolis => Model::Coriolis,
            },
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
            state: device_state(s.state),
            fault: fault_code(s.fault),
            precession: motor(0),
            spin: motor(1),
            bowl_mrad_s: round(s.combined_measured_rad_s * 1000.0) as u16,
            residence_flat: predicted(ResidenceModel::Flat),
            residence_coriolis: predicted(ResidenceModel::Coriolis),
        }
    }

    fn reset_info(&self) -> Hello {
        self.hello
    }

    fn set_speeds(&mut self, precession_mrad_s: i16, spin_mrad_s: i16) -> Result<(), Reason> {
        self.ctrl
            .set_motor_speeds(
                f32::from(precession_mrad_s) * 1e-3,
                f32::from(spin_mrad_s) * 1e-3,
            )
            .map_err(reason)
    }

    fn set_residence(&mut self, model: ResidenceModel, time_ms: u32) -> Result<(), Reason> {
        let m = self.model(model);
        match self
            .ctrl
            .set_target_residence_time(time_ms as f32 * 1e-3, &m)
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
        match id {
            // Owned by the protocol device, never passed here.
            ParamId::TelemetryHz => return Err(Reason::Internal),
            // The scene only feeds RTIME and the predictions: any time.
            ParamId::RimUm | ParamId::StartUm | ParamId::MuPpm | ParamId::K2Ppm => {}
            // Loop tuning: also while running, bumpless.
            ParamId::Bandwidth1MradS
            | ParamId::Bandwidth2MradS
            | ParamId::PerPulse1Milli
            | ParamId::PerPulse2Milli => {
                let axis = usize::from(matches!(
                    id,
                    ParamId::Bandwidth2MradS | ParamId::PerPulse2Milli
                ));
                let a = &cfg.axes[axis];
                self.ctrl
                    .set_loop_tuning(axis, a.bandwidth_rad_s, a.per_pulse_bandwidth)
                    .map_err(reason)?;
            }
            // Everything else rebuilds the controller: idle or faulted only.
            _ => self.ctrl.set_parameters(cfg).map_err(reason)?,
        }
        self.scene = scene;
        self.params = next;
        self.params_dirty = true;
        Ok(())
    }

    fn param(&self, id: ParamId) -> i32 {
        self.params[id.index()]
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

    fn models(&self) -> Result<[AxisModel; AXES], Reason> {
        let identified = self.ctrl.identified();
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
                identified: identified[axis].is_some(),
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
mod tests {
    extern crate std;

    use super::*;
    use crate::wire::device::Device;
    use crate::wire::{Frame, ResetCause, decode_frame};

    /// The protocol device and the rig, as the firmware and the virtual rig pair them.
    struct TestDevice {
        device: Device,
        rig: ControllerBackend<NoInjection>,
    }

    impl TestDevice {
        fn params_to_persist(&self) -> Persisted {
            self.rig.to_persist(self.device.telemetry_hz())
        }
    }

    fn station() -> TestDevice {
        let hello = Hello {
            reset_cause: ResetCause::PowerOn,
            reset_count: 0,
        };
        let (rig, ok) = ControllerBackend::new(
            ControllerConfig::nominal(),
            default_persisted(),
            hello,
            NoInjection,
        );
        assert_eq!(ok, Ok(()), "the defaults must pass their own checks");
        TestDevice {
            device: Device::new(),
            rig,
        }
    }

    fn command(s: &mut TestDevice, line: &str) -> Frame {
        let payload = line.trim_start_matches('$');
        let crc = crate::wire::crc::crc32(payload.as_bytes());
        let bytes = std::format!("${payload}*{crc:08X}\n");
        let mut answer = None;
        s.device.receive(&mut s.rig, bytes.as_bytes(), |f: &[u8]| {
            answer = Some(decode_frame(f).expect("the rig's answer decodes"))
        });
        answer.expect("every command gets an answer")
    }

    #[test]
    fn defaults_round_trip_through_params_and_persisting() {
        let s = station();
        assert_eq!(s.params_to_persist(), default_persisted());
        let (params, models) = split_persisted(&default_persisted());
        assert_eq!(params, default_params());
        assert_eq!(models[1], ControllerConfig::nominal().axes[1].model);
    }

    #[test]
    fn rejected_parameter_changes_nothing() {
        let mut s = station();
        let before = s.params_to_persist();
        // Start radius beyond the rim: inside the wire range, rejected by the scene check.
        let f = command(&mut s, "C1,5,SET,START_UM,900000");
        assert_eq!(
            f,
            Frame::Reject {
                id: 5,
                reason: Reason::Range
            }
        );
        // A duty limit the controller's validation refuses (inside the wire range).
        let f = command(&mut s, "C1,6,SET,DUTY_MAX1_BP,0");
        assert_eq!(
            f,
            Frame::Reject {
                id: 6,
                reason: Reason::Range
            }
        );
        assert_eq!(s.params_to_persist(), before);
        assert!(!s.rig.take_params_to_save());
    }

    #[test]
    fn accepted_parameter_changes_the_controller_and_asks_to_be_saved() {
        let mut s = station();
        let f = command(&mut s, "C1,7,SET,TEETH2,60");
        assert_eq!(f, Frame::Ack { id: 7 });
        assert_eq!(s.rig.controller().config().axes[1].pulses_per_rev, 60);
        assert!(s.rig.take_params_to_save());
        assert!(!s.rig.take_params_to_save(), "saved once");
        let f = command(&mut s, "C1,8,SET,BW1_MRAD_S,4000");
        assert_eq!(f, Frame::Ack { id: 8 });
        assert_eq!(s.rig.controller().config().axes[0].bandwidth_rad_s, 4.0);
        let f = command(&mut s, "C1,9,SET,RATIO_PPM,1500000");
        assert_eq!(f, Frame::Ack { id: 9 });
        assert_eq!(s.rig.controller().config().spin_per_precession, 1.5);
    }

    #[test]
    fn invalid_stored_params_fall_back_to_defaults_and_say_so() {
        let mut bad = default_persisted();
        bad[ParamId::RimUm.index()] = 10_000;
        bad[ParamId::StartUm.index()] = 20_000;
        let (rig, outcome) = ControllerBackend::new(
            ControllerConfig::nominal(),
            bad,
            Hello {
                reset_cause: ResetCause::Pin,
                reset_count: 1,
            },
            NoInjection,
        );
        assert_eq!(outcome, Err(Reason::Range));
        assert_eq!(rig.params(), &default_params());
    }

    #[test]
    fn stored_motor_models_are_used_and_bad_ones_refused() {
        let hello = Hello {
            reset_cause: ResetCause::Software,
            reset_count: 2,
        };
        let (params, mut models) = split_persisted(&default_persisted());
        models[0].time_constant_s = 0.11;
        let (rig, ok) = ControllerBackend::new(
            ControllerConfig::nominal(),
            persisted(&params, &models),
            hello,
            NoInjection,
        );
        assert_eq!(ok, Ok(()));
        assert_eq!(
            rig.controller().config().axes[0].model.time_constant_s,
            0.11
        );
        models[1].volts_per_rad_s = f32::NAN;
        let (rig, ok) = ControllerBackend::new(
            ControllerConfig::nominal(),
            persisted(&params, &models),
            hello,
            NoInjection,
        );
        assert_eq!(ok, Err(Reason::Range));
        let nominal = ControllerConfig::nominal();
        assert_eq!(
            rig.controller().config().axes[1].model,
            nominal.axes[1].model
        );
        assert_eq!(
            rig.controller().config().axes[0].model,
            nominal.axes[0].model
        );
    }

    #[test]
    fn residence_target_sets_speeds_whose_prediction_matches() {
        let mut s = station();
        let f = command(&mut s, "C1,10,RTIME,FLAT,2500");
        assert_eq!(f, Frame::Ack { id: 10 });
        let st = s.rig.controller().status();
        // The forward model at the combined target speed gives back the target.
        let m = s.rig.model(ResidenceModel::Flat);
        let Residence::Ms(t) = m.predicted(st.combined_target_rad_s) else {
            panic!("the particle leaves at the chosen speed");
        };
        assert!(t.abs_diff(2500) <= 3, "predicted {t} ms for a 2.5 s target");
    }

    #[test]
    fn inject_is_unsupported_on_hardware() {
        let mut s = station();
        let f = command(&mut s, "C1,11,INJECT,SENSOR1");
        assert_eq!(
            f,
            Frame::Reject {
                id: 11,
                reason: Reason::Unsupported
            }
        );
    }

    /// The wire's state and fault codes follow the controller's numbering, so a person reading
    /// a code in a frame and one reading the controller's docs see the same number.
    #[test]
    fn state_and_fault_names_keep_the_controller_codes() {
        for state in [
            State::Idle,
            State::Commissioning,
            State::SpinningUp,
            State::Running,
            State::Stopping,
            State::Fault,
        ] {
            assert_eq!(device_state(state).code(), state as u8, "{state:?}");
        }
        for fault in [
            Fault::SensorLostOrStall(0),
            Fault::SensorLostOrStall(1),
            Fault::Overspeed(0),
            Fault::Overspeed(1),
            Fault::HostSilent,
            Fault::InvalidConfiguration,
        ] {
            assert_eq!(fault_code(Some(fault)).code(), fault.code(), "{fault:?}");
        }
        assert_eq!(fault_code(None), FaultCode::None);
    }

    /// MODELS reports the models in force and the PI gains that follow from them (the loop's
    /// design rule: kp = tau Ke / V wc, ki = Ke / V wc, computed here from the configuration).
    #[test]
    fn models_report_the_models_and_gains_in_force() {
        let mut s = station();
        let Frame::Models { id: 20, axes } = command(&mut s, "C1,20,MODELS") else {
            panic!("MODELS answers with a models frame");
        };
        let cfg = ControllerConfig::nominal();
        for (a, c) in axes.iter().zip(cfg.axes.iter()) {
            assert!(!a.identified, "nothing commissioned yet");
            let m = c.model;
            let ppm = |x: f32| libm::round(f64::from(x) * 1e6);
            assert_eq!(f64::from(a.back_emf_uv_per_rad_s), ppm(m.volts_per_rad_s));
            assert_eq!(f64::from(a.friction_ppm), ppm(m.friction_duty));
            assert_eq!(f64::from(a.time_constant_us), ppm(m.time_constant_s));
            let ke_v = f64::from(m.volts_per_rad_s) / f64::from(cfg.supply_v);
            let wc = f64::from(c.bandwidth_rad_s);
            let kp = f64::from(m.time_constant_s) * ke_v * wc * 1e6;
            let ki = ke_v * wc * 1e6;
            assert!((f64::from(a.kp_ppm_per_rad_s) - kp).abs() <= 1e-5 * kp + 1.0);
            assert!((f64::from(a.ki_ppm_per_rad) - ki).abs() <= 1e-5 * ki + 1.0);
        }
    }
}

//! The backend through the protocol device, as the firmware and the virtual rig pair them.

extern crate std;

use super::*;
use crate::binding::{NoInjection, default_persisted};
use crate::wire::device::Device;
use crate::wire::{Frame, ResetCause, decode_frame};

/// The protocol device and the rig, as the firmware and the virtual rig pair them.
pub(super) struct TestDevice {
    device: Device,
    pub(super) rig: ControllerBackend<NoInjection>,
}

impl TestDevice {
    fn params_to_persist(&self) -> Persisted {
        self.rig.to_persist(self.device.telemetry_hz())
    }
}

pub(super) fn station() -> TestDevice {
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

pub(super) fn command(s: &mut TestDevice, line: &str) -> Frame {
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
    let r = split_persisted(&default_persisted());
    assert_eq!(r.params, default_params());
    assert_eq!(r.models[1], ControllerConfig::nominal().axes[1].model);
    assert_eq!(r.identified, [false, false]);
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
    // A duty limit below its wire range (the range is what the controller accepts).
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
    let Record {
        params, mut models, ..
    } = split_persisted(&default_persisted());
    let boot = |models| {
        ControllerBackend::new(
            ControllerConfig::nominal(),
            persisted(&Record {
                params,
                models,
                identified: [false; AXES],
            }),
            hello,
            NoInjection,
        )
    };
    models[0].time_constant_s = 0.11;
    let (rig, ok) = boot(models);
    assert_eq!(ok, Ok(()));
    assert_eq!(
        rig.controller().config().axes[0].model.time_constant_s,
        0.11
    );
    models[1].volts_per_rad_s = f32::NAN;
    let (rig, ok) = boot(models);
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
        State::ChangingSpeed,
        State::Running,
        State::Stopping,
        State::Fault,
    ] {
        assert_eq!(DeviceState::from(state).code(), state as u8, "{state:?}");
    }
    // Each fault and the wire fault named for it, written out here as the reference (a new
    // fault fails to compile in `listed` until it has its row).
    let table = [
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
        (Fault::SensorLost(0), FaultCode::SensorLostPrecession),
        (Fault::SensorLost(1), FaultCode::SensorLostSpin),
        (Fault::Stall(0), FaultCode::StallPrecession),
        (Fault::Stall(1), FaultCode::StallSpin),
        (Fault::OverCurrent(0), FaultCode::OverCurrentPrecession),
        (Fault::OverCurrent(1), FaultCode::OverCurrentSpin),
        (
            Fault::CurrentAboveModel(0),
            FaultCode::CurrentAboveModelPrecession,
        ),
        (
            Fault::CurrentAboveModel(1),
            FaultCode::CurrentAboveModelSpin,
        ),
        (Fault::HardwareStop, FaultCode::HardwareStop),
    ];
    let listed = |f: Fault| match f {
        Fault::SensorLostOrStall(_)
        | Fault::Overspeed(_)
        | Fault::HostSilent
        | Fault::InvalidConfiguration
        | Fault::SensorLost(_)
        | Fault::Stall(_)
        | Fault::OverCurrent(_)
        | Fault::CurrentAboveModel(_)
        | Fault::HardwareStop => table.iter().any(|&(g, _)| g == f),
    };
    for &(fault, wire) in &table {
        assert!(listed(fault));
        assert_eq!(FaultCode::from(Some(fault)), wire, "{fault:?}");
        assert_eq!(wire.code(), fault.code(), "{fault:?}");
    }
    // An axis index past the spin's is the spin's, as `Fault::code` reads it.
    assert_eq!(FaultCode::from(Some(Fault::Stall(7))), FaultCode::StallSpin);
    // Every wire fault but "none" is some controller fault's.
    assert_eq!(table.len(), FaultCode::ALL.len() - 1);
    assert_eq!(FaultCode::from(None), FaultCode::None);
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
        // The ceiling: the configured bandwidth, or the per-pulse schedule at 2.1 rad/s.
        let at_top = f64::from(c.per_pulse_bandwidth) * f64::from(c.pulses_per_rev)
            / std::f64::consts::TAU
            * 2.1;
        let wc = f64::from(c.bandwidth_rad_s).min(at_top);
        let kp = f64::from(m.time_constant_s) * ke_v * wc * 1e6;
        let ki = ke_v * wc * 1e6;
        assert!((f64::from(a.kp_ppm_per_rad_s) - kp).abs() <= 1e-5 * kp + 1.0);
        assert!((f64::from(a.ki_ppm_per_rad) - ki).abs() <= 1e-5 * ki + 1.0);
    }
}

/// A model identified on an earlier boot is reported identified after a reset, and only on the
/// axes whose stored flag says so; a record that fails its checks brings no flag with it.
#[test]
fn identified_flags_survive_a_reset_with_their_models() {
    let boot = |identified: [bool; AXES], models: [MotorModel; AXES]| {
        let (rig, ok) = ControllerBackend::new(
            ControllerConfig::nominal(),
            persisted(&Record {
                params: default_params(),
                models,
                identified,
            }),
            Hello {
                reset_cause: ResetCause::Pin,
                reset_count: 1,
            },
            NoInjection,
        );
        let mut s = TestDevice {
            device: Device::new(),
            rig,
        };
        let Frame::Models { axes, .. } = command(&mut s, "C1,7,MODELS") else {
            panic!("MODELS answers with a models frame");
        };
        (ok, axes, s)
    };
    let nominal = ControllerConfig::nominal();
    let mut models = [nominal.axes[0].model, nominal.axes[1].model];
    models[1].time_constant_s = 0.21;
    let (ok, axes, s) = boot([false, true], models);
    assert_eq!(ok, Ok(()));
    assert_eq!([axes[0].identified, axes[1].identified], [false, true]);
    assert_eq!(axes[1].time_constant_us, 210_000);
    // Persisting again keeps the flags: the record round-trips.
    assert_eq!(
        split_persisted(&s.params_to_persist()).identified,
        [false, true]
    );
    models[1].volts_per_rad_s = f32::NAN;
    let (ok, axes, _) = boot([true, true], models);
    assert_eq!(ok, Err(Reason::Range));
    assert!(!axes[0].identified && !axes[1].identified);
}

/// `ParamRole::changes_while_running` is what the rig does: with the motors started, SET of
/// each parameter (to its default) is taken exactly when its role says so, and refused STATE
/// otherwise (the PC's refusal words rely on it).
#[test]
fn set_while_running_follows_each_parameters_role() {
    let mut s = station();
    assert_eq!(
        command(&mut s, "C1,1,SPEED,1000,1000"),
        Frame::Ack { id: 1 }
    );
    assert_eq!(command(&mut s, "C1,2,START"), Frame::Ack { id: 2 });
    for (i, id) in ParamId::ALL.iter().copied().enumerate() {
        let n = 10 + i as u16;
        let line = std::format!("C1,{n},SET,{},{}", id.token(), id.default_value());
        let f = command(&mut s, &line);
        if ParamRole::of(id).changes_while_running() {
            assert_eq!(f, Frame::Ack { id: n }, "{}", id.token());
        } else {
            assert_eq!(
                f,
                Frame::Reject {
                    id: n,
                    reason: Reason::State
                },
                "{}",
                id.token()
            );
        }
    }
}

/// TELEM_HZ is kept by the protocol device, not the backend, yet it is saved with the other
/// parameters: a SET of it alone must ask for a save, or the board comes back from a reset at
/// the old rate while every other parameter set the same way survives.
#[test]
fn a_new_telemetry_rate_alone_asks_to_be_saved() {
    let mut s = station();
    assert!(!s.rig.take_params_to_save());
    let f = command(&mut s, "C1,7,SET,TELEM_HZ,10");
    assert_eq!(f, Frame::Ack { id: 7 });
    assert!(s.rig.take_params_to_save(), "a new rate is saved");
    let saved = split_persisted(&s.params_to_persist());
    assert_eq!(saved.params[ParamId::TelemetryHz.index()], 10);
    // The same rate again changes nothing: no flash write for it.
    let f = command(&mut s, "C1,8,SET,TELEM_HZ,10");
    assert_eq!(f, Frame::Ack { id: 8 });
    assert!(!s.rig.take_params_to_save());
}

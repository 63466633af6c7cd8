//! The backend through the protocol device, as the firmware and the virtual rig pair them.

extern crate std;

use super::*;
use crate::binding::{NoInjection, default_persisted};
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
fn residence_target_sets_speeds_whose_prediction_matches() {
    let mut s = station();
    let f = command(&mut s, "C1,10,RTIME,FLAT,2500");
    let st = s.rig.controller().status();
    // The answer names the model and carries the setpoints the controller now holds.
    let Frame::ResidenceSet {
        id: 10,
        model: ResidenceModel::Flat,
        precession_mrad_s,
        spin_mrad_s,
    } = f
    else {
        panic!("{f:?}");
    };
    let held = st.axes.map(|a| (a.target_rad_s * 1e3).round() as i16);
    assert_eq!([precession_mrad_s, spin_mrad_s], held);
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
        Fault::SensorLost(0),
        Fault::SensorLost(1),
        Fault::Stall(0),
        Fault::Stall(1),
        Fault::OverCurrent(0),
        Fault::OverCurrent(1),
        Fault::CurrentAboveModel(0),
        Fault::CurrentAboveModel(1),
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

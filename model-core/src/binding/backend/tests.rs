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
    let m = s.rig.model(crate::particle::Model::Flat);
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

/// Stores `times_us` at bowl speeds 0.5..=3.6 rad/s as the PC does: speeds off first, the
/// fastest speed last (it switches the table on).
fn store_table(s: &mut TestDevice, times_us: [i32; 8]) {
    let mut id = 100;
    let mut set = |s: &mut TestDevice, token: &str, v: i32| {
        id += 1;
        let f = command(s, &std::format!("C1,{id},SET,{token},{v}"));
        assert_eq!(f, Frame::Ack { id }, "SET {token} {v}");
    };
    set(s, "RT_W_HI_MRAD_S", 0);
    for (k, t) in times_us.iter().enumerate() {
        set(s, &std::format!("RT_T{}_US", k + 1), *t);
    }
    set(s, "RT_W_LO_MRAD_S", 500);
    set(s, "RT_W_HI_MRAD_S", 3600);
}

/// The times of a table `T = 2 s / (1 + w)` at 0.5 + k 3.1/7 rad/s, us.
fn falling_table_us() -> [i32; 8] {
    core::array::from_fn(|k| {
        let w = 0.5 + k as f64 * 3.1 / 7.0;
        (2e6 / (1.0 + w)).round() as i32
    })
}

#[test]
fn rtime_table_without_a_table_is_infeasible() {
    let mut s = station();
    let f = command(&mut s, "C1,20,RTIME,TABLE,500");
    assert_eq!(
        f,
        Frame::Reject {
            id: 20,
            reason: Reason::Infeasible
        }
    );
}

#[test]
fn rtime_table_inside_the_table_sets_the_interpolated_speed() {
    let mut s = station();
    let times = falling_table_us();
    store_table(&mut s, times);
    // 0.8 s: between entries 2 (w = 1.386, T = 0.8381 s) and 3 (w = 1.829, T = 0.7071 s).
    let f = command(&mut s, "C1,21,RTIME,TABLE,800");
    let Frame::ResidenceSet {
        model: ResidenceModel::Table,
        ..
    } = f
    else {
        panic!("{f:?}");
    };
    // Independently: linear interpolation between the two bracketing entries.
    let (w2, w3) = (0.5 + 2.0 * 3.1 / 7.0, 0.5 + 3.0 * 3.1 / 7.0);
    let (t2, t3) = (f64::from(times[2]) * 1e-6, f64::from(times[3]) * 1e-6);
    let expected = w2 + (0.8 - t2) / (t3 - t2) * (w3 - w2);
    let got = f64::from(s.rig.controller().status().combined_target_rad_s);
    assert!(
        (got - expected).abs() < 1e-4,
        "{got} rad/s, expected {expected}"
    );
    // And the table at that speed gives the target back.
    let table = table_from_params(s.rig.params()).unwrap().unwrap();
    let back = table.residence_at_s(got as f32).unwrap();
    assert!((back - 0.8).abs() < 1e-4, "{back}");
}

#[test]
fn rtime_table_outside_or_flat_is_infeasible_and_changes_nothing() {
    let mut s = station();
    store_table(&mut s, falling_table_us());
    let before = s.rig.controller().status().combined_target_rad_s;
    // The table spans 0.4348 s (3.6 rad/s) to 1.3333 s (0.5 rad/s).
    for (id, ms) in [(30, 400), (31, 1400)] {
        let f = command(&mut s, &std::format!("C1,{id},RTIME,TABLE,{ms}"));
        assert_eq!(
            f,
            Frame::Reject {
                id,
                reason: Reason::Infeasible
            }
        );
    }
    assert_eq!(s.rig.controller().status().combined_target_rad_s, before);
    // 0.143 to 0.144 s over the whole range: speed cannot set it, even inside.
    store_table(
        &mut s,
        core::array::from_fn(|k| 143_000 + (k as i32) * 1_000 / 7),
    );
    let f = command(&mut s, "C1,32,RTIME,TABLE,143");
    assert_eq!(
        f,
        Frame::Reject {
            id: 32,
            reason: Reason::Infeasible
        }
    );
}

#[test]
fn a_switched_on_table_with_a_zero_time_is_refused() {
    let mut s = station();
    store_table(&mut s, falling_table_us());
    let f = command(&mut s, "C1,40,SET,RT_T4_US,0");
    assert_eq!(
        f,
        Frame::Reject {
            id: 40,
            reason: Reason::Range
        }
    );
    // Switched off, the same value is taken (the PC writes a table that way).
    assert_eq!(
        command(&mut s, "C1,41,SET,RT_W_HI_MRAD_S,0"),
        Frame::Ack { id: 41 }
    );
    assert_eq!(
        command(&mut s, "C1,42,SET,RT_T4_US,0"),
        Frame::Ack { id: 42 }
    );
}

#[test]
fn rtime_with_a_paper_model_outside_the_speed_limits_is_infeasible() {
    // Without a table the 1-D models answer, and refuse a time no allowed speed gives: the
    // flat model's T grows without bound as the bowl slows, and below the lowest speed the
    // sensors can measure, no setpoint gives 9999 s.
    let mut s = station();
    let f = command(&mut s, "C1,50,RTIME,FLAT,9999999");
    assert_eq!(
        f,
        Frame::Reject {
            id: 50,
            reason: Reason::Infeasible
        }
    );
    let f = command(&mut s, "C1,51,RTIME,CORI,1");
    assert_eq!(
        f,
        Frame::Reject {
            id: 51,
            reason: Reason::Infeasible
        }
    );
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

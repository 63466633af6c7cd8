//! Supervisor and command contract, with faults injected on the simulated rig.

use model_core::control::{ConfigError, Controller, ControllerConfig, Fault, Rejection, State};
use model_core::sim::experiments::{rig_with_pulses, true_model_config};
use model_core::sim::{ClosedLoop, Plant, PlantParams};

/// A controller given the nominal rig's true model (no commissioning: faster tests).
fn running_loop(rig: PlantParams, cfg_edit: impl FnOnce(&mut ControllerConfig)) -> ClosedLoop {
    let mut cfg = true_model_config(&rig);
    cfg_edit(&mut cfg);
    ClosedLoop::new(Plant::new(rig, 7), Controller::new(cfg).unwrap())
}

/// Runs to steady 3 rad/s, injects with `inject` at t = 3 s, returns (time of the fault after
/// injection, fault) and checks both duties are zero from the fault tick on.
fn fault_after(
    rig: PlantParams,
    inject: impl Fn(&mut PlantParams, f32),
    speed: f32,
) -> (f32, Option<Fault>) {
    let mut cl = running_loop(rig, |_| {});
    cl.ctrl.set_motor_speeds(speed, speed).unwrap();
    cl.ctrl.start().unwrap();
    let n = rig.axes[0].sensor.pulses_per_rev as f32;
    cl.run(
        3.0f32.max(12.0 * std::f32::consts::TAU / (n * speed)),
        |_| {},
    );
    assert_eq!(
        cl.ctrl.state(),
        State::Running,
        "not running before the fault"
    );
    let t0 = cl.rig.time_s() as f32;
    inject(cl.rig.params_mut(), t0);
    let dt = cl.dt_s();
    for k in 0..20_000 {
        let d = cl.tick();
        if cl.ctrl.fault().is_some() {
            assert_eq!(d, [0.0, 0.0], "duties not zero in the fault tick");
            for _ in 0..100 {
                assert_eq!(cl.tick(), [0.0, 0.0], "duties not held at zero");
            }
            assert_eq!(cl.ctrl.state(), State::Fault);
            return ((k + 1) as f32 * dt, cl.ctrl.fault());
        }
    }
    (f32::INFINITY, None)
}

#[test]
fn dead_sensor_is_detected_within_max_200ms_or_3_pulse_periods() {
    for (n, speed) in [(12u16, 3.0f32), (60, 3.0), (12, 1.0), (1, 3.0)] {
        for axis in 0..2 {
            let rig = rig_with_pulses(n);
            let (t, fault) = fault_after(
                rig,
                |p, t0| p.axes[axis].faults.dead_sensor_from_s = t0,
                speed,
            );
            let period = std::f32::consts::TAU / (n as f32 * speed);
            let limit = (3.0 * period).max(0.2);
            assert_eq!(
                fault,
                Some(Fault::SensorLostOrStall(axis as u8)),
                "N {n} axis {axis}"
            );
            // One tick of slack for the detection tick itself.
            assert!(t <= limit + 0.002, "N {n} axis {axis}: {t} s > {limit} s");
        }
    }
}

#[test]
fn blocked_shaft_is_the_same_fault_and_stops_both_motors() {
    let (t, fault) = fault_after(
        rig_with_pulses(12),
        |p, t0| p.axes[1].faults.blocked_from_s = t0,
        3.0,
    );
    assert_eq!(fault, Some(Fault::SensorLostOrStall(1)));
    assert!(t < 0.6, "{t}");
}

#[test]
fn overspeed_latches_and_clear_returns_to_idle() {
    let mut c = Controller::new(ControllerConfig::nominal()).unwrap();
    // 12 pulses/rev at 7 rad/s (over the 5.5 rad/s limit): a pulse every 74.8 ms.
    let period_ticks = (std::f32::consts::TAU / (12.0 * 7.0) * 1e6) as u32;
    let mut next = 1000u32;
    let mut fault = None;
    for k in 1..2000u32 {
        let now = k * 1000;
        let mut e = Vec::new();
        while next <= now {
            e.push(next);
            next += period_ticks;
        }
        c.tick(now, [&[], &e]);
        if c.fault().is_some() {
            fault = c.fault();
            break;
        }
    }
    assert_eq!(fault, Some(Fault::Overspeed(1)));
    assert_eq!(fault.unwrap().code(), 4);
    assert_eq!(c.start(), Err(Rejection::Faulted(Fault::Overspeed(1))));
    assert_eq!(
        c.set_motor_speeds(1.0, 1.0),
        Err(Rejection::Faulted(Fault::Overspeed(1)))
    );
    assert_eq!(c.clear_fault(), Ok(()));
    assert_eq!(c.state(), State::Idle);
    assert_eq!(c.clear_fault(), Err(Rejection::NotFaulted));
}

#[test]
fn host_silence_faults_only_when_enabled() {
    for (timeout, heartbeat, want) in [
        (0.0, false, None),
        (0.5, false, Some(Fault::HostSilent)),
        (0.5, true, None),
    ] {
        let mut cl = running_loop(rig_with_pulses(12), |c| c.host_timeout_s = timeout);
        cl.ctrl.set_motor_speeds(2.0, 2.0).unwrap();
        cl.ctrl.start().unwrap();
        let mut fault_at = None;
        for k in 0..3000 {
            if heartbeat && k % 200 == 0 {
                cl.ctrl.host_heartbeat();
            }
            cl.tick();
            if fault_at.is_none() && cl.ctrl.fault().is_some() {
                fault_at = Some(k);
            }
        }
        assert_eq!(
            cl.ctrl.fault(),
            want,
            "timeout {timeout} heartbeat {heartbeat}"
        );
        if want.is_some() {
            let k = fault_at.unwrap();
            assert!((499..=502).contains(&k), "host fault at tick {k}");
            assert_eq!(cl.duties(), [0.0, 0.0]);
        }
    }
}

#[test]
fn invalid_configuration_is_refused_or_boots_faulted() {
    let mut bad = ControllerConfig::nominal();
    bad.axes[1].pulses_per_rev = 0;
    assert_eq!(
        Controller::new(bad).err(),
        Some(ConfigError::PulsesPerRev(1))
    );
    let mut c = Controller::new_or_faulted(bad);
    assert_eq!(c.fault(), Some(Fault::InvalidConfiguration));
    assert_eq!(c.fault().unwrap().code(), 6);
    assert_eq!(c.tick(1000, [&[], &[]]), [0.0, 0.0]);
    assert_eq!(
        c.clear_fault(),
        Err(Rejection::InvalidConfig(ConfigError::PulsesPerRev(1)))
    );
    assert_eq!(
        c.set_parameters(bad),
        Err(Rejection::InvalidConfig(ConfigError::PulsesPerRev(1)))
    );
    assert_eq!(c.set_parameters(ControllerConfig::nominal()), Ok(()));
    assert_eq!(
        c.state(),
        State::Fault,
        "the fault stays latched until cleared"
    );
    assert_eq!(c.clear_fault(), Ok(()));
    assert_eq!(c.state(), State::Idle);
}

/// SET of a parameter keeps the speeds asked for (the rig found it zeroed them: START then
/// answered ok with both motors still), unless the new limits refuse them.
#[test]
fn set_parameters_keeps_the_speeds_asked_for() {
    let mut c = Controller::new(ControllerConfig::nominal()).unwrap();
    assert_eq!(c.set_motor_speeds(1.8, 2.1), Ok(()));
    assert_eq!(c.set_parameters(ControllerConfig::nominal()), Ok(()));
    let axes = c.status().axes;
    assert_eq!([axes[0].target_rad_s, axes[1].target_rad_s], [1.8, 2.1]);
    let mut slow = ControllerConfig::nominal();
    slow.axes[1].max_speed_rad_s = 1.0;
    assert_eq!(c.set_parameters(slow), Ok(()));
    assert_eq!(c.status().axes[1].target_rad_s, 0.0);
}

#[test]
fn rejected_commands_change_nothing() {
    let mut c = Controller::new(ControllerConfig::nominal()).unwrap();
    c.set_motor_speeds(1.0, 2.0).unwrap();
    let before = c;
    let cases = [
        (
            c.clone().set_motor_speeds(f32::NAN, 1.0),
            Rejection::NotFinite,
        ),
        (
            c.clone().set_motor_speeds(1.0, 4.5),
            Rejection::AboveMaxSpeed(1),
        ),
        (
            c.clone().set_motor_speeds(-4.5, 1.0),
            Rejection::AboveMaxSpeed(0),
        ),
        (
            c.clone().set_motor_speeds(0.1, 1.0),
            Rejection::BelowMinSpeed(0),
        ),
        (
            c.clone().set_loop_tuning(0, -1.0, 0.5),
            Rejection::InvalidTuning,
        ),
        (
            c.clone().set_loop_tuning(2, 1.0, 0.5),
            Rejection::InvalidTuning,
        ),
    ];
    for (got, want) in cases {
        assert_eq!(got, Err(want));
    }
    // The same commands on the controller itself leave it bit-for-bit unchanged, apart from the
    // host-silence timer every command resets (zero here anyway).
    let _ = c.set_motor_speeds(f32::NAN, 1.0);
    let _ = c.set_motor_speeds(1.0, 4.5);
    let _ = c.set_motor_speeds(0.1, 1.0);
    let _ = c.set_loop_tuning(0, -1.0, 0.5);
    let mut bad = ControllerConfig::nominal();
    bad.supply_v = f32::INFINITY;
    assert_eq!(
        c.set_parameters(bad),
        Err(Rejection::InvalidConfig(ConfigError::SupplyVoltage))
    );
    assert_eq!(c, before);
    // Zero is always a valid speed, negative speeds are a direction.
    assert_eq!(c.set_motor_speeds(0.0, -2.0), Ok(()));
    assert_eq!(c.status().axes[1].target_rad_s, -2.0);
}

#[test]
fn states_follow_start_stop_and_refuse_out_of_order_commands() {
    let mut cl = running_loop(rig_with_pulses(12), |_| {});
    assert_eq!(cl.ctrl.state(), State::Idle);
    assert_eq!(cl.ctrl.stop(), Ok(()));
    cl.ctrl.set_motor_speeds(2.0, 2.0).unwrap();
    cl.ctrl.start().unwrap();
    assert_eq!(
        cl.ctrl.start(),
        Err(Rejection::WrongState(State::ChangingSpeed))
    );
    assert_eq!(
        cl.ctrl.set_parameters(ControllerConfig::nominal()),
        Err(Rejection::WrongState(State::ChangingSpeed))
    );
    cl.run(3.0, |_| {});
    assert_eq!(cl.ctrl.state(), State::Running);
    cl.ctrl.stop().unwrap();
    assert_eq!(cl.ctrl.state(), State::Stopping);
    assert_eq!(
        cl.ctrl.set_motor_speeds(1.0, 1.0),
        Err(Rejection::WrongState(State::Stopping))
    );
    cl.run(6.0, |_| {});
    assert_eq!(cl.ctrl.state(), State::Idle);
    assert!(cl.rig.speed_rad_s(0).abs() < 1e-3 && cl.rig.speed_rad_s(1).abs() < 1e-3);
    // Idle: zero duty, whatever edges arrive.
    assert_eq!(cl.tick(), [0.0, 0.0]);
}

#[test]
fn zero_setpoint_gives_exactly_zero_duty_no_hum() {
    let mut cl = running_loop(rig_with_pulses(12), |_| {});
    cl.ctrl.set_motor_speeds(0.0, 0.0).unwrap();
    cl.ctrl.start().unwrap();
    let mut max = 0.0f32;
    cl.run(3.0, |c| {
        max = max.max(c.duties()[0].abs()).max(c.duties()[1].abs())
    });
    assert_eq!(max, 0.0);
    assert_eq!(cl.ctrl.fault(), None);
}

#[test]
fn dead_sensor_from_power_up_faults_during_spin_up() {
    let mut rig = rig_with_pulses(12);
    rig.axes[0].faults.dead_sensor_from_s = 0.0;
    let mut cl = running_loop(rig, |_| {});
    cl.ctrl.set_motor_speeds(3.0, 3.0).unwrap();
    cl.ctrl.start().unwrap();
    let mut t_fault = None;
    for k in 0..3000 {
        cl.tick();
        if cl.ctrl.fault().is_some() {
            t_fault = Some(k as f32 * 1e-3);
            assert_eq!(cl.duties(), [0.0, 0.0]);
            break;
        }
    }
    assert_eq!(cl.ctrl.fault(), Some(Fault::SensorLostOrStall(0)));
    // The model needs about 0.8 s to turn three pitches from rest on this ramp.
    assert!(t_fault.unwrap() < 1.2, "{t_fault:?}");
}

#[test]
fn sixteen_bit_capture_timer_runs_the_same_loop() {
    let mut rig = rig_with_pulses(12);
    rig.timer_bits = 16;
    let mut cl = running_loop(rig, |c| c.timer_bits = 16);
    cl.ctrl.set_motor_speeds(0.5, 3.0).unwrap();
    cl.ctrl.start().unwrap();
    cl.run(8.0, |_| {});
    assert_eq!(cl.ctrl.fault(), None);
    assert!((cl.rig.speed_rad_s(0) - 0.5).abs() < 0.02);
    assert!((cl.rig.speed_rad_s(1) - 3.0).abs() < 0.06);
    let s = cl.ctrl.status();
    assert!(
        (s.axes[0].measured_rad_s - 0.5).abs() < 0.03,
        "{:?}",
        s.axes[0]
    );
}

#[test]
fn a_dead_sensor_at_low_speed_is_detected_whatever_the_duty() {
    // At 0.5 and 0.2 rad/s the duty that holds the nominal shaft (about 0.13 and 0.09) is below
    // the old fixed stall threshold of 0.15: the watch runs on expected edge times alone.
    for speed in [0.5f32, 0.2] {
        let rig = rig_with_pulses(12);
        let (t, fault) = fault_after(rig, |p, t0| p.axes[1].faults.dead_sensor_from_s = t0, speed);
        let bound = (3.0 * std::f32::consts::TAU / (12.0 * speed)).max(0.2);
        assert_eq!(fault, Some(Fault::SensorLostOrStall(1)), "{speed} rad/s");
        assert!(
            t <= bound,
            "{speed} rad/s: detected after {t} s, bound {bound} s"
        );
    }
}

#[test]
fn a_bridge_stuck_on_is_caught_by_the_first_early_edge() {
    // Full duty from 1 rad/s: the shaft runs towards 7 rad/s; the first edge interval faster
    // than 1.2 x the model speed + 0.3 rad/s latches the over-speed fault long before the
    // filtered speed reaches the 5.5 rad/s limit.
    let rig = rig_with_pulses(12);
    let (t, fault) = fault_after(rig, |p, t0| p.axes[1].faults.bridge_stuck_from_s = t0, 1.0);
    assert_eq!(fault, Some(Fault::Overspeed(1)));
    // Within two pulse periods at the setpoint (the second edge after injection at the latest).
    assert!(
        t <= 2.0 * std::f32::consts::TAU / 12.0,
        "detected after {t} s"
    );
}

#[test]
fn speeds_below_what_the_pulses_can_measure_are_refused() {
    // One pulse per revolution: the lowest speed is 2 pi / 4 s = 1.57 rad/s, above the
    // configured 0.2 rad/s.
    let rig = rig_with_pulses(1);
    let mut cl = running_loop(rig, |_| {});
    assert_eq!(
        cl.ctrl.set_motor_speeds(1.0, 1.0),
        Err(Rejection::BelowMinSpeed(0))
    );
    assert!(cl.ctrl.set_motor_speeds(1.6, 1.6).is_ok());
}

#[test]
fn a_bridge_stuck_on_near_the_top_speed_is_caught_by_its_duty_and_its_revolution() {
    // A supply at which full duty drives the spin only 8 % above a 3 rad/s setpoint: one or
    // two early intervals cannot tell that from tooth offsets, but the loop lowers its duty
    // against the excess speed while the shaft keeps it, and the revolution's mean rises.
    let mut rig = rig_with_pulses(12);
    let spin = rig.axes[1].motor;
    let (volts_per_rad_s, _, _) = spin.ideal_model(12.0);
    let top_rad_s = 3.24;
    rig.supply_v =
        top_rad_s * volts_per_rad_s + spin.resistance_ohm * spin.coulomb_nm / spin.torque_constant;
    let mut cl = running_loop(rig, |c| c.supply_v = rig.supply_v);
    cl.ctrl.set_motor_speeds(1.0, 3.0).unwrap();
    cl.ctrl.start().unwrap();
    cl.run(8.0, |c| {
        assert_eq!(c.ctrl.fault(), None, "a healthy shaft faulted")
    });
    assert_eq!(cl.ctrl.state(), State::Running);
    let t0 = cl.rig.time_s() as f32;
    cl.rig.params_mut().axes[1].faults.bridge_stuck_from_s = t0;
    let mut peak = 0.0f32;
    let mut detected = None;
    for k in 0..3_000 {
        let d = cl.tick();
        peak = peak.max(cl.rig.speed_rad_s(1));
        if cl.ctrl.fault().is_some() {
            assert_eq!(d, [0.0, 0.0], "duties not zero in the fault tick");
            detected = Some((k + 1) as f32 * cl.dt_s());
            break;
        }
    }
    assert_eq!(cl.ctrl.fault(), Some(Fault::Overspeed(1)));
    let t = detected.unwrap();
    // Measured 0.51 s (3 pulse periods: 0.52 s); 0.67 s by the duty rule alone, never by the
    // interval rules.
    assert!(t < 0.6, "detected after {t} s");
    assert!(peak < 1.1 * 3.0, "peak {peak} rad/s");
}

#[test]
fn material_leaving_the_bowl_near_the_top_speed_is_no_runaway() {
    // The spin near its top speed carries material the model does not know; the material
    // leaves at once: the shaft speeds up until the loop has lowered its duty, a lasting excess
    // to no rule, and no fault.
    let mut rig = rig_with_pulses(12);
    let spin = rig.axes[1].motor;
    let (volts_per_rad_s, _, _) = spin.ideal_model(12.0);
    rig.supply_v =
        4.0 * volts_per_rad_s + spin.resistance_ohm * spin.coulomb_nm / spin.torque_constant;
    rig.axes[1].faults.load_step_from_s = 0.0;
    // As much as the families pour in at most.
    rig.axes[1].faults.load_step_nm = 0.1;
    let mut cl = running_loop(rig, |c| c.supply_v = rig.supply_v);
    cl.ctrl.set_motor_speeds(1.0, 3.0).unwrap();
    cl.ctrl.start().unwrap();
    cl.run(10.0, |_| {});
    assert_eq!(cl.ctrl.state(), State::Running);
    cl.rig.params_mut().axes[1].faults.load_step_nm = 0.0;
    let mut peak = 0.0f32;
    cl.run(10.0, |c| {
        peak = peak.max(c.rig.speed_rad_s(1));
        assert_eq!(c.ctrl.fault(), None, "faulted at {} s", c.rig.time_s());
    });
    // The load's release shows: the shaft did speed up.
    assert!(peak > 3.05, "peak {peak} rad/s");
}

#[test]
fn a_hardware_stop_latches_in_its_tick_and_asks_for_the_supply_cut() {
    let mut cl = running_loop(PlantParams::nominal(), |_| {});
    cl.ctrl.set_motor_speeds(1.0, 2.0).unwrap();
    cl.ctrl.start().unwrap();
    cl.run(2.0, |_| {});
    assert!(cl.ctrl.fault().is_none());
    assert!(
        cl.tick().iter().any(|d| *d != 0.0),
        "not driving before the stop"
    );
    // The board's break input tripped: latched at once, both duties zero from the next tick.
    cl.ctrl.hardware_stop();
    assert_eq!(cl.ctrl.state(), State::Fault);
    assert_eq!(cl.ctrl.fault(), Some(Fault::HardwareStop));
    assert!(Fault::HardwareStop.cuts_supply());
    assert_eq!(cl.tick(), [0.0, 0.0]);
    // The other faults are stopped by the bridge itself: no supply cut asked.
    for f in [
        Fault::SensorLostOrStall(0),
        Fault::Overspeed(1),
        Fault::HostSilent,
        Fault::InvalidConfiguration,
    ] {
        assert!(!f.cuts_supply(), "{f:?} asks for the supply cut");
    }
    // CLEAR returns to Idle; a stop tripped again (the line still low) latches again.
    cl.ctrl.clear_fault().unwrap();
    assert_eq!(cl.ctrl.state(), State::Idle);
    cl.ctrl.hardware_stop();
    assert_eq!(cl.ctrl.fault(), Some(Fault::HardwareStop));
    // A fault latched first is kept (the first cause is the one to read).
    cl.ctrl.clear_fault().unwrap();
    cl.ctrl.set_motor_speeds(1.0, 2.0).unwrap();
    cl.ctrl.start().unwrap();
    cl.rig.params_mut().axes[1].faults.dead_sensor_from_s = cl.rig.time_s() as f32;
    cl.run(3.0, |_| {});
    assert_eq!(cl.ctrl.fault(), Some(Fault::SensorLostOrStall(1)));
    cl.ctrl.hardware_stop();
    assert_eq!(cl.ctrl.fault(), Some(Fault::SensorLostOrStall(1)));
}

/// A speed that wanders about the reached band's edge (a tooth map a few percent off at low
/// speed) stays running: it used to flip between running and changing speed at every tick.
#[test]
fn a_speed_wandering_about_the_band_edge_stays_running() {
    use model_core::control::supervisor::{REACHED_FLOOR_RAD_S, REACHED_SHARE, closed_loop_state};
    let r = [0.5f32, -1.0];
    let edge = |k: usize| {
        let side = if k.is_multiple_of(2) { 0.99 } else { 1.01 };
        [
            r[0] + side * (REACHED_SHARE * 0.5 + REACHED_FLOOR_RAD_S),
            r[1] - side * (REACHED_SHARE * 1.0 + REACHED_FLOOR_RAD_S),
        ]
    };
    let mut state = State::ChangingSpeed;
    let mut states = Vec::new();
    for k in 0..20 {
        state = closed_loop_state(state, r, r, edge(k));
        states.push(state);
    }
    assert_eq!(states[0], State::Running, "inside the band is running");
    assert!(
        states.iter().all(|&s| s == State::Running),
        "flickered: {states:?}"
    );
    // Straying past twice the band is changing speed again, and coming back inside the band
    // (not only inside twice the band) is needed to be running again.
    let off = |bands: f32| {
        [
            r[0] + bands * (REACHED_SHARE * 0.5 + REACHED_FLOOR_RAD_S),
            r[1],
        ]
    };
    let after = |was: State, bands: f32| closed_loop_state(was, r, r, off(bands));
    assert_eq!(after(State::Running, 2.1), State::ChangingSpeed);
    assert_eq!(after(State::ChangingSpeed, 1.5), State::ChangingSpeed);
    assert_eq!(after(State::Running, 1.5), State::Running);
    // A ramp that has not ended is changing speed however close the speed is.
    assert_eq!(
        closed_loop_state(State::Running, [0.5, -1.0], [0.6, -1.0], r),
        State::ChangingSpeed
    );
}

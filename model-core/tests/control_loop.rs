//! The speed loop in closed loop with the simulated rig: step figures, the family with and
//! without feedback, low-speed limit cycles, anti-windup, bumpless changes, sensor faults.

use model_core::control::estimator::WindowEvents;
use model_core::control::pi::{LoopConstants, LoopInput, SpeedLoop};
use model_core::control::{AxisConfig, ControllerConfig, State};
use model_core::sim::experiments::{
    commissioned_step, family_step, low_speed_hold_at_rate, rig_with_pulses, true_model_config,
};
use model_core::sim::{ClosedLoop, Plant, PlantParams, StepMetrics};

fn true_model_loop(rig: PlantParams) -> ClosedLoop {
    let cfg = true_model_config(&rig);
    ClosedLoop::new(
        Plant::new(rig, 3),
        model_core::control::Controller::new(cfg).unwrap(),
    )
}

#[test]
fn nominal_step_meets_the_control_targets() {
    let o = commissioned_step(
        rig_with_pulses(12),
        ControllerConfig::nominal(),
        1,
        3.0,
        true,
        [0.0; 2],
    );
    assert!(o.commissioned && o.fault.is_none());
    for r in o.reports {
        assert!(r.overshoot <= 0.02, "{r:?}");
        assert!(r.settling_time_s <= 2.5, "{r:?}");
        assert!(r.rms_ripple <= 0.005, "{r:?}");
        assert!(r.steady_state_error <= 0.01, "{r:?}");
    }
}

#[test]
fn sixty_pulses_per_rev_settles_within_one_second() {
    for n in [60u16, 120] {
        let o = commissioned_step(
            rig_with_pulses(n),
            ControllerConfig::nominal(),
            1,
            3.0,
            true,
            [0.0; 2],
        );
        for r in o.reports {
            assert!(r.settling_time_s <= 1.0, "N {n}: {r:?}");
        }
    }
}

/// The family targets; feedback on passes, feedforward alone fails (the material load added
/// after commissioning is invisible to the feedforward).
fn family_passes(plants: u32, feedback: bool) -> bool {
    (0..plants).all(|i| {
        let o = family_step(1, i, feedback);
        o.commissioned
            && o.fault.is_none()
            && o.reports.iter().all(|r| {
                r.overshoot <= 0.05 && r.settling_time_s <= 4.0 && r.steady_state_error <= 0.01
            })
    })
}

#[test]
fn family_passes_with_feedback_and_fails_with_feedforward_alone() {
    assert!(family_passes(12, true));
    assert!(!family_passes(12, false));
}

#[test]
fn no_limit_cycle_above_5_percent_at_half_a_rad_per_second_with_12_pulses() {
    let (r, fault) = low_speed_hold_at_rate(1000, 5, 12, 0.5, 0.5, true, 20.0, 20.0);
    assert!(fault.is_none());
    assert!(r.half_peak_to_peak <= 0.05, "{r:?}");
    assert!(r.steady_state_error <= 0.02, "{r:?}");
}

#[test]
fn with_the_window_lag_modelled_the_unscheduled_gain_holds_at_low_speed() {
    // The loop gain that is right at 3 rad/s (per-pulse bandwidth 1), kept at 0.5 rad/s (one
    // pulse a second with 12 pulses/rev), limit-cycled or ran away while the loop held each
    // window's error for the whole next window (the dead time in the loop; the stability map
    // in docs/control.md). With the correction's own effect modelled (pi.rs, `e`) the dead
    // time is out of the loop and the same gain holds the speed: quiet, scheduled or not.
    let (scheduled, f_s) = low_speed_hold_at_rate(1000, 5, 12, 0.5, 1.0, true, 20.0, 20.0);
    let (fixed, f_f) = low_speed_hold_at_rate(1000, 5, 12, 0.5, 1.0, false, 20.0, 20.0);
    assert!(
        f_s.is_none() && scheduled.half_peak_to_peak <= 0.05,
        "{scheduled:?}"
    );
    assert!(
        f_f.is_none() && fixed.half_peak_to_peak <= 0.05,
        "fixed {fixed:?} {f_f:?}"
    );
}

fn constants() -> LoopConstants {
    LoopConstants::new(&AxisConfig::nominal(), 1e-3, 12.0)
}

fn sample(error_model_minus_meas: f32, r: f32) -> WindowEvents {
    // A window of 0.1 s that closed just now, measuring r - error.
    let _ = r;
    WindowEvents {
        restarted_s_ago: None,
        closed: Some(model_core::control::estimator::WindowSample {
            ago_s: 0.0,
            span_s: 0.1,
            raw_speed_rad_s: error_model_minus_meas,
        }),
        bound_active: false,
    }
}

#[test]
fn anti_windup_holds_the_integral_when_the_output_saturates() {
    let k = constants();
    let mut l = SpeedLoop::default();
    let quiet = WindowEvents {
        restarted_s_ago: None,
        closed: None,
        bound_active: false,
    };
    // Open the window, then report a shaft at rest (blocked) for 30 s at 4 rad/s reference.
    let input = |ev| LoopInput {
        reference_rad_s: 4.0,
        measured_rad_s: 0.0,
        direction: 1.0,
        measurement_valid: true,
        events: ev,
        feedback: true,
        extra_duty: 0.0,
        at_rest: false,
        torque_duty: None,
        early_edge_drops_kick: false,
    };
    l.step(&k, input(sample(0.0, 4.0)));
    for i in 0..30_000 {
        let ev = if i % 100 == 0 {
            sample(0.0, 4.0)
        } else {
            quiet
        };
        l.step(&k, input(ev));
    }
    assert!(l.duty() <= 0.95 + 1e-6);
    // The integral is held where the output met the clamp, not run away to it.
    let ff = k.feedforward(4.0);
    assert!(
        l.integral() <= 0.95 - ff + 0.05,
        "integral {}",
        l.integral()
    );
    // Unblocked and suddenly fast (measured 4.4 > model): the duty comes off the clamp at once
    // (by 0.039 in 50 ms on 12 teeth, whose loop holds 2 rad/s of bandwidth above 2.1 rad/s;
    // with the correction's effect modelled, by 0.032 within 10 ms, after which the filtered
    // error, still 0.9 rad/s "too slow" from the blocked windows, holds it near there).
    let mut fast = input(sample(4.4, 4.0));
    fast.measured_rad_s = 4.4;
    let d0 = l.duty();
    let mut lowest = d0;
    for _ in 0..50 {
        l.step(&k, fast);
        fast.events = quiet;
        lowest = lowest.min(l.duty());
    }
    assert!(lowest < d0 - 0.03, "duty stuck at {}", l.duty());
}

#[test]
fn retuning_while_running_is_bumpless() {
    let mut cl = true_model_loop(rig_with_pulses(12));
    cl.ctrl.set_motor_speeds(2.0, 2.0).unwrap();
    cl.ctrl.start().unwrap();
    cl.run(4.0, |_| {});
    let before = cl.duties();
    cl.ctrl.set_loop_tuning(1, 3.0, 0.3).unwrap();
    cl.ctrl.set_loop_tuning(0, 20.0, 1.0).unwrap();
    let after = cl.tick();
    for i in 0..2 {
        assert!(
            (after[i] - before[i]).abs() < 0.01,
            "{before:?} -> {after:?}"
        );
    }
    let mut m = StepMetrics::new(2.0, 2.0);
    let mut t = 0.0;
    cl.run(4.0, |c| {
        t += 1e-3;
        m.add(t, c.rig.speed_rad_s(1));
    });
    assert!(m.report().steady_state_error < 0.01);
}

#[test]
fn setpoint_change_is_ramped_and_tracked() {
    let mut cl = true_model_loop(rig_with_pulses(12));
    cl.ctrl.set_motor_speeds(1.0, 1.0).unwrap();
    cl.ctrl.start().unwrap();
    cl.run(4.0, |_| {});
    cl.ctrl.set_motor_speeds(3.0, 2.0).unwrap();
    let mut max_step = 0.0f32;
    let mut prev = cl.ctrl.status().axes[0].reference_rad_s;
    cl.run(5.0, |c| {
        let r = c.ctrl.status().axes[0].reference_rad_s;
        max_step = max_step.max((r - prev).abs());
        prev = r;
    });
    let accel = ControllerConfig::nominal().axes[0].accel_limit_rad_s2;
    assert!(max_step <= accel * 1e-3 * 1.0001, "ramp step {max_step}");
    assert_eq!(cl.ctrl.state(), State::Running);
    assert!((cl.rig.speed_rad_s(0) - 3.0).abs() < 0.06);
    assert!((cl.rig.speed_rad_s(1) - 2.0).abs() < 0.04);
}

#[test]
fn missing_and_bouncing_pulses_do_not_upset_the_loop() {
    let mut rig = rig_with_pulses(12);
    rig.axes[1].faults.missing_probability = 0.1;
    rig.axes[0].faults.bounce_probability = 0.3;
    let mut cl = true_model_loop(rig);
    cl.ctrl.set_motor_speeds(3.0, 3.0).unwrap();
    cl.ctrl.start().unwrap();
    cl.run(4.0, |_| {});
    let mut m = [StepMetrics::new(3.0, 0.0), StepMetrics::new(3.0, 0.0)];
    let mut t = 0.0;
    cl.run(6.0, |c| {
        t += 1e-3;
        m[0].add(t, c.rig.speed_rad_s(0));
        m[1].add(t, c.rig.speed_rad_s(1));
    });
    assert_eq!(cl.ctrl.fault(), None);
    for r in m.map(|m| m.report()) {
        assert!(r.steady_state_error < 0.01, "{r:?}");
        assert!(r.half_peak_to_peak < 0.04, "{r:?}");
    }
    let s = cl.ctrl.status();
    assert!(s.axes[0].rejected_edges > 5, "{:?}", s.axes[0]);
    assert!(s.axes[1].inferred_missing > 0, "{:?}", s.axes[1]);
}

#[test]
fn reversal_goes_through_zero_and_waits_for_rest() {
    let mut cl = true_model_loop(rig_with_pulses(12));
    cl.ctrl.set_motor_speeds(2.0, 2.0).unwrap();
    cl.ctrl.start().unwrap();
    cl.run(4.0, |_| {});
    cl.ctrl.set_motor_speeds(2.0, -2.0).unwrap();
    let mut drove_negative_while_turning_forward = false;
    cl.run(8.0, |c| {
        if c.duties()[1] < 0.0 && c.rig.speed_rad_s(1) > 0.05 {
            drove_negative_while_turning_forward = true;
        }
    });
    assert!(!drove_negative_while_turning_forward);
    assert!(
        (cl.rig.speed_rad_s(1) + 2.0).abs() < 0.05,
        "{}",
        cl.rig.speed_rad_s(1)
    );
    assert!(cl.ctrl.status().axes[1].measured_rad_s < 0.0);
}

#[test]
fn a_shaft_stuck_in_stiction_at_low_duty_is_pushed_free_not_left_silent() {
    // Stiction above what the feedforward gives at 0.5 rad/s (and below the stall-watch duty):
    // without the stuck rule the integral would stay frozen (no measurement) forever.
    let mut rig = rig_with_pulses(12);
    rig.axes[1].motor.stiction_nm = 0.3;
    let mut cl = true_model_loop(rig);
    cl.ctrl.set_motor_speeds(0.5, 0.5).unwrap();
    cl.ctrl.start().unwrap();
    cl.run(20.0, |_| {});
    let w = cl.rig.speed_rad_s(1);
    assert!(
        cl.ctrl.fault().is_some() || (w - 0.5).abs() < 0.05,
        "stuck silently at {w} rad/s, duty {:?}",
        cl.duties()
    );
}

/// A loaded spin shaft started at 0.5 rad/s in `direction` (+1 or -1): when the loop first
/// measured it, s, and the worst deviation of its true speed from the setpoint after that
/// (relative, from a second later: the plant's lag and one window).
fn loaded_crawl(direction: f32) -> (Option<f32>, f32, Option<model_core::control::Fault>) {
    let mut rig = rig_with_pulses(12);
    let spin = &mut rig.axes[1];
    spin.motor.inertia_kg_m2 = 0.0078;
    spin.motor.viscous_nm_s = 0.0082;
    spin.motor.coulomb_nm = 0.082;
    spin.motor.stiction_nm = 0.115;
    spin.faults.load_step_nm = 0.095;
    spin.faults.load_step_from_s = 0.0;
    let mut cl = true_model_loop(rig);
    cl.ctrl
        .set_motor_speeds(0.5 * direction, 0.5 * direction)
        .unwrap();
    cl.ctrl.start().unwrap();
    let mut first_measured_s = None;
    let mut worst_after = 0.0f32;
    cl.run(14.0, |c| {
        let t = c.rig.time_s() as f32;
        let measured = c.ctrl.status().axes[1].measured_rad_s * direction;
        if first_measured_s.is_none() && measured > 0.0 {
            first_measured_s = Some(t);
        }
        if let Some(t0) = first_measured_s
            && t > t0 + 1.0
        {
            let w = c.rig.speed_rad_s(1) * direction;
            worst_after = worst_after.max((w - 0.5).abs() / 0.5);
        }
    });
    (first_measured_s, worst_after, cl.ctrl.fault())
}

#[test]
fn a_loaded_shaft_that_crawls_takes_its_load_from_the_crawl_not_by_overshooting() {
    // Material the model does not know (0.095 N m on 0.082 N m of Coulomb friction) on the spin
    // axis at 0.5 rad/s, a pulse a second: the shaft breaks away, crawls between its first two
    // edges while the push rises, then runs. The first window after the crawl reads the load
    // (mean duty against mean speed); holding only part of the push and letting the slow
    // low-speed integral find the rest left such shafts 15..25 % fast, or 15 % slow, for
    // several seconds (the window mean of a crawl reads far below the speed the push reached).
    // Both directions: what the push held is a duty in the commanded direction.
    for direction in [1.0, -1.0] {
        let (first, worst_after, fault) = loaded_crawl(direction);
        assert!(fault.is_none(), "{direction}: {fault:?}");
        let t0 = first.expect("the shaft was measured");
        assert!(t0 < 6.0, "{direction}: first measurement only at {t0} s");
        assert!(
            worst_after <= 0.03,
            "{direction}: worst deviation {worst_after} after {t0} s"
        );
    }
}

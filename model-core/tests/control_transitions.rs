//! Set-point changes while running, the most ordinary thing an operator does: slowing down,
//! speeding up, to and from low speed, on the nominal rig and on the seeded family (each plant
//! commissioned first, then loaded with material its model does not know). A step down used to
//! fault healthy plants: a shaft slowing towards its new reference gives intervals of two or three
//! of its last measured periods, which were read as missing pulses. (Starts from rest:
//! control_transitions_from_rest.rs.)

mod plant_rows;

use model_core::control::ControllerConfig;
use model_core::sim::experiments::{commissioned_transition, family_plant, rig_with_pulses};

/// Every change between these speeds, both ways, on `plants` plants of seed `seed`: no fault.
fn no_fault_on_family(seed: u32, plants: u32, changes: &[(f32, f32)]) {
    for i in 0..plants {
        let (rig, load) = family_plant(seed, i);
        for &(from, to) in changes {
            let o = commissioned_transition(
                rig,
                ControllerConfig::nominal(),
                seed.wrapping_add(i),
                from,
                to,
                true,
                load,
            );
            assert!(o.commissioned, "plant {i}: commissioning failed");
            assert!(
                o.fault.is_none(),
                "plant {i} of seed {seed}, {from} -> {to} rad/s: false fault {:?}",
                o.fault
            );
        }
    }
}

#[test]
fn slowing_down_never_faults_a_healthy_plant() {
    no_fault_on_family(1, 10, &[(3.0, 1.0), (3.0, 0.5), (4.0, 1.0)]);
}

#[test]
fn speeding_up_and_small_changes_never_fault() {
    no_fault_on_family(2, 6, &[(1.0, 3.0), (0.5, 3.0), (3.0, 2.0), (2.0, 3.0)]);
}

/// The nominal rig slows from 3 to 1 rad/s and from 4 to 2 rad/s within the targets: the
/// shaft passes the new speed by at most 5 % of it and is inside +/-2 % within 3 s.
#[test]
fn nominal_step_down_meets_the_targets() {
    for (from, to) in [(3.0f32, 1.0f32), (4.0, 2.0)] {
        let o = commissioned_transition(
            rig_with_pulses(12),
            ControllerConfig::nominal(),
            1,
            from,
            to,
            true,
            [0.0; 2],
        );
        assert!(
            o.commissioned && o.fault.is_none(),
            "{from} -> {to}: {:?}",
            o.fault
        );
        for r in o.reports {
            // The report's overshoot is a fraction of the change; the target is % of the speed.
            let past_target = r.overshoot * (from - to) / to;
            assert!(past_target <= 0.05, "{from} -> {to}: {r:?}");
            assert!(r.settling_time_s <= 3.0, "{from} -> {to}: {r:?}");
            assert!(
                r.settled && r.steady_state_error <= 0.01,
                "{from} -> {to}: {r:?}"
            );
        }
    }
}

/// Slowing from 3 to 0.5 rad/s, the shaft passes below the new speed by little: the
/// deceleration's "too fast" windows are not integrated as a load (they wound the duty below
/// friction and the shaft fell far below the target, or stalled).
#[test]
fn slowing_to_low_speed_does_not_undershoot_far() {
    let mut worst = 0.0f32;
    for i in 0..10 {
        let (rig, load) = family_plant(1, i);
        let o = commissioned_transition(
            rig,
            ControllerConfig::nominal(),
            1 + i,
            3.0,
            0.5,
            true,
            load,
        );
        assert!(o.fault.is_none(), "plant {i}: {:?}", o.fault);
        for r in o.reports {
            worst = worst.max(r.overshoot * (3.0 - 0.5) / 0.5);
        }
    }
    // Measured: 4.2 % with the hold, 5.6 % without it (integrating the deceleration).
    assert!(
        worst <= 0.05,
        "worst undershoot past 0.5 rad/s: {:.1} %",
        100.0 * worst
    );
}

/// Commissions `rig`, pours its material in, runs both axes at 4 rad/s for `hold_s`, then
/// commands 0.2 rad/s and runs 20 s: no fault, and the precession shaft turning at the end.
fn four_to_lowest_without_fault(rig: model_core::sim::plant::PlantParams, seed: u32, hold_s: f32) {
    use model_core::control::{Controller, State};
    use model_core::sim::harness::ClosedLoop;
    use model_core::sim::plant::Plant;

    let ctrl = Controller::new(ControllerConfig::nominal()).expect("nominal configuration");
    let mut cl = ClosedLoop::new(Plant::new(rig, seed), ctrl);
    assert_eq!(cl.commission(300.0), State::Idle);
    let now = cl.rig.time_s() as f32;
    for a in cl.rig.params_mut().axes.iter_mut() {
        a.faults.load_step_from_s = now;
        a.faults.load_step_nm = a.load_step_nm;
    }
    assert!(cl.ctrl.set_motor_speeds(4.0, 4.0).is_ok() && cl.ctrl.start().is_ok());
    cl.run(hold_s, |_| {});
    assert_eq!(cl.ctrl.fault(), None, "while running at 4 rad/s");
    assert!(cl.ctrl.set_motor_speeds(0.2, 0.2).is_ok());
    let mut fault = None;
    let mut t = 0.0f32;
    let dt = cl.dt_s();
    cl.run(20.0, |c| {
        t += dt;
        if fault.is_none() {
            fault = c.ctrl.fault().map(|f| (f, t));
        }
    });
    assert_eq!(fault, None, "held {hold_s} s: (fault, s after the command)");
    // Not only unfaulted: the shaft turns again, recovering towards its reference.
    let w = cl.rig.speed_rad_s(0);
    assert!(
        w > 0.05,
        "held {hold_s} s: precession at {w} rad/s 20 s later"
    );
}

/// family-60's plant p25 (tests/rigs/family-60.toml): heavy friction on its precession axis
/// (Coulomb 0.0995 N m, stiction 0.1326 N m on 0.105 kg m^2) and 0.0434 N m of material its
/// model does not know, so the duty that holds it at 0.2 rad/s is mostly load. Slowing from 4
/// to 0.2 rad/s, the loop's gain schedule lowered the gain with the reference all the way down
/// and the bumpless transfer moved the deceleration's "too fast" error into the integral: the
/// load it had learned at 4 rad/s was gone, the duty fell below what holds the shaft, the shaft
/// crawled to a stop and the expected-edge watch faulted it 7.5 s after the command. With the
/// integral kept, the shaft still slowed to 0.11 rad/s under its load, and the observer, which
/// had learned the deceleration as less load, expected it at 0.37 rad/s: the watch faulted the
/// turning shaft 8 s after the command. Held at 4 rad/s as long as the family report's settling
/// takes for this plant (4.83 s), and long.
#[test]
fn a_loaded_heavy_shaft_slows_to_the_lowest_speed_without_fault() {
    let rig = plant_rows::rig_from_table(
        12.895,
        0.591,
        [
            [
                1.2279, 0.10536, 0.00995, 0.0995, 0.1326, 0.0368, 0.000321, 0.002, 0.0434,
            ],
            [
                1.9083, 0.03205, 0.03363, 0.3363, 0.4708, 0.0452, 0.000632, 0.0075, 0.0584,
            ],
        ],
    );
    for hold_s in [4.83f32, 12.0] {
        four_to_lowest_without_fault(rig, 1025, hold_s);
    }
}

/// Plant p00 of `bowl sim make-family --seed 8 --plants 60`: light friction on a heavy
/// precession axis (Coulomb 0.03 N m, 0.119 kg m^2) whose identified slope is 5 % steep, so at
/// 4 rad/s the integral holds -0.014 duty although the shaft carries material: carried whole
/// down to 0.2 rad/s, the duty stayed 0.017 below what holds the shaft, it crawled, and the
/// watch faulted it 5.6 s after the command.
#[test]
fn a_model_too_steep_at_the_top_does_not_starve_the_lowest_speed() {
    let rig = plant_rows::rig_from_table(
        12.086,
        0.6,
        [
            [
                1.1512, 0.11911, 0.003, 0.03, 0.04, 0.0277, 0.000118, 0.002, 0.0131,
            ],
            [
                1.747, 0.01086, 0.01521, 0.1521, 0.213, 0.0322, 0.000767, 0.0065, 0.0316,
            ],
        ],
    );
    four_to_lowest_without_fault(rig, 8000, 5.91);
}

/// Plant p37 of `bowl sim make-family --seed 7 --plants 60`: heavy friction on a heavy
/// precession axis (Coulomb 0.098 N m, stiction 0.131 N m on 0.099 kg m^2, 10 V supply).
/// Slowing from 4 to 0.2 rad/s it crawls at 0.10 rad/s, below what its 12 pulses measure, and
/// the loop pushes it off the crawl: it leaps to 0.6..0.7 rad/s, past the runaway bound of a
/// 0.2 rad/s model (1.2 x 0.2 + 0.3), and the over-speed rule faulted it 13.8 s after the
/// command. The runaway is judged against what the applied duty drives too
/// (`supervisor::edge_runaway`). Held at 4 rad/s as long as the family report's settling takes
/// for this plant (4.78 s).
#[test]
fn a_heavy_shaft_pushed_off_its_crawl_is_no_runaway() {
    let rig = plant_rows::rig_from_table(
        10.006,
        0.405,
        [
            [
                1.1526, 0.09904, 0.00984, 0.0984, 0.1312, 0.0465, 0.000803, 0.002, 0.0305,
            ],
            [
                1.6131, 0.01629, 0.00529, 0.0529, 0.0741, 0.0223, 0.000136, 0.0066, 0.0566,
            ],
        ],
    );
    four_to_lowest_without_fault(rig, 7037, 4.78);
}

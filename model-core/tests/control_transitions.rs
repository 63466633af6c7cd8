//! Set-point changes while running, the most ordinary thing an operator does: slowing down,
//! speeding up, to and from low speed, on the nominal rig and on the seeded family (each plant
//! commissioned first, then loaded with material its model does not know). A step down used to
//! fault healthy plants: a shaft slowing towards its new reference gives intervals of two or three
//! of its last measured periods, which were read as missing pulses.

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

//! Starts from rest to a set point, on the nominal rig and on plants of the seeded families
//! (each commissioned first, then loaded with material its model does not know): the kick, the
//! start's first windows, the spin's start at the rod's first edge and its decoupling. (Set-point
//! changes while running are in control_transitions.rs.)

mod from_rest;
mod plant_rows;

use model_core::control::ControllerConfig;
use model_core::sim::experiments::{commissioned_transition, rig_with_pulses};

/// family-60's plant p28 (tests/rigs/family-60.toml) from rest to 1 rad/s: its precession's
/// first edge came 55 ms after the command, while the planner still ramped the reference (0.33
/// rad/s), and the integral kept half the kick that reference needed (0.034 duty; at 1 rad/s
/// the kick is 0.004): the shaft ran at 1.17 rad/s until the first measurement and peaked 24 %
/// past the target. The kept share now follows the kick the rising reference still needs (the
/// breakaway duty held the shaft at most 0.06 rad/s with no kick, docs/control.md "From rest to
/// 1 rad/s: the floor of a start from pulses": the overshoot is the loop's, not the leap's).
#[test]
fn a_first_edge_during_the_ramp_keeps_only_the_kick_the_target_needs() {
    let rig = plant_rows::rig_from_table(
        10.699,
        0.567,
        [
            [
                1.2401, 0.01657, 0.00353, 0.0353, 0.0470, 0.0048, 0.000251, 0.002, 0.0465,
            ],
            [
                1.5532, 0.05445, 0.02933, 0.2933, 0.4106, 0.0101, 0.000101, 0.0044, 0.0861,
            ],
        ],
    );
    let o = commissioned_transition(
        rig,
        ControllerConfig::nominal(),
        1028,
        0.0,
        1.0,
        true,
        [0.0465, 0.0861],
    );
    assert!(o.commissioned && o.fault.is_none(), "{:?}", o.fault);
    let over = o.reports[0].overshoot;
    assert!(
        over < 0.10,
        "precession {:.1} % past 1 rad/s (the issue's bound: 10 %)",
        100.0 * over
    );
}

/// From rest to 1 rad/s a window closes up to a pitch (0.52 s at 12 pulses a revolution) after
/// the speed it measures. Held as the shortfall against the reference alone, each window's
/// error kept the integral rising for the whole next window on a shaft already at its speed,
/// and the shaft passed the target by 2 to 6 % (2 % settling after 3 s on most of family-60's
/// axes). With the correction's own effect modelled (the loop's dead time taken out by the
/// identified model) these two family-60 axes stay within 4 %: p25's precession (4.24 %
/// before, 1.2 % with it) and p04's spin (5.18 % before, under 2.5 % with it alone, 3.5 % since
/// commissioning holds the spin's steps for a revolution to find the eccentric load: its
/// identified model moved, and without the eccentric load it passes by 2.8 %), each loaded
/// with the material its model does not know.
#[test]
fn from_rest_to_one_rad_s_the_window_lag_does_not_overshoot() {
    let p25 = plant_rows::rig_from_table(
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
    let p04 = plant_rows::rig_from_table(
        10.905,
        0.537,
        [
            [
                1.493, 0.0201, 0.00758, 0.0758, 0.1011, 0.036, 0.000757, 0.002, 0.0115,
            ],
            [
                1.421, 0.04287, 0.00939, 0.0939, 0.1314, 0.039, 0.000928, 0.0025, 0.0724,
            ],
        ],
    );
    for (name, rig, seed, axis) in [("p25", p25, 1025u32, 0usize), ("p04", p04, 1004, 1)] {
        let load = [rig.axes[0].load_step_nm, rig.axes[1].load_step_nm];
        // At the per-pulse bandwidth the loop had while the dead time was in it (0.5): the
        // window's lag alone, not the faster loop the model now allows.
        let mut cfg = ControllerConfig::nominal();
        for a in cfg.axes.iter_mut() {
            a.per_pulse_bandwidth = 0.5;
        }
        let o = commissioned_transition(rig, cfg, seed, 0.0, 1.0, true, load);
        assert!(o.commissioned && o.fault.is_none(), "{name}: {:?}", o.fault);
        // From rest the report's overshoot (a fraction of the change) is % of the target.
        let past = o.reports[axis].overshoot;
        assert!(
            past <= 0.04,
            "{name} axis {axis}: {:.2} % past 1 rad/s",
            100.0 * past
        );
    }
}

/// From rest to the lowest speed on the nominal rig: the kick breaks stiction and half of it
/// stays in the integral at the first edge (so a loaded shaft does not stick again), which
/// on this unloaded rig drives the precession to 0.52 rad/s. With the window's dead time
/// modelled, the loop removes that at its scheduled bandwidth (0.19 rad/s at 0.2 rad/s, a 5 s
/// time constant): 76 % above the target over the step's steady window, still 0.24 rad/s 13 s
/// after the command. The first measurement of a kick-started shaft now reads the load
/// instead (pi.rs, `take_start_load`): both axes within 10 % over the steady window (3.0 % and
/// 1.3 % measured; before the correction model the held error's push gave 64 % and 42 %).
#[test]
fn from_rest_to_the_lowest_speed_the_kept_kick_is_read_away() {
    let o = commissioned_transition(
        rig_with_pulses(12),
        ControllerConfig::nominal(),
        1,
        0.0,
        0.2,
        true,
        [0.0; 2],
    );
    assert!(o.commissioned && o.fault.is_none(), "{:?}", o.fault);
    for (axis, r) in o.reports.iter().enumerate() {
        assert!(
            r.steady_state_error <= 0.10,
            "axis {axis}: {:.1} % off 0.2 rad/s over the steady window",
            100.0 * r.steady_state_error
        );
    }
}

/// From rest, the spin starts with the rod (planner.rs): the rod's motor is kicked to its
/// breakaway from its first tick, so the spin's reaction cannot drag it backwards, and waiting
/// for the rod's first edge held the spin 0.05-0.8 s (docs/control.md, "The spin starts with
/// the rod"). Pulses only and with current sense: the spin's duty comes on within two ticks of
/// the rod's, the rod never turns backwards, and both axes of a rig loaded with material the
/// model does not know are inside +/-2 % of 1 rad/s within 3 s.
#[test]
fn from_rest_the_spin_starts_with_the_rod() {
    use model_core::control::Controller;
    use model_core::sim::CurrentSense;
    use model_core::sim::experiments::true_model_config;
    use model_core::sim::harness::{ClosedLoop, StepMetrics};
    use model_core::sim::plant::Plant;

    for sense in [CurrentSense::NONE, CurrentSense::TYPICAL] {
        let mut rig = rig_with_pulses(12);
        for a in &mut rig.axes {
            a.current_sense = sense;
        }
        let mut cl = ClosedLoop::new(
            Plant::new(rig, 1),
            Controller::new_or_faulted(true_model_config(&rig)),
        );
        for a in &mut cl.rig.params_mut().axes {
            a.faults.load_step_from_s = 0.0;
            a.faults.load_step_nm = 0.04;
        }
        assert!(cl.ctrl.set_motor_speeds(1.0, 1.0).is_ok() && cl.ctrl.start().is_ok());
        let dt = cl.dt_s();
        let (mut t, mut rod_s, mut spin_s, mut slowest) = (0.0f32, None, None, 0.0f32);
        let mut m = [StepMetrics::new(1.0, 4.0), StepMetrics::new(1.0, 4.0)];
        cl.run(8.0, |c| {
            t += dt;
            if rod_s.is_none() && c.duties()[0] != 0.0 {
                rod_s = Some(t);
            }
            if spin_s.is_none() && c.duties()[1] != 0.0 {
                spin_s = Some(t);
            }
            slowest = slowest.min(c.rig.speed_rad_s(0));
            m[0].add(t, c.rig.speed_rad_s(0));
            m[1].add(t, c.rig.speed_rad_s(1));
        });
        assert_eq!(cl.ctrl.fault(), None);
        let (rod, spin) = (rod_s.unwrap(), spin_s.unwrap());
        assert!(
            spin >= rod && spin <= rod + 2.5 * dt,
            "{sense:?}: the rod started at {rod:.3} s, the spin at {spin:.3} s"
        );
        assert!(
            slowest >= 0.0,
            "{sense:?}: the rod turned backwards at {slowest} rad/s"
        );
        for (axis, m) in m.iter().enumerate() {
            let r = m.report();
            assert!(
                r.settled && r.settling_time_s <= 3.0,
                "{sense:?}, axis {axis}: {r:?}"
            );
        }
    }
}

/// From rest to 1 rad/s the start's first window (pi.rs, `take_start_load`) spans the kick's
/// acceleration: family-60 p02's rod ran 0.06 rad/s ahead of its model through it, because the
/// kick's duty (0.0165 for the 0.6 s before the first edge) was in neither the model nor the
/// correction's history. Read as a negative load, it dropped the duty from 0.243 to 0.227, below
/// the 0.235 the rod needs at 1 rad/s: it sagged to 0.936 rad/s and the integral took it back
/// into 2 % at 3.16 s. With the kick in the correction's history the window reads no load and
/// the rod settles within 2 % by 2 s (docs/control.md, "The kick in the start's first window").
/// Since commissioning fits a slow shaft once it is steady (p02's rod: tau 0.39 s, identified
/// 0.355 s before), its measured reaction is larger and the spin's decoupling, which assumes this
/// loaded spin follows its model, feeds the rod more than the reaction takes through that window:
/// 2.12 s (docs/control.md, "A slow shaft's steps fitted once it is steady"), hence 2.2 here.
#[test]
fn from_rest_the_first_window_reads_the_kick_it_spans() {
    let p02 = plant_rows::rig_from_table(
        10.914,
        0.564,
        [
            [
                1.3050, 0.09067, 0.01862, 0.1862, 0.2483, 0.0016, 0.000496, 0.0020, 0.0003,
            ],
            [
                1.6130, 0.01516, 0.00203, 0.0203, 0.0285, 0.0347, 0.000469, 0.0086, 0.0548,
            ],
        ],
    );
    let rod = from_rest::rod_from_rest_to_1_rad_s(p02, 1002);
    assert!(
        rod.settled && rod.settling_time_s <= 2.2,
        "the rod settled within 2 % of 1 rad/s at {:.2} s (settled: {})",
        rod.settling_time_s,
        rod.settled
    );
}

/// A kick far above what the shaft needs (commissioning's breakaway duty is 2-3x the truth)
/// drives a light rod past 1 rad/s before its first measurement, and half of it stays in the
/// integral (`PUSH_KEPT`). Family-60 p29's first window is 0.46 s: below the 0.5 s the start's
/// reading once needed (the shaft still accelerating through shorter windows read as a load),
/// so the loop took the kept kick away at its bandwidth and the rod settled within 2 % at 4.6 s.
/// With the kick in the correction's history such a window reads what the shaft needs, and
/// windows from 0.4 s are read: the kept kick goes at the first measurement (2.6 s). The peak
/// before that measurement (22.8 %, then 18.1 %) was the kick's, which ran on while its model of
/// the shaft stood still (the next test).
/// Family-60 p29 (`tests/rigs/family-60.toml`): a light rod whose breakaway duty commissioning
/// reads 3.4x the truth (0.191 against 0.056).
fn family60_p29() -> model_core::sim::PlantParams {
    plant_rows::rig_from_table(
        12.942,
        0.460,
        [
            [
                1.1595, 0.01524, 0.00783, 0.0783, 0.1044, 0.0438, 0.000955, 0.0020, 0.0184,
            ],
            [
                1.6456, 0.05057, 0.00947, 0.0947, 0.1326, 0.0201, 0.000266, 0.0028, 0.0343,
            ],
        ],
    )
}

#[test]
fn from_rest_a_rod_the_kick_drove_past_the_target_is_read_at_its_first_window() {
    let rod = from_rest::rod_from_rest_to_1_rad_s(family60_p29(), 1029);
    assert!(
        rod.settled && rod.settling_time_s <= 3.0,
        "the rod settled within 2 % of 1 rad/s at {:.2} s (settled: {})",
        rod.settling_time_s,
        rod.settled
    );
}

/// A spin the push started (its material holds it at the kick) is not read at its first window:
/// that window carries the leap of the stiction the push overcame. Left to the loop from there
/// at its bandwidth at 1 rad/s (about 1 rad/s), the last 5-15 % of the load crept in at two
/// edges a second: seed 5 p11's spin (`bowl sim make-family --seed 5 --plants 60`) measured 0.82
/// rad/s at 1.93 s, 0.86 at 2.53 s, and settled within 2 % of 1 rad/s at 3.95 s. Its second
/// window, past the leap, now reads the load at once (pi.rs, `late_reading`; docs/control.md,
/// "... a pushed start reads its second window").
#[test]
fn from_rest_a_pushed_spin_reads_the_load_at_its_second_window() {
    let p11 = plant_rows::rig_from_table(
        10.053,
        0.401,
        [
            [
                1.6756, 0.02143, 0.00407, 0.0407, 0.0542, 0.0285, 0.000383, 0.0020, 0.0218,
            ],
            [
                1.1763, 0.00663, 0.04629, 0.4629, 0.6481, 0.0131, 0.000128, 0.0040, 0.0528,
            ],
        ],
    );
    let spin = from_rest::from_rest_to_1_rad_s(p11, 5011)[1];
    from_rest::assert_settled_within_2_pct_by(spin, 3.0, "the spin");
}

/// The once-per-revolution load (load_pattern.rs) found while commissioning was fed forward
/// only from a start's first measurement, a window or two after its first edge: up to then an
/// eccentric bowl's pull acted unfed, the start's reading took its value at that angle into the
/// integral as a steady load, and the feedforward then gave it a second time. Seed 8 p24's spin
/// (`bowl sim make-family --seed 8 --plants 60`; 9.2 mN m of eccentric load, about 5 % of its
/// speed at 1 rad/s) then crept into 2 % of 1 rad/s at 3.42 s. Fed from the first edge (the
/// tooth count runs through the stop, so the angle is known there), it settles at 2.17 s
/// (docs/control.md, "The eccentric load fed from the first edge").
#[test]
fn from_rest_the_eccentric_load_is_fed_from_the_first_edge() {
    let p24 = plant_rows::rig_from_table(
        11.913,
        0.468,
        [
            [
                2.0344, 0.07800, 0.04026, 0.4026, 0.5368, 0.0188, 0.000913, 0.0020, 0.0185,
            ],
            [
                1.3661, 0.02242, 0.00503, 0.0503, 0.0705, 0.0325, 0.000956, 0.0092, 0.0940,
            ],
        ],
    );
    let spin = from_rest::from_rest_to_1_rad_s(p24, 8024)[1];
    from_rest::assert_settled_within_2_pct_by(spin, 2.7, "the spin");
}

/// A light rod the kick ran to 1 rad/s before its first tooth (seed 5 p44: true breakaway about
/// 0.07 duty, commissioning's 0.193): half the kick was kept at that edge (0.031 duty) until its
/// first measurement half a second later, and the rod ran to 1.20 rad/s, 20 % past. The edge
/// came before the model, the kick's speed included, had turned a pitch: nothing showed the
/// shaft behind it, so nothing of the kick is kept (`early` in `SpeedLoop::step`); the rod's
/// peak is now 0.8 %.
#[test]
fn from_rest_a_first_edge_that_does_not_show_the_rod_behind_keeps_no_kick() {
    let p44 = plant_rows::rig_from_table(
        12.294,
        0.579,
        [
            [
                1.4297, 0.03328, 0.00313, 0.0313, 0.0417, 0.0183, 0.000975, 0.0020, 0.0197,
            ],
            [
                1.6735, 0.04452, 0.00689, 0.0689, 0.0964, 0.0221, 0.000391, 0.0095, 0.0417,
            ],
        ],
    );
    let rod = from_rest::rod_from_rest_to_1_rad_s(p44, 5044);
    assert!(
        rod.overshoot <= 0.05,
        "the rod passed 1 rad/s by {:.1} %",
        100.0 * rod.overshoot
    );
}

/// The kick ends when a model of the shaft driven by the duty actually applied reaches the
/// reference, and that model runs through the whole start. It used to stand still on the ticks
/// the kick was off: once it reached the ramping reference the kick went off and on from tick
/// to tick, the slew limit held the duty at the identified breakaway duty (0.191 where the
/// truth is 0.056 on family-60 p29's light rod), and the rod ran 18 % past 1 rad/s before its
/// first edge could tell (docs/control.md, "The kick's model runs through the whole start").
#[test]
fn from_rest_the_kick_ends_when_its_model_reaches_the_reference() {
    let rod = from_rest::rod_from_rest_to_1_rad_s(family60_p29(), 1029);
    assert!(
        rod.overshoot <= 0.05,
        "the rod passed 1 rad/s by {:.1} %",
        100.0 * rod.overshoot
    );
}

/// The spin's reaction is expected where both its model and the duty it is given through its
/// identified plant (its observer, corrected at its edges) say it accelerates, and as the
/// smaller of the two. From rest the model alone fed family-60 p04's rod more than the reaction
/// took as its loaded spin lagged its model: the rod overshot 1 rad/s by 2.5 % and settled within
/// 2 % at 2.24 s; decoupled by what the spin does, 0.9 % and 2.10 s (docs/control.md, "The rod
/// decoupled by what the spin does").
#[test]
fn from_rest_the_rod_is_decoupled_by_what_the_spin_does() {
    let p04 = plant_rows::rig_from_table(
        10.905,
        0.537,
        [
            [
                1.493, 0.0201, 0.00758, 0.0758, 0.1011, 0.036, 0.000757, 0.002, 0.0115,
            ],
            [
                1.421, 0.04287, 0.00939, 0.0939, 0.1314, 0.039, 0.000928, 0.0025, 0.0724,
            ],
        ],
    );
    let rod = from_rest::rod_from_rest_to_1_rad_s(p04, 1004);
    assert!(
        rod.overshoot <= 0.015 && rod.settled && rod.settling_time_s <= 2.2,
        "the rod overshot 1 rad/s by {:.1} % and settled within 2 % at {:.2} s (settled: {})",
        100.0 * rod.overshoot,
        rod.settling_time_s,
        rod.settled
    );
}

/// Seed 7 p24's spin (`bowl sim make-family --seed 7 --plants 60`): its material holds it at
/// the kick, the push starts it (breakaway at 0.43 duty, 1.60 s into the start) and goes on
/// rising until the first edge at 1.97 s. At a push span of 0.12 duty it peaked 19 % past
/// 1 rad/s, at 0.09 11 % (docs/control.md, "The push's span").
#[test]
fn from_rest_a_pushed_spin_is_not_pushed_far_past_its_breakaway() {
    let p24 = plant_rows::rig_from_table(
        11.056,
        0.537,
        [
            [
                1.1841, 0.02302, 0.05287, 0.5287, 0.7049, 0.0125, 0.000272, 0.0020, 0.0069,
            ],
            [
                1.1332, 0.01061, 0.04276, 0.4276, 0.5986, 0.0066, 0.000742, 0.0072, 0.0768,
            ],
        ],
    );
    let [rod, spin] = from_rest::from_rest_to_1_rad_s(p24, 7024);
    assert!(
        spin.overshoot <= 0.13,
        "the spin passed 1 rad/s by {:.1} %",
        spin.overshoot * 100.0
    );
    assert!(
        rod.overshoot <= 0.05,
        "the rod passed 1 rad/s by {:.1} %",
        rod.overshoot * 100.0
    );
}

//! The once-per-revolution load, learned and fed forward (control/load_pattern.rs), on the
//! nominal rig with an eccentric load four times the nominal one (8 mN m): the pattern learned
//! is the load the plant applies (its torque in duty, from the motor's own constants), and the
//! true speed's ripple falls once it is fed forward.

mod plant_rows;

use model_core::control::Controller;
use model_core::sim::experiments::{rig_with_pulses, true_model_config};
use model_core::sim::{ClosedLoop, Plant, PlantParams};

const RIPPLE_NM: f32 = 0.008;
const SPEED_RAD_S: f32 = 1.0;

fn eccentric_rig() -> PlantParams {
    let mut rig = rig_with_pulses(12);
    for a in &mut rig.axes {
        a.ripple_nm = RIPPLE_NM;
    }
    rig
}

/// RMS of the true speed about its mean, in % of the mean.
fn ripple_pct(trace: &[(f32, u16)]) -> f32 {
    let n = trace.len() as f32;
    let mean = trace.iter().map(|s| s.0).sum::<f32>() / n;
    let var = trace.iter().map(|s| (s.0 - mean).powi(2)).sum::<f32>() / n;
    100.0 * var.sqrt() / mean
}

fn started(rig: PlantParams) -> ClosedLoop {
    let ctrl = Controller::new(true_model_config(&rig)).expect("the nominal configuration");
    let mut cl = ClosedLoop::new(Plant::new(rig, 1), ctrl);
    cl.ctrl
        .set_motor_speeds(SPEED_RAD_S, SPEED_RAD_S)
        .expect("speeds in range");
    cl.ctrl.start().expect("starts");
    cl
}

#[test]
fn the_learned_pattern_is_the_plants_eccentric_load() {
    let rig = eccentric_rig();
    let mut cl = started(rig);
    // The true speed and the revolutions learned, every tick for 60 s.
    let mut trace = Vec::new();
    cl.run(60.0, |c| {
        trace.push((c.rig.speed_rad_s(1), c.ctrl.load_pattern(1).0))
    });
    let (revs, amplitude) = cl.ctrl.load_pattern(1);
    // The duty that holds a load torque T against the armature: T R / (k V).
    let m = rig.axes[1].motor;
    let expected = RIPPLE_NM * m.resistance_ohm / (m.torque_constant * rig.supply_v);
    assert!(revs >= 3, "revolutions learned: {revs}");
    assert!(
        (amplitude - expected).abs() <= 0.15 * expected,
        "learned {amplitude:.5} duty, the plant's load is {expected:.5}"
    );
    // The revolution that ended with the first pattern learned (none fed forward through it)
    // against the last one.
    let per_rev = (core::f32::consts::TAU / SPEED_RAD_S / cl.dt_s()) as usize;
    let first = trace
        .iter()
        .position(|&(_, r)| r > 0)
        .expect("a pattern learned");
    assert!(
        first > per_rev + 1000,
        "the first revolution began after 1 s: {first} ticks"
    );
    let before = ripple_pct(&trace[first - per_rev..first]);
    let after = ripple_pct(&trace[trace.len() - per_rev..]);
    eprintln!(
        "learned {amplitude:.5} duty (plant {expected:.5}) in {revs} revolutions; \
         ripple {before:.2} % -> {after:.2} %"
    );
    assert!(
        after < 0.35 * before,
        "true speed ripple {before:.2} % before learning, {after:.2} % after"
    );
}

#[test]
fn a_stop_forgets_the_pattern_and_a_restart_learns_it_again() {
    let mut cl = started(eccentric_rig());
    cl.run(40.0, |_| {});
    assert!(cl.ctrl.load_pattern(1).0 >= 3);
    cl.ctrl.stop().expect("stops");
    cl.run(15.0, |_| {});
    assert_eq!(cl.ctrl.load_pattern(1), (0, 0.0), "forgotten at rest");
    cl.ctrl
        .set_motor_speeds(SPEED_RAD_S, SPEED_RAD_S)
        .expect("speeds in range");
    cl.ctrl.start().expect("starts again");
    cl.run(40.0, |_| {});
    assert!(cl.ctrl.load_pattern(1).0 >= 3, "learned again");
}

/// Above the speed the tooth map learns at, nothing is learned (the wheel's own pattern would
/// read as a load there), and nothing is fed forward.
#[test]
fn nothing_is_learned_above_the_tooth_maps_speed() {
    let rig = eccentric_rig();
    let ctrl = Controller::new(true_model_config(&rig)).expect("the nominal configuration");
    let mut cl = ClosedLoop::new(Plant::new(rig, 1), ctrl);
    cl.ctrl.set_motor_speeds(3.0, 3.0).expect("speeds in range");
    cl.ctrl.start().expect("starts");
    cl.run(30.0, |_| {});
    assert_eq!(cl.ctrl.load_pattern(1), (0, 0.0));
}

/// The load belongs to the angle, not to the speed: a pattern learned at 1 rad/s is kept
/// through a set-point change (to 2 rad/s, where nothing is learned, and back), and the shaft
/// coming back to 1 rad/s is within 2 % of it (the true speed averaged over a second, as the
/// family report judges settling) from 3 s after the step on, with no revolution learned anew.
#[test]
fn a_set_point_change_keeps_the_pattern() {
    let mut cl = started(eccentric_rig());
    cl.run(40.0, |_| {});
    let (learned, amplitude) = cl.ctrl.load_pattern(1);
    assert!(learned >= 3, "revolutions learned at 1 rad/s: {learned}");
    cl.ctrl.set_motor_speeds(2.0, 2.0).expect("speeds in range");
    cl.run(10.0, |_| {});
    assert_eq!(
        cl.ctrl.load_pattern(1),
        (learned, amplitude),
        "kept unchanged at 2 rad/s"
    );
    cl.ctrl
        .set_motor_speeds(SPEED_RAD_S, SPEED_RAD_S)
        .expect("speeds in range");
    // The spin axis's angle every tick for 3 s after the step, then one revolution more.
    let dt = cl.dt_s();
    let mut angle = Vec::new();
    let until = 3.0 + core::f32::consts::TAU / SPEED_RAD_S + 0.5;
    cl.run(until, |c| angle.push(c.rig.angle_rad(1)));
    let first_k = (3.0 / dt) as usize;
    let half = (0.5 / dt) as usize;
    let mut worst_pct = 0.0f64;
    for k in first_k..angle.len() - half {
        let w = (angle[k + half] - angle[k - half]) / (2 * half) as f64 / dt as f64;
        worst_pct = worst_pct.max(100.0 * (w - SPEED_RAD_S as f64).abs() / SPEED_RAD_S as f64);
    }
    eprintln!("back at 1 rad/s: worst 1 s mean {worst_pct:.2} % off from 3 s on");
    assert!(
        worst_pct <= 2.0,
        "1 s mean {worst_pct:.2} % off the target 3 s after the step back to 1 rad/s"
    );
    assert!(
        cl.ctrl.load_pattern(1).0 >= learned,
        "the pattern was restarted by the set-point change"
    );
}

/// The eccentric load on the spin only: the rod's load is not found while commissioning (its
/// high step is the reaction's reference and is not held longer), and would ripple the spin
/// through the coupling.
fn spin_eccentric_rig() -> PlantParams {
    let mut rig = eccentric_rig();
    rig.axes[0].ripple_nm = 0.0;
    rig
}

/// That rig with a worn wheel: each tooth up to 8 % of a pitch off its place (the plant's
/// hashed offsets), which gives the wheel a once-per-revolution pattern of its own.
fn worn_eccentric_rig() -> PlantParams {
    let mut rig = spin_eccentric_rig();
    for a in &mut rig.axes {
        a.sensor.tooth_error = 0.08;
    }
    rig
}

/// Commissioned on `rig` (the loop's model identified, not given), then at `speed_rad_s`.
fn commissioned(rig: PlantParams, speed_rad_s: f32) -> ClosedLoop {
    let ctrl = Controller::new(true_model_config(&rig)).expect("the nominal configuration");
    let mut cl = ClosedLoop::new(Plant::new(rig, 1), ctrl);
    assert_eq!(cl.commission(300.0), model_core::control::State::Idle);
    cl.ctrl
        .set_motor_speeds(speed_rad_s, speed_rad_s)
        .expect("speeds in range");
    cl.ctrl.start().expect("starts");
    cl
}

/// The worst 1 s mean of the spin's true speed, in % off `target`, from `from_s` after now
/// for `for_s`.
fn worst_mean_off_pct(cl: &mut ClosedLoop, target: f32, from_s: f32, for_s: f32) -> f64 {
    let dt = cl.dt_s();
    let mut angle = Vec::new();
    cl.run(from_s + for_s + 0.5, |c| angle.push(c.rig.angle_rad(1)));
    let half = (0.5 / dt) as usize;
    let mut worst_pct = 0.0f64;
    for k in (from_s / dt) as usize..angle.len() - half {
        let w = (angle[k + half] - angle[k - half]) / (2 * half) as f64 / dt as f64;
        worst_pct = worst_pct.max(100.0 * (w - target as f64).abs() / target as f64);
    }
    worst_pct
}

/// Commissioning runs two steady steps at different speeds; the wheel's pattern and the load
/// differ in how they grow with the speed, so the two tell the load apart: the pattern found
/// is the plant's eccentric load (its torque in duty), not the worn wheel's, before any step.
#[test]
fn commissioning_finds_the_load_apart_from_a_worn_wheel() {
    let rig = worn_eccentric_rig();
    let m = rig.axes[1].motor;
    let expected = RIPPLE_NM * m.resistance_ohm / (m.torque_constant * rig.supply_v);
    let cl = commissioned(rig, 3.0);
    let (revs, amplitude) = cl.ctrl.load_pattern(1);
    eprintln!("after commissioning: {amplitude:.5} duty (plant {expected:.5}), {revs} revs");
    assert_eq!(revs, 0, "nothing learned in closed loop yet");
    assert!(
        (amplitude - expected).abs() <= 0.25 * expected,
        "found {amplitude:.5} duty, the plant's load is {expected:.5}"
    );
    // The same wheel without the load: what is found is the wheel's, and small.
    let mut rig = worn_eccentric_rig();
    for a in &mut rig.axes {
        a.ripple_nm = 0.0;
    }
    let cl = commissioned(rig, 3.0);
    let (_, amplitude) = cl.ctrl.load_pattern(1);
    eprintln!("no load: {amplitude:.5} duty");
    assert!(
        amplitude <= 0.25 * expected,
        "found {amplitude:.5} duty with no load (the load would be {expected:.5})"
    );
}

/// Coming down from 3 rad/s (where nothing is learned: the wheel's pattern reads as a load
/// there) to 1 rad/s, the load found while commissioning is fed from the first revolution:
/// the 1 s mean of the true speed is within 2 % of 1 rad/s from 3 s after the step on (0.42 %;
/// 2.74 % with the commissioning's load not fed). On a wheel worn as in
/// [`worn_eccentric_rig`] the loop's chase of the wheel's own first harmonic, which the tooth
/// map leaves in, costs 3.14 % by itself (no load; measured, not asserted here).
#[test]
fn from_three_to_one_the_load_is_fed_from_the_first_revolution() {
    let mut cl = commissioned(spin_eccentric_rig(), 3.0);
    cl.run(15.0, |_| {});
    cl.ctrl
        .set_motor_speeds(SPEED_RAD_S, SPEED_RAD_S)
        .expect("speeds in range");
    let worst_pct = worst_mean_off_pct(&mut cl, SPEED_RAD_S, 3.0, 7.0);
    eprintln!("3 -> 1 rad/s: worst 1 s mean {worst_pct:.2} % off from 3 s on");
    assert!(
        worst_pct <= 2.0,
        "1 s mean {worst_pct:.2} % off 1 rad/s from 3 s after the step down from 3 rad/s"
    );
}

/// A slow spin (seed-8 family plant p00's rod put on the spin axis: time constant 0.7 s, a
/// light load 0.002 N m on a wheel 2.8 % worn) has not settled half a step into commissioning:
/// the revolution recorded there would carry the approach's trend into the harmonic (on that
/// rod, with no drift limit, 0.0055 duty against the plant's 0.00115). It is not kept, so
/// nothing wrong is fed forward.
#[test]
fn an_unsettled_commissioning_step_gives_no_load() {
    let rig = plant_rows::rig_from_table(
        12.086,
        0.6,
        [
            [
                1.747, 0.01086, 0.01521, 0.1521, 0.213, 0.0322, 0.000767, 0.0, 0.0,
            ],
            [
                1.1512, 0.11911, 0.003, 0.03, 0.04, 0.0277, 0.000118, 0.002, 0.0,
            ],
        ],
    );
    let m = rig.axes[1].motor;
    let expected = 0.002 * m.resistance_ohm / (m.torque_constant * rig.supply_v);
    let ctrl = Controller::new(true_model_config(&rig)).expect("a valid configuration");
    let mut cl = ClosedLoop::new(Plant::new(rig, 8000), ctrl);
    assert_eq!(cl.commission(300.0), model_core::control::State::Idle);
    let (_, amplitude) = cl.ctrl.load_pattern(1);
    eprintln!("slow spin: {amplitude:.5} duty (plant {expected:.5})");
    assert!(
        amplitude == 0.0 || (amplitude - expected).abs() <= 0.25 * expected,
        "fed {amplitude:.5} duty, the plant's load is {expected:.5}"
    );
}

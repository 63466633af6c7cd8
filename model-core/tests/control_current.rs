//! The supervisor's current trips (model-core/src/control/supervisor.rs, `CurrentWatch`) against
//! the simulated rig with current sense: each fault caught at the first current sample after it
//! (one 1 ms tick), the supply cut opened only when a current flows with the bridge told to stop,
//! a stall told from a dead sensor, and no trip on a healthy rig.

use model_core::control::{Controller, CurrentTrip, CurrentWatch, DetectedBy, Fault, State};
use model_core::sim::experiments::true_model_config;
use model_core::sim::{ClosedLoop, CurrentSense, Plant, PlantParams};

fn sensed_rig() -> PlantParams {
    let mut p = PlantParams::nominal();
    for a in &mut p.axes {
        a.current_sense = CurrentSense::TYPICAL;
    }
    p
}

/// Both axes settled at `speed` from rest on the nominal rig with current sense, the controller
/// given the true model (idle for 0.1 s first: the offset is learned while the bridges coast).
fn running(speed: f32) -> ClosedLoop {
    let rig = sensed_rig();
    let mut cl = ClosedLoop::new(
        Plant::new(rig, 7),
        Controller::new(true_model_config(&rig)).unwrap(),
    );
    cl.run(0.1, |_| {});
    cl.ctrl.set_motor_speeds(speed, speed).unwrap();
    cl.ctrl.start().unwrap();
    cl.run(
        3.0f32.max(12.0 * std::f32::consts::TAU / (12.0 * speed)),
        |c| assert_eq!(c.ctrl.fault(), None, "a false fault at {speed} rad/s"),
    );
    assert_eq!(cl.ctrl.state(), State::Running);
    cl
}

struct Outcome {
    /// Ticks from the injection to the tick that latched the fault.
    ticks: u32,
    fault: Option<Fault>,
    /// Highest true speed of the faulted axis until 1 s after the fault.
    peak_rad_s: f32,
    supply_cut: bool,
}

fn inject(mut cl: ClosedLoop, axis: usize, what: impl Fn(&mut PlantParams, f32)) -> Outcome {
    let t0 = cl.rig.time_s() as f32;
    what(cl.rig.params_mut(), t0);
    let mut peak: f32 = 0.0;
    let mut ticks = None;
    for k in 1..=20_000u32 {
        cl.ctrl.host_heartbeat();
        cl.tick();
        peak = peak.max(cl.rig.speed_rad_s(axis).abs());
        if ticks.is_none() && cl.ctrl.fault().is_some() {
            ticks = Some(k);
        }
        if ticks.is_some_and(|t| k > t + 1000) {
            break;
        }
    }
    Outcome {
        ticks: ticks.unwrap_or(u32::MAX),
        fault: cl.ctrl.fault(),
        peak_rad_s: peak,
        supply_cut: cl.rig.supply_is_cut(),
    }
}

/// The fault shows in the current of the period after the injection; the controller reads it at
/// the next tick: the second tick counted from the injection (1 ms after the fault).
const FIRST_SAMPLE_AFTER: u32 = 2;

#[test]
fn a_bridge_stuck_on_trips_on_the_current_at_the_first_sample() {
    for speed in [0.2f32, 0.5, 1.0, 3.0] {
        for axis in 0..2 {
            let o = inject(running(speed), axis, |p, t0| {
                p.axes[axis].faults.bridge_stuck_from_s = t0
            });
            assert_eq!(
                o.fault,
                Some(Fault::CurrentAboveModel(axis as u8)),
                "{speed}"
            );
            assert_eq!(o.fault.unwrap().detected_by(), DetectedBy::Current);
            assert!(
                o.ticks <= FIRST_SAMPLE_AFTER,
                "{speed} rad/s: {} ticks",
                o.ticks
            );
            assert!(
                o.peak_rad_s < 1.5 * speed + 0.3,
                "{speed}: {}",
                o.peak_rad_s
            );
            // At low speed its current is more than the duty drives into a held shaft: a bridge
            // not to be trusted, the supply is cut. At 3 rad/s a stall would look the same.
            assert_eq!(o.supply_cut, speed < 3.0, "{speed} rad/s, axis {axis}");
        }
    }
}

#[test]
fn a_shorted_bridge_trips_and_the_supply_cut_stops_it() {
    for speed in [0.2f32, 0.5, 1.0, 3.0] {
        for axis in 0..2 {
            let o = inject(running(speed), axis, |p, t0| {
                p.axes[axis].faults.bridge_shorted_from_s = t0
            });
            assert_eq!(
                o.fault,
                Some(Fault::CurrentAboveModel(axis as u8)),
                "{speed}"
            );
            assert!(
                o.ticks <= FIRST_SAMPLE_AFTER,
                "{speed} rad/s: {} ticks",
                o.ticks
            );
            assert!(
                o.supply_cut,
                "{speed} rad/s, axis {axis}: the bridge drives on"
            );
            assert!(
                o.peak_rad_s < 1.5 * speed + 0.3,
                "{speed}: {}",
                o.peak_rad_s
            );
        }
    }
}

#[test]
fn a_stall_at_speed_trips_on_the_current_without_a_supply_cut() {
    for axis in 0..2 {
        let o = inject(running(3.0), axis, |p, t0| {
            p.axes[axis].faults.blocked_from_s = t0
        });
        // The back-EMF of 3 rad/s vanishes at once: the current is the held shaft's.
        assert_eq!(o.fault, Some(Fault::CurrentAboveModel(axis as u8)));
        assert!(o.ticks <= FIRST_SAMPLE_AFTER, "{} ticks", o.ticks);
        assert!(!o.supply_cut);
    }
}

#[test]
fn a_stall_and_a_dead_sensor_are_told_apart_by_the_current() {
    for speed in [0.2f32, 0.5, 1.0] {
        for axis in 0..2 {
            let stall = inject(running(speed), axis, |p, t0| {
                p.axes[axis].faults.blocked_from_s = t0
            });
            assert_eq!(stall.fault, Some(Fault::Stall(axis as u8)), "{speed}");
            assert!(!stall.supply_cut);
            let dead = inject(running(speed), axis, |p, t0| {
                p.axes[axis].faults.dead_sensor_from_s = t0
            });
            assert_eq!(dead.fault, Some(Fault::SensorLost(axis as u8)), "{speed}");
            assert!(!dead.supply_cut);
        }
    }
}

#[test]
fn a_bridge_shorted_while_idle_trips_and_cuts_the_supply() {
    let rig = sensed_rig();
    let mut cl = ClosedLoop::new(
        Plant::new(rig, 7),
        Controller::new(true_model_config(&rig)).unwrap(),
    );
    // The offset is learned first (its trip is armed after 32 samples at zero duty).
    cl.run(0.1, |c| assert_eq!(c.ctrl.fault(), None));
    let t0 = cl.rig.time_s() as f32;
    // A shorted bridge drives in the direction it last drove: here the default, forward.
    cl.rig.params_mut().axes[1].faults.bridge_shorted_from_s = t0;
    cl.run(0.002, |_| {});
    assert_eq!(cl.ctrl.fault(), Some(Fault::CurrentAboveModel(1)));
    assert!(cl.ctrl.supply_cut_requested());
    assert!(cl.rig.supply_is_cut());
}

#[test]
fn without_current_sense_nothing_changes() {
    // The same run with and without a sense that reads nothing: identical duties (the trips
    // and the learning only act on readings).
    let rig = PlantParams::nominal();
    let cfg = true_model_config(&rig);
    let mut a = ClosedLoop::new(Plant::new(rig, 7), Controller::new(cfg).unwrap());
    let mut b = a;
    a.ctrl.set_motor_speeds(1.0, 2.0).unwrap();
    a.ctrl.start().unwrap();
    b.ctrl.set_motor_speeds(1.0, 2.0).unwrap();
    b.ctrl.start().unwrap();
    for _ in 0..5000 {
        let now = a.rig.now_ticks();
        let da = a.ctrl.tick(now, [a.rig.edges(0), a.rig.edges(1)]);
        a.rig.advance(da, a.dt_s());
        b.tick();
        assert_eq!(da, b.duties());
    }
    assert!(!b.ctrl.supply_cut_requested());
}

#[test]
fn a_braking_duty_and_its_regenerative_current_are_no_trip() {
    // g = 1.5 A per duty, offset 20 mA, back-EMF 0.146 duty per rad/s (the nominal rig).
    let (g, offset, emf) = (1.5f32, 0.02f32, 1.75f32 / 12.0);
    let mut w = CurrentWatch::NEW;
    for _ in 0..40 {
        assert_eq!(w.sample(offset, 0.0, 1.0, true, 0.0, emf, 0.95), None);
    }
    // A start from rest: the held shaft draws g d.
    for _ in 0..5 {
        assert_eq!(
            w.sample(offset + g * 0.2, 0.2, 1.0, true, 0.0, emf, 0.95),
            None
        );
    }
    // The first edge: the start's fit is taken.
    assert_eq!(
        w.sample(offset + 0.1, 0.2, 1.0, false, 0.0, emf, 0.95),
        None
    );
    assert!(
        (w.amps_per_duty() - g).abs() < 1e-3,
        "{}",
        w.amps_per_duty()
    );
    // Slowing from 2 rad/s forward on a slightly reversed duty: the current is negative and
    // larger than g |d| (the back-EMF adds to the reversed drive), which is no bridge fault.
    for speed in [2.0f32, 1.0, 0.3] {
        let d = -0.005;
        let i = g * (d - emf * speed);
        assert_eq!(
            w.sample(offset + i, d, 1.0, false, 0.5 * speed, emf, 0.95),
            None
        );
    }
    // The same duty, a bridge stuck on forward instead: full duty's current trips.
    let i = g * (1.0 - emf * 2.0);
    assert_eq!(
        w.sample(offset + i, 0.3, 1.0, false, 1.0, emf, 0.95),
        Some(CurrentTrip::BridgeDriving)
    );
}

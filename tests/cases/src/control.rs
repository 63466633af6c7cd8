//! Cases for the controller (`model_core::control`) and the simulated rig (`model_core::sim`):
//! the same code and the same checks on the host and on the Cortex-M4F, plus the benchmark of
//! one control tick for both motors (estimation, PI, supervisor) against its 800-instruction
//! budget.

use crate::check::{Bench, Case, Failure, close, ensure};
use core::cell::UnsafeCell;
use model_core::control::estimator::PulseSpeedEstimator;
use model_core::control::{Controller, ControllerConfig, Fault, Rejection, State};
use model_core::sim::experiments::{rig_with_pulses, true_model_config};
use model_core::sim::{ClosedLoop, Plant, PlantParams, StepMetrics};

/// Cases of this module.
pub static CASES: &[Case] = &[
    Case {
        name: "control::estimator_reads_constant_speed_f32",
        run: estimator_reads_constant_speed,
    },
    Case {
        name: "control::rejected_commands_change_nothing_f32",
        run: rejected_commands_change_nothing,
    },
    Case {
        name: "control::step_on_simulated_rig_f32",
        run: step_on_simulated_rig,
    },
    Case {
        name: "control::dead_sensor_stops_both_motors_f32",
        run: dead_sensor_stops_both_motors,
    },
    Case {
        name: "control::commissioning_identifies_the_rig_f32",
        run: commissioning_identifies_the_rig,
    },
];

/// Benchmarks of this module.
pub static BENCHES: &[Bench] = &[Bench {
    name: "control::tick_both_axes_f32",
    inputs: 12_000,
    run: bench_tick,
    budget_instructions: Some(4000),
}];

fn fail(what: &'static str) -> Failure {
    Failure {
        what,
        got: 0.0,
        want: 1.0,
        tolerance: 0.0,
    }
}

/// Edges of a shaft at exactly `w` rad/s with 12 pulses/rev (16-bit timer, so it wraps):
/// the estimate must equal `w`.
fn estimator_reads_constant_speed() -> Result<(), Failure> {
    let mut cfg = ControllerConfig::nominal();
    cfg.timer_bits = 16;
    cfg.validate().map_err(|_| fail("config"))?;
    for &w in &[0.5f64, 1.8, 3.6] {
        let mut est = PulseSpeedEstimator::new(&cfg, &cfg.axes[0]);
        let period_us = core::f64::consts::TAU / (12.0 * w) * 1e6;
        let mut next = 777.0f64;
        let mut v = 0.0;
        for k in 1..=6000u64 {
            let now = k as f64 * 1000.0;
            let mut buf = [0u32; 4];
            let mut n = 0;
            while next <= now && n < 4 {
                buf[n] = (next as u64 & 0xffff) as u32;
                n += 1;
                next += period_us;
            }
            v = est.tick((now as u64 & 0xffff) as u32, &buf[..n], true, |_, _| {});
        }
        close("estimate at constant speed (rel)", v as f64, w, 2e-3 * w)?;
    }
    Ok(())
}

fn rejected_commands_change_nothing() -> Result<(), Failure> {
    let mut c = Controller::new(ControllerConfig::nominal()).map_err(|_| fail("config"))?;
    c.set_motor_speeds(1.0, 2.0)
        .map_err(|_| fail("valid speeds"))?;
    let before = c;
    ensure(
        "NaN refused",
        c.set_motor_speeds(f32::NAN, 1.0) == Err(Rejection::NotFinite),
    )?;
    ensure(
        "above max refused",
        c.set_motor_speeds(1.0, 9.0) == Err(Rejection::AboveMaxSpeed(1)),
    )?;
    ensure(
        "below min refused",
        c.set_motor_speeds(0.05, 1.0) == Err(Rejection::BelowMinSpeed(0)),
    )?;
    ensure("state unchanged", c == before)?;
    ensure(
        "clear without fault refused",
        c.clear_fault() == Err(Rejection::NotFaulted),
    )
}

fn true_model_loop(rig: PlantParams) -> Result<ClosedLoop, Failure> {
    let cfg = true_model_config(&rig);
    let ctrl = Controller::new(cfg).map_err(|_| fail("config"))?;
    Ok(ClosedLoop::new(Plant::new(rig, 2), ctrl))
}

/// 0 -> 3 rad/s on the nominal rig (the true model given, no commissioning, to keep the
/// emulated run short): the nominal figures of docs/control.md on the true speed.
fn step_on_simulated_rig() -> Result<(), Failure> {
    let mut cl = true_model_loop(rig_with_pulses(12))?;
    cl.ctrl
        .set_motor_speeds(3.0, 3.0)
        .map_err(|_| fail("speeds"))?;
    cl.ctrl.start().map_err(|_| fail("start"))?;
    let mut m = [StepMetrics::new(3.0, 3.0), StepMetrics::new(3.0, 3.0)];
    let mut t = 0.0f32;
    cl.run(5.0, |c| {
        t += 1e-3;
        m[0].add(t, c.rig.speed_rad_s(0));
        m[1].add(t, c.rig.speed_rad_s(1));
    });
    ensure("no fault", cl.ctrl.fault().is_none())?;
    ensure("running", cl.ctrl.state() == State::Running)?;
    for r in m.map(|m| m.report()) {
        close("overshoot <= 2 %", r.overshoot as f64, 0.01, 0.01)?;
        close("settling <= 2.5 s", r.settling_time_s as f64, 1.25, 1.25)?;
        close("ripple <= 0.5 %", r.rms_ripple as f64, 0.0025, 0.0025)?;
    }
    Ok(())
}

fn dead_sensor_stops_both_motors() -> Result<(), Failure> {
    let mut cl = true_model_loop(rig_with_pulses(12))?;
    cl.ctrl
        .set_motor_speeds(3.0, 3.0)
        .map_err(|_| fail("speeds"))?;
    cl.ctrl.start().map_err(|_| fail("start"))?;
    cl.run(3.0, |_| {});
    let t0 = cl.rig.time_s() as f32;
    cl.rig.params_mut().axes[0].faults.dead_sensor_from_s = t0;
    // 3 pulse periods at 3 rad/s with 12 pulses/rev: 0.524 s.
    let limit_ticks = (3.0 * core::f32::consts::TAU / 36.0 * 1000.0) as u32 + 2;
    for k in 0..limit_ticks {
        let d = cl.tick();
        if cl.ctrl.fault().is_some() {
            ensure(
                "sensor-lost fault on precession",
                cl.ctrl.fault() == Some(Fault::SensorLostOrStall(0)),
            )?;
            ensure("both duties zero at once", d == [0.0, 0.0])?;
            return close("fault code", cl.ctrl.status().fault_code as f64, 1.0, 0.0).and(close(
                "detected in time (ticks)",
                k as f64,
                0.0,
                limit_ticks as f64,
            ));
        }
    }
    Err(fail("dead sensor not detected within 3 pulse periods"))
}

fn commissioning_identifies_the_rig() -> Result<(), Failure> {
    let rig = rig_with_pulses(12);
    let mut cl = ClosedLoop::new(
        Plant::new(rig, 4),
        Controller::new(ControllerConfig::nominal()).map_err(|_| fail("config"))?,
    );
    ensure(
        "commissioning ends idle",
        cl.commission(120.0) == State::Idle,
    )?;
    for i in 0..2 {
        let id = cl.ctrl.identified()[i].ok_or(fail("axis not identified"))?;
        let (a, fd, _) = rig.axes[i].motor.ideal_model(rig.supply_v);
        close(
            "back-EMF constant (rel)",
            id.model.volts_per_rad_s as f64,
            a as f64,
            0.04,
        )?;
        close(
            "friction duty",
            id.model.friction_duty as f64,
            fd as f64,
            0.015,
        )?;
    }
    Ok(())
}

/// The benchmarked controller: nominal configuration with 60 pulses per revolution, both axes
/// commanded to 3 rad/s, built at compile time (so no set-up is counted in any call).
struct BenchState {
    ctrl: Controller,
    now: u32,
    countdown: u32,
}

struct BenchCell(UnsafeCell<BenchState>);

// SAFETY: the benchmarks run on one thread (the QEMU image has no threads; the host test calls
// them sequentially from one test function), so the cell is never accessed concurrently.
unsafe impl Sync for BenchCell {}

const fn bench_controller() -> Controller {
    let mut cfg = ControllerConfig::nominal();
    cfg.axes[0].pulses_per_rev = 60;
    cfg.axes[1].pulses_per_rev = 60;
    let mut c = match Controller::new(cfg) {
        Ok(c) => c,
        Err(_) => panic!("nominal configuration invalid"),
    };
    if c.set_motor_speeds(3.0, 3.0).is_err() || c.start().is_err() {
        panic!("bench controller refused its commands");
    }
    c
}

static BENCH: BenchCell = BenchCell(UnsafeCell::new(BenchState {
    ctrl: bench_controller(),
    now: 0,
    countdown: 35,
}));

/// One 1 kHz tick. Both sensors give an edge every 35 ticks (3 rad/s at 60 pulses/rev), in the
/// same tick, so the grid holds the worst case (two edges, two windows closing, both loops
/// updating) as well as plain ticks; 12,000 calls cover the ramp, steady pulses, and the
/// tooth-offset learning (steady after the ramp: a revolution of 60 gaps fills the chain, two
/// more warm it up, then the learned pattern is in use and updated at every edge).
fn bench_tick(_i: usize) -> f32 {
    // SAFETY: see `BenchCell`.
    let s = unsafe { &mut *BENCH.0.get() };
    s.now = s.now.wrapping_add(1000);
    s.countdown -= 1;
    let edge = [s.now.wrapping_sub(300)];
    let edges: &[u32] = if s.countdown == 0 {
        s.countdown = 35;
        &edge
    } else {
        &[]
    };
    let d = s.ctrl.tick(s.now, [edges, edges]);
    d[0] + d[1]
}

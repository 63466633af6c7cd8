//! The standard experiments on the simulated rig, shared by `bowl sim`, the host tests and the
//! QEMU cases: the commissioned 0 -> target step, the seeded family of perturbed plants, and
//! the low-speed hold.

use super::harness::{ClosedLoop, SETTLING_BAND, StepMetrics, StepReport};
use super::plant::{Plant, PlantParams};
use super::prng::Prng;
use crate::control::{Controller, ControllerConfig, Fault, State};

/// Length of a step run after the step, s.
pub const STEP_RUN_S: f32 = 8.0;
/// The steady window (steady-state error, ripple) starts this long after the step, s.
pub const STEADY_FROM_S: f32 = 5.0;

/// Result of one commissioned step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepOutcome {
    /// `[precession, spin]`, measured on the rig's true speed.
    pub reports: [StepReport; 2],
    /// First fault latched during commissioning or the run.
    pub fault: Option<Fault>,
    /// Commissioning ended in Idle.
    pub commissioned: bool,
}

/// The nominal rig with `n` pulses per revolution on both axes.
pub fn rig_with_pulses(n: u16) -> PlantParams {
    let mut rig = PlantParams::nominal();
    for a in &mut rig.axes {
        a.sensor.pulses_per_rev = n;
    }
    rig
}

/// The nominal controller configuration given `rig`'s true motor models and pulse counts, as if
/// commissioning had identified them exactly (tests that are not about commissioning start here).
pub fn true_model_config(rig: &PlantParams) -> ControllerConfig {
    let mut cfg = ControllerConfig::nominal();
    for (ax, rig_ax) in cfg.axes.iter_mut().zip(&rig.axes) {
        let (a, fd, tau) = rig_ax.motor.ideal_model(rig.supply_v);
        ax.pulses_per_rev = rig_ax.sensor.pulses_per_rev;
        ax.model.volts_per_rad_s = a;
        ax.model.friction_duty = fd;
        ax.model.time_constant_s = tau;
    }
    cfg
}

/// Commissions a controller (configuration `cfg`, pulses per revolution taken from the rig) on
/// `rig`, adds `load_after_commissioning_nm` of material drag per axis (a load the identified
/// model does not know), then steps both axes from 0 to `target_rad_s` and measures the true
/// speed for [`STEP_RUN_S`].
pub fn commissioned_step(
    rig: PlantParams,
    cfg: ControllerConfig,
    seed: u32,
    target_rad_s: f32,
    feedback: bool,
    load_after_commissioning_nm: [f32; 2],
) -> StepOutcome {
    commissioned_transition(
        rig,
        cfg,
        seed,
        0.0,
        target_rad_s,
        feedback,
        load_after_commissioning_nm,
    )
}

/// How long both axes run at the starting speed of a transition before the step, s: the
/// from-rest step's whole run, so the loop has settled there (and its integral holds the load).
pub const HOLD_BEFORE_STEP_S: f32 = STEP_RUN_S;

/// [`commissioned_step`] from `from_rad_s` instead of rest: both axes run at `from_rad_s` for
/// [`HOLD_BEFORE_STEP_S`] (longer at low speed: three revolutions at least), then the setpoint
/// changes to `target_rad_s` while running and the true speed is measured for [`STEP_RUN_S`]
/// (overshoot and rise as fractions of the change). `from_rad_s == 0` is the step from rest.
pub fn commissioned_transition(
    rig: PlantParams,
    mut cfg: ControllerConfig,
    seed: u32,
    from_rad_s: f32,
    target_rad_s: f32,
    feedback: bool,
    load_after_commissioning_nm: [f32; 2],
) -> StepOutcome {
    for i in 0..2 {
        cfg.axes[i].pulses_per_rev = rig.axes[i].sensor.pulses_per_rev;
    }
    let ctrl = Controller::new_or_faulted(cfg);
    let mut cl = ClosedLoop::new(Plant::new(rig, seed), ctrl);
    let commissioned = cl.commission(300.0) == State::Idle;
    cl.ctrl.set_feedback_enabled(feedback);
    let now = cl.rig.time_s() as f32;
    for (a, load) in cl
        .rig
        .params_mut()
        .axes
        .iter_mut()
        .zip(load_after_commissioning_nm)
    {
        a.faults.load_step_from_s = now;
        a.faults.load_step_nm = load;
    }
    let metrics = || StepMetrics::between(from_rad_s, target_rad_s, SETTLING_BAND, STEADY_FROM_S);
    let mut m = [metrics(), metrics()];
    let mut fault = cl.ctrl.fault();
    let mut ready = commissioned;
    if ready && from_rad_s != 0.0 {
        ready = cl.ctrl.set_motor_speeds(from_rad_s, from_rad_s).is_ok() && cl.ctrl.start().is_ok();
        let hold = HOLD_BEFORE_STEP_S.max(3.0 * core::f32::consts::TAU / from_rad_s.abs());
        cl.run(hold, |c| {
            if fault.is_none() {
                fault = c.ctrl.fault();
            }
        });
        ready &= fault.is_none();
    }
    let started = |c: &mut ClosedLoop| {
        c.ctrl.set_motor_speeds(target_rad_s, target_rad_s).is_ok()
            && (from_rad_s != 0.0 || c.ctrl.start().is_ok())
    };
    if ready && started(&mut cl) {
        let dt = cl.dt_s();
        let mut t = 0.0f32;
        cl.run(STEP_RUN_S, |c| {
            t += dt;
            m[0].add(t, c.rig.speed_rad_s(0));
            m[1].add(t, c.rig.speed_rad_s(1));
            if fault.is_none() {
                fault = c.ctrl.fault();
            }
        });
    }
    StepOutcome {
        reports: [m[0].report(), m[1].report()],
        fault,
        commissioned,
    }
}

/// Plant `index` of the seeded family, and the material drag `[precession, spin]` (N m) added
/// after commissioning. Inertia +/-30 %, torque constant +/-15 %, friction x0.5..x2 (log-uniform),
/// 1 % tooth-spacing error, 200 us jitter, load ripple x0.5..x2, coupling +/-20 %.
pub fn family_plant(seed: u32, index: u32) -> (PlantParams, [f32; 2]) {
    let mut rng = Prng::new(seed.wrapping_mul(0x9e37_79b9) ^ index);
    let mut rig = PlantParams::nominal();
    for a in &mut rig.axes {
        let m = &mut a.motor;
        m.inertia_kg_m2 *= rng.range(0.7, 1.3);
        m.torque_constant *= rng.range(0.85, 1.15);
        let friction = libm::expf(rng.range(libm::logf(0.5), libm::logf(2.0)));
        m.viscous_nm_s *= friction;
        m.coulomb_nm *= friction;
        m.stiction_nm *= friction;
        a.sensor.tooth_error = 0.01;
        a.sensor.jitter_s = 200e-6;
        a.ripple_nm *= rng.range(0.5, 2.0);
    }
    rig.coupling *= rng.range(0.8, 1.2);
    // Granulating material: 0.2 to 0.5 kg rolling in the bowl drags the spin axis; the
    // precession axis sees less.
    let load = [rng.range(0.0, 0.05), rng.range(0.02, 0.1)];
    (rig, load)
}

/// Runs family plant `index` through [`commissioned_step`] to 3 rad/s.
pub fn family_step(seed: u32, index: u32, feedback: bool) -> StepOutcome {
    let (rig, load) = family_plant(seed, index);
    commissioned_step(
        rig,
        ControllerConfig::nominal(),
        seed.wrapping_add(index),
        3.0,
        feedback,
        load,
    )
}

/// At control tick rate `tick_hz` (the physics keeps a step of 250 us or less), holds
/// `speed_rad_s` on both axes of the nominal rig with `pulses` per revolution and no
/// disturbances (no ripple, ideal sensor), the controller given the true model; after
/// `settle_s`, measures the spin axis's true speed for `measure_s`. `per_pulse_bandwidth`
/// sets the loop gain; with `scheduled == false` the bandwidth is fixed at what the schedule
/// gives at 3 rad/s (no reduction at low pulse rates). Returns the report and any fault.
#[allow(clippy::too_many_arguments)]
pub fn low_speed_hold_at_rate(
    tick_hz: u32,
    seed: u32,
    pulses: u16,
    speed_rad_s: f32,
    per_pulse_bandwidth: f32,
    scheduled: bool,
    settle_s: f32,
    measure_s: f32,
) -> (StepReport, Option<Fault>) {
    let mut rig = rig_with_pulses(pulses);
    rig.substeps = (4000 / tick_hz.max(1)).max(1);
    for a in &mut rig.axes {
        a.ripple_nm = 0.0;
    }
    // rig_with_pulses gives both axes `pulses`, so the true-model config counts `pulses` too.
    let mut cfg = true_model_config(&rig);
    cfg.tick_hz = tick_hz;
    for ax in &mut cfg.axes {
        ax.per_pulse_bandwidth = per_pulse_bandwidth;
        if !scheduled {
            let at3 = per_pulse_bandwidth * pulses as f32 * 3.0 / core::f32::consts::TAU;
            ax.bandwidth_rad_s = at3.min(ax.bandwidth_rad_s);
            ax.per_pulse_bandwidth = 10.0;
        }
        ax.min_speed_rad_s = ax.min_speed_rad_s.min(0.5 * speed_rad_s);
    }
    let mut cl = ClosedLoop::new(Plant::new(rig, seed), Controller::new_or_faulted(cfg));
    let _ = cl.ctrl.set_motor_speeds(speed_rad_s, speed_rad_s);
    let _ = cl.ctrl.start();
    cl.run(settle_s, |_| {});
    let mut m = StepMetrics::new(speed_rad_s, 0.0);
    let dt = cl.dt_s();
    let mut t = 0.0;
    cl.run(measure_s, |c| {
        t += dt;
        m.add(t, c.rig.speed_rad_s(1));
    });
    (m.report(), cl.ctrl.fault())
}

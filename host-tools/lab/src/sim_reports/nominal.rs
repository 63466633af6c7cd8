//! The reports on the nominal rig and the project's seeded family: the step (rise, overshoot,
//! 2 % settling, steady error, ripple of the rig's true speed), the family's worst case and
//! median, identification against the true model, and the CSV sweeps and traces.

use model_core::control::{Controller, ControllerConfig, Fault};
use model_core::sim::experiments::{self, STEP_RUN_S, family_plant, rig_with_pulses};
use model_core::sim::{ClosedLoop, Plant, PlantParams, StepReport};
use model_core::wire::{DeviceState, FaultCode};
use serde::Serialize;

use crate::sim_reports;

/// The step-response figures of one axis.
#[derive(Serialize, Clone, Copy, Debug)]
pub struct AxisFigures {
    /// 10-90 % rise time, s.
    pub rise_time_s: f32,
    /// Overshoot: the largest excursion past the target in the step's direction, percent of
    /// the target.
    pub overshoot_pct: f32,
    /// 2 % settling time, s; `None` (null) when the run ended outside the band: the time it
    /// was last outside would be the end of the run, read as a settling time.
    pub settling_time_s: Option<f32>,
    /// Steady-state error, percent of the target.
    pub steady_state_error_pct: f32,
    /// RMS ripple of the true speed, percent of the target.
    pub rms_ripple_pct: f32,
}

impl AxisFigures {
    /// The figures of `r`, a run ticking every `dt_s`: its times in whole ticks
    /// ([`crate::number::tick_s`]: 0.785 s, not the f32 sum's 0.78499347).
    fn of(r: StepReport, dt_s: f32) -> Self {
        let dt = crate::number::from_f32(dt_s);
        let ticks = |t: f32| crate::number::tick_s(f64::from(t), dt) as f32;
        Self {
            rise_time_s: ticks(r.rise_time_s),
            overshoot_pct: 100.0 * r.overshoot,
            settling_time_s: r.settled.then_some(ticks(r.settling_time_s)),
            steady_state_error_pct: 100.0 * r.steady_state_error,
            rms_ripple_pct: 100.0 * r.rms_ripple,
        }
    }
}

/// One step run.
#[derive(Serialize, Clone, Debug)]
pub struct StepOutcome {
    /// `[precession, spin]`.
    pub axes: [AxisFigures; 2],
    /// The worse axis of each figure.
    pub worst: AxisFigures,
    /// Fault code latched during the run (0 = none); kept for the CSV reports and scripts.
    pub fault_code: u8,
    /// The same fault in the console's word (`bowl send ... status`, `sim family`'s `fault`),
    /// null when none latched.
    pub fault: Option<&'static str>,
    /// Commissioning ended in Idle (not a fault).
    pub commissioned: bool,
}

/// A line for each axis of a step run that never settled (its `settling_time_s` is null): how
/// far short it ended and, where full duty cannot take it to the target, the speed it can reach
/// (the limit to ask within). Empty when both settled or the run faulted (the fault says why).
pub fn unsettled_words(
    o: &StepOutcome,
    rig: &PlantParams,
    cfg: &ControllerConfig,
    target: f32,
    load_nm: [f32; 2],
) -> Vec<String> {
    if o.fault_code != 0 || !o.commissioned {
        return Vec::new();
    }
    let mut words = Vec::new();
    for (i, (a, name)) in o.axes.iter().zip(["precession", "spin"]).enumerate() {
        if a.settling_time_s.is_some() {
            continue;
        }
        let mut line = format!(
            "the {name} axis never settled at --target-rad-s {target} within the {STEP_RUN_S} s \
             run (it ended {:.1} % off the target), so its settling_time_s is null",
            a.steady_state_error_pct
        );
        let duty = cfg.axes[i].duty_limit;
        let reach = sim_reports::full_duty_speed_rad_s(rig, i, duty, load_nm[i]);
        if reach < target {
            line.push_str(&format!(
                ": at full duty ({duty} of {} V) its motor reaches about {reach:.2} rad/s against \
                 its friction{}; ask for at most that, or give the rig more supply_v",
                rig.supply_v,
                if load_nm[i] > 0.0 {
                    " and material"
                } else {
                    ""
                }
            ));
        }
        words.push(line);
    }
    words
}

/// Commissions, runs both axes at `from` (0 = rest), then steps them to `target` (see
/// `model_core::sim::experiments::commissioned_transition`).
#[allow(clippy::too_many_arguments)]
pub fn step_run_with(
    rig: PlantParams,
    cfg: ControllerConfig,
    seed: u32,
    from: f32,
    target: f32,
    feedback: bool,
    load_after_commissioning_nm: [f32; 2],
) -> StepOutcome {
    let o = experiments::commissioned_transition(
        rig,
        cfg,
        seed,
        from,
        target,
        feedback,
        load_after_commissioning_nm,
    );
    let mut out = outcome_json(o, cfg.tick_hz);
    // The model's overshoot is a fraction of the change; the report's is % of the target.
    let scale = ((target - from) / target).abs();
    for a in out.axes.iter_mut() {
        a.overshoot_pct *= scale;
    }
    out.worst = worst_of(&out.axes);
    out
}

/// The report of `o`, a run whose controller ticked at `tick_hz`.
pub fn outcome_json(o: experiments::StepOutcome, tick_hz: u32) -> StepOutcome {
    // The tick as the harness makes it (model_core::sim::ClosedLoop::new).
    let dt_s = 1.0 / tick_hz as f32;
    let axes = [
        AxisFigures::of(o.reports[0], dt_s),
        AxisFigures::of(o.reports[1], dt_s),
    ];
    StepOutcome {
        worst: worst_of(&axes),
        axes,
        fault_code: o.fault.map_or(0, Fault::code),
        fault: o.fault.map(|f| FaultCode::from(Some(f)).token()),
        commissioned: o.commissioned,
    }
}

pub fn step_run(rig: PlantParams, seed: u32, target: f32, feedback: bool) -> StepOutcome {
    step_run_with(
        rig,
        ControllerConfig::nominal(),
        seed,
        0.0,
        target,
        feedback,
        [0.0; 2],
    )
}

pub fn worst_of(a: &[AxisFigures]) -> AxisFigures {
    let mut w = a[0];
    for x in &a[1..] {
        w.rise_time_s = w.rise_time_s.max(x.rise_time_s);
        w.overshoot_pct = w.overshoot_pct.max(x.overshoot_pct);
        // An axis that never settled is the worst.
        w.settling_time_s = w
            .settling_time_s
            .zip(x.settling_time_s)
            .map(|(a, b)| a.max(b));
        w.steady_state_error_pct = w.steady_state_error_pct.max(x.steady_state_error_pct);
        w.rms_ripple_pct = w.rms_ripple_pct.max(x.rms_ripple_pct);
    }
    w
}

pub fn median_of(a: &[AxisFigures]) -> AxisFigures {
    let med = |f: fn(&AxisFigures) -> f32| {
        let mut v: Vec<f32> = a.iter().map(f).collect();
        v.sort_by(f32::total_cmp);
        v[v.len() / 2]
    };
    // Never settled sorts after every time.
    let mut settling: Vec<Option<f32>> = a.iter().map(|x| x.settling_time_s).collect();
    settling.sort_by(|x, y| match (x, y) {
        (Some(x), Some(y)) => x.total_cmp(y),
        (x, y) => x.is_none().cmp(&y.is_none()),
    });
    AxisFigures {
        rise_time_s: med(|x| x.rise_time_s),
        overshoot_pct: med(|x| x.overshoot_pct),
        settling_time_s: settling[settling.len() / 2],
        steady_state_error_pct: med(|x| x.steady_state_error_pct),
        rms_ripple_pct: med(|x| x.rms_ripple_pct),
    }
}

/// `bowl sim step`'s JSON.
#[derive(Serialize)]
pub struct StepJson {
    /// What was run.
    pub scenario: &'static str,
    /// Pulses per revolution.
    pub pulses_per_rev: u16,
    /// Speed both axes held before the step, rad/s (0 = from rest).
    pub from_rad_s: f32,
    /// Target, rad/s.
    pub target_rad_s: f32,
    /// Feedback on.
    pub feedback: bool,
    /// The outcome.
    #[serde(flatten)]
    pub outcome: StepOutcome,
}

/// `bowl sim family`'s JSON.
#[derive(Serialize)]
pub struct FamilyJson {
    /// What was run.
    pub scenario: &'static str,
    /// Plants.
    pub plants: u32,
    /// Seed.
    pub seed: u32,
    /// Feedback on.
    pub feedback: bool,
    /// Worst of every figure over all plants and both axes.
    pub worst: AxisFigures,
    /// Median of every figure over all plants (worse axis of each).
    pub median: AxisFigures,
    /// Plants whose run latched a fault (any fault is false: the plants are healthy).
    pub faulted_plants: u32,
    /// Plants whose commissioning failed.
    pub commissioning_failures: u32,
}

pub fn family(seed: u32, plants: u32, feedback: bool) -> FamilyJson {
    let outcomes: Vec<StepOutcome> = (0..plants)
        .map(|i| {
            let o = experiments::family_step(seed, i, feedback);
            outcome_json(o, ControllerConfig::nominal().tick_hz)
        })
        .collect();
    if std::env::var_os("BOWL_SIM_VERBOSE").is_some() {
        for (i, o) in outcomes.iter().enumerate() {
            eprintln!("plant {i}: {o:?}");
        }
    }
    let worsts: Vec<AxisFigures> = outcomes.iter().map(|o| o.worst).collect();
    FamilyJson {
        scenario: "family: inertia +/-30 %, torque constant +/-15 %, friction x0.5..x2, 1 % tooth error, 200 us jitter, load ripple x0.5..x2, axis coupling +/-20 %; each commissioned, then a material load (precession 0..0.05 N m, spin 0.02..0.1 N m) the model does not know; 0 -> 3 rad/s, 12 pulses/rev",
        plants,
        seed,
        feedback,
        worst: worst_of(&worsts),
        median: median_of(&worsts),
        faulted_plants: outcomes.iter().filter(|o| o.fault_code != 0).count() as u32,
        commissioning_failures: outcomes.iter().filter(|o| !o.commissioned).count() as u32,
    }
}

/// Identified vs true model of one axis.
#[derive(Serialize)]
pub struct AxisIdentification {
    /// Identified effective back-EMF constant, V s/rad.
    pub volts_per_rad_s: f32,
    /// True value (`k + R b / k`).
    pub true_volts_per_rad_s: f32,
    /// Identified friction duty.
    pub friction_duty: f32,
    /// True value (`R Tc / (k V)`).
    pub true_friction_duty: f32,
    /// Identified time constant, s.
    pub time_constant_s: f32,
    /// True value (`J R / (k^2 + R b)`).
    pub true_time_constant_s: f32,
    /// Identified breakaway duty (the breakaway search's duty at the first edge).
    pub breakaway_duty: f32,
    /// True value (`R Ts / (k V)`, stiction `Ts`).
    pub true_breakaway_duty: f32,
    /// Identified duty per rad/s^2 of the other axis's acceleration (precession; 0: not
    /// measured).
    pub reaction_duty_s2_per_rad: f32,
    /// True value on the precession axis (`coupling J2 R1 / (k1 V)`), 0 on the spin.
    pub true_reaction_duty_s2_per_rad: f32,
}

/// `bowl sim commission`'s JSON.
#[derive(Serialize)]
pub struct CommissionJson {
    /// Final state after the routine.
    pub state: String,
    /// Seconds the routine took.
    pub duration_s: f32,
    /// `[precession, spin]`, if identified.
    pub axes: Vec<Option<AxisIdentification>>,
}

pub fn commission_report(seed: u32) -> CommissionJson {
    let rig = PlantParams::nominal();
    let ctrl = Controller::new(ControllerConfig::nominal()).expect("valid");
    let mut cl = ClosedLoop::new(Plant::new(rig, seed), ctrl);
    let state = cl.commission(300.0);
    let ids = cl.ctrl.identified();
    let axes = (0..2)
        .map(|i| {
            ids[i].map(|id| {
                let (a, fd, tau) = rig.axes[i].motor.ideal_model(rig.supply_v);
                AxisIdentification {
                    volts_per_rad_s: id.model.volts_per_rad_s,
                    true_volts_per_rad_s: a,
                    friction_duty: id.model.friction_duty,
                    true_friction_duty: fd,
                    time_constant_s: id.model.time_constant_s,
                    true_time_constant_s: tau,
                    breakaway_duty: id.model.breakaway_duty,
                    true_breakaway_duty: rig.axes[i].motor.ideal_breakaway_duty(rig.supply_v),
                    reaction_duty_s2_per_rad: id.model.reaction_duty_s2_per_rad,
                    true_reaction_duty_s2_per_rad: if i == 0 {
                        rig.ideal_reaction_duty_s2_per_rad()
                    } else {
                        0.0
                    },
                }
            })
        })
        .collect();
    CommissionJson {
        state: DeviceState::from(state).words().to_string(),
        duration_s: cl.rig.time_s() as f32,
        axes,
    }
}

pub fn sweep(seed: u32) {
    println!("pulses_per_rev,settling_time_s,overshoot_pct,rms_ripple_pct,rise_time_s,fault_code");
    for n in [1u16, 2, 4, 6, 8, 12, 16, 24, 32, 48, 60, 90, 120, 180, 240] {
        let o = step_run(rig_with_pulses(n), seed, 3.0, true);
        println!(
            "{n},{},{:.3},{:.4},{:.3},{}",
            o.worst
                .settling_time_s
                .map_or_else(|| "never".into(), |s| format!("{s:.3}")),
            o.worst.overshoot_pct,
            o.worst.rms_ripple_pct,
            o.worst.rise_time_s,
            o.fault_code
        );
    }
}

pub fn stability(seed: u32, speed: f32, only: Option<u16>, tick_hz: u32) {
    println!(
        "tick_hz,pulses_per_rev,pulse_rate_hz,per_pulse_bandwidth,scheduled,half_peak_to_peak_pct,fault_code,mean_error_pct"
    );
    // A count asked for runs alone, whichever it is (any other than these four printed the
    // header and no row).
    for n in only.map_or_else(|| vec![1u16, 4, 12, 60], |n| vec![n]) {
        for ppb in [0.1f32, 0.25, 0.5, 1.0, 2.0, 4.0] {
            for scheduled in [true, false] {
                let (r, fault) = experiments::low_speed_hold_at_rate(
                    tick_hz, seed, n, speed, ppb, scheduled, 20.0, 20.0,
                );
                let (cycle, err, fault) = (
                    100.0 * r.half_peak_to_peak,
                    100.0 * r.steady_state_error,
                    fault.map_or(0, Fault::code),
                );
                let rate = speed * n as f32 / core::f32::consts::TAU;
                println!("{tick_hz},{n},{rate:.3},{ppb},{scheduled},{cycle:.3},{fault},{err:.3}");
            }
        }
    }
}

pub fn trace(
    seed: u32,
    plant: Option<u32>,
    from_file: Option<rig_file::Rig>,
    (from, target): (f32, f32),
) {
    let mut cfg = ControllerConfig::nominal();
    let (rig, rig_seed, load) = match plant {
        _ if from_file.is_some() => {
            let r = from_file.unwrap_or_else(|| unreachable!());
            cfg = sim_reports::config_for(&r);
            let load = [r.params.axes[0].load_step_nm, r.params.axes[1].load_step_nm];
            (r.params, r.seed, load)
        }
        Some(i) => {
            let (rig, load) = family_plant(seed, i);
            (rig, seed.wrapping_add(i), load)
        }
        None => (PlantParams::nominal(), seed, [0.0; 2]),
    };
    let ctrl = Controller::new(cfg).expect("valid");
    let mut cl = ClosedLoop::new(Plant::new(rig, rig_seed), ctrl);
    let state = cl.commission(300.0);
    eprintln!("commissioning: {}", DeviceState::from(state).words());
    for (name, id) in ["precession", "spin"].iter().zip(cl.ctrl.identified()) {
        match id {
            Some(id) => {
                let m = id.model;
                eprintln!(
                    "  {name}: {:.4} V s/rad, friction duty {:.4}, time constant {:.4} s, \
                     breakaway duty {:.4}, reaction {:.5} duty s^2/rad",
                    m.volts_per_rad_s,
                    m.friction_duty,
                    m.time_constant_s,
                    m.breakaway_duty,
                    m.reaction_duty_s2_per_rad
                );
            }
            None => eprintln!("  {name}: not identified"),
        }
    }
    let now = cl.rig.time_s() as f32;
    for (a, l) in cl.rig.params_mut().axes.iter_mut().zip(load) {
        a.faults.load_step_from_s = now;
        a.faults.load_step_nm = l;
    }
    if from > 0.0 {
        // Settled at the starting speed first (as `sim family --from-rad-s`); the trace's
        // time counts from the step's command.
        let _ = cl.ctrl.set_motor_speeds(from, from);
        let _ = cl.ctrl.start();
        if super::step::settle_at(&mut cl, from) {
            eprintln!("faulted while settling at {from} rad/s");
        }
    }
    let _ = cl.ctrl.set_motor_speeds(target, target);
    let _ = cl.ctrl.start();
    println!(
        "t_s,true_prec,true_spin,meas_prec,meas_spin,ref_prec,ref_spin,duty_prec,duty_spin,state,fault"
    );
    let dt = cl.dt_s();
    let mut k = 0u32;
    cl.run(sim_reports::step_run_s(target).max(STEP_RUN_S), |c| {
        k += 1;
        if k.is_multiple_of(10) {
            let s = c.ctrl.status();
            println!(
                "{:.3},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{},{}",
                k as f32 * dt,
                c.rig.speed_rad_s(0),
                c.rig.speed_rad_s(1),
                s.axes[0].measured_rad_s,
                s.axes[1].measured_rad_s,
                s.axes[0].reference_rad_s,
                s.axes[1].reference_rad_s,
                s.axes[0].duty,
                s.axes[1].duty,
                DeviceState::from(s.state).token(),
                // The same words as `bowl send status` and `bowl replay --csv`.
                FaultCode::from_code(i64::from(s.fault_code)).map_or("unknown", FaultCode::token)
            );
        }
    });
}

//! `bowl sim`: the controller against the simulated rig (model-core's `sim`), on the host.
//!
//! - `bowl sim step`: 0 to 3 rad/s on both axes of the nominal rig (12 pulses/rev), after
//!   commissioning; JSON with rise time, overshoot, 2 % settling, steady-state error, RMS ripple
//!   of the rig's *true* speed.
//! - `bowl sim family`: the same step on a seeded family of plants the controller is not told
//!   about, each commissioned first; JSON with the worst case and the median.
//! - `bowl sim commission`: identification on the simulated rig, identified vs true model.
//! - `bowl sim sweep`: CSV of settling time against pulses per revolution.
//! - `bowl sim stability`: CSV map of the limit-cycle amplitude at low speed against loop gain
//!   (per-pulse bandwidth) and pulse rate, with and without the pulse-rate schedule.
//! - `bowl sim trace`: CSV trace of the step on one family plant (or the nominal rig).
//!
//! The virtual rig on a link (pseudo-terminal or capture file) is `bowl serve` (`crate::serve`).

use anyhow::{Result, bail};
use model_core::control::{Controller, ControllerConfig, Fault};
use model_core::sim::experiments::{self, STEP_RUN_S, family_plant, rig_with_pulses};
use model_core::sim::{ClosedLoop, Plant, PlantParams, StepReport};
use serde::Serialize;

use crate::{family_file, rig_file, sim_reports};

#[derive(clap::Subcommand)]
pub(crate) enum What {
    /// Step 0 -> 3 rad/s on the nominal rig; JSON.
    Step(StepArgs),
    /// The step on a seeded family of perturbed plants; JSON with worst case and median.
    Family(FamilyArgs),
    /// Identification on the simulated rig; JSON.
    Commission(CommonArgs),
    /// CSV: settling time against pulses per revolution.
    Sweep(CommonArgs),
    /// CSV: limit-cycle amplitude at low speed against loop gain and pulse rate.
    Stability(StabilityArgs),
    /// CSV trace (every 10 ms) of the 0 -> 3 rad/s step on one family plant (or the nominal rig).
    Trace(TraceArgs),
    /// The fault matrix on every plant of a rig file; JSON.
    Faults(FaultsArgs),
    /// Writes a seeded family file of plants spread the way lab rigs differ (TOML, stdout).
    MakeFamily(MakeFamilyArgs),
}

#[derive(clap::Args)]
pub(crate) struct FaultsArgs {
    /// Rig file or family file (TOML, see docs/rigs/nominal.toml).
    #[arg(long)]
    rig_file: std::path::PathBuf,
    /// Speed both axes run at when each fault is injected, rad/s.
    #[arg(long, default_value_t = 3.0)]
    speed_rad_s: f32,
    /// JSON output (the only format; accepted for symmetry with the other reports).
    #[arg(long)]
    json: bool,
}

#[derive(clap::Args)]
pub(crate) struct MakeFamilyArgs {
    /// Seed of the spread.
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// Number of plants.
    #[arg(long, default_value_t = 60)]
    plants: u32,
}

#[derive(clap::Args)]
pub(crate) struct TraceArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Family plant index; without it, the nominal rig.
    #[arg(long)]
    plant: Option<u32>,
    /// A rig file instead (the plant named by --name, or its first).
    #[arg(long)]
    rig_file: Option<std::path::PathBuf>,
    /// The plant's name in --rig-file.
    #[arg(long)]
    name: Option<String>,
    /// Step target, rad/s.
    #[arg(long, default_value_t = 3.0)]
    target_rad_s: f32,
}

#[derive(clap::Args, Clone)]
pub(crate) struct CommonArgs {
    /// Seed of tooth errors, jitter and the family.
    #[arg(long, default_value_t = 1)]
    seed: u32,
}

#[derive(clap::Args)]
pub(crate) struct StepArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Pulses per revolution of both sensors.
    #[arg(long, default_value_t = 12)]
    pulses_per_rev: u16,
    /// Step target, rad/s.
    #[arg(long, default_value_t = 3.0)]
    target_rad_s: f32,
    /// Feedforward only (feedback off): shows what the loop adds.
    #[arg(long)]
    no_feedback: bool,
    /// Override the once-per-revolution load ripple of both axes, N m.
    #[arg(long)]
    ripple_nm: Option<f32>,
    /// Override the loop's per-pulse bandwidth.
    #[arg(long)]
    per_pulse_bandwidth: Option<f32>,
    /// Override the estimator's filter weight.
    #[arg(long)]
    filter_weight: Option<f32>,
    /// Override the setpoint ramp, rad/s^2.
    #[arg(long)]
    accel_rad_s2: Option<f32>,
    /// A rig file (one rig) instead of the nominal rig; its pulses per revolution and load
    /// step apply (`--pulses-per-rev` and `--ripple-nm` are then ignored).
    #[arg(long)]
    rig_file: Option<std::path::PathBuf>,
}

#[derive(clap::Args)]
pub(crate) struct FamilyArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Number of plants (at least 50).
    #[arg(long, default_value_t = 50)]
    plants: u32,
    /// Feedforward only (feedback off): the family must then fail.
    #[arg(long)]
    no_feedback: bool,
    /// Allow fewer than 50 plants (for quick tests).
    #[arg(long, hide = true)]
    allow_small: bool,
    /// Run the plants of this rig or family file instead of the built-in family.
    #[arg(long)]
    rig_file: Option<std::path::PathBuf>,
    /// Step target with --rig-file, rad/s.
    #[arg(long, default_value_t = 3.0)]
    target_rad_s: f32,
    /// JSON output (the only format; accepted for symmetry).
    #[arg(long)]
    json: bool,
}

#[derive(clap::Args)]
pub(crate) struct StabilityArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Speed of the test, rad/s.
    #[arg(long, default_value_t = 0.5)]
    speed_rad_s: f32,
    /// Only this pulse count (default: 1, 4, 12 and 60).
    #[arg(long)]
    pulses_per_rev: Option<u16>,
    /// Control tick rate, Hz (the loop rate axis of the map).
    #[arg(long, default_value_t = 1000)]
    tick_hz: u32,
}

/// Runs `bowl sim`.
pub(crate) fn run(what: &What) -> Result<()> {
    match what {
        What::Step(a) if a.rig_file.is_some() => {
            let path = a.rig_file.as_deref().unwrap_or(std::path::Path::new(""));
            let rigs = rig_file::load(path)?;
            if rigs.len() != 1 {
                bail!(
                    "{} holds {} plants; `bowl sim step` runs one rig (use `bowl sim family --rig-file` for a family)",
                    path.display(),
                    rigs.len()
                );
            }
            let rig = &rigs[0];
            let cfg = sim_reports::config_for(rig);
            let load = [
                rig.params.axes[0].load_step_nm,
                rig.params.axes[1].load_step_nm,
            ];
            let out = StepJson {
                scenario: "rig file, both axes 0 -> target, commissioned first, true speed",
                pulses_per_rev: rig.params.axes[1].sensor.pulses_per_rev,
                target_rad_s: a.target_rad_s,
                feedback: !a.no_feedback,
                outcome: step_run_with(
                    rig.params,
                    cfg,
                    rig.seed,
                    a.target_rad_s,
                    !a.no_feedback,
                    load,
                ),
            };
            println!("{}", serde_json::to_string_pretty(&out)?);
        }
        What::Family(a) if a.rig_file.is_some() => {
            let path = a.rig_file.as_deref().unwrap_or(std::path::Path::new(""));
            check_speed(a.target_rad_s, "--target-rad-s")?;
            let rigs = rig_file::load(path)?;
            check_lowest(&rigs, a.target_rad_s, "--target-rad-s")?;
            let plants = parallel(&rigs, |r| sim_reports::family_plant(r, a.target_rad_s));
            let summary = sim_reports::summary(&plants);
            let out = serde_json::json!({ "plants": plants, "summary": summary });
            println!("{}", serde_json::to_string_pretty(&out)?);
        }
        What::Faults(a) => {
            check_speed(a.speed_rad_s, "--speed-rad-s")?;
            let rigs = rig_file::load(&a.rig_file)?;
            check_lowest(&rigs, a.speed_rad_s, "--speed-rad-s")?;
            let plants = parallel(&rigs, |r| sim_reports::fault_plant(r, a.speed_rad_s));
            let out = serde_json::json!({ "plants": plants });
            println!("{}", serde_json::to_string_pretty(&out)?);
        }
        What::MakeFamily(a) => print!("{}", family_file::family_toml(a.seed, a.plants)),
        What::Step(a) => {
            let mut rig = rig_with_pulses(a.pulses_per_rev);
            if let Some(r) = a.ripple_nm {
                for ax in &mut rig.axes {
                    ax.ripple_nm = r;
                }
            }
            let mut cfg = ControllerConfig::nominal();
            for ax in &mut cfg.axes {
                if let Some(p) = a.per_pulse_bandwidth {
                    ax.per_pulse_bandwidth = p;
                }
                if let Some(w) = a.filter_weight {
                    ax.filter_weight = w;
                }
                if let Some(acc) = a.accel_rad_s2 {
                    ax.accel_limit_rad_s2 = acc;
                }
            }
            let out = StepJson {
                scenario: "nominal rig, both axes 0 -> target, commissioned first, true speed",
                pulses_per_rev: a.pulses_per_rev,
                target_rad_s: a.target_rad_s,
                feedback: !a.no_feedback,
                outcome: step_run_with(
                    rig,
                    cfg,
                    a.common.seed,
                    a.target_rad_s,
                    !a.no_feedback,
                    [0.0; 2],
                ),
            };
            println!("{}", serde_json::to_string_pretty(&out)?);
        }
        What::Family(a) => {
            if a.plants < 50 && !a.allow_small {
                bail!(
                    "--plants must be at least 50, the family size the control targets are stated for (got {}); docs/control.md",
                    a.plants
                );
            }
            let out = family(a.common.seed, a.plants, !a.no_feedback);
            println!("{}", serde_json::to_string_pretty(&out)?);
        }
        What::Commission(a) => {
            let out = commission_report(a.seed);
            println!("{}", serde_json::to_string_pretty(&out)?);
        }
        What::Sweep(a) => sweep(a.seed),
        What::Stability(a) => stability(a.common.seed, a.speed_rad_s, a.pulses_per_rev, a.tick_hz),
        What::Trace(a) => {
            let rig = match &a.rig_file {
                Some(path) => {
                    let rigs = rig_file::load(path)?;
                    let found = match &a.name {
                        Some(n) => rigs.into_iter().find(|r| &r.name == n),
                        None => rigs.into_iter().next(),
                    };
                    Some(
                        found
                            .ok_or_else(|| anyhow::anyhow!("no plant of that name in the file"))?,
                    )
                }
                None => None,
            };
            trace(a.common.seed, a.plant, rig, a.target_rad_s)
        }
    }
    Ok(())
}

fn check_speed(x: f32, flag: &str) -> Result<()> {
    let max = ControllerConfig::nominal().axes[0].max_speed_rad_s;
    if !(x.is_finite() && x > 0.0 && x <= max) {
        bail!("{flag} {x} is outside 0 to {max} rad/s (the controller's speed range)");
    }
    Ok(())
}

/// Refuses a speed below the lowest one a plant's sensors can measure (one pulse per 4 s).
fn check_lowest(rigs: &[rig_file::Rig], x: f32, flag: &str) -> Result<()> {
    for r in rigs {
        let cfg = sim_reports::config_for(r);
        for (axis, name) in cfg.axes.iter().zip(["precession", "spin"]) {
            let lowest = model_core::control::estimator::lowest_speed_rad_s(axis);
            if x < lowest {
                bail!(
                    "{flag} {x} is below the lowest speed of plant {}'s {name} axis, {lowest:.3} rad/s ({} pulses per revolution); ask for at least that",
                    r.name,
                    axis.pulses_per_rev
                );
            }
        }
    }
    Ok(())
}

/// `f` over `items` on all cores, results in order; a panic in `f` is raised again here.
pub(crate) fn parallel<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let chunk = items.len().div_ceil(threads).max(1);
    std::thread::scope(|s| {
        let handles: Vec<_> = items
            .chunks(chunk)
            .map(|c| s.spawn(|| c.iter().map(&f).collect::<Vec<R>>()))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect()
    })
}

/// The step-response figures of one axis.
#[derive(Serialize, Clone, Copy, Debug)]
pub struct AxisFigures {
    /// 10-90 % rise time, s.
    pub rise_time_s: f32,
    /// Overshoot, percent of the target.
    pub overshoot_pct: f32,
    /// 2 % settling time, s.
    pub settling_time_s: f32,
    /// Steady-state error, percent of the target.
    pub steady_state_error_pct: f32,
    /// RMS ripple of the true speed, percent of the target.
    pub rms_ripple_pct: f32,
}

impl From<StepReport> for AxisFigures {
    fn from(r: StepReport) -> Self {
        Self {
            rise_time_s: r.rise_time_s,
            overshoot_pct: 100.0 * r.overshoot,
            settling_time_s: r.settling_time_s,
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
    /// Fault code latched during the run (0 = none).
    pub fault_code: u8,
    /// Commissioning ended in Idle (not a fault).
    pub commissioned: bool,
}

/// Commissions, then steps both axes (see `model_core::sim::experiments::commissioned_step`).
pub fn step_run_with(
    rig: PlantParams,
    cfg: ControllerConfig,
    seed: u32,
    target: f32,
    feedback: bool,
    load_after_commissioning_nm: [f32; 2],
) -> StepOutcome {
    outcome_json(experiments::commissioned_step(
        rig,
        cfg,
        seed,
        target,
        feedback,
        load_after_commissioning_nm,
    ))
}

fn outcome_json(o: experiments::StepOutcome) -> StepOutcome {
    let axes = [
        AxisFigures::from(o.reports[0]),
        AxisFigures::from(o.reports[1]),
    ];
    StepOutcome {
        worst: worst_of(&axes),
        axes,
        fault_code: o.fault.map_or(0, Fault::code),
        commissioned: o.commissioned,
    }
}

fn step_run(rig: PlantParams, seed: u32, target: f32, feedback: bool) -> StepOutcome {
    step_run_with(
        rig,
        ControllerConfig::nominal(),
        seed,
        target,
        feedback,
        [0.0; 2],
    )
}

fn worst_of(a: &[AxisFigures]) -> AxisFigures {
    let mut w = a[0];
    for x in &a[1..] {
        w.rise_time_s = w.rise_time_s.max(x.rise_time_s);
        w.overshoot_pct = w.overshoot_pct.max(x.overshoot_pct);
        w.settling_time_s = w.settling_time_s.max(x.settling_time_s);
        w.steady_state_error_pct = w.steady_state_error_pct.max(x.steady_state_error_pct);
        w.rms_ripple_pct = w.rms_ripple_pct.max(x.rms_ripple_pct);
    }
    w
}

fn median_of(a: &[AxisFigures]) -> AxisFigures {
    let med = |f: fn(&AxisFigures) -> f32| {
        let mut v: Vec<f32> = a.iter().map(f).collect();
        v.sort_by(f32::total_cmp);
        v[v.len() / 2]
    };
    AxisFigures {
        rise_time_s: med(|x| x.rise_time_s),
        overshoot_pct: med(|x| x.overshoot_pct),
        settling_time_s: med(|x| x.settling_time_s),
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

fn family(seed: u32, plants: u32, feedback: bool) -> FamilyJson {
    let outcomes: Vec<StepOutcome> = (0..plants)
        .map(|i| outcome_json(experiments::family_step(seed, i, feedback)))
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

fn commission_report(seed: u32) -> CommissionJson {
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
                }
            })
        })
        .collect();
    CommissionJson {
        state: format!("{state:?}"),
        duration_s: cl.rig.time_s() as f32,
        axes,
    }
}

fn sweep(seed: u32) {
    println!("pulses_per_rev,settling_time_s,overshoot_pct,rms_ripple_pct,rise_time_s,fault_code");
    for n in [1u16, 2, 4, 6, 8, 12, 16, 24, 32, 48, 60, 90, 120, 180, 240] {
        let o = step_run(rig_with_pulses(n), seed, 3.0, true);
        println!(
            "{n},{:.3},{:.3},{:.4},{:.3},{}",
            o.worst.settling_time_s,
            o.worst.overshoot_pct,
            o.worst.rms_ripple_pct,
            o.worst.rise_time_s,
            o.fault_code
        );
    }
}

fn stability(seed: u32, speed: f32, only: Option<u16>, tick_hz: u32) {
    println!(
        "tick_hz,pulses_per_rev,pulse_rate_hz,per_pulse_bandwidth,scheduled,half_peak_to_peak_pct,fault_code,mean_error_pct"
    );
    for n in [1u16, 4, 12, 60] {
        if only.is_some_and(|o| o != n) {
            continue;
        }
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

fn trace(seed: u32, plant: Option<u32>, from_file: Option<rig_file::Rig>, target: f32) {
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
    eprintln!(
        "commissioning: {state:?}, identified {:?}",
        cl.ctrl.identified()
    );
    let now = cl.rig.time_s() as f32;
    for (a, l) in cl.rig.params_mut().axes.iter_mut().zip(load) {
        a.faults.load_step_from_s = now;
        a.faults.load_step_nm = l;
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
                "{:.3},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:?},{}",
                k as f32 * dt,
                c.rig.speed_rad_s(0),
                c.rig.speed_rad_s(1),
                s.axes[0].measured_rad_s,
                s.axes[1].measured_rad_s,
                s.axes[0].reference_rad_s,
                s.axes[1].reference_rad_s,
                s.axes[0].duty,
                s.axes[1].duty,
                s.state,
                s.fault_code
            );
        }
    });
}

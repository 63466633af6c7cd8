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
//! The virtual rig on a link (pseudo-terminal or capture file) is `bowl serve` (`virtual_rig::serve`).

use anyhow::{Result, bail};
use model_core::control::ControllerConfig;

pub(crate) mod flags;
use flags::Plant;

use crate::exit_code::usage;
use model_core::sim::experiments::rig_with_pulses;

use lab::parallel::parallel;
use lab::sim_reports::nominal::{
    StepJson, StepOutcome, commission_report, family, stability, step_run_with, sweep, trace,
    unsettled_words,
};
use lab::{family_file, sim_reports};

#[derive(clap::Subcommand)]
pub enum What {
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
pub struct FaultsArgs {
    /// Rig file or family file (TOML, see docs/rigs/nominal.toml).
    #[arg(long, value_name = "RIG.toml")]
    rig_file: std::path::PathBuf,
    /// Speed both axes run at when each fault is injected, rad/s.
    #[arg(long, value_parser = crate::cmd::number32, default_value_t = 3.0)]
    speed_rad_s: f32,
    /// Give every plant the typical current sense (`current_sense = true`) where its file
    /// gave none.
    #[arg(long)]
    current_sense: bool,
    /// Each sensor drops this share of its pulses at random (a worn target, a marginal gap),
    /// %, from after commissioning on; the plants are then held at speed 30 s more before the
    /// faults are injected, and the JSON says per axis what was dropped and inferred.
    #[arg(long, value_parser = crate::cmd::number32, default_value_t = 0.0, allow_negative_numbers = true)]
    drop_pulses_pct: f32,
    /// JSON output (the only format; accepted for symmetry with the other reports).
    #[arg(long)]
    json: bool,
}

#[derive(clap::Args)]
pub struct MakeFamilyArgs {
    /// Seed of the spread.
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// Number of plants (1 or more: a family file with none is refused by every reader).
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(1..))]
    plants: u32,
}

#[derive(clap::Args)]
pub struct TraceArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Family plant index; without it, the nominal rig.
    #[arg(long)]
    plant: Option<u32>,
    /// A rig file instead (the plant named by --name, or its first).
    #[arg(long, value_name = "RIG.toml")]
    rig_file: Option<std::path::PathBuf>,
    /// The plant's name in --rig-file.
    #[arg(long)]
    name: Option<String>,
    /// Step target, rad/s.
    #[arg(long, value_parser = crate::cmd::number32, default_value_t = 3.0)]
    target_rad_s: f32,
    /// Both axes first settle at this speed, then step to --target-rad-s (0 = from rest),
    /// rad/s; the trace starts at the step's command.
    #[arg(long, value_parser = crate::cmd::number32, default_value_t = 0.0)]
    from_rad_s: f32,
}

#[derive(clap::Args, Clone)]
pub struct CommonArgs {
    /// Seed of tooth errors, jitter and the family.
    #[arg(long, default_value_t = 1)]
    seed: u32,
}

/// The step of `sim step` and `sim family --rig-file`: from a speed (or rest) to a target.
#[derive(clap::Args)]
pub struct StepSpeeds {
    /// Step target, rad/s.
    #[arg(long, value_parser = crate::cmd::number32, default_value_t = 3.0, allow_negative_numbers = true)]
    target_rad_s: f32,
    /// Both axes first settle at this speed, then step to --target-rad-s (0 = from rest), rad/s.
    #[arg(long, value_parser = crate::cmd::number32, default_value_t = 0.0, allow_negative_numbers = true)]
    from_rad_s: f32,
}

impl StepSpeeds {
    /// `(from, target)`, each judged in words against the plants the step runs on.
    fn checked(&self, plants: &[Plant]) -> Result<(f32, f32)> {
        flags::step(self.from_rad_s, self.target_rad_s, plants)
    }
}

#[derive(clap::Args)]
pub struct StepArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Pulses per revolution of both sensors (at least 1: the controller measures speed from
    /// the pulses).
    #[arg(long, default_value_t = 12, value_parser = clap::value_parser!(u16).range(1..))]
    pulses_per_rev: u16,
    #[command(flatten)]
    step: StepSpeeds,
    /// JSON output (the only format; accepted for symmetry with the other reports).
    #[arg(long)]
    json: bool,
    /// Feedforward only (feedback off): shows what the loop adds.
    #[arg(long)]
    no_feedback: bool,
    /// Override the once-per-revolution load ripple of both axes, N m.
    #[arg(long, value_parser = crate::cmd::number32)]
    ripple_nm: Option<f32>,
    /// Override the loop's per-pulse bandwidth.
    #[arg(long, value_parser = crate::cmd::number32)]
    per_pulse_bandwidth: Option<f32>,
    /// Override the estimator's filter weight.
    #[arg(long, value_parser = crate::cmd::number32)]
    filter_weight: Option<f32>,
    /// Override the setpoint ramp, rad/s^2.
    #[arg(long, value_parser = crate::cmd::number32)]
    accel_rad_s2: Option<f32>,
    /// A rig file (one rig) instead of the nominal rig; its pulses per revolution and load
    /// step apply (`--pulses-per-rev` and `--ripple-nm` are then ignored).
    #[arg(long, value_name = "RIG.toml")]
    rig_file: Option<std::path::PathBuf>,
}

#[derive(clap::Args)]
pub struct FamilyArgs {
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
    #[arg(long, value_name = "RIG.toml")]
    rig_file: Option<std::path::PathBuf>,
    /// With --rig-file: the step.
    #[command(flatten)]
    step: StepSpeeds,
    /// With --rig-file: give every plant the typical current sense (`current_sense = true`)
    /// where its file gave none.
    #[arg(long, requires = "rig_file")]
    current_sense: bool,
    /// JSON output (the only format; accepted for symmetry).
    #[arg(long)]
    json: bool,
}

#[derive(clap::Args)]
pub struct StabilityArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Speed of the test, rad/s.
    #[arg(long, value_parser = crate::cmd::number32, default_value_t = 0.5)]
    speed_rad_s: f32,
    /// Only this pulse count (default: 1, 4, 12 and 60); at least 1, and enough for the
    /// sensors to measure --speed-rad-s.
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..))]
    pulses_per_rev: Option<u16>,
    /// Control tick rate, Hz (the loop rate axis of the map; the controller runs at 100 to
    /// 10 000).
    #[arg(long, default_value_t = 1000, value_parser = clap::value_parser!(u32).range(100..=10_000))]
    tick_hz: u32,
}

/// Runs `bowl sim`.
pub fn run(what: &What) -> Result<()> {
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
            let (from, target) = a.step.checked(&[Plant::of_rig(rig)])?;
            let cfg = sim_reports::config_for(rig);
            let load = [
                rig.params.axes[0].load_step_nm,
                rig.params.axes[1].load_step_nm,
            ];
            let outcome = step_run_with(
                rig.params,
                cfg,
                rig.seed,
                from,
                target,
                !a.no_feedback,
                load,
            );
            let unsettled = unsettled_words(&outcome, &rig.params, &cfg, target, load);
            print_step(
                "rig file, both axes from --from-rad-s (0 = rest) to the target, commissioned first, true speed",
                rig.params.axes[1].sensor.pulses_per_rev,
                (from, target),
                !a.no_feedback,
                outcome,
            )?;
            say_notes(&unsettled);
        }
        What::Family(a) if a.rig_file.is_some() => {
            let path = a.rig_file.as_deref().unwrap_or(std::path::Path::new(""));
            let rigs = sensed(rig_file::load(path)?, a.current_sense);
            let (from, target) = a.step.checked(&plants_of(&rigs))?;
            let plants = parallel(&rigs, |r| sim_reports::family_plant(r, from, target));
            let summary = sim_reports::summary(&plants);
            let out = serde_json::json!({
                "from_rad_s": from,
                "target_rad_s": target,
                "plants": plants,
                "summary": summary,
            });
            println!("{}", serde_json::to_string_pretty(&out)?);
            say_notes(&sim_reports::no_reachable_words(&summary, target));
        }
        What::Faults(a) => {
            if !(0.0..=50.0).contains(&a.drop_pulses_pct) {
                return Err(usage(format!(
                    "--drop-pulses-pct must be from 0 to 50 (% of pulses the sensors drop; got {}): above half the pulses the controller cannot tell a dropping sensor from a dead one",
                    a.drop_pulses_pct
                )));
            }
            let rigs = sensed(rig_file::load(&a.rig_file)?, a.current_sense);
            flags::speed(a.speed_rad_s, "--speed-rad-s", &plants_of(&rigs))?;
            let plants = parallel(&rigs, |r| {
                sim_reports::fault_plant(r, a.speed_rad_s, a.drop_pulses_pct)
            });
            let out = serde_json::json!({ "plants": plants });
            println!("{}", serde_json::to_string_pretty(&out)?);
            // A speed the motor cannot reach read as detections late against their bound.
            let unreachable = sim_reports::unreachable_words(&rigs, a.speed_rad_s, "--speed-rad-s");
            say_notes(&unreachable);
        }
        What::MakeFamily(a) => print!("{}", family_file::family_toml(a.seed, a.plants)),
        What::Step(a) => {
            let (from, target) = a.step.checked(&[Plant::nominal(a.pulses_per_rev)])?;
            let mut rig = rig_with_pulses(a.pulses_per_rev);
            if let Some(r) = a.ripple_nm {
                if !(r.is_finite() && r >= 0.0) {
                    return Err(usage(format!(
                        "--ripple-nm {r}: the load ripple must be a torque of 0 N m or more"
                    )));
                }
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
            // The controller's own check of its settings, in its own words.
            cfg.validate().map_err(|e| {
                usage(format!(
                    "--per-pulse-bandwidth, --filter-weight or --accel-rad-s2: {} (per-pulse \
                     bandwidth 0.01 to 10, filter weight above 0 and at most 1, acceleration \
                     0.01 to 1000 rad/s^2)",
                    virtual_rig::controller_words::config(e)
                ))
            })?;
            let feedback = !a.no_feedback;
            let outcome = step_run_with(rig, cfg, a.common.seed, from, target, feedback, [0.0; 2]);
            let unsettled = unsettled_words(&outcome, &rig, &cfg, target, [0.0; 2]);
            print_step(
                "nominal rig, both axes from --from-rad-s (0 = rest) to the target, commissioned first, true speed",
                a.pulses_per_rev,
                (from, target),
                feedback,
                outcome,
            )?;
            say_notes(&unsettled);
        }
        What::Family(a) => {
            if a.plants < 50 && !a.allow_small {
                return Err(usage(format!(
                    "--plants must be at least 50, the family size the control targets are stated for (got {}); docs/control.md",
                    a.plants
                )));
            }
            let out = family(a.common.seed, a.plants, !a.no_feedback);
            println!("{}", serde_json::to_string_pretty(&out)?);
        }
        What::Commission(a) => {
            let out = commission_report(a.seed);
            println!("{}", serde_json::to_string_pretty(&out)?);
        }
        What::Sweep(a) => sweep(a.seed),
        What::Stability(a) => {
            // The default grid runs 1 pulse a revolution below its floor on purpose (the
            // CSV's mean error says the shaft never turned); a pulse count asked for alone
            // must measure the speed, or every row reads as a perfect hold.
            let asked: Vec<Plant> = a.pulses_per_rev.map(Plant::nominal).into_iter().collect();
            flags::speed(a.speed_rad_s, "--speed-rad-s", &asked)?;
            stability(a.common.seed, a.speed_rad_s, a.pulses_per_rev, a.tick_hz)
        }
        What::Trace(a) => {
            let rig = match &a.rig_file {
                Some(path) => {
                    let rigs = rig_file::load(path)?;
                    let names: Vec<String> = rigs.iter().map(|r| r.name.clone()).collect();
                    let found = match &a.name {
                        Some(n) => rigs.into_iter().find(|r| &r.name == n),
                        None => rigs.into_iter().next(),
                    };
                    Some(found.ok_or_else(|| {
                        usage(format!(
                            "--name {}: no plant of that name in {} (its plants: {})",
                            a.name.as_deref().unwrap_or(""),
                            path.display(),
                            names.join(", ")
                        ))
                    })?)
                }
                None => None,
            };
            let plant = match &rig {
                Some(r) => Plant::of_rig(r),
                None => Plant::nominal(ControllerConfig::nominal().axes[0].pulses_per_rev),
            };
            flags::step(a.from_rad_s, a.target_rad_s, &[plant])?;
            trace(a.common.seed, a.plant, rig, (a.from_rad_s, a.target_rad_s));
        }
    }
    Ok(())
}

/// The rigs, with the typical current sense where `on` and a rig has none.
fn sensed(rigs: Vec<rig_file::Rig>, on: bool) -> Vec<rig_file::Rig> {
    if on {
        rigs.into_iter()
            .map(rig_file::Rig::with_current_sense)
            .collect()
    } else {
        rigs
    }
}

/// Notes on stderr beside a report's JSON: an axis that never settled (its settling time read
/// as the run's length, 7.998 s, exit 0 and no word), a speed a plant cannot reach.
fn say_notes(words: &[String]) {
    for w in words {
        eprintln!("note: {w}");
    }
}

/// A step run that faulted or was never commissioned has no step figures: say so, fail.
/// Prints a step's report as JSON, then fails if it is no step response.
fn print_step(
    scenario: &'static str,
    pulses_per_rev: u16,
    (from_rad_s, target_rad_s): (f32, f32),
    feedback: bool,
    outcome: StepOutcome,
) -> Result<()> {
    let out = StepJson {
        scenario,
        pulses_per_rev,
        from_rad_s,
        target_rad_s,
        feedback,
        outcome,
    };
    println!("{}", serde_json::to_string_pretty(&out)?);
    check_step(&out.outcome)
}

fn check_step(o: &StepOutcome) -> Result<()> {
    if !o.commissioned {
        // The fault that ended it, named as a faulted run's is (it gave the code alone).
        let why = o.fault.map_or_else(
            || format!("fault code {}", o.fault_code),
            |f| {
                format!(
                    "it latched {f}, fault code {}, see docs/protocol.md",
                    o.fault_code
                )
            },
        );
        bail!("commissioning did not finish ({why}): the figures above are not a step response");
    }
    if o.fault_code != 0 {
        bail!(
            "the run faulted ({}, fault code {}, see docs/protocol.md): the figures above are not \
             a step response",
            o.fault.unwrap_or("unknown fault"),
            o.fault_code
        );
    }
    Ok(())
}

/// The controller's view of each plant, for judging speed flags.
fn plants_of(rigs: &[rig_file::Rig]) -> Vec<Plant> {
    rigs.iter().map(Plant::of_rig).collect()
}

#[cfg(test)]
mod tests {
    use lab::sim_reports::nominal::AxisFigures;

    use super::*;

    fn outcome(fault_code: u8, commissioned: bool) -> StepOutcome {
        let axis = AxisFigures {
            rise_time_s: 0.5,
            overshoot_pct: 0.0,
            settling_time_s: Some(0.0),
            steady_state_error_pct: 0.0,
            rms_ripple_pct: 0.0,
        };
        StepOutcome {
            axes: [axis; 2],
            worst: axis,
            fault_code,
            fault: model_core::wire::FaultCode::from_code(i64::from(fault_code))
                .filter(|&f| f != model_core::wire::FaultCode::None)
                .map(model_core::wire::FaultCode::token),
            commissioned,
        }
    }

    /// A faulted or uncommissioned run is an error that says why, never a row of zeros.
    #[test]
    fn a_faulted_step_is_an_error() {
        assert!(check_step(&outcome(0, true)).is_ok());
        let e = check_step(&outcome(3, true)).unwrap_err().to_string();
        assert!(
            e.contains("faulted (overspeed-precession, fault code 3"),
            "{e}"
        );
        let e = check_step(&outcome(3, false)).unwrap_err().to_string();
        assert!(
            e.contains(
                "commissioning did not finish (it latched overspeed-precession, fault code 3"
            ),
            "{e}"
        );
    }
}

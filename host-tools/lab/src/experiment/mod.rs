//! A plan of releases run on a simulated rig ([`simulated`]) or on a rig over its serial line
//! ([`port`]), one row per release written (see [`crate::results`]); a plan suggested
//! ([`suggest`]); the fit's statistics benchmarked on simulated rigs ([`benchmark`]). Method and
//! limits: docs/experiment.md; the command is `bowl experiment`.

pub mod benchmark;
pub mod plan;
pub mod port;
pub mod simulated;
pub mod suggest;

use std::io::Write;

use anyhow::Result;
use model_core::wire::{DeviceState, FaultCode};

use crate::results::{self, Row, Writer};
use simulated::Release;

/// A rig the plan's releases run on.
pub trait ReleaseRig {
    /// The nominal start radius (m), rim radius (m) and k2 of its granules (results columns).
    fn geometry(&self) -> (f64, f64, f64);
    /// Motor speeds for a combined bowl speed by the rig's split rule, rad/s.
    fn split(&self, bowl_rad_s: f64) -> Result<[f64; 2]>;
    /// Angle between the vertical (precession axis) and the bowl's own axis, rad (paper Eq. 2):
    /// the combined bowl speed of a condition given as two motor speeds is computed with it.
    fn axes_angle_rad(&self) -> f64;
    /// The azimuth of the last granule dropped (from the downhill direction, degrees), when the
    /// rig knows it; `None` by default (a rig over its serial line does not report it).
    fn last_release_azimuth_deg(&self) -> Option<f64> {
        None
    }
    /// Sets the motor speeds (starting the loop if idle) and waits until both measured speeds
    /// are within 2 % for a second, then `settle_s` more.
    fn settle(&mut self, targets: [f64; 2], settle_s: f64) -> Result<(), Release>;
    /// Drops one granule and follows it to the exit gate.
    fn release(&mut self) -> Release;
    /// Stops the motors.
    fn stop(&mut self);
    /// The fastest each motor may turn (precession, spin), rad/s, when the rig says.
    fn max_speeds_rad_s(&self) -> Option<[f64; 2]> {
        None
    }
}

/// Every condition's motor speeds within the rig's limits, checked before the first release:
/// a plan beyond them ran to the end, every row a motor fault without the limit.
pub fn check_speeds(rig: &impl ReleaseRig, plan: &plan::Plan) -> Result<()> {
    let Some(max) = rig.max_speeds_rad_s() else {
        return Ok(());
    };
    for (ci, c) in plan.condition.iter().enumerate() {
        let (targets, asked) = match (c.bowl_rad_s, c.precession_rad_s, c.spin_rad_s) {
            (Some(w), _, _) => (rig.split(w)?, format!("bowl_rad_s = {w}, which needs")),
            (None, Some(p), Some(s)) => ([p, s], "it asks for".to_string()),
            _ => continue,
        };
        for (i, motor) in ["precession", "spin"].into_iter().enumerate() {
            if targets[i].abs() > max[i] {
                let fastest = match rig.split(1.0) {
                    Ok(per) => (0..2)
                        .map(|k| max[k] / per[k].abs().max(1e-9))
                        .fold(f64::INFINITY, f64::min),
                    Err(_) => f64::NAN,
                };
                let hint = if fastest.is_finite() {
                    format!("; the fastest bowl speed this rig can run is {fastest:.3} rad/s")
                } else {
                    String::new()
                };
                anyhow::bail!(
                    "condition {}: {asked} a {motor} speed of {:.3} rad/s, above the rig's \
                     limit of {:.3} rad/s for that motor{hint}: lower the condition's speed \
                     (nothing was run)",
                    ci + 1,
                    targets[i].abs(),
                    max[i]
                );
            }
        }
    }
    Ok(())
}

/// A fault a rig reports, in the words the results file writes (the monitor's and `bowl send
/// status`'s, [`FaultCode::words`]): its state and fault code as its telemetry carries them, so
/// both rigs, over the wire and simulated, say the same; none unless the rig is faulted.
fn reported_fault(state: DeviceState, fault: FaultCode) -> Option<String> {
    (state == DeviceState::Faulted).then(|| fault.words().to_string())
}

/// The angle between the axes from the rig's AXES_MDEG parameter (millidegrees), rad: how
/// both rigs, over the wire and simulated, read it.
fn axes_angle_rad(axes_mdeg: f64) -> f64 {
    (axes_mdeg * 1e-3).to_radians()
}

/// Runs every release of `plan` on `rig`, writing each row as it is measured; returns the
/// number of releases. A progress bar on standard error when `progress`.
pub fn run_plan(
    rig: &mut impl ReleaseRig,
    plan: &plan::Plan,
    writer: &mut Writer,
    progress: bool,
) -> Result<usize> {
    check_speeds(rig, plan)?;
    let (release_radius_m, rim_radius_m, k2) = rig.geometry();
    let total = plan::releases(plan);
    let mut run_no = 0;
    for (ci, c) in plan.condition.iter().enumerate() {
        let targets = match (c.bowl_rad_s, c.precession_rad_s, c.spin_rad_s) {
            (Some(w), _, _) => rig.split(w)?,
            (None, Some(p), Some(s)) => [p, s],
            _ => unreachable!("plan::parse checked the condition"),
        };
        let bowl = match c.bowl_rad_s {
            Some(w) => w,
            None => crate::fit::models::combined_rad_s(targets, rig.axes_angle_rad()),
        };
        for _ in 0..c.repeats {
            run_no += 1;
            let outcome = match rig.settle(targets, plan.settle_s) {
                Ok(()) => rig.release(),
                Err(e) => e,
            };
            let mut row = Row {
                run: run_no,
                condition: ci + 1,
                bowl_rad_s: bowl,
                precession_rad_s: targets[0],
                spin_rad_s: targets[1],
                release_radius_m,
                rim_radius_m,
                k2,
                status: results::STATUS_OK.into(),
                residence_s: None,
                trace_mean_rad_s: None,
                trace_sd_rad_s: None,
                trace_path: String::new(),
                release_azimuth_deg: None,
            };
            let trace = match outcome {
                Release::Left(t, trace) => {
                    row.residence_s = Some(t);
                    row.release_azimuth_deg = rig.last_release_azimuth_deg();
                    Some(trace)
                }
                Release::NeverLeft(trace) => {
                    row.status = results::STATUS_NEVER_LEFT.into();
                    Some(trace)
                }
                Release::NotSettled => {
                    row.status = results::STATUS_NOT_SETTLED.into();
                    None
                }
                Release::MotorFault(f) => {
                    row.status = format!("{}: {f}", results::STATUS_MOTOR_FAULT);
                    None
                }
            };
            if let Some(trace) = trace {
                if let Some((m, s)) = results::mean_sd(&trace) {
                    row.trace_mean_rad_s = Some(m);
                    row.trace_sd_rad_s = Some(s);
                }
                row.trace_path = writer.write_trace(run_no, &trace)?;
            }
            writer.push(&row)?;
            if progress {
                let done = run_no * 30 / total;
                eprint!(
                    "\r[{}{}] {run_no}/{total}",
                    "#".repeat(done),
                    ".".repeat(30 - done)
                );
                let _ = std::io::stderr().flush();
            }
        }
    }
    rig.stop();
    if progress {
        eprintln!();
    }
    Ok(run_no)
}

#[cfg(test)]
mod tests;

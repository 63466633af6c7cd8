//! The speed flags of `bowl sim` judged against the plants they run on: each refusal is a usage
//! error ([`crate::exit_code::Usage`]) that names the flag, the value and the range.

use anyhow::Result;
use model_core::control::ControllerConfig;
use model_core::control::estimator::lowest_speed_rad_s;

use crate::exit_code::usage;

/// A plant a speed must suit: its name in messages and the controller's view of its axes.
pub struct Plant {
    /// `plant NAME` or `the nominal rig`, as the messages say it.
    pub label: String,
    pub cfg: ControllerConfig,
}

impl Plant {
    /// A plant of a rig or family file.
    pub fn of_rig(rig: &rig_file::Rig) -> Plant {
        Plant {
            label: format!("plant {}", rig.name),
            cfg: lab::sim_reports::config_for(rig),
        }
    }

    /// The nominal rig with `pulses_per_rev` on both sensors (what `sim step` runs).
    pub fn nominal(pulses_per_rev: u16) -> Plant {
        let mut cfg = ControllerConfig::nominal();
        for a in &mut cfg.axes {
            a.pulses_per_rev = pulses_per_rev;
        }
        Plant {
            label: "the nominal rig".into(),
            cfg,
        }
    }
}

/// A speed the controller can hold on every plant: above the lowest speed each sensor can
/// measure (below it the motor never moves and the figures would read as a perfect step) and
/// at most the controller's limit.
pub fn speed(x: f32, flag: &str, plants: &[Plant]) -> Result<()> {
    let max = ControllerConfig::nominal().axes[0].max_speed_rad_s;
    let floor = plants
        .iter()
        .flat_map(|p| p.cfg.axes.iter().map(lowest_speed_rad_s))
        .fold(0.0f32, f32::max);
    if !(x.is_finite() && x > 0.0 && x <= max) {
        // No plants: a report that runs below the sensors' floor on purpose (`sim stability`).
        let range = if plants.is_empty() {
            format!("above 0 and up to {max} rad/s")
        } else {
            format!(
                "{floor:.3} to {max} rad/s (the lower end is the lowest speed the sensors can \
                 measure)"
            )
        };
        return Err(usage(format!(
            "{flag} {x} is outside the controller's speed range, {range}; give a speed in it"
        )));
    }
    for p in plants {
        for (axis, name) in p.cfg.axes.iter().zip(["precession", "spin"]) {
            let lowest = lowest_speed_rad_s(axis);
            if x < lowest {
                return Err(usage(format!(
                    "{flag} {x} is below the lowest speed of {}'s {name} axis, {lowest:.3} rad/s \
                     ({}): the motor would not move; ask for at least that",
                    p.label,
                    lab::number::count(
                        usize::from(axis.pulses_per_rev),
                        "pulse per revolution",
                        "pulses per revolution"
                    )
                )));
            }
        }
    }
    Ok(())
}

/// `--from-rad-s`: 0 (from rest) or a speed the plants can hold, not the target itself.
pub fn from(from: f32, target: f32, plants: &[Plant]) -> Result<()> {
    if from == 0.0 {
        return Ok(());
    }
    speed(from, "--from-rad-s", plants)?;
    if from == target {
        return Err(usage(format!(
            "--from-rad-s {from} equals --target-rad-s: there is no step; give a different speed \
             or 0 (from rest)"
        )));
    }
    Ok(())
}

/// `--target-rad-s` and `--from-rad-s` of one step: `(from, target)`.
pub fn step(from_rad_s: f32, target_rad_s: f32, plants: &[Plant]) -> Result<(f32, f32)> {
    speed(target_rad_s, "--target-rad-s", plants)?;
    from(from_rad_s, target_rad_s, plants)?;
    Ok((from_rad_s, target_rad_s))
}

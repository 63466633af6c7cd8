//! What speed can do (issue 30 part 4, docs/model.md §11): the residence time over the rig's
//! speed range, `dT/domega` at the asked speed, and the table `RTIME TABLE` inverts on the rig
//! (`--store-table PORT` computes it at the rig's own limits and split, and stores it).
//!
//! "Speed" is the combined bowl speed of paper Eq. 2, as RTIME sets it: both motors scale
//! together at a fixed ratio of spin to precession. Without a rig the ratio and the spin's
//! direction are the flags' and the limits are the parameter table's defaults (each motor
//! between the lowest speed its sensor measures and `SPEED_MAXn`); with `--store-table` they
//! are the rig's (`RATIO_PPM`, `SPEED_MAXn_MRAD_S`, `TEETHn`), the spin's direction still the
//! flags'.

use anyhow::{Result, bail};
use model_core::binding::{TABLE_PARAMS, config_from_params, default_params, table_to_params};
use model_core::bowl::{MotorSpeeds, combined_speed_from_trig};
use model_core::control::ControllerConfig;
use model_core::control::estimator::lowest_speed_rad_s;
use model_core::particle::rolling::RollingScene;
use model_core::particle::speed_table::{SPEED_TABLE_LEN, SpeedTable};
use model_core::wire::{ParamId, ParamValues};
use serde_json::{Value, json};

/// How the bowl speed maps to the two motors, and the range the rig allows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedAxis {
    /// Precession per bowl speed.
    pub precession_per_omega: f64,
    /// Spin per bowl speed (signed: the model's spin direction).
    pub spin_per_omega: f64,
    /// The slowest and fastest bowl speed both motors allow, rad/s (`None`: none does).
    pub range_rad_s: Option<(f64, f64)>,
}

/// Each motor's lowest measurable speed and its limit, rad/s.
type MotorLimits = [(f64, f64); 2];

/// Each motor's limits and the rig's split (spin per precession, the angle between the axes),
/// from wire parameters.
fn limits(params: &ParamValues) -> Result<(MotorLimits, f64, f64)> {
    let cfg = config_from_params(&ControllerConfig::default(), params)
        .map_err(|_| anyhow::anyhow!("the rig's parameters do not make a valid configuration"))?;
    let m = |i: usize| {
        let a = &cfg.axes[i];
        (
            f64::from(lowest_speed_rad_s(a)),
            f64::from(a.max_speed_rad_s),
        )
    };
    Ok((
        [m(0), m(1)],
        f64::from(cfg.spin_per_precession),
        f64::from(cfg.axes_angle_rad),
    ))
}

/// The bowl speed range where both motors are within their limits, for motors at
/// `per_omega` times the bowl speed.
fn range(per_omega: [f64; 2], limits: MotorLimits) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (0.0f64, f64::INFINITY);
    for (c, (min, max)) in per_omega.into_iter().zip(limits) {
        if c != 0.0 {
            lo = lo.max(min / c.abs());
            hi = hi.min(max / c.abs());
        }
    }
    (hi.is_finite() && lo < hi).then_some((lo, hi))
}

impl SpeedAxis {
    /// The flags' motors (their ratio, the spin's direction) within the parameter table's
    /// default limits; the bowl speed of the flags is Eq. 2 of the motors' magnitudes.
    pub fn of_scene(scene: &RollingScene<f64>) -> Result<(Self, f64)> {
        let (lims, _, _) = limits(&default_params())?;
        let th = scene.axes_angle_rad;
        let omega = combined_speed_from_trig(
            th.cos(),
            th.sin(),
            MotorSpeeds {
                precession_rad_s: scene.precession_rad_s.abs(),
                spin_rad_s: scene.spin_rad_s.abs(),
            },
        )
        .unwrap_or(0.0);
        if omega.is_nan() || omega <= 0.0 {
            bail!("both motor speeds are 0: there is no speed to vary");
        }
        let per = [scene.precession_rad_s / omega, scene.spin_rad_s / omega];
        Ok((
            Self {
                precession_per_omega: per[0],
                spin_per_omega: per[1],
                range_rad_s: range(per, lims),
            },
            omega,
        ))
    }

    /// The rig's split (`RATIO_PPM`, `AXES_MDEG`) and limits, the spin turning as in `scene`;
    /// refused when the rig's axes angle is not the scene's tilt.
    pub fn of_rig(params: &ParamValues, scene: &RollingScene<f64>) -> Result<Self> {
        let (lims, ratio, axes_rad) = limits(params)?;
        if (axes_rad - scene.axes_angle_rad).abs() > 1e-4 {
            bail!(
                "the rig's AXES_MDEG is {:.3} deg but the scene's tilt is {:.3} deg: the table \
                 would describe another bowl (set the rig's AXES_MDEG or give --axes-angle-deg)",
                axes_rad.to_degrees(),
                scene.axes_angle_rad.to_degrees()
            );
        }
        let k = combined_speed_from_trig(
            axes_rad.cos(),
            axes_rad.sin(),
            MotorSpeeds {
                precession_rad_s: 1.0,
                spin_rad_s: ratio,
            },
        )
        .unwrap_or(f64::NAN);
        let sign = if scene.spin_rad_s < 0.0 { -1.0 } else { 1.0 };
        let per = [1.0 / k, sign * ratio / k];
        Ok(Self {
            precession_per_omega: per[0],
            spin_per_omega: per[1],
            range_rad_s: range(per, lims),
        })
    }

    /// `scene` with its motors at bowl speed `omega_rad_s`.
    pub fn at(&self, scene: &RollingScene<f64>, omega_rad_s: f64) -> RollingScene<f64> {
        RollingScene {
            precession_rad_s: self.precession_per_omega * omega_rad_s,
            spin_rad_s: self.spin_per_omega * omega_rad_s,
            ..*scene
        }
    }
}

/// T over the speed range and its slope at the asked speed.
#[derive(Debug, Clone)]
pub struct SpeedReport {
    /// The table at [`SPEED_TABLE_LEN`] evenly spaced speeds (`None`: no range, or a speed
    /// where no release leaves).
    pub table: Option<SpeedTable>,
    /// The same times in f64 (what is printed), with their speeds; `None` where none leaves.
    pub samples: Vec<(f64, Option<f64>)>,
    /// dT/domega at the asked speed (central difference, 2 % of it each side), s per rad/s.
    pub slope_s2_per_rad: Option<f64>,
    /// Why there is no table, in words.
    pub why_not: Option<String>,
    /// The table checked against the model between its speeds: the worst relative error of
    /// its linear interpolation at a segment's midpoint, and that midpoint's speed, rad/s.
    pub midpoint_error: Option<(f64, f64)>,
}

/// Above this relative error between the table and the model between its speeds, the words
/// say so: the model's own accuracy against the independent reference (issue 30: 1 %).
const INTERPOLATION_WARNING: f64 = 0.01;

/// Computes the report: `t_of` is the model's mean T at a scene (`None` if no release leaves).
pub fn report(
    scene: &RollingScene<f64>,
    axis: &SpeedAxis,
    omega_rad_s: f64,
    t_of: &dyn Fn(&RollingScene<f64>) -> Option<f64>,
) -> SpeedReport {
    let h = 0.02 * omega_rad_s;
    let slope = match (
        t_of(&axis.at(scene, omega_rad_s + h)),
        t_of(&axis.at(scene, omega_rad_s - h)),
    ) {
        (Some(up), Some(down)) if h > 0.0 => Some((up - down) / (2.0 * h)),
        _ => None,
    };
    let Some((lo, hi)) = axis.range_rad_s else {
        return SpeedReport {
            table: None,
            samples: Vec::new(),
            slope_s2_per_rad: slope,
            why_not: Some(
                "no bowl speed keeps both motors between their lowest measurable speed and \
                 their limit at this ratio"
                    .into(),
            ),
            midpoint_error: None,
        };
    };
    // The speeds as the rig stores them (whole mrad/s, inside the limits).
    let (lo, hi) = ((lo * 1e3).ceil() * 1e-3, (hi * 1e3).floor() * 1e-3);
    let samples: Vec<(f64, Option<f64>)> = (0..SPEED_TABLE_LEN)
        .map(|k| {
            let w = lo + (hi - lo) * k as f64 / (SPEED_TABLE_LEN - 1) as f64;
            (w, t_of(&axis.at(scene, w)))
        })
        .collect();
    let missing: Vec<String> = samples
        .iter()
        .filter(|(_, t)| t.is_none())
        .map(|(w, _)| format!("{w:.3}"))
        .collect();
    let (table, why_not) = if missing.is_empty() {
        // Whole microseconds, as the rig stores them, so the words here and in its
        // refusals are the same.
        let t: [f32; SPEED_TABLE_LEN] = core::array::from_fn(|k| {
            ((samples[k].1.unwrap_or(f64::NAN) * 1e6).round() * 1e-6) as f32
        });
        match SpeedTable::new(lo as f32, hi as f32, t) {
            Ok(table) => (Some(table), None),
            Err(_) => (None, Some("the times do not make a table".to_string())),
        }
    } else {
        (
            None,
            Some(format!(
                "no release leaves at bowl speed {} rad/s, so T has no value there",
                missing.join(", ")
            )),
        )
    };
    // Between the speeds the rig interpolates linearly: check it against the model at each
    // segment's midpoint (T jumps where the regime changes, e.g. a wall that holds or lets go).
    let midpoint_error = table.and_then(|_| {
        samples
            .windows(2)
            .filter_map(|w| {
                let (a, ta) = (w[0].0, w[0].1?);
                let (b, tb) = (w[1].0, w[1].1?);
                let mid = 0.5 * (a + b);
                let t = t_of(&axis.at(scene, mid))?;
                Some(((0.5 * (ta + tb) - t).abs() / t, mid))
            })
            .reduce(|x, y| if y.0 > x.0 { y } else { x })
    });
    SpeedReport {
        table,
        samples,
        slope_s2_per_rad: slope,
        why_not,
        midpoint_error,
    }
}

impl SpeedReport {
    /// The JSON object `speed` of `bowl predict`.
    pub fn json(&self, tilt_deg: f64) -> Value {
        let times: Vec<f64> = self.samples.iter().filter_map(|s| s.1).collect();
        let range = |v: &[f64]| {
            let lo = v.iter().copied().reduce(f64::min);
            let hi = v.iter().copied().reduce(f64::max);
            lo.zip(hi).map(|(a, b)| json!([a, b]))
        };
        let speeds: Vec<f64> = self.samples.iter().map(|s| s.0).collect();
        json!({
            "speed_range_rad_s": range(&speeds),
            "residence_time_range_s": range(&times),
            "dT_domega_s2_per_rad": self.slope_s2_per_rad,
            "speed_can_set_T": self.table.map(|t| !t.is_flat()),
            "table": self.samples.iter().map(|(w, t)| json!({"omega_rad_s": w, "residence_time_s": t})).collect::<Vec<_>>(),
            "words": self.words(tilt_deg),
            "why_no_table": self.why_not,
            "table_midpoint_error_max_rel": self.midpoint_error.map(|e| e.0),
            "table_midpoint_error_at_rad_s": self.midpoint_error.map(|e| e.1),
        })
    }

    /// What speed can do, in words.
    pub fn words(&self, tilt_deg: f64) -> String {
        let slope = self
            .slope_s2_per_rad
            .map(|s| format!("; dT/domega {s:.3e} s per rad/s at the asked speed"))
            .unwrap_or_default();
        let bumpy = match self.midpoint_error {
            Some((e, at)) if e > INTERPOLATION_WARNING => format!(
                "; between its {SPEED_TABLE_LEN} speeds the table is off by up to {:.1} % (near \
                 {at:.2} rad/s: T is not smooth there, the regime changes), so RTIME TABLE lands \
                 within that there",
                100.0 * e
            ),
            _ => String::new(),
        };
        match (&self.table, &self.why_not) {
            (Some(t), _) => format!(
                "{}{slope}{bumpy}",
                rig_client::refusal::speed_range_words(tilt_deg, t)
            ),
            (None, Some(why)) => format!("speed range: {why}{slope}"),
            (None, None) => format!("speed range: none{slope}"),
        }
    }
}

/// Stores `table` on the rig at `port` (off first, the times, then the speeds: the fastest
/// last switches it on), and says what it stored.
pub fn store(port: &str, table: &SpeedTable) -> Result<()> {
    use rig_client::rig::{Reply, Rig};
    let values = table_to_params(table).map_err(|_| {
        anyhow::anyhow!(
            "a time in the table is over 8 s, more than the rig's RT_Tn_US parameters hold: \
             `rtime cori` / `rtime flat` still answer with the paper's models"
        )
    })?;
    let mut rig = Rig::open(port, 115_200, std::time::Duration::from_millis(1000))?;
    let mut writes: Vec<(ParamId, i32)> = vec![(ParamId::RtSpeedHiMradS, 0)];
    writes.extend(
        TABLE_PARAMS[2..]
            .iter()
            .copied()
            .zip(values[2..].iter().copied()),
    );
    writes.push((TABLE_PARAMS[0], values[0]));
    writes.push((TABLE_PARAMS[1], values[1]));
    for (id, v) in writes {
        if let Reply::Refused(r) = rig.set(id, v)? {
            bail!(
                "the rig refused SET {} {v}: {} - {}",
                id.token(),
                r.token(),
                rig_client::lines::explain(r)
            );
        }
    }
    Ok(())
}

/// The rig's parameters, read from `port`.
pub fn rig_params(port: &str) -> Result<ParamValues> {
    use rig_client::rig::{Reply, Rig};
    let mut rig = Rig::open(port, 115_200, std::time::Duration::from_millis(1000))?;
    match rig.params()? {
        Reply::Done(p) => Ok(p),
        Reply::Refused(r) => bail!("the rig refused PARAMS: {}", r.token()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(w1: f64, w2: f64) -> RollingScene<f64> {
        RollingScene::with_speeds(w1, w2, 60f64.to_radians(), 0.075)
    }

    #[test]
    fn the_range_keeps_both_motors_inside_their_limits() {
        let s = scene(1.2, -2.7);
        let (axis, omega) = SpeedAxis::of_scene(&s).unwrap();
        let (lo, hi) = axis.range_rad_s.unwrap();
        // The spin motor is the faster one: it reaches 4 rad/s first.
        let at_hi = axis.at(&s, hi);
        assert!((at_hi.spin_rad_s.abs() - 4.0).abs() < 1e-9, "{at_hi:?}");
        assert!(at_hi.spin_rad_s < 0.0 && at_hi.precession_rad_s > 0.0);
        // The precession motor is the slower one: at the lowest bowl speed it is at its lowest.
        let (lims, _, _) = limits(&default_params()).unwrap();
        let at_lo = axis.at(&s, lo);
        assert!(
            (at_lo.precession_rad_s - lims[0].0).abs() < 1e-9,
            "{at_lo:?}"
        );
        // The asked speed maps back to the asked motors.
        let back = axis.at(&s, omega);
        assert!((back.precession_rad_s - 1.2).abs() < 1e-12);
        assert!((back.spin_rad_s + 2.7).abs() < 1e-12);
    }

    #[test]
    fn a_linear_model_gives_its_slope_and_ends() {
        // T = 3 - 0.3 omega (any scene): the report's slope and range are the line's.
        let s = scene(1.0, 1.0);
        let (axis, omega) = SpeedAxis::of_scene(&s).unwrap();
        let t_of = |x: &RollingScene<f64>| {
            let w = x.precession_rad_s / axis.precession_per_omega;
            Some(3.0 - 0.3 * w)
        };
        let r = report(&s, &axis, omega, &t_of);
        assert!((r.slope_s2_per_rad.unwrap() + 0.3).abs() < 1e-9);
        let table = r.table.unwrap();
        let (w_lo, w_hi) = table.speed_range_rad_s();
        let (t_lo, t_hi) = table.residence_range_s();
        assert!((f64::from(t_hi) - (3.0 - 0.3 * f64::from(w_lo))).abs() < 1e-5);
        assert!((f64::from(t_lo) - (3.0 - 0.3 * f64::from(w_hi))).abs() < 1e-5);
        assert!(!table.is_flat());
    }
}

//! `bowl predict --model rolling`: the granule rolling on the tilted, precessing bowl
//! (model-core `particle::rolling`, docs/model.md §9), for one release azimuth or the mean, min
//! and max over the twelve azimuths 0, 30, ..., 330 degrees.

use anyhow::{Result, bail};
use model_core::particle::rolling::hierarchy::{Wanted, tolerance_from_resistance_uncertainty};
use model_core::particle::rolling::{
    self, AZIMUTHS_DEG, RollingMethod, RollingOutcome, RollingScene,
};
use serde_json::json;

pub use super::rolling_words::words;
use super::rolling_words::{given_words, run_words};
use super::{Inputs, MethodChoice, validity};

/// Inputs of the rolling model (the shared ones: `--mu` is its rolling resistance, `--ri-m`,
/// `--rim-radius-m`, `--g`, `--k2`, `--method`, `--tol`, `--step-s`, `--json`).
#[derive(Debug, Clone)]
pub struct RollingInputs {
    /// Rolling model: precession speed w1 of the bowl's axis about the vertical, rad/s.
    pub precession_rad_s: Option<f64>,
    /// Rolling model: spin speed w2 of the bowl about its own axis, rad/s (negative: the
    /// other way, e.g. --spin-rad-s -2.7).
    pub spin_rad_s: Option<f64>,
    /// Rolling model: angle between the bowl's axis and the vertical, degrees (paper Eq. 2).
    pub axes_angle_deg: Option<f64>,
    /// Rolling model: granule radius a, m.
    pub particle_radius_m: f64,
    /// Rolling model: the rod's horizontal offset L, the distance of the bowl's centre from the
    /// precession axis, m. Not the rod's length: a rod of length l at angle th from the
    /// vertical gives L = l sin(th) (l overstates L by 15 % at 60 deg). `--rod-length-m` is
    /// this flag's old name, kept as an alias.
    pub rod_offset_m: f64,
    /// Rolling model: release azimuth from the downhill direction, degrees, or `all` (mean, min
    /// and max over 0, 30, ..., 330).
    pub release_azimuth_deg: String,
    /// Rolling model: the friction coefficient the contact can give (slip beyond it is reported).
    pub sliding_mu: f64,
    /// Rolling model: every member of the model hierarchy on this scene, its mean residence
    /// time and its difference from the full model, and the cheapest member within this
    /// relative tolerance (e.g. 0.05).
    pub hierarchy_tolerance: Option<f64>,
    /// Rolling model: as --hierarchy-tolerance, the tolerance set by this uncertainty in the
    /// rolling resistance (the change of the full model's mean T when mu moves by it).
    pub hierarchy_uncertainty_mu: Option<f64>,
    /// Rolling model: with the hierarchy, judge each single release (the worst azimuth), not
    /// the mean over the releases.
    pub each_release: bool,
}

impl RollingInputs {
    /// The contact's sliding coefficient (every model judges its rolling against it).
    pub fn sliding_mu(&self) -> f64 {
        self.sliding_mu
    }

    /// `--release-azimuth-deg` as given.
    pub fn release_azimuth_deg(&self) -> &str {
        &self.release_azimuth_deg
    }

    /// The tilted bowl's scene from the flags (the rolling and the bowl model share it), and
    /// the tilt in degrees; `model` names the model in the words of a missing flag.
    pub fn scene(
        &self,
        args: &Inputs,
        model: &str,
        default_tilt_deg: Option<f64>,
    ) -> Result<(RollingScene<f64>, f64)> {
        let tilt = self.axes_angle_deg.or(default_tilt_deg);
        let (Some(w1), Some(w2), Some(th_deg)) = (self.precession_rad_s, self.spin_rad_s, tilt)
        else {
            bail!(
                "the {model} model needs --precession-rad-s, --spin-rad-s and --axes-angle-deg \
                 (the two motor speeds and the tilt of the bowl's axis)"
            );
        };
        let scene = RollingScene {
            precession_rad_s: w1,
            spin_rad_s: w2,
            axes_angle_rad: th_deg.to_radians(),
            rolling_resistance: args.mu,
            sliding_friction: self.sliding_mu,
            g_m_s2: args.g,
            k2: args.k2,
            particle_radius_m: self.particle_radius_m,
            rod_length_m: self.rod_offset_m,
            ri_m: args.ri_m,
            rim_radius_m: args.rim_radius_m,
        };
        scene
            .validate()
            .map_err(|e| anyhow::anyhow!(given_words(e, &scene, th_deg)))?;
        super::refusals::gravity(scene.g_m_s2, "--g")?;
        fits(&scene)?;
        Ok((scene, th_deg))
    }
}

/// The largest rod offset L the models are checked for (the bowl model's property test runs
/// rod offsets to 1 m, docs/model.md §10), the same bound as a rig file's largest bowl radius:
/// L = 1e8 m answered "still inside after 10 s", marked valid.
pub const ROD_OFFSET_MAX_M: f64 = 1.0;

/// The granule fits the bowl: its radius below the bottom's (the model puts its centre on the
/// bottom at the release radius; a 1 m granule in a 75 mm bowl was answered as valid, a 1e9 m
/// one ran for minutes and gave up).
pub fn fits(scene: &RollingScene<f64>) -> Result<()> {
    if scene.rod_length_m > ROD_OFFSET_MAX_M {
        bail!(
            "--rod-offset-m {} m is beyond {ROD_OFFSET_MAX_M} m: the models are checked for rod \
             offsets up to that (docs/model.md §10; a rig file bounds a bowl's radius to 1 m \
             the same way), and far beyond it they answer wrongly without knowing; give the \
             horizontal offset L = l sin(th) of your rod in metres",
            scene.rod_length_m
        );
    }
    if scene.particle_radius_m >= scene.rim_radius_m {
        bail!(
            "--particle-radius-m {} m is not smaller than the bowl's radius R = {} m \
             (--rim-radius-m): a granule that size does not fit the bowl; give the granule's \
             radius (0.003 m for a 6 mm sago pearl)",
            scene.particle_radius_m,
            scene.rim_radius_m
        );
    }
    Ok(())
}

/// The rolling model's regime over `total_s`, of which it was held at rest `held_s`.
fn roll_or_held(total_s: f64, held_s: f64) -> serde_json::Value {
    if held_s > 0.0 && total_s > 0.0 {
        json!({"roll": 1.0 - held_s / total_s, "held": held_s / total_s})
    } else {
        json!({"roll": 1.0})
    }
}

/// One release's outcome, as JSON and in words.
fn outcome(o: &RollingOutcome<f64>, sliding_mu: f64) -> (serde_json::Value, String) {
    match *o {
        RollingOutcome::Leaves {
            residence_time_s,
            exit_speed_m_s,
            max_friction_ratio,
            first_slip_s,
        } => {
            let slip = match first_slip_s {
                Some(t) => format!(
                    "; from t = {t:.4} s rolling needs friction up to {max_friction_ratio:.3} of \
                     the normal force, more than the {sliding_mu} the contact gives: the granule \
                     slides there, so this T is the rolling model's"
                ),
                None => format!(
                    "; rolls throughout (friction needed at most {max_friction_ratio:.3} of the \
                     normal force)"
                ),
            };
            (
                json!({
                    "outcome": "leaves", "residence_time_s": residence_time_s,
                    "exit_speed_relative_m_s": exit_speed_m_s,
                    "max_friction_ratio": max_friction_ratio, "first_slip_s": first_slip_s,
                }),
                format!(
                    "leaves after T = {} s at {} m/s relative to the bowl{slip}",
                    crate::number::fixed(residence_time_s, 6),
                    crate::number::fixed(exit_speed_m_s, 4)
                ),
            )
        }
        RollingOutcome::Held => (
            json!({"outcome": "held"}),
            "held: the resistance keeps it at rest".into(),
        ),
        RollingOutcome::LiftsOff { time_s } => (
            json!({"outcome": "lifts_off", "time_s": time_s}),
            format!("lifts off the bottom at t = {time_s:.4} s (normal force reaches zero)"),
        ),
        RollingOutcome::NotLeftBy { horizon_s } => (
            json!({"outcome": "not_left", "horizon_s": horizon_s}),
            format!("still in the bowl after {horizon_s} s"),
        ),
    }
}

/// Runs `bowl predict --model rolling`.
pub fn run(args: &Inputs, r: &RollingInputs) -> Result<()> {
    let (Some(w1), Some(w2), Some(th_deg)) = (r.precession_rad_s, r.spin_rad_s, r.axes_angle_deg)
    else {
        bail!(
            "the rolling model needs --precession-rad-s, --spin-rad-s and --axes-angle-deg \
             (the two motor speeds and the tilt of the bowl's axis)"
        );
    };
    if args.target_time_s.is_some() || args.batch.is_some() {
        bail!("--target-time-s and --batch are for the flat and Coriolis models, not rolling");
    }
    let method = match args.method {
        MethodChoice::Closed | MethodChoice::Dp54 => RollingMethod::Dp54 { rtol: args.tol },
        MethodChoice::Rk4 => RollingMethod::Rk4 {
            step_s: args.step_s.unwrap_or(1e-3),
        },
        other => bail!(
            "--method {} is not offered for the rolling model: use dp54 (default) or rk4",
            super::method_name(other)
        ),
    };
    // The scene as the bowl model reads it (one check of every flag, g above 0 included).
    let (scene, _) = r.scene(args, "rolling", None)?;
    let head = format!(
        "rolling model: w1 {w1} rad/s, w2 {w2} rad/s, tilt {th_deg} deg (combined {:.4} rad/s), \
         mu_r {}, a {} m, L {} m, ri {} m, R {} m",
        scene.combined_speed_rad_s(),
        args.mu,
        r.particle_radius_m,
        r.rod_offset_m,
        args.ri_m,
        args.rim_radius_m
    );
    let wanted = if r.each_release {
        Wanted::EachRelease
    } else {
        Wanted::AzimuthMean
    };
    if let Some(tol) = r.hierarchy_tolerance {
        return hierarchy(&scene, method, tol, wanted, args.json, &head);
    }
    if let Some(dmu) = r.hierarchy_uncertainty_mu {
        if !(dmu.is_finite() && dmu >= 0.0) {
            bail!("--hierarchy-uncertainty-mu must be 0 or more, e.g. 0.01");
        }
        let tol = tolerance_from_resistance_uncertainty(&scene, dmu, method).ok_or_else(|| {
            anyhow::anyhow!(
                "the rolling model gives no mean residence time here (a release does not leave), \
                 so no tolerance follows from the uncertainty"
            )
        })?;
        if !args.json {
            println!(
                "an uncertainty of {dmu} in mu_r moves the mean residence time by {:.3} %: that is \
                 the tolerance",
                tol * 100.0
            );
        }
        return hierarchy(&scene, method, tol, wanted, args.json, &head);
    }
    let betas = azimuths(r.release_azimuth_deg())?;
    let (sum, validity, reports) = over_azimuths(&scene, method, &betas)?;
    let n = betas.len();
    if args.json {
        let per: Vec<_> = betas
            .iter()
            .zip(&reports)
            .map(|(&deg, rep)| {
                let (more, _) = outcome(&rep.outcome, r.sliding_mu);
                // The model rolls until it ends (the rim, lift-off, the horizon), but for the
                // time it is held at rest on the way.
                let (t, regime) = match rep.outcome {
                    RollingOutcome::Leaves {
                        residence_time_s, ..
                    } => (
                        Some(residence_time_s),
                        roll_or_held(residence_time_s, rep.held_s),
                    ),
                    RollingOutcome::Held => (None, json!({"held": 1.0})),
                    RollingOutcome::LiftsOff { time_s } => (None, roll_or_held(time_s, rep.held_s)),
                    RollingOutcome::NotLeftBy { horizon_s } => {
                        (None, roll_or_held(horizon_s, rep.held_s))
                    }
                };
                super::release_json::entry(deg, t, regime, more)
            })
            .collect();
        let mut v = json!({
            "model": "rolling", "release_azimuths_deg": betas,
            "residence_time_mean_s": sum.mean_s, "residence_time_min_s": sum.min_s,
            "residence_time_max_s": sum.max_s, "releases": n, "releases_leaving": sum.left,
            "releases_sliding": sum.slid, "releases_lifting_off": sum.lifted,
            "max_friction_ratio": sum.max_friction_ratio,
            "rhs_evaluations": sum.evaluations, "per_release": per,
        });
        super::release_json::add_single_release(&mut v);
        validity.add_to(&mut v);
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    if let Some(line) = validity.text_line("rolling") {
        println!("{line}");
    }
    println!("{head}");
    if r.release_azimuth_deg.trim() != "all" {
        for (deg, rep) in betas.iter().zip(&reports) {
            println!(
                "release at {deg} deg: {}",
                outcome(&rep.outcome, r.sliding_mu).1
            );
        }
    }
    if n > 1 {
        match (sum.mean_s, sum.min_s, sum.max_s) {
            (Some(m), Some(lo), Some(hi)) => println!(
                "over {}: T mean {} s, min {} s, max {} s; {} of {n} leave, {} of those slide \
                 on the way",
                crate::number::count(n, "release azimuth", "release azimuths"),
                crate::number::fixed(m, 6),
                crate::number::fixed(lo, 6),
                crate::number::fixed(hi, 6),
                sum.left,
                sum.slid
            ),
            _ => println!("none of the {n} releases leaves the bowl"),
        }
    }
    Ok(())
}

/// The rolling model over the twelve release azimuths, and whether it holds there (the
/// granule slides or lifts off on the way).
fn over_azimuths(
    scene: &RollingScene<f64>,
    method: RollingMethod<f64>,
    betas: &[f64],
) -> Result<(
    rolling::AzimuthSummary<f64>,
    validity::Validity,
    Vec<rolling::RollingReport<f64>>,
)> {
    let mut tally = rolling::AzimuthTally::new();
    let mut reports = Vec::with_capacity(betas.len());
    for &deg in betas {
        let rep = rolling::residence(scene, deg.to_radians(), method)
            .map_err(|e| anyhow::anyhow!(run_words(e, method)))?;
        tally.add(&rep);
        reports.push(rep);
    }
    let sum = tally.summary();
    let validity = validity::rolling(
        sum.slid,
        sum.lifted,
        betas.len() as u32,
        sum.max_friction_ratio,
        scene.sliding_friction,
    );
    Ok((sum, validity, reports))
}

/// `--hierarchy-tolerance`: each member's mean residence time and difference from the full
/// model, and the cheapest member within the tolerance.
fn hierarchy(
    scene: &RollingScene<f64>,
    method: RollingMethod<f64>,
    tol: f64,
    wanted: Wanted,
    json_out: bool,
    head: &str,
) -> Result<()> {
    use model_core::particle::rolling::hierarchy::{
        MEMBERS, cheapest_within, differences, mean_residence_s,
    };
    if !(tol.is_finite() && tol >= 0.0) {
        bail!("--hierarchy-tolerance must be a relative difference of 0 or more, e.g. 0.05");
    }
    let diffs = differences(scene, method, wanted);
    let rows: Vec<_> = MEMBERS
        .iter()
        .zip(diffs)
        .map(|(&m, diff)| (m, mean_residence_s(m, scene, method), diff))
        .collect();
    let (chosen, diff) = cheapest_within(scene, tol, method, wanted);
    // Every member is judged against the rolling model: where that does not hold (the granule
    // slides or lifts off), neither does the member chosen, and the answer says so first.
    let (_, validity, _) = over_azimuths(scene, method, &AZIMUTHS_DEG)?;
    if json_out {
        let members: Vec<_> = rows
            .iter()
            .map(|(m, t, d)| {
                json!({"member": m.name(), "residence_time_mean_s": t, "difference_from_rolling": d})
            })
            .collect();
        let mut v = json!({
            "model": "rolling", "tolerance": tol, "members": members,
            "judged_on": if wanted == Wanted::EachRelease { "each release" } else { "azimuth mean" },
            "chosen": chosen.name(), "chosen_difference": diff,
        });
        validity.add_to(&mut v);
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    if let Some(line) = validity.text_line(chosen.name()) {
        println!("{line}");
    }
    println!("{head}");
    println!(
        "{:<16} {:>12} {:>22}",
        "member", "mean T, s", "difference from rolling"
    );
    for (m, t, d) in &rows {
        let t = t.map_or_else(|| "never leaves".into(), |t| format!("{t:.6}"));
        let d = d.map_or_else(|| "-".into(), |d| format!("{:.2} %", d * 100.0));
        println!("{:<16} {t:>12} {d:>22}", m.name());
    }
    println!(
        "cheapest within {:.2} %: {}{}",
        tol * 100.0,
        chosen.name(),
        diff.map_or(String::new(), |d| format!(
            " (differs by {:.3} %)",
            d * 100.0
        ))
    );
    Ok(())
}

/// `all`, one azimuth or a comma-separated list, degrees.
pub(super) fn azimuths(text: &str) -> Result<Vec<f64>> {
    if text.trim() == "all" {
        return Ok(AZIMUTHS_DEG.to_vec());
    }
    text.split(',')
        .map(|p| {
            let v: f64 = p.trim().parse().map_err(|_| {
                anyhow::anyhow!(
                    "--release-azimuth-deg {text:?}: {p:?} is not a number of degrees (give \
                     `all`, one number, or numbers separated by commas)"
                )
            })?;
            if !v.is_finite() {
                bail!("--release-azimuth-deg must be finite numbers of degrees, not {p:?}");
            }
            Ok(v)
        })
        .collect()
}

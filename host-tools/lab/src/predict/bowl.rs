//! `bowl predict --model bowl`: the granule in the real bowl (model-core `particle::bowl`,
//! docs/model.md §10): rolling or sliding on the flat bottom, the fillet and the wall, until
//! its centre passes the lip's radius, for one, several or the twelve release azimuths.

use anyhow::{Result, bail};
use model_core::ode::system::SystemLimits;
use model_core::particle::bowl::{self, BowlError, BowlOutcome, BowlReport, BowlShape, HeldAt};
use model_core::particle::rolling::{MAX_STEPS, RollingMethod, RollingScene};
use serde_json::{Value, json};

pub(super) use super::bowl_setup::{BowlSetup, scene_and_shape};
use super::speed_range::{self, SpeedAxis, SpeedReport};
use super::validity::Validity;
use super::{Inputs, rolling};
use super::{gave_up, release_json};
use crate::number::{count, fixed, shares};

/// The bowl model's own flags (the scene's are the rolling model's; `--mu` is the rolling
/// resistance, `--sliding-mu` the contact's sliding coefficient).
#[derive(Debug, Clone)]
pub struct BowlInputs {
    /// Bowl model: the wall's angle from the bottom plane, degrees (90 = vertical; default 90
    /// or the rig file's).
    pub wall_angle_deg: Option<f64>,
    /// Bowl model: the wall's height above the bottom, m (0 = a bare rim at --rim-radius-m;
    /// default 0 or the rig file's).
    pub wall_height_m: Option<f64>,
    /// Bowl model: the fillet's radius between bottom and wall, m (0 = a sharp corner; default
    /// 0 or the rig file's).
    pub fillet_radius_m: Option<f64>,
    /// Bowl model: coefficient of restitution of the impact with a sharp corner's wall
    /// (default 0.5 or the rig file's).
    pub restitution: Option<f64>,
    /// Bowl model: follow each release this long, s; still inside then, it has not left.
    pub max_time_s: f64,
    /// Bowl model: the bowl from a rig file's [bowl] table (docs/rigs/nominal.toml): its wall
    /// keys unless given as flags, its tilt unless --axes-angle-deg is given, and its bottom
    /// and granule radii in place of --rim-radius-m and --particle-radius-m.
    pub rig_file: Option<std::path::PathBuf>,
    /// Bowl model: also report what speed can do (`speed_range`).
    pub speed_range: bool,
    /// Bowl model: store the residence-time table on the rig at this port.
    pub store_table: Option<String>,
}

pub(crate) fn words(e: BowlError) -> String {
    match e {
        BowlError::Scene(e) => rolling::words(e),
        BowlError::InvalidWallAngle => {
            "--wall-angle-deg must be above 0 and at most 90 degrees (90 = a vertical wall)".into()
        }
        BowlError::InvalidWallHeight => "--wall-height-m must be 0 or more (0 = a bare rim)".into(),
        BowlError::InvalidFillet => {
            "--fillet-radius-m must be 0 or more (0 = a sharp corner)".into()
        }
        BowlError::FilletReachesRelease => "the granule released at --ri-m already touches the \
             corner between bottom and wall (the fillet, --fillet-radius-m, widened by the \
             granule's radius, --particle-radius-m): give a smaller --ri-m, --fillet-radius-m or \
             --particle-radius-m (the granule starts on the flat bottom)"
            .into(),
        BowlError::FilletAboveWall => "the fillet (--fillet-radius-m) rises higher than the \
             wall it rounds into (--wall-height-m, --wall-angle-deg): give a smaller fillet or a \
             taller wall"
            .into(),
        BowlError::InvalidRestitution => "--restitution must lie between 0 and 1".into(),
        BowlError::InvalidHorizon => "--max-time-s must be a positive number of seconds".into(),
    }
}

/// Each mode's share of the time a release spent in the bowl.
fn regime(r: &BowlReport<f64>) -> Value {
    if r.outcome == BowlOutcome::Held {
        return json!({"held": 1.0});
    }
    // Held: at rest on the bottom (the rolling resistance) or in a vertical wall's corner.
    let held = r.regime.held_s + r.held_s;
    let total = r.regime.roll_s + r.regime.slide_s + r.flight_s + held;
    let mut m = serde_json::Map::new();
    if total > 0.0 {
        for (name, t) in [
            ("roll", r.regime.roll_s),
            ("slide", r.regime.slide_s),
            ("fly", r.flight_s),
            ("held", held),
        ] {
            if t > 0.0 {
                m.insert(name.into(), json!(t / total));
            }
        }
    }
    Value::Object(m)
}

/// Where a release still inside at the horizon is held at rest, in the text's words: the
/// same wherever its last mode is `held` (before, only a vertical wall's sharp corner said
/// "held by the wall"; one the rolling resistance held on the fillet said "still inside").
fn held_words(at: Option<HeldAt>) -> Option<&'static str> {
    at.map(|at| match at {
        HeldAt::Bottom => "held at rest on the bottom",
        HeldAt::Fillet => "held on the fillet",
        HeldAt::Wall => "held by the wall",
    })
}

/// The JSON's `held_at`: `bottom`, `fillet`, `wall` or null.
fn held_at_name(at: Option<HeldAt>) -> Value {
    at.map_or(Value::Null, |at| {
        json!(match at {
            HeldAt::Bottom => "bottom",
            HeldAt::Fillet => "fillet",
            HeldAt::Wall => "wall",
        })
    })
}

fn outcome_name(o: &BowlOutcome<f64>) -> &'static str {
    match o {
        BowlOutcome::Leaves { .. } => "leaves",
        BowlOutcome::Held => "held",
        BowlOutcome::LiftsOff { .. } => "lifts_off",
        BowlOutcome::Inside { .. } => "inside",
    }
}

/// Runs `bowl predict --model bowl`.
pub fn run(args: &Inputs, r: &rolling::RollingInputs, b: &BowlInputs) -> Result<()> {
    if args.target_time_s.is_some() || args.batch.is_some() {
        bail!("--target-time-s and --batch are for the flat and Coriolis models, not the bowl");
    }
    let BowlSetup {
        scene,
        th_deg,
        wall,
        shape,
        method,
    } = scene_and_shape(args, r, b)?;
    let limits = SystemLimits {
        horizon_s: b.max_time_s,
        max_steps: MAX_STEPS,
    };
    let betas = rolling::azimuths(r.release_azimuth_deg())?;
    let mut rows = Vec::new();
    // A release the integrator gives up on (the step cap, e.g. a granule chattering at the
    // stick threshold in a corner, or a stall: steps that no longer advance the time, found
    // by the stall watch in tens of steps instead of at the cap, docs/model.md §12) is
    // reported as such; the others still count.
    let mut gave_up = Vec::new();
    for &deg in &betas {
        match bowl::residence_or_stall(&scene, &shape, deg.to_radians(), method, limits) {
            Ok(rep) => rows.push((deg, rep)),
            Err(
                e @ BowlError::Scene(model_core::particle::rolling::RollingError::Integration(_)),
            ) => {
                gave_up.push((deg, e));
            }
            Err(e) => bail!("release at {deg} deg: {}", words(e)),
        }
    }
    let times: Vec<f64> = rows
        .iter()
        .filter_map(|(_, rep)| match rep.outcome {
            BowlOutcome::Leaves {
                residence_time_s, ..
            } => Some(residence_time_s),
            _ => None,
        })
        .collect();
    let mean = (!times.is_empty()).then(|| times.iter().sum::<f64>() / times.len() as f64);
    let min = times.iter().copied().reduce(f64::min);
    let max = times.iter().copied().reduce(f64::max);
    let lifted = rows
        .iter()
        .filter(|(_, rep)| matches!(rep.outcome, BowlOutcome::LiftsOff { .. }))
        .count();
    let releases = betas.len();
    let mut why = Vec::new();
    if lifted > 0 {
        why.push(format!(
            "the granule lifts off in {lifted} of {releases} releases and no landing was \
             found, so those releases have no residence time"
        ));
    }
    if !gave_up.is_empty() {
        let settings = gave_up::Settings::Bowl {
            method,
            max_time_s: b.max_time_s,
        };
        why.push(gave_up::sentence(&gave_up, releases, &settings));
    }
    let validity = if why.is_empty() {
        Validity::valid()
    } else {
        Validity(Some(why.join("; ")))
    };
    let alpha = wall.angle_deg.to_radians();
    let lip = if wall.height_m > 0.0 {
        scene.rim_radius_m + wall.height_m * alpha.cos() / alpha.sin()
    } else {
        scene.rim_radius_m
    };
    let evaluations: u64 = rows.iter().map(|(_, rep)| u64::from(rep.evaluations)).sum();
    // What speed can do: the same releases at other bowl speeds (docs/model.md §11).
    let mean_t = |s: &RollingScene<f64>| mean_time(s, &shape, &betas, method, limits);
    let speed = speed_report(&scene, b, &mean_t)?;
    if args.json {
        let mut per: Vec<(f64, Value)> = rows
            .iter()
            .map(|(deg, rep)| {
                let (t, v) = match rep.outcome {
                    BowlOutcome::Leaves {
                        residence_time_s,
                        exit_speed_m_s,
                    } => (Some(residence_time_s), Some(exit_speed_m_s)),
                    _ => (None, None),
                };
                (
                    *deg,
                    release_json::entry(
                        *deg,
                        t,
                        regime(rep),
                        json!({
                            "outcome": outcome_name(&rep.outcome),
                            "held_at": held_at_name(rep.held_at),
                            "exit_speed_relative_m_s": v, "on_wall_s": rep.on_wall_s,
                            "flight_s": rep.flight_s, "landings": rep.landings,
                            "left_in_flight": t.is_some() && rep.left_in_flight,
                            "switches": rep.switches, "rhs_evaluations": rep.evaluations,
                        }),
                    ),
                )
            })
            .collect();
        for (deg, e) in &gave_up {
            per.push((
                *deg,
                release_json::entry(
                    *deg,
                    None,
                    Value::Null,
                    json!({"outcome": "gave_up", "error": gave_up::what(e)}),
                ),
            ));
        }
        // In the order the azimuths were given.
        per.sort_by_key(|(deg, _)| betas.iter().position(|b| b == deg));
        let per: Vec<Value> = per.into_iter().map(|(_, v)| v).collect();
        let mut v = json!({
            "model": "bowl",
            "residence_time_mean_s": mean, "residence_time_min_s": min,
            "residence_time_max_s": max, "releases": releases,
            "releases_leaving": times.len(), "per_release": per,
            "bowl": {
                "rim_radius_m": scene.rim_radius_m, "wall_angle_deg": wall.angle_deg,
                "wall_height_m": wall.height_m, "fillet_radius_m": wall.fillet_m,
                "lip_radius_m": lip, "restitution": wall.restitution,
                "axes_angle_deg": th_deg, "particle_radius_m": scene.particle_radius_m,
                "from_rig_file": b.rig_file.as_ref().map(|p| p.display().to_string()),
            },
            "max_time_s": b.max_time_s, "rhs_evaluations": evaluations,
        });
        if let (Some(obj), Some(sp)) = (v.as_object_mut(), &speed) {
            obj.insert("speed".into(), sp.json(th_deg));
        }
        super::release_json::add_single_release(&mut v);
        validity.add_to(&mut v);
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    if let Some(line) = validity.text_line("bowl") {
        println!("{line}");
    }
    println!(
        "bowl model: w1 {} rad/s, w2 {} rad/s, tilt {th_deg} deg, mu_r {}, mu_s {}, a {} m, ri {} m; \
         bottom R {} m, wall {} deg, {} m high, fillet {} m, lip at {lip:.4} m, e {}",
        scene.precession_rad_s,
        scene.spin_rad_s,
        scene.rolling_resistance,
        scene.sliding_friction,
        scene.particle_radius_m,
        scene.ri_m,
        scene.rim_radius_m,
        wall.angle_deg,
        wall.height_m,
        wall.fillet_m,
        wall.restitution
    );
    if let Some(p) = &b.rig_file {
        println!(
            "  (the bowl, tilt and granule radius from {}'s [bowl] table; mu_r, mu_s, k2 and the \
             release radius from its [particle] table; a flag given overrides any of these but \
             the rim and the granule's radius)",
            p.display()
        );
    }
    for (deg, rep) in &rows {
        let what = match rep.outcome {
            BowlOutcome::Leaves {
                residence_time_s,
                exit_speed_m_s,
            } => format!(
                "leaves over the lip after T = {} s at {} m/s",
                fixed(residence_time_s, 6),
                fixed(exit_speed_m_s, 4)
            ),
            BowlOutcome::Held => "held at rest where it was released".into(),
            BowlOutcome::LiftsOff { time_s } => {
                format!("lifts off at t = {} s (no landing found)", fixed(time_s, 4))
            }
            BowlOutcome::Inside { horizon_s } => match held_words(rep.held_at) {
                Some(held) => format!("{held}: still inside after {horizon_s} s"),
                None => format!("still inside after {horizon_s} s"),
            },
        };
        println!(
            "release at {deg} deg: {what}; regime {}",
            shares(&regime(rep))
        );
    }
    for (deg, e) in &gave_up {
        println!("release at {deg} deg: no answer: {}", gave_up::what(e));
    }
    if let Some(sp) = &speed {
        println!(
            "what speed can do: {}{}",
            sp.words(th_deg),
            not_all_leave(times.len(), releases)
        );
    }
    match (mean, min, max) {
        (Some(m), Some(lo), Some(hi)) => println!(
            "over {}: {} leave, T mean {} s, min {} s, max {} s",
            count(releases, "release", "releases"),
            times.len(),
            fixed(m, 6),
            fixed(lo, 6),
            fixed(hi, 6)
        ),
        _ => println!(
            "{} within {} s",
            match rows.len() {
                1 => "the release does not leave".to_string(),
                n => format!("none of the {n} releases leaves"),
            },
            b.max_time_s
        ),
    }
    Ok(())
}

/// The speed paragraph's caveat when some releases never leave: its T is the mean over those
/// that do (6 of 12 leaving was offered as a T range for RTIME TABLE without a word).
fn not_all_leave(leaving: usize, releases: usize) -> String {
    if leaving == releases {
        return String::new();
    }
    // None leaving: there is no mean to caveat (it read "only 0 of 12 releases leave ...: these
    // times are the mean over the releases that leave").
    if leaving == 0 {
        return format!(
            "; and at the asked speed none of the {releases} releases leaves (each stays in the \
             bowl)"
        );
    }
    format!(
        "; but only {leaving} of {releases} releases leave at the asked speed (the others stay \
         in the bowl): these times are the mean over the releases that leave, and a granule \
         released elsewhere may never come out"
    )
}

/// The mean residence time over the releases that leave (`None`: none leaves or one fails).
fn mean_time(
    scene: &RollingScene<f64>,
    shape: &BowlShape<f64>,
    betas: &[f64],
    method: RollingMethod<f64>,
    limits: SystemLimits<f64>,
) -> Option<f64> {
    let mut times = Vec::new();
    for deg in betas {
        let rep = bowl::residence(scene, shape, deg.to_radians(), method, limits).ok()?;
        if let BowlOutcome::Leaves {
            residence_time_s, ..
        } = rep.outcome
        {
            times.push(residence_time_s);
        }
    }
    (!times.is_empty()).then(|| times.iter().sum::<f64>() / times.len() as f64)
}

/// What speed can do at the flags' ratio and the default limits, and with `--store-table` at
/// the rig's, stored there; `None` with `--speed-range false`.
fn speed_report(
    scene: &RollingScene<f64>,
    b: &BowlInputs,
    mean_t: &dyn Fn(&RollingScene<f64>) -> Option<f64>,
) -> Result<Option<SpeedReport>> {
    if let Some(port) = &b.store_table {
        let params = speed_range::rig_params(port)?;
        let axis = SpeedAxis::of_rig(&params, scene)?;
        let omega = axis.range_rad_s.map_or(0.0, |(lo, hi)| 0.5 * (lo + hi));
        let rep = speed_range::report(scene, &axis, omega, mean_t);
        let Some(table) = rep.table else {
            bail!(
                "no table to store: {}",
                rep.why_not.unwrap_or_else(|| "no speed range".into())
            );
        };
        speed_range::store(port, &table)?;
        eprintln!(
            "stored on {port}: T at {} bowl speeds from {:.3} to {:.3} rad/s (the rig's limits \
             and RATIO_PPM); `rtime table MS` now uses it",
            table.residence_s().len(),
            table.speed_range_rad_s().0,
            table.speed_range_rad_s().1
        );
        return Ok(Some(rep));
    }
    if !b.speed_range {
        return Ok(None);
    }
    Ok(Some(match SpeedAxis::of_scene(scene) {
        Ok((axis, omega)) => speed_range::report(scene, &axis, omega, mean_t),
        // A bowl at rest: no speed to vary; the prediction itself stands.
        Err(e) => SpeedReport {
            table: None,
            samples: Vec::new(),
            slope_s2_per_rad: None,
            why_not: Some(e.to_string()),
            midpoint_error: None,
        },
    }))
}

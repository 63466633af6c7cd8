//! `bowl predict --model auto` on the tilted bowl (any of `--precession-rad-s`, `--spin-rad-s`,
//! `--axes-angle-deg` or `--rig-file` given): the chooser over the whole hierarchy
//! (model-core `choose::whole`, docs/model.md §12) picks the least model that meets the
//! tolerance and says why each cheaper one does not; the chosen one answers.

use anyhow::Result;
use model_core::choose::incline_rotation::release_second_order_s;
use model_core::choose::whole::{
    Fails, InclineMode, LEVELS, Level, WholeChoice, choose_level, friction_needed_at_release,
    friction_needed_at_rim, incline_mode, incline_release_s, may_stick,
};
use model_core::ode::system::{SystemError, SystemLimits};
use model_core::particle::bowl::{self, BowlOutcome, BowlShape};
use model_core::particle::rolling::{
    self, AZIMUTHS_DEG, MAX_STEPS, RollingMethod, RollingOutcome, RollingScene,
};
use serde_json::{Value, json};

use super::validity::Validity;
use super::{Inputs, bowl as bowl_cli};

/// The tolerance when none is given: the bowl model's own accuracy against the independent
/// reference (issue 30: T per release within 1 %).
pub const DEFAULT_TOLERANCE: f64 = 0.01;

/// The integrated levels' DP5(4) tolerance: a tenth of the tolerance (the model takes the
/// rest), and at most 1e-6: looser, the rolling-or-sliding switch near the stick threshold can
/// chatter for the whole step cap (measured in docs/model.md §12: a 30 deg scene at 3.6 rad/s
/// takes over 30 s per call at 1e-3 to 1e-5, 0.05 s at 1e-6).
pub fn integrator_rtol(tolerance: f64) -> f64 {
    (0.1 * tolerance).clamp(1e-12, 1e-6)
}

/// Whether `--model auto` means the tilted bowl (its flags or a rig file are given).
pub fn wanted(args: &Inputs) -> bool {
    let r = &args.rolling;
    r.precession_rad_s.is_some()
        || r.spin_rad_s.is_some()
        || r.axes_angle_deg.is_some()
        || args.bowl.rig_file.is_some()
}

/// Why a level does not hold, in words.
pub fn fails_words(f: &Fails<f64>, tolerance: f64) -> String {
    match *f {
        Fails::Wall {
            lip_m,
            rim_m,
            height_m,
        } if lip_m > rim_m => format!(
            "the wall matters: the lip at {lip_m:.4} m is beyond R = {rim_m:.4} m (a wall \
             {height_m} m high)"
        ),
        Fails::Wall { height_m, .. } => format!(
            "the wall matters: a vertical wall {height_m} m high holds the granule unless it \
             climbs it"
        ),
        Fails::Slides { needed, mu_s } => format!(
            "slides at this tilt: rolling needs {needed:.3} of the normal force at release, the \
             contact gives mu_s = {mu_s}"
        ),
        Fails::Rotation { estimate } => format!(
            "the bowl's rotation changes T by up to {:.2} %, more than the tolerance {}",
            100.0 * estimate,
            super::choice::percent(tolerance)
        ),
        Fails::EachRelease => {
            "single releases are wanted, and the incline does not follow a release's turning path"
                .into()
        }
        Fails::NoDrive => "the tilt does not move the granule down the incline".into(),
    }
}

/// Why the incline holds, in words: the a-priori estimate, or where that is above the
/// tolerance, the rotation's second order along the incline's path and its bound (with the
/// incline's mean corrected by it where only the corrected one is within).
fn incline_words(choice: &WholeChoice<f64>) -> String {
    match choice.second_order {
        Some(b) if b.corrected => format!(
            "the cheapest model, corrected for the bowl's rotation to second order: along the \
             incline's path the rotation changes T by {:+.3} %, which the answer includes, and \
             what is left is at most {:.3} % (the plain incline's bound, {:.3} %, and the \
             a-priori estimate, {:.3} %, were above the tolerance)",
            100.0 * b.c2,
            100.0 * b.corrected_bound,
            100.0 * b.bound,
            100.0 * choice.rotation_estimate
        ),
        Some(b) => format!(
            "the cheapest model, and within the tolerance by the rotation's second order: along \
             the incline's path the bowl's rotation changes T by {:+.3} %, so the \
             incline is off by at most {:.3} % (the a-priori estimate, {:.3} %, was above the \
             tolerance)",
            100.0 * b.c2,
            100.0 * b.bound,
            100.0 * choice.rotation_estimate
        ),
        None => format!(
            "the cheapest model, and within the tolerance: the rotation changes T by up to {:.3} %",
            100.0 * choice.rotation_estimate
        ),
    }
}

/// What the chosen level gave.
pub(crate) struct Answer {
    pub(crate) level: Level,
    /// Per release: azimuth, T (None: did not leave).
    pub(crate) times: Vec<(f64, Option<f64>)>,
    validity: Validity,
    /// Why the first level run was given up for this one, if it was.
    pub(crate) escalated: Option<String>,
}

/// Runs `level` on the releases; `None` when it holds no answer (the rolling model found the
/// granule slides).
pub(crate) fn run_level(
    level: Level,
    scene: &RollingScene<f64>,
    shape: &BowlShape<f64>,
    betas: &[f64],
    method: RollingMethod<f64>,
    limits: SystemLimits<f64>,
) -> Result<std::result::Result<Answer, String>> {
    let mut times = Vec::new();
    let mut why = Vec::new();
    let mut failed = Vec::new();
    match level {
        Level::Incline => {
            for &deg in betas {
                times.push((deg, incline_release_s(scene, deg.to_radians())));
            }
        }
        Level::Rolling => {
            for &deg in betas {
                let rep = match rolling::residence_within(scene, deg.to_radians(), method, limits) {
                    Ok(rep) => rep,
                    // The next level answers (the rolling model is the one that gave up).
                    Err(e) => {
                        return Ok(Err(format!(
                            "the rolling model gave no answer at {deg} deg: {}",
                            super::rolling::words(e)
                        )));
                    }
                };
                match rep.outcome {
                    // The first release that needs more than mu_s hands over: the rest of
                    // the rolling runs would be thrown away with it.
                    RollingOutcome::Leaves {
                        max_friction_ratio, ..
                    } if max_friction_ratio > scene.sliding_friction => {
                        return Ok(Err(format!(
                            "it rolled at release but slides later: rolling needed \
                             {max_friction_ratio:.3} of the normal force at {deg} deg, the \
                             contact gives mu_s = {}",
                            scene.sliding_friction
                        )));
                    }
                    RollingOutcome::Leaves {
                        residence_time_s, ..
                    } => times.push((deg, Some(residence_time_s))),
                    // A lift-off hands over too: the rolling model ends there, and was taken
                    // as the answer (not valid, "none of the 12 releases leaves") where the
                    // next level follows the flight and every release leaves.
                    RollingOutcome::LiftsOff { time_s } => {
                        return Ok(Err(format!(
                            "it lifts off at {deg} deg (the normal force reaches zero at t = {} \
                             s), and the rolling model does not follow a flight",
                            crate::number::fixed(time_s, 4)
                        )));
                    }
                    _ => times.push((deg, None)),
                }
            }
        }
        Level::RollingOrSliding | Level::Bowl => {
            let shape = if level == Level::Bowl {
                *shape
            } else {
                BowlShape {
                    wall_height_m: 0.0,
                    ..*shape
                }
            };
            // Near the stick threshold the slide/roll switch can stall the integrator at a
            // loose tolerance (and, erratically, at some tight ones): each release runs with a
            // stall watch (`bowl::residence_or_stall`: sixteen steps in a row that do not
            // advance the time) and at most 5 000 steps; one that stalls is run again at a
            // tenth of the tolerance, and the scene's later releases start there (they share
            // its threshold); one that takes all the steps is run at rtol 1e-10 without either
            // limit (which gets through), and once two have, so are the later ones (a scene
            // whose releases all take that long, e.g. held in a wall's corner, pays the loose
            // run twice, not twelve times). Where the granule rolls at release and must slide
            // before the rim (the switch is on every path) they all start at 1e-10
            // (docs/model.md §12).
            let quick = SystemLimits {
                max_steps: limits.max_steps.min(5_000),
                ..limits
            };
            // The chooser runs DP5(4) (`integrator_rtol`); a fixed-step method is not a rung.
            let start = match method {
                RollingMethod::Dp54 { rtol } => rtol,
                RollingMethod::Rk4 { .. } => 1e-10,
            };
            // The last rung: 1e-10, or the asked tolerance where that is tighter.
            let tight = start.min(1e-10);
            let mu_s = scene.sliding_friction;
            // A sliding granule the rotation may bring to stick starts at 1e-6 as well: its
            // slides no longer creep at 1e-6 (`slide::friction_direction`; docs/model.md §12,
            // "A slip below the tolerance").
            let mut rung = if friction_needed_at_release(scene) <= mu_s
                && friction_needed_at_rim(scene) > mu_s
            {
                tight
            } else {
                start
            };
            let mut capped = 0;
            for &deg in betas {
                let b = deg.to_radians();
                // This release's rung: a stall lowers the scene's; 5 000 steps only its own,
                // the scene's from the second release that takes them.
                let mut own = rung;
                let rep = loop {
                    if own <= tight {
                        break bowl::residence(
                            scene,
                            &shape,
                            b,
                            RollingMethod::Dp54 { rtol: tight },
                            limits,
                        );
                    }
                    match bowl::residence_or_stall(
                        scene,
                        &shape,
                        b,
                        RollingMethod::Dp54 { rtol: own },
                        quick,
                    ) {
                        // A stall is the loose tolerance's own: a tenth of it gets past.
                        Err(bowl::BowlError::Scene(rolling::RollingError::Integration(
                            SystemError::Stalled,
                        ))) => {
                            own = if 0.1 * own <= 1.5 * tight {
                                tight
                            } else {
                                0.1 * own
                            };
                            rung = own;
                        }
                        // 5 000 steps without a stall: the cost is erratic in the tolerance
                        // there (a tenth can take ten times the steps); 1e-10 gets through.
                        Err(bowl::BowlError::Scene(rolling::RollingError::Integration(_))) => {
                            own = tight;
                            capped += 1;
                            if capped >= 2 {
                                rung = tight;
                            }
                        }
                        other => break other,
                    }
                };
                match rep {
                    Ok(rep) => match rep.outcome {
                        BowlOutcome::Leaves {
                            residence_time_s, ..
                        } => times.push((deg, Some(residence_time_s))),
                        BowlOutcome::LiftsOff { .. } => {
                            why.push(
                                "the normal force reaches zero in a release (it would fly): \
                                 flight is not modelled"
                                    .to_string(),
                            );
                            times.push((deg, None));
                        }
                        _ => times.push((deg, None)),
                    },
                    Err(e) => {
                        failed.push((deg, e));
                        times.push((deg, None));
                    }
                }
            }
        }
    }
    if !failed.is_empty() {
        // One sentence for all of them (it was one per release, eight times over).
        why.push(super::gave_up::sentence(
            &failed,
            times.len(),
            &super::gave_up::Settings::Chooser {
                max_time_s: limits.horizon_s,
            },
        ));
    }
    why.dedup();
    Ok(Ok(Answer {
        level,
        times,
        validity: if why.is_empty() {
            Validity::valid()
        } else {
            Validity(Some(why.join("; ")))
        },
        escalated: None,
    }))
}

/// Runs the chosen `level`, and where it holds no answer (the rolling model found the granule
/// slides later) the rolling-or-sliding disc after it, with the reason in `escalated`: what
/// `bowl predict` runs, and what the chooser's cost is measured on. `Err(why)` where the disc
/// too gives none.
pub(crate) fn run_chosen(
    level: Level,
    scene: &RollingScene<f64>,
    shape: &BowlShape<f64>,
    betas: &[f64],
    method: RollingMethod<f64>,
    limits: SystemLimits<f64>,
) -> Result<std::result::Result<Answer, String>> {
    match run_level(level, scene, shape, betas, method, limits)? {
        Ok(a) => Ok(Ok(a)),
        Err(why) => Ok(
            run_level(Level::RollingOrSliding, scene, shape, betas, method, limits)?.map(
                |mut a| {
                    a.escalated = Some(why);
                    a
                },
            ),
        ),
    }
}

/// Runs the chooser and the model it picks.
pub fn run(args: &Inputs) -> Result<()> {
    let setup = bowl_cli::scene_and_shape(args, &args.rolling, &args.bowl)?;
    let (scene, th_deg, shape) = (setup.scene, setup.th_deg, setup.shape);
    let tolerance = args.tolerance.unwrap_or(DEFAULT_TOLERANCE);
    if !(tolerance.is_finite() && tolerance > 0.0) {
        anyhow::bail!("--tolerance must be a positive number (0.01 = 1 %), not {tolerance}");
    }
    let betas = super::rolling::azimuths(args.rolling.release_azimuth_deg())?;
    // The incline's bounds hold for the mean over the twelve azimuths only: releases picked by
    // hand are single releases (the rotation turns each path; at 60 deg, 2 rad/s the incline
    // corrected for the mean gave a release at 30 deg its own second-order time, unbounded).
    let each = args.rolling.each_release || betas.as_slice() != AZIMUTHS_DEG.as_slice();
    let choice = choose_level(&scene, &shape, tolerance, each);
    let method = RollingMethod::Dp54 {
        rtol: integrator_rtol(tolerance),
    };
    let limits = SystemLimits {
        horizon_s: args.bowl.max_time_s,
        max_steps: MAX_STEPS,
    };
    let mut answer = run_chosen(choice.level, &scene, &shape, &betas, method, limits)?
        .map_err(anyhow::Error::msg)?;
    if answer.level == Level::Incline {
        answer.validity = Validity::valid();
        if choice.second_order.is_some_and(|b| b.corrected) {
            // The corrected incline: each release to second order in the rotation, `T0 + T1 +
            // T2` (`T1` is odd in the azimuth and cancels in the mean, which is the chooser's
            // `T (1 + c2)`).
            for (deg, t) in &mut answer.times {
                *t = release_second_order_s(&scene, deg.to_radians())
                    .map(|(t0, t1, t2)| t0 + t1 + t2);
            }
        }
    }
    report(args, &scene, th_deg, tolerance, &choice, &answer)
}

fn report(
    args: &Inputs,
    scene: &RollingScene<f64>,
    th_deg: f64,
    tolerance: f64,
    choice: &WholeChoice<f64>,
    a: &Answer,
) -> Result<()> {
    let left: Vec<f64> = a.times.iter().filter_map(|t| t.1).collect();
    let mean = (!left.is_empty()).then(|| left.iter().sum::<f64>() / left.len() as f64);
    let min = left.iter().copied().reduce(f64::min);
    let max = left.iter().copied().reduce(f64::max);
    let rejected: Vec<(Level, String)> = LEVELS
        .iter()
        .zip(choice.cheaper_fail)
        .filter_map(|(l, f)| {
            f.map(|f| {
                let mut w = fails_words(&f, tolerance);
                if let (Fails::Rotation { .. }, None) = (f, choice.second_order)
                    && incline_mode(scene) == InclineMode::Slides
                    && may_stick(scene)
                {
                    w.push_str(
                        "; the rotation may bring the sliding granule to stick on its way out \
                         (at the rim its centrifugal push works against gravity), where the \
                         incline's second order does not hold",
                    );
                }
                if let (Fails::Rotation { .. }, Some(b)) = (f, choice.second_order) {
                    w.push_str(&format!(
                        "; its second order along the incline's path bounds it at {:.2} % \
                         (corrected by it, at {:.2} %), also above",
                        100.0 * b.bound,
                        100.0 * b.corrected_bound
                    ));
                }
                (*l, w)
            })
        })
        .chain(a.escalated.as_ref().map(|w| (Level::Rolling, w.clone())))
        .collect();
    let why = if rejected.is_empty() {
        incline_words(choice)
    } else {
        let (l, w) = &rejected[rejected.len() - 1];
        format!("not the {} model: {w}", l.name())
    };
    if args.json {
        let mut v = json!({
            "model": "auto",
            "chosen": a.level.name(),
            "tolerance": tolerance,
            "why": why,
            "not_cheaper": rejected.iter().map(|(l, w)| json!({"model": l.name(), "why": w})).collect::<Vec<Value>>(),
            "rotation_estimate_rel": choice.rotation_estimate.is_finite().then_some(choice.rotation_estimate),
            "rotation_second_order_rel": choice.second_order.map(|b| b.c2),
            "rotation_second_order_bound_rel": choice.second_order.map(|b| b.bound),
            "rotation_second_order_corrected_bound_rel": choice.second_order.map(|b| b.corrected_bound),
            "rotation_second_order_corrected": choice.second_order.is_some_and(|b| b.corrected),
            "friction_needed_at_release": choice.friction_needed,
            "residence_time_mean_s": mean, "residence_time_min_s": min,
            "residence_time_max_s": max, "releases": a.times.len(),
            "releases_leaving": left.len(),
            // The chooser's levels give T alone: `regime` is null (the shape is the bowl model's).
            "per_release": a.times.iter().map(|&(d, t)| super::release_json::entry(d, t, Value::Null, super::release_json::none())).collect::<Vec<Value>>(),
            "axes_angle_deg": th_deg,
        });
        super::release_json::add_single_release(&mut v);
        a.validity.add_to(&mut v);
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    if let Some(line) = a.validity.text_line(a.level.name()) {
        println!("{line}");
    }
    println!(
        "chooser (tolerance {}): the {} model, the least of incline < rolling < \
         rolling-or-sliding < bowl that meets it at this scene (tilt {th_deg} deg, |Omega| {:.3} rad/s)",
        super::choice::percent(tolerance),
        a.level.name(),
        scene.combined_speed_rad_s()
    );
    for (l, w) in &rejected {
        println!("  not the {}: {w}", l.name());
    }
    if a.level == Level::Incline {
        println!(
            "  the incline holds: {} (docs/model.md §12)",
            incline_words(choice)
        );
    }
    match (mean, min, max) {
        (Some(m), Some(lo), Some(hi)) => println!(
            "over {}: {} leave, T mean {} s, min {} s, max {} s",
            crate::number::count(a.times.len(), "release", "releases"),
            left.len(),
            crate::number::fixed(m, 6),
            crate::number::fixed(lo, 6),
            crate::number::fixed(hi, 6)
        ),
        _ => println!(
            "{}",
            match a.times.len() {
                1 => "the release does not leave".to_string(),
                n => format!("none of the {n} releases leaves"),
            }
        ),
    }
    Ok(())
}

#[cfg(test)]
mod pinned;
#[cfg(test)]
mod rotation_fit;
#[cfg(test)]
mod rotation_orders;
#[cfg(test)]
mod tests;

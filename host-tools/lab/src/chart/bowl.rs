//! Charts of the granule in the real bowl (docs/model.md §10): residence time against bowl
//! speed for each bowl shape (bare rim, walls flared at 60 deg, a vertical wall) beside the
//! rolling model of the flat bottom, the trend of the paper's Figure 7.

use anyhow::{Result, anyhow};
use model_core::ode::system::SystemLimits;
use model_core::particle::bowl::{self, BowlOutcome, BowlShape};
use model_core::particle::rolling::{self, AZIMUTHS_DEG, MAX_STEPS, RollingMethod, RollingScene};

/// The scene both bowl charts draw, said under their legends.
const SCENE_NOTE: &str = "75 mm bottom, ri = R/2, mu_r 0.029, mu_s 0.4";

use super::plot::{Figure, Mark, Series};
use super::table::Table;

const METHOD: RollingMethod<f64> = RollingMethod::Dp54 { rtol: 1e-9 };
/// The bowl's bottom radius, m (the rigid-body simulation's 75 mm bowl).
const RIM_M: f64 = 0.075;
/// How long a release is followed, s.
const HORIZON_S: f64 = 3.0;

/// The shapes drawn: name, wall angle (deg), wall height (m).
const SHAPES: [(&str, f64, f64); 5] = [
    ("bare rim", 90.0, 0.0),
    ("wall 60 deg 10 mm", 60.0, 0.01),
    ("wall 60 deg 20 mm", 60.0, 0.02),
    ("wall 60 deg 40 mm", 60.0, 0.04),
    ("vertical wall 20 mm", 90.0, 0.02),
];

/// The mean residence time over the twelve releases and how many leave.
fn mean(scene: &RollingScene<f64>, shape: &BowlShape<f64>) -> Result<(Option<f64>, usize)> {
    let limits = SystemLimits {
        horizon_s: HORIZON_S,
        max_steps: MAX_STEPS,
    };
    let mut times = Vec::new();
    for deg in AZIMUTHS_DEG {
        // A release the integrator gives up on counts as not leaving here.
        if let Ok(r) = bowl::residence(scene, shape, deg.to_radians(), METHOD, limits)
            && let BowlOutcome::Leaves {
                residence_time_s, ..
            } = r.outcome
        {
            times.push(residence_time_s);
        }
    }
    let n = times.len();
    Ok((
        (n == AZIMUTHS_DEG.len()).then(|| times.iter().sum::<f64>() / n as f64),
        n,
    ))
}

/// T against the combined speed (w1 = w2) at tilt `tilt_deg`, each bowl shape and the rolling
/// model; mu_r 0.029, mu_s 0.4, granule 3 mm, release at R/2.
pub fn residence(tilt_deg: f64) -> Result<(Figure, Table)> {
    let mut table = Table::new(&["shape", "omega_rad_s", "mean_s", "releases_leaving"]);
    let mut series = Vec::new();
    let speeds: Vec<f64> = (0..=7).map(|i| 0.5 + 3.1 * f64::from(i) / 7.0).collect();
    let mut roll = Vec::new();
    for &w in &speeds {
        let s = RollingScene::equal_speeds(w, tilt_deg.to_radians(), RIM_M);
        let sum = rolling::residence_over_azimuths(&s, METHOD)
            .map_err(|e| anyhow!("{}", crate::predict::rolling_words(e)))?;
        roll.push((w, sum.mean_s.unwrap_or(f64::NAN)));
        table.row(vec![
            "rolling model (flat, no slip)".into(),
            format!("{w}"),
            sum.mean_s.map_or("never".into(), |t| format!("{t}")),
            format!("{}", sum.left),
        ]);
    }
    series.push(Series {
        name: "rolling model, bare rim (no slip)".into(),
        points: roll,
        mark: Mark::Dashed,
        color: 0,
    });
    for (i, (name, alpha, h)) in SHAPES.iter().enumerate() {
        let shape = BowlShape {
            wall_angle_rad: alpha.to_radians(),
            wall_height_m: *h,
            fillet_radius_m: 0.0,
            restitution: 0.5,
        };
        let mut points = Vec::new();
        for &w in &speeds {
            let s = RollingScene::equal_speeds(w, tilt_deg.to_radians(), RIM_M);
            let (m, n) = mean(&s, &shape)?;
            points.push((w, m.unwrap_or(f64::NAN)));
            table.row(vec![
                (*name).into(),
                format!("{w}"),
                m.map_or("not all leave".into(), |t| format!("{t}")),
                format!("{n}"),
            ]);
        }
        series.push(Series {
            name: format!("bowl model, {name}"),
            points,
            mark: Mark::LinePoints,
            color: i + 1,
        });
    }
    let fig = Figure::linear(
        format!(
            "Residence time against bowl speed in the real bowl, axis tilted {tilt_deg} deg (cf. paper Fig. 7)"
        ),
        "combined bowl speed |w1 e_z + w2 n|, rad/s (w1 = w2)",
        "mean residence time over 12 releases, s",
        series,
        &[
            SCENE_NOTE,
            "granule 3 mm; sharp corners, e 0.5",
            "gap: not all 12 releases leave in 3 s",
            "(the vertical wall holds every one)",
        ],
    );
    Ok((fig, table))
}

/// The regime map against the tilt at one speed: for each bowl shape, the share of the time
/// the granules slide and fly (the rest they roll, or sit held) and the share of releases that
/// leave within the horizon (the rest are held by the wall).
pub fn regimes(omega_rad_s: f64) -> Result<(Figure, Table)> {
    let mut table = Table::new(&[
        "shape",
        "tilt_deg",
        "slide_share",
        "fly_share",
        "held_share",
        "leaving_share",
    ]);
    let tilts: Vec<f64> = (1..=16).map(|i| 5.0 * f64::from(i)).collect();
    let limits = SystemLimits {
        horizon_s: HORIZON_S,
        max_steps: MAX_STEPS,
    };
    let mut series = Vec::new();
    for (i, (name, alpha, h)) in [SHAPES[0], SHAPES[2], SHAPES[4]].iter().enumerate() {
        let shape = BowlShape {
            wall_angle_rad: alpha.to_radians(),
            wall_height_m: *h,
            fillet_radius_m: 0.0,
            restitution: 0.5,
        };
        let (mut slide, mut fly, mut leave) = (Vec::new(), Vec::new(), Vec::new());
        for &tilt in &tilts {
            let s = RollingScene::equal_speeds(omega_rad_s, tilt.to_radians(), RIM_M);
            let (mut sl, mut fl, mut held, mut total, mut left) = (0.0, 0.0, 0.0, 0.0, 0usize);
            for deg in AZIMUTHS_DEG {
                let Ok(r) = bowl::residence(&s, &shape, deg.to_radians(), METHOD, limits) else {
                    continue;
                };
                sl += r.regime.slide_s;
                fl += r.flight_s;
                held += r.held_s;
                total += r.regime.slide_s + r.regime.roll_s + r.flight_s + r.held_s;
                left += usize::from(matches!(r.outcome, BowlOutcome::Leaves { .. }));
            }
            let share = |x: f64| if total > 0.0 { x / total } else { f64::NAN };
            let leaving = left as f64 / AZIMUTHS_DEG.len() as f64;
            slide.push((tilt, share(sl)));
            fly.push((tilt, share(fl)));
            leave.push((tilt, leaving));
            table.row(vec![
                (*name).into(),
                format!("{tilt}"),
                format!("{}", share(sl)),
                format!("{}", share(fl)),
                format!("{}", share(held)),
                format!("{leaving}"),
            ]);
        }
        series.push(Series {
            name: format!("{name}: share of time sliding"),
            points: slide,
            mark: Mark::LinePoints,
            color: i + 1,
        });
        series.push(Series {
            name: format!("{name}: share of time flying"),
            points: fly,
            mark: Mark::Points,
            color: i + 1,
        });
        series.push(Series {
            name: format!("{name}: share of releases leaving"),
            points: leave,
            mark: Mark::DashedPoints,
            color: i + 1,
        });
    }
    let fig = Figure::linear(
        format!("Regimes against the tilt at {omega_rad_s} rad/s (w1 = w2)"),
        "angle between the vertical and the bowl's axis (paper Eq. 2), deg",
        "share",
        series,
        &[
            SCENE_NOTE,
            "not sliding or flying: rolling, or held",
            "in a corner; not leaving in 3 s: held",
        ],
    );
    Ok((fig, table))
}

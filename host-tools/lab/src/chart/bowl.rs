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
use super::rolling::{method_runs, method_series, work_precision_figure};
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
                held += r.held_s + r.regime.held_s;
                total +=
                    r.regime.slide_s + r.regime.roll_s + r.flight_s + r.held_s + r.regime.held_s;
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

/// The dominant regime over the tilt and the speed (w1 = w2): for each release the mode it
/// spent most time in (roll, slide or fly), or held by the wall if it has not left within the
/// horizon; each cell is marked with what most of its twelve releases did. A 60 deg wall 20 mm
/// high with a sharp corner (e 0.5), on a rod offset of `rod_m` (lift-off needs one).
pub fn regime_map(rod_m: f64) -> Result<(Figure, Table)> {
    let mut table = Table::new(&[
        "tilt_deg",
        "speed_rad_s",
        "roll",
        "slide",
        "fly",
        "held",
        "dominant",
    ]);
    let limits = SystemLimits {
        horizon_s: HORIZON_S,
        max_steps: MAX_STEPS,
    };
    let shape = BowlShape {
        wall_angle_rad: 60f64.to_radians(),
        wall_height_m: 0.02,
        fillet_radius_m: 0.0,
        restitution: 0.5,
    };
    let names = ["roll", "slide", "fly", "held by the wall"];
    let mut points: [Vec<(f64, f64)>; 4] = Default::default();
    for ti in 1..=16 {
        let tilt = 5.0 * f64::from(ti);
        for wi in 1..=10 {
            let w = 0.5 * f64::from(wi);
            let sc = RollingScene {
                precession_rad_s: w,
                spin_rad_s: w,
                axes_angle_rad: tilt.to_radians(),
                rod_length_m: rod_m,
                rolling_resistance: 0.029,
                sliding_friction: 0.4,
                ..RollingScene::equal_speeds(1.0, 1.0, RIM_M)
            };
            let mut count = [0usize; 4];
            for deg in AZIMUTHS_DEG {
                let Ok(r) = bowl::residence(&sc, &shape, deg.to_radians(), METHOD, limits) else {
                    continue;
                };
                let which = if !matches!(r.outcome, BowlOutcome::Leaves { .. }) {
                    3
                } else {
                    let t = [r.regime.roll_s, r.regime.slide_s, r.flight_s];
                    (0..3).fold(0, |b, i| if t[i] > t[b] { i } else { b })
                };
                count[which] += 1;
            }
            let dominant = (0..4).fold(0, |b, i| if count[i] > count[b] { i } else { b });
            points[dominant].push((tilt, w));
            table.row(vec![
                format!("{tilt}"),
                format!("{w}"),
                format!("{}", count[0]),
                format!("{}", count[1]),
                format!("{}", count[2]),
                format!("{}", count[3]),
                names[dominant].into(),
            ]);
        }
    }
    let series = points
        .into_iter()
        .enumerate()
        .map(|(i, p)| Series {
            name: format!("most releases: {}", names[i]),
            points: p,
            mark: Mark::Points,
            color: i + 1,
        })
        .collect();
    let rod_note = format!("rod offset {rod_m} m; wall 60 deg 20 mm, sharp corner, e 0.5");
    let fig = Figure::linear(
        "Regime map: what most of the 12 releases do, over tilt and speed".to_string(),
        "angle between the vertical and the bowl's axis (paper Eq. 2), deg",
        "w1 = w2, rad/s",
        series,
        &[
            SCENE_NOTE,
            &rod_note,
            "a release's regime: the mode it spends",
            "most time in; held: not out in 3 s",
        ],
    );
    Ok((fig, table))
}

/// Mean residence time over the twelve releases by `method` and the right-hand-side
/// evaluations it took (a flight's arc is in closed form: its scan is not counted).
fn bowl_mean_by(
    s: &RollingScene<f64>,
    shape: &BowlShape<f64>,
    method: RollingMethod<f64>,
) -> Result<(f64, u64)> {
    let limits = SystemLimits {
        horizon_s: HORIZON_S,
        max_steps: MAX_STEPS,
    };
    let (mut sum, mut n) = (0.0, 0u64);
    for deg in AZIMUTHS_DEG {
        let r = bowl::residence(s, shape, deg.to_radians(), method, limits)
            .map_err(|e| anyhow!("release at {deg} deg: {}", crate::predict::bowl::words(e)))?;
        let BowlOutcome::Leaves {
            residence_time_s, ..
        } = r.outcome
        else {
            return Err(anyhow!("the release at {deg} deg does not leave"));
        };
        sum += residence_time_s;
        n += u64::from(r.evaluations);
    }
    Ok((sum / AZIMUTHS_DEG.len() as f64, n))
}

/// Work-precision of DP5(4) and RK4 on the bowl model: the error in the mean residence time
/// against right-hand-side evaluations, on the rig's scene with a 60 deg wall 20 mm high (its
/// sharp corner's rebound flies) and on issue 30's lift-off scene (rod offset 0.3 m, 4.4 rad/s,
/// a 5 mm fillet): every mode change an event located on the interpolant.
pub fn work_precision() -> Result<(Figure, Table)> {
    let wall = |fillet: f64| BowlShape {
        wall_angle_rad: 60f64.to_radians(),
        wall_height_m: 0.02,
        fillet_radius_m: fillet,
        restitution: 0.5,
    };
    let rig = RollingScene {
        rolling_resistance: 0.029,
        sliding_friction: 0.4,
        ..RollingScene::equal_speeds(1.8, 60f64.to_radians(), RIM_M)
    };
    let lift = RollingScene {
        precession_rad_s: 4.4,
        spin_rad_s: 2.0,
        rod_length_m: 0.3,
        ..rig
    };
    let scenes = [
        ("60 deg, 1.8 rad/s, wall 60 deg 20 mm", rig, wall(0.0)),
        ("lift-off: rod 0.3 m, w1 4.4, w2 2 rad/s", lift, wall(0.005)),
    ];
    let mut table = Table::new(&["scene", "method", "setting", "rhs_evaluations", "rel_error"]);
    let mut series = Vec::new();
    for (si, (name, s, shape)) in scenes.iter().enumerate() {
        let (reference, _) = bowl_mean_by(s, shape, RollingMethod::Dp54 { rtol: 1e-14 })?;
        let runs = method_runs(3..=11, 2e-3, 8);
        series.extend(method_series(
            name,
            si,
            reference,
            runs,
            |m| bowl_mean_by(s, shape, m).map(|(t, n)| (t, n as f64)),
            &mut table,
        ));
    }
    let fig = work_precision_figure(
        "Work-precision on the bowl model (mean over 12 releases)",
        series,
        vec![
            SCENE_NOTE.into(),
            "reference: DP5(4) at rtol 1e-14".into(),
            "DP5(4) rtol 1e-3..1e-11; RK4 h 2 ms / 2^k".into(),
            "flights in closed form (not counted)".into(),
        ],
    );
    Ok((fig, table))
}

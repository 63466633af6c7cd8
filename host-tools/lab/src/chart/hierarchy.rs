//! The whole hierarchy on one work-precision chart (docs/model.md §12): every member that
//! answers at a scene, error in the mean residence time against host time per call, beside
//! where the chooser lands at 5 %, 1 % and 0.1 %. The closed forms (the incline, and the
//! incline corrected by the rotation's second order) are single points; the integrated levels
//! (rolling, rolling-or-sliding, the bowl) a line each over DP5(4)'s tolerance. Host time is
//! the median over batches of calls (`timing::ns_per_call`, as the other work-precision
//! charts): it moves with the machine's load, the order of the members does not.

use anyhow::Result;
use model_core::choose::incline_rotation::mean_second_order;
use model_core::choose::whole::{Level, choose_level, incline_mean_s};
use model_core::ode::system::SystemLimits;
use model_core::particle::bowl::BowlShape;
use model_core::particle::rolling::{AZIMUTHS_DEG, MAX_STEPS, RollingMethod, RollingScene};

use super::plot::{Figure, Mark, Scale, Series};
use super::table::Table;
use super::timing::{Budget, ns_per_call};
use crate::predict::whole::{integrator_rtol, run_chosen, run_level};

/// How long a release is followed, s.
const LIMITS: SystemLimits<f64> = SystemLimits {
    horizon_s: 10.0,
    max_steps: MAX_STEPS,
};

/// The integrated levels and their colours (the closed forms take 6 and 7, the chooser 8).
const INTEGRATED: [(Level, usize); 3] = [
    (Level::Rolling, 0),
    (Level::RollingOrSliding, 2),
    (Level::Bowl, 4),
];

/// Time per call of `f`, s (`timing::ns_per_call`'s median over batches, as the other
/// work-precision charts).
fn per_call<R>(f: impl FnMut() -> R) -> f64 {
    ns_per_call(Budget::FULL, f).median_ns * 1e-9
}

/// The mean over the twelve releases of `level` at DP5(4) `rtol` and its time per call, and
/// whether the rolling model gave up for the disc (`run_chosen`, as `bowl predict` runs a
/// choice; `escalate` false: the level alone); `None` where it gives no answer (a release does
/// not leave, or the level alone gives none).
fn level_mean(
    level: Level,
    s: &RollingScene<f64>,
    rtol: f64,
    escalate: bool,
) -> Result<Option<(f64, f64, bool)>> {
    let betas = AZIMUTHS_DEG.to_vec();
    let method = RollingMethod::Dp54 { rtol };
    let bare = BowlShape::bare_rim();
    let run = || {
        if escalate {
            run_chosen(level, s, &bare, &betas, method, LIMITS)
        } else {
            run_level(level, s, &bare, &betas, method, LIMITS)
        }
    };
    let Ok(answer) = run()? else {
        return Ok(None);
    };
    let left: Vec<f64> = answer.times.iter().filter_map(|t| t.1).collect();
    if left.len() < betas.len() {
        return Ok(None);
    }
    let time = per_call(run);
    let mean = left.iter().sum::<f64>() / left.len() as f64;
    Ok(Some((mean, time, answer.escalated.is_some())))
}

/// The chart on two bare-rim scenes: the rig's tilt where the granule slides all the way
/// (60 deg, 2 rad/s, mu_s 0.4) and one where it rolls all the way (30 deg, 1.8 rad/s,
/// mu_s 0.4); both motors at the speed named. Reference: the
/// bowl model at rtol 1e-12.
pub fn work_precision() -> Result<(Figure, Table)> {
    let scene = |tilt_deg: f64, w: f64, mu_s: f64| RollingScene {
        rolling_resistance: 0.029,
        sliding_friction: mu_s,
        ..RollingScene::with_speeds(w, w, tilt_deg.to_radians(), 0.075)
    };
    let scenes = [
        ("60 deg, 2 rad/s, mu_s 0.4 (slides)", scene(60.0, 2.0, 0.4)),
        ("30 deg, 1.8 rad/s, mu_s 0.4 (rolls)", scene(30.0, 1.8, 0.4)),
    ];
    let mut table = Table::new(&["scene", "member", "setting", "host_s", "rel_error"]);
    let mut series = Vec::new();
    let row = |table: &mut Table, scene: &str, member: &str, setting: String, t: f64, e: f64| {
        table.row(vec![
            scene.into(),
            member.into(),
            setting,
            format!("{t:e}"),
            format!("{e:e}"),
        ]);
    };
    for (si, (name, s)) in scenes.iter().enumerate() {
        let Some((reference, ..)) = level_mean(Level::Bowl, s, 1e-12, false)? else {
            anyhow::bail!("the bowl model gives no reference at {name}");
        };
        let err = |t: f64| ((t - reference) / reference).abs().max(1e-17);
        let mark = if si == 0 {
            Mark::LinePoints
        } else {
            Mark::DashedPoints
        };
        let short = if si == 0 { "60 deg" } else { "30 deg" };
        for (level, color) in INTEGRATED {
            let mut points = Vec::new();
            for k in 3..=10 {
                let rtol = 10f64.powi(-k);
                if let Some((t, cost, _)) = level_mean(level, s, rtol, false)? {
                    points.push((cost, err(t)));
                    row(
                        &mut table,
                        name,
                        level.name(),
                        format!("{rtol:e}"),
                        cost,
                        err(t),
                    );
                }
            }
            if !points.is_empty() {
                series.push(Series {
                    name: format!("{}, {short}", level.name()),
                    points,
                    mark,
                    color,
                });
            }
        }
        // The closed forms.
        let incline = incline_mean_s(s).ok_or_else(|| anyhow::anyhow!("no incline at {name}"))?;
        let cost = per_call(|| {
            std::hint::black_box(incline_mean_s(std::hint::black_box(s)));
        });
        row(
            &mut table,
            name,
            "incline",
            "closed form".into(),
            cost,
            err(incline),
        );
        series.push(Series {
            name: format!("incline, {short}"),
            points: vec![(cost, err(incline))],
            mark: Mark::Points,
            color: 6,
        });
        if let Some((mean, rel)) = mean_second_order(s) {
            let cost = per_call(|| {
                std::hint::black_box(mean_second_order(std::hint::black_box(s)));
            });
            let t = mean * (1.0 + rel);
            row(
                &mut table,
                name,
                "incline corrected",
                "second order".into(),
                cost,
                err(t),
            );
            series.push(Series {
                name: format!("incline corrected, {short}"),
                points: vec![(cost, err(t))],
                mark: Mark::Points,
                color: 7,
            });
        }
        // Where the chooser lands: its whole cost (its checks, then the level it picks at a
        // tenth of the tolerance), each tolerance a cross.
        let mut picks = Vec::new();
        for tol in [0.05, 0.01, 0.001] {
            let c = choose_level(s, &BowlShape::bare_rim(), tol, false);
            let choice = per_call(|| {
                std::hint::black_box(choose_level(
                    std::hint::black_box(s),
                    &BowlShape::bare_rim(),
                    tol,
                    false,
                ));
            });
            let (t, cost, escalated) = if c.level == Level::Incline {
                (c.incline_mean_s.unwrap_or(f64::NAN), choice, false)
            } else {
                // As `bowl predict` runs it (`run_chosen`): where the rolling model finds the
                // granule slides later, the disc answers after it, both runs timed.
                let Some((t, cost, escalated)) =
                    level_mean(c.level, s, integrator_rtol(tol), true)?
                else {
                    continue;
                };
                (t, cost + choice, escalated)
            };
            let what = match c.second_order {
                Some(b) if c.level == Level::Incline && b.corrected => "incline corrected",
                _ if escalated => "rolling, then rolling-or-sliding",
                _ => c.level.name(),
            };
            row(
                &mut table,
                name,
                "chooser",
                format!("tol {tol}: {what}"),
                cost,
                err(t),
            );
            picks.push((cost, err(t)));
        }
        series.push(Series {
            name: format!("chooser (5, 1, 0.1 %), {short}"),
            points: picks,
            mark: Mark::Crosses,
            color: 8,
        });
    }
    let fig = Figure {
        title:
            "The hierarchy on the tilted bowl: error against cost (bare rim, mean over 12 releases)"
                .into(),
        x_label: "host time per call, s (12 releases)".into(),
        y_label: "relative error in the mean residence time".into(),
        x_scale: Scale::Log,
        y_scale: Scale::Log,
        series,
        hlines: Vec::new(),
        vlines: vec![],
        notes: vec![
            "75 mm bottom, ri = R/2, mu_r 0.029, w1 = w2".into(),
            "reference: the bowl model, DP5(4) rtol 1e-12".into(),
            "lines: DP5(4) rtol 1e-3..1e-10".into(),
            "points: closed forms; crosses: the chooser".into(),
            "solid: 60 deg, 2 rad/s, mu_s 0.4 (slides)".into(),
            "dashed: 30 deg, 1.8 rad/s, mu_s 0.4 (rolls)".into(),
        ],
    };
    Ok((fig, table))
}

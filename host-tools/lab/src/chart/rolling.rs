//! Charts of the rolling model of the tilted, precessing bowl (docs/model.md §9): the paper's
//! Figure 7 with the rolling model beside the paper's, the granules' paths on the bowl bottom,
//! the hierarchy map (each simpler member's difference from the full model), and the
//! integrators' work-precision and behaviour near the stick/slip threshold on this equation.

use std::ops::ControlFlow;

use anyhow::{Result, anyhow};
use model_core::ode::system::{self, Ended, SystemLimits};
use model_core::particle::rolling::equations::{State, forces};
use model_core::particle::rolling::hierarchy::{MEMBERS, Member, mean_residence_s};
use model_core::particle::rolling::{
    self, AZIMUTHS_DEG, RollingError, RollingMethod, RollingScene,
};

use super::plot::{Figure, Mark, Scale, Series};
use super::table::Table;

/// The bowl speeds of the paper's experiments, rad/s.
const SPEEDS: (f64, f64) = (0.5, 3.6);
/// Bowl sizes of the paper, mm, read as diameters (as in the paper's figures redrawn).
const BOWL_SIZES_MM: [f64; 4] = [150.0, 200.0, 250.0, 300.0];
/// The tight method every other is measured against.
const REFERENCE: RollingMethod<f64> = RollingMethod::Dp54 { rtol: 1e-13 };
/// The method the charts use where accuracy is not the subject.
const CHART_METHOD: RollingMethod<f64> = RollingMethod::Dp54 { rtol: 1e-9 };

fn speeds(n: usize) -> Vec<f64> {
    (0..=n)
        .map(|i| SPEEDS.0 + (SPEEDS.1 - SPEEDS.0) * i as f64 / n as f64)
        .collect()
}

fn rig(omega: f64, tilt_deg: f64, size_mm: f64) -> RollingScene<f64> {
    RollingScene::equal_speeds(omega, tilt_deg.to_radians(), size_mm / 2000.0)
}

fn err(e: RollingError) -> anyhow::Error {
    anyhow!(
        "the rolling model gave no answer: {}",
        crate::predict::rolling_words(e)
    )
}

fn cell(v: Option<f64>) -> String {
    v.map_or_else(|| "never".into(), |x| format!("{x}"))
}

/// Paper Figure 7 (residence time against bowl speed, four bowls) with the rolling model's mean
/// over the twelve release azimuths beside the paper's Coriolis model, at tilt `tilt_deg`.
pub fn residence(tilt_deg: f64) -> Result<(Figure, Table)> {
    let mut table = Table::new(&[
        "bowl_mm",
        "omega_rad_s",
        "rolling_mean_s",
        "rolling_min_s",
        "rolling_max_s",
        "paper_coriolis_s",
    ]);
    let mut series = Vec::new();
    for (i, size) in BOWL_SIZES_MM.iter().enumerate() {
        let (mut mean, mut paper) = (Vec::new(), Vec::new());
        for w in speeds(31) {
            let s = rig(w, tilt_deg, *size);
            let sum = rolling::residence_over_azimuths(&s, CHART_METHOD).map_err(err)?;
            let full = (sum.left == 12).then_some(sum.mean_s).flatten();
            let p = mean_residence_s(Member::PaperCoriolis, &s, CHART_METHOD);
            mean.push((w, full.unwrap_or(f64::NAN)));
            paper.push((w, p.unwrap_or(f64::NAN)));
            table.row(vec![
                format!("{size}"),
                format!("{w}"),
                cell(full),
                cell(sum.min_s),
                cell(sum.max_s),
                cell(p),
            ]);
        }
        series.push(Series {
            name: format!("{size} mm, rolling (mean of 12 releases)"),
            points: mean,
            mark: Mark::LinePoints,
            color: i,
        });
        series.push(Series {
            name: format!("{size} mm, paper Eq. 10/11"),
            points: paper,
            mark: Mark::Dashed,
            color: i,
        });
    }
    let fig = Figure {
        title: format!(
            "Residence time against bowl speed, axis tilted {tilt_deg} deg (cf. paper Fig. 7)"
        ),
        x_label: "combined bowl speed |w1 e_z + w2 n|, rad/s (w1 = w2)".into(),
        y_label: "residence time T, s".into(),
        x_scale: Scale::Linear,
        y_scale: Scale::Log,
        series,
        hlines: Vec::new(),
        vlines: vec![],
        notes: vec![
            "rolling resistance 0.029, granule 3 mm, release at R/2".into(),
            "paper: gaps where its model says the granule never leaves".into(),
        ],
    };
    Ok((fig, table))
}

/// The rim radius of the 300 mm bowl, m.
const RIM_300_MM: f64 = 0.15;

/// The paths of the twelve releases on the bowl bottom (bowl frame), 60 deg tilt, 3.6 rad/s,
/// 300 mm bowl, with the rim.
pub fn trajectories() -> Result<(Figure, Table)> {
    let s = rig(3.6, 60.0, 2000.0 * RIM_300_MM);
    let rim = s.rim_radius_m;
    let mut table = Table::new(&["release_deg", "t_s", "x_m", "y_m"]);
    let mut series = Vec::new();
    for (i, deg) in AZIMUTHS_DEG.iter().enumerate() {
        let beta = deg.to_radians();
        let y0: State<f64> = [-s.ri_m * beta.cos(), -s.ri_m * beta.sin(), 0.0, 0.0, 0.0];
        let mut path = vec![(y0[0], y0[1])];
        let mut rows = vec![(0.0, y0[0], y0[1])];
        let run = system::rk4(
            |t, y: &State<f64>| forces(&s, t, y).derivative,
            0.0,
            y0,
            1e-3,
            |y: &State<f64>, dy: &State<f64>| {
                (
                    y[0] * y[0] + y[1] * y[1] - RIM_300_MM * RIM_300_MM,
                    2.0 * (y[0] * dy[0] + y[1] * dy[1]),
                )
            },
            |t, y: &State<f64>| {
                path.push((y[0], y[1]));
                rows.push((t, y[0], y[1]));
                ControlFlow::<()>::Continue(())
            },
            SystemLimits {
                horizon_s: 5.0,
                max_steps: 100_000,
            },
        )
        .map_err(|e| {
            anyhow!(
                "integration failed: {}",
                crate::predict::rolling_words(RollingError::Integration(e))
            )
        })?;
        if let Ended::Event { t, y } = run.ended {
            path.push((y[0], y[1]));
            rows.push((t, y[0], y[1]));
        }
        for (t, x, y) in rows {
            table.row(vec![
                format!("{deg}"),
                format!("{t}"),
                format!("{x}"),
                format!("{y}"),
            ]);
        }
        series.push(Series {
            name: format!("release at {deg} deg"),
            points: path,
            mark: Mark::Line,
            color: i,
        });
    }
    let circle: Vec<(f64, f64)> = (0..=200)
        .map(|i| {
            let a = i as f64 / 200.0 * std::f64::consts::TAU;
            (rim * a.cos(), rim * a.sin())
        })
        .collect();
    series.push(Series {
        name: "rim".into(),
        points: circle,
        mark: Mark::Dashed,
        color: 12,
    });
    let fig = Figure {
        title: "Paths on the bowl bottom: 60 deg tilt, 3.6 rad/s, 300 mm bowl (bowl frame)".into(),
        x_label: "x, m (downhill at release is -x)".into(),
        y_label: "y, m".into(),
        x_scale: Scale::Linear,
        y_scale: Scale::Linear,
        series,
        hlines: Vec::new(),
        vlines: vec![],
        notes: vec!["released at rest at R/2; rolling resistance 0.029".into()],
    };
    Ok((fig, table))
}

/// The hierarchy map: each simpler member's difference from the full rolling model in the mean
/// residence time, against bowl speed, at tilts 0, 30 and 60 deg (300 mm bowl, mu_r `mu`).
pub fn hierarchy_map(mu: f64) -> Result<(Figure, Table)> {
    let tilts = [0.0, 30.0, 60.0];
    let mut table = Table::new(&["tilt_deg", "omega_rad_s", "member", "mean_s", "difference"]);
    let mut series = Vec::new();
    for (ti, tilt) in tilts.iter().enumerate() {
        let mut lines: Vec<Vec<(f64, f64)>> = vec![Vec::new(); MEMBERS.len() - 1];
        for w in speeds(31) {
            let s = RollingScene {
                rolling_resistance: mu,
                ..rig(w, *tilt, 300.0)
            };
            let full = mean_residence_s(Member::Full, &s, CHART_METHOD);
            for (mi, m) in MEMBERS.iter().enumerate() {
                let t = mean_residence_s(*m, &s, CHART_METHOD);
                let d = t.zip(full).map(|(t, f)| ((t - f) / f).abs());
                table.row(vec![
                    format!("{tilt}"),
                    format!("{w}"),
                    m.name().into(),
                    cell(t),
                    cell(d),
                ]);
                if mi < lines.len() {
                    lines[mi].push((w, d.unwrap_or(f64::NAN)));
                }
            }
        }
        for (mi, pts) in lines.into_iter().enumerate() {
            series.push(Series {
                name: format!("{} at {tilt} deg", MEMBERS[mi].name()),
                points: pts,
                mark: [Mark::Line, Mark::Dashed, Mark::DashedPoints][ti],
                color: mi,
            });
        }
    }
    let fig = Figure {
        title: format!(
            "Model hierarchy: difference from the rolling model (mu_r {mu}, 300 mm bowl)"
        ),
        x_label: "combined bowl speed, rad/s (w1 = w2)".into(),
        y_label: "|T_member - T_rolling| / T_rolling (mean of 12 releases)".into(),
        x_scale: Scale::Linear,
        y_scale: Scale::Log,
        series,
        hlines: Vec::new(),
        vlines: vec![],
        notes: vec![
            "solid 0 deg, dashed 30 deg, dashed with points 60 deg".into(),
            "a gap: the member or the rolling model says it never leaves".into(),
        ],
    };
    Ok((fig, table))
}

/// Mean residence time over the azimuths by `method`, with its right-hand-side evaluations.
fn mean_by(s: &RollingScene<f64>, method: RollingMethod<f64>) -> Result<(f64, u32)> {
    let sum = rolling::residence_over_azimuths(s, method).map_err(err)?;
    let mean = sum
        .mean_s
        .filter(|_| sum.left == 12)
        .ok_or_else(|| anyhow!("not every release leaves"))?;
    Ok((mean, sum.evaluations))
}

/// One run of a work-precision sweep: its family (`dp54` or `rk4`), its setting as the table
/// writes it, the method.
pub(super) type Run = (&'static str, String, RollingMethod<f64>);

/// A work-precision chart's runs: DP5(4) at rtol `1e-k` for each `k` of `dp54_exponents`, then
/// RK4 at `first_step_s` halved `rk4_halvings` times.
pub(super) fn method_runs(
    dp54_exponents: core::ops::RangeInclusive<i32>,
    first_step_s: f64,
    rk4_halvings: i32,
) -> Vec<Run> {
    let mut runs: Vec<Run> = dp54_exponents
        .map(|k| {
            let tol = 10f64.powi(-k);
            (
                "dp54",
                format!("{tol:e}"),
                RollingMethod::Dp54 { rtol: tol },
            )
        })
        .collect();
    runs.extend((0..=rk4_halvings).map(|k| {
        let h = first_step_s / 2f64.powi(k);
        ("rk4", format!("{h:e}"), RollingMethod::Rk4 { step_s: h })
    }));
    runs
}

/// One scene's runs on a work-precision chart: each run's error in the mean residence time
/// against `reference` (from `mean_by`: the mean and the right-hand-side evaluations) as a row of
/// `table` and a point of its family's series, DP5(4) solid and RK4 dashed in the scene's two
/// colours; a run that fails is a row that says why.
pub(super) fn method_series(
    name: &str,
    scene_index: usize,
    reference: f64,
    runs: Vec<Run>,
    mut mean_by: impl FnMut(RollingMethod<f64>) -> Result<(f64, f64)>,
    table: &mut Table,
) -> [Series; 2] {
    let (mut dp, mut rk) = (Vec::new(), Vec::new());
    for (family, setting, method) in runs {
        match mean_by(method) {
            Ok((t, n)) => {
                let e = ((t - reference) / reference).abs().max(1e-17);
                if family == "dp54" { &mut dp } else { &mut rk }.push((n, e));
                table.row(vec![
                    name.into(),
                    family.into(),
                    setting,
                    format!("{n}"),
                    format!("{e:e}"),
                ]);
            }
            Err(e) => table.row(vec![
                name.into(),
                family.into(),
                setting,
                "-".into(),
                format!("failed: {e}").replace(',', ";"),
            ]),
        }
    }
    [
        Series {
            name: format!("DP5(4), {name}"),
            points: dp,
            mark: Mark::LinePoints,
            color: 2 * scene_index,
        },
        Series {
            name: format!("RK4, {name}"),
            points: rk,
            mark: Mark::DashedPoints,
            color: 2 * scene_index + 1,
        },
    ]
}

/// A work-precision figure: evaluations against the relative error, both on log axes.
pub(super) fn work_precision_figure(
    title: &str,
    series: Vec<Series>,
    notes: Vec<String>,
) -> Figure {
    Figure {
        title: title.into(),
        x_label: "right-hand-side evaluations (12 releases)".into(),
        y_label: "relative error in the mean residence time".into(),
        x_scale: Scale::Log,
        y_scale: Scale::Log,
        series,
        hlines: Vec::new(),
        vlines: vec![],
        notes,
    }
}

/// Work-precision of DP5(4) and RK4 on the rolling equation: the error in the mean residence
/// time against right-hand-side evaluations, on the rig's 60-degree scene and on a 30-degree
/// scene close to the stick/slip threshold (resistance near `tan 30`), where the start from rest
/// is stiff.
pub fn work_precision() -> Result<(Figure, Table)> {
    let scenes = [
        ("60 deg, 3.6 rad/s, mu_r 0.029", rig(3.6, 60.0, 300.0)),
        (
            "30 deg, 2 rad/s, mu_r 0.55 (near stick)",
            RollingScene {
                rolling_resistance: 0.55,
                ..rig(2.0, 30.0, 150.0)
            },
        ),
    ];
    let mut table = Table::new(&["scene", "method", "setting", "rhs_evaluations", "rel_error"]);
    let mut series = Vec::new();
    for (si, (name, s)) in scenes.iter().enumerate() {
        let (reference, _) = mean_by(s, REFERENCE)?;
        let runs = method_runs(3..=12, 0.02, 10);
        series.extend(method_series(
            name,
            si,
            reference,
            runs,
            |m| mean_by(s, m).map(|(t, n)| (t, f64::from(n))),
            &mut table,
        ));
    }
    let fig = work_precision_figure(
        "Work-precision on the rolling equation (mean over 12 releases)",
        series,
        vec![
            "reference: DP5(4) at rtol 1e-13".into(),
            "DP5(4) rtol 1e-3..1e-12; RK4 h 0.02 s / 2^k".into(),
        ],
    );
    Ok((fig, table))
}

#[cfg(test)]
mod tests {
    use super::*;
    use model_core::particle::rolling::RollingOutcome;
    use model_core::particle::{self, Model, Outcome, Scene};

    /// The paper's models at the rig's combined speed (for the tests of the charts' claims).
    fn paper_time(s: &RollingScene<f64>, model: Model) -> Option<f64> {
        let scene = Scene {
            omega_rad_s: s.combined_speed_rad_s(),
            mu: s.rolling_resistance,
            g_m_s2: s.g_m_s2,
            k2: s.k2,
            ri_m: s.ri_m,
            rim_radius_m: s.rim_radius_m,
        };
        match particle::residence(&scene, model) {
            Ok(Outcome::Leaves {
                residence_time_s, ..
            }) => Some(residence_time_s),
            _ => None,
        }
    }

    /// Whether a release leaves (for the tests of the charts' claims).
    fn leaves(s: &RollingScene<f64>, beta_rad: f64) -> bool {
        matches!(
            rolling::residence(s, beta_rad, CHART_METHOD).map(|r| r.outcome),
            Ok(RollingOutcome::Leaves { .. })
        )
    }

    /// The claims the charts make: on the tilted rig every release leaves even at the paper's
    /// mu = 0.4 where the paper's models say nothing leaves, the mean residence time hardly
    /// changes with speed over 0.5..3.6 rad/s, and the paper is off by a factor.
    #[test]
    fn the_tilted_rig_is_ruled_by_gravity() {
        let paper_mu = RollingScene {
            rolling_resistance: 0.4,
            ..rig(3.6, 60.0, 300.0)
        };
        assert!(
            AZIMUTHS_DEG
                .iter()
                .all(|d| leaves(&paper_mu, d.to_radians()))
        );
        assert_eq!(paper_time(&paper_mu, Model::Coriolis), None);
        let slow = mean_by(&rig(0.5, 60.0, 300.0), CHART_METHOD).unwrap().0;
        let fast = mean_by(&rig(3.6, 60.0, 300.0), CHART_METHOD).unwrap().0;
        assert!(((slow - fast) / fast).abs() < 0.05, "{slow} vs {fast}");
        let paper = paper_time(&rig(3.6, 60.0, 300.0), Model::Coriolis).unwrap();
        assert!(paper / fast > 2.0, "paper {paper} vs rolling {fast}");
    }
}

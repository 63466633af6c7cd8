//! The paper's Figures 5, 6 and 7 redrawn from our corrected model, with and without the Coriolis
//! term: r(t) at 3.6 rad/s, total exit speed against bowl speed, residence time against bowl speed.
//!
//! Parameters are the model's documented defaults (`Scene::default()`: effective rolling
//! resistance 0.029, g 9.81, k2 5/7, start radius half the rim radius); the bowl "sizes" 150, 200,
//! 250 and 300 mm are read as diameters (rim radius 75 to 150 mm), as in the model's docs.
//! Where the particle never leaves (ri <= a = mu g / omega^2) there is no residence time and no
//! exit speed: the curve has a gap, and the threshold speed of each bowl is marked.

use model_core::particle::{Model, Outcome, Scene, SceneError, position_m, residence};

use super::plot::{Figure, Mark, Scale, Series, VLine};
use super::table::Table;

/// The bowl speeds of the paper's experiments span 0.5 to 3.6 rad/s.
const OMEGA_MIN: f64 = 0.5;
/// Upper end of the speed axis.
const OMEGA_MAX: f64 = 3.6;
/// Bowl sizes of the paper, mm (read as diameters).
const BOWL_SIZES_MM: [f64; 4] = [150.0, 200.0, 250.0, 300.0];

fn scene_for(size_mm: f64, omega: f64) -> Scene<f64> {
    let rim = size_mm / 2000.0;
    Scene {
        omega_rad_s: omega,
        rim_radius_m: rim,
        ri_m: rim / 2.0,
        ..Scene::default()
    }
}

/// The model's refusal of a chart's scene, in the words `bowl predict` uses.
pub fn scene_err(e: SceneError) -> anyhow::Error {
    anyhow::anyhow!(
        "model rejected the scene: {}",
        crate::predict::scene_words(e)
    )
}

fn model_name(m: Model) -> &'static str {
    match m {
        Model::Flat => "flat",
        Model::Coriolis => "coriolis",
    }
}

fn omega_grid() -> Vec<f64> {
    let n = 310;
    (0..=n)
        .map(|i| OMEGA_MIN + (OMEGA_MAX - OMEGA_MIN) * i as f64 / n as f64)
        .collect()
}

/// Threshold speed `sqrt(mu g / ri)` below which the particle never leaves.
fn threshold_omega(s: &Scene<f64>) -> f64 {
    (s.mu * s.g_m_s2 / s.ri_m).sqrt()
}

/// Paper Figure 5: r(t) at 3.6 rad/s in the default bowl, flat and Coriolis, up to the rim.
pub fn radial() -> anyhow::Result<(Figure, Table)> {
    let base = Scene {
        omega_rad_s: 3.6,
        ..Scene::default()
    };
    let mut table = Table::new(&["model", "mu", "t_s", "r_m"]);
    let mut series = Vec::new();
    let mut notes = vec![
        format!(
            "omega 3.6 rad/s, ri {} m, R {} m, k2 5/7",
            base.ri_m, base.rim_radius_m
        ),
        "curves stop where the particle leaves".to_string(),
    ];
    // The default coefficient, and a larger one where the Coriolis term is visible.
    let cases = [(0.029, 0usize), (0.06, 2usize)];
    for &(mu, colour) in &cases {
        let scene = Scene { mu, ..base };
        let mut times = Vec::new();
        for model in [Model::Flat, Model::Coriolis] {
            let out = residence(&scene, model).map_err(scene_err)?;
            let t_end = match out {
                Outcome::Leaves {
                    residence_time_s, ..
                } => residence_time_s,
                _ => anyhow::bail!("the default scene at mu {mu} should leave"),
            };
            times.push(t_end);
            let n = 200;
            let mut pts = Vec::with_capacity(n + 1);
            for i in 0..=n {
                let t = t_end * i as f64 / n as f64;
                let r = position_m(&scene, model, t).map_err(scene_err)?;
                pts.push((t, r));
                table.row(vec![
                    model_name(model).into(),
                    format!("{mu}"),
                    format!("{t:.17e}"),
                    format!("{r:.17e}"),
                ]);
            }
            series.push(Series {
                name: format!("{} mu={mu}: T={t_end:.4} s", model_name(model)),
                points: pts,
                mark: if model == Model::Flat {
                    Mark::Line
                } else {
                    Mark::Dashed
                },
                color: colour + usize::from(model == Model::Coriolis),
            });
        }
        notes.push(format!(
            "mu {mu}: Coriolis T is {:+.2} % of flat",
            100.0 * (times[1] / times[0] - 1.0)
        ));
    }
    // The paper's literal sliding coefficient: nothing moves.
    let literal = Scene { mu: 0.4, ..base };
    if let Outcome::NeverLeaves {
        equilibrium_radius_m,
        ..
    } = residence(&literal, Model::Flat).map_err(scene_err)?
    {
        notes.push(format!(
            "paper's mu 0.4: never leaves (a = {equilibrium_radius_m:.3} m > ri)"
        ));
    }
    series.push(Series {
        name: format!("rim R = {} m", base.rim_radius_m),
        points: vec![
            (0.0, base.rim_radius_m),
            (times_max(&series), base.rim_radius_m),
        ],
        mark: Mark::Dashed,
        color: 7,
    });
    Ok((
        Figure {
            title: "Radial position r(t) at 3.6 rad/s (cf. paper Fig. 5)".into(),
            x_label: "time t (s)".into(),
            y_label: "radial position r (m)".into(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            series,
            hlines: Vec::new(),
            vlines: vec![],
            notes,
        },
        table,
    ))
}

fn times_max(series: &[Series]) -> f64 {
    series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0))
        .fold(0.0, f64::max)
}

/// Which quantity a speed sweep shows.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Sweep {
    /// Paper Fig. 6: total exit speed (Eq. 12).
    Velocity,
    /// Paper Fig. 7: residence time.
    Residence,
}

fn sweep(which: Sweep) -> anyhow::Result<(Figure, Table)> {
    let mut table = Table::new(&[
        "bowl_size_mm",
        "rim_radius_m",
        "model",
        "w_rad_s",
        "outcome",
        "residence_time_s",
        "exit_total_velocity_m_s",
    ]);
    let mut series = Vec::new();
    let mut vlines = Vec::new();
    let mut max_ratio: f64 = 1.0;
    for (i, &size) in BOWL_SIZES_MM.iter().enumerate() {
        let th = threshold_omega(&scene_for(size, 1.0));
        vlines.push(VLine {
            x: th,
            label: format!("{size:.0}"),
            color: i,
        });
        let mut flat_t = Vec::new();
        for model in [Model::Flat, Model::Coriolis] {
            let mut pts = Vec::new();
            // The uniform grid plus speeds just above the threshold, where T grows like
            // -ln(omega - omega_th), so the curve's climb is drawn rather than cut off.
            let mut grid = omega_grid();
            grid.extend((1..=6).map(|e| th * (1.0 + 10f64.powi(-e))));
            grid.sort_by(f64::total_cmp);
            for (j, w) in grid.into_iter().enumerate() {
                let s = scene_for(size, w);
                let out = residence(&s, model).map_err(scene_err)?;
                let (kind, t, v) = match out {
                    Outcome::Leaves {
                        residence_time_s,
                        exit_total_velocity_m_s,
                        ..
                    } => ("leaves", residence_time_s, exit_total_velocity_m_s),
                    Outcome::AlreadyAtRim {
                        exit_total_velocity_m_s,
                    } => ("at_rim", 0.0, exit_total_velocity_m_s),
                    Outcome::NeverLeaves { .. } => ("never_leaves", f64::INFINITY, f64::NAN),
                };
                if model == Model::Flat {
                    flat_t.push(t);
                } else if t.is_finite() && flat_t[j].is_finite() {
                    max_ratio = max_ratio.max(t / flat_t[j]);
                }
                table.row(vec![
                    format!("{size}"),
                    format!("{}", s.rim_radius_m),
                    model_name(model).into(),
                    format!("{w}"),
                    kind.into(),
                    // Never leaves: empty cells (the kind column says so), not inf and NaN.
                    if t.is_finite() {
                        format!("{t:.17e}")
                    } else {
                        String::new()
                    },
                    if v.is_finite() {
                        format!("{v:.17e}")
                    } else {
                        String::new()
                    },
                ]);
                // Never leaves: no point, so the line has a gap (NaN).
                let y = match which {
                    Sweep::Velocity => v,
                    Sweep::Residence => t,
                };
                pts.push((w, if y.is_finite() { y } else { f64::NAN }));
            }
            series.push(Series {
                name: format!("{size:.0} mm, {}", model_name(model)),
                points: pts,
                mark: if model == Model::Flat {
                    Mark::Line
                } else {
                    Mark::Dashed
                },
                color: i,
            });
        }
    }
    let notes = vec![
        "solid: flat model (Eq. 5-7); dashed: with Coriolis (Eq. 9-11)".to_string(),
        "bowl size read as diameter; ri = R/2, mu = 0.029".to_string(),
        "dashed verticals: threshold speed sqrt(mu g / ri)".to_string(),
        "left of it the particle never leaves (ri <= a):".to_string(),
        "no curve there (the CSV says never_leaves); no marker".to_string(),
        "is drawn at a value the model does not give".to_string(),
        format!("largest T_coriolis/T_flat on this grid: {:.4}", max_ratio),
    ];
    let (title, y_label, y_scale) = match which {
        Sweep::Velocity => (
            "Total exit speed against bowl speed (cf. paper Fig. 6)",
            "total exit speed V (m/s), Eq. 12",
            Scale::Linear,
        ),
        Sweep::Residence => (
            "Residence time against bowl speed (cf. paper Fig. 7)",
            "residence time T (s)",
            Scale::Log,
        ),
    };
    Ok((
        Figure {
            title: title.into(),
            x_label: "combined bowl speed omega (rad/s)".into(),
            y_label: y_label.into(),
            x_scale: Scale::Linear,
            y_scale,
            series,
            hlines: Vec::new(),
            vlines,
            notes,
        },
        table,
    ))
}

/// Paper Figure 6: total exit speed against bowl speed for four bowl sizes.
pub fn velocity() -> anyhow::Result<(Figure, Table)> {
    sweep(Sweep::Velocity)
}

/// Paper Figure 7: residence time against bowl speed for four bowl sizes.
pub fn residence_time() -> anyhow::Result<(Figure, Table)> {
    sweep(Sweep::Residence)
}

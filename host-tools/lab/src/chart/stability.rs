//! `bowl chart stability`: error in T against the step `h omega` for the fixed-step integrators,
//! with each method's stability bound marked, on a scene with strong friction (mu 0.4, where the
//! Coriolis term makes the fast mode fastest) and a frictionless one.
//!
//! The bounds are computed here from the linear stability of the fast mode
//! `l2 = -k omega (s + k mu)` (docs/model.md, "Stability"; `s + k mu = 1` without friction):
//! explicit Euler is stable for `h |l2| <= 2`, RK4 for `h |l2| <= 2.785` (its real-axis limit);
//! semi-implicit Euler (friction implicit) has no bound. Beyond a bound the model refuses the
//! step (`OdeError::BeyondStabilityLimit`): the chart marks those steps with crosses, and the
//! CSV says `refused`.

use model_core::ode;
use model_core::particle::{self, Model, Scene};

use super::plot::{Figure, Mark, Series, VLine};
use super::reference::{self, RefModel, RefOutcome, RefScene};
use super::table::Table;

/// RK4's stability interval on the negative real axis, `h lambda >= -2.7853`.
pub const RK4_REAL_LIMIT: f64 = 2.785_293_563_405_282;
/// Explicit Euler's, `h lambda >= -2`.
pub const EULER_REAL_LIMIT: f64 = 2.0;

/// A stability scene: name, model, scene.
pub struct StabilityScene {
    /// Short name for the CSV and legend.
    pub name: &'static str,
    /// Model integrated.
    pub model: Model,
    /// The scene.
    pub scene: Scene<f64>,
}

/// The two scenes of the chart: strong friction with Coriolis, and frictionless.
pub fn scenes() -> [StabilityScene; 2] {
    let base = Scene {
        omega_rad_s: 10.0,
        mu: 0.4,
        g_m_s2: 9.81,
        k2: 5.0 / 7.0,
        ri_m: 0.05,
        rim_radius_m: 0.1,
    };
    [
        StabilityScene {
            name: "mu0.4-coriolis",
            model: Model::Coriolis,
            scene: base,
        },
        StabilityScene {
            name: "mu0-flat",
            model: Model::Flat,
            scene: Scene { mu: 0.0, ..base },
        },
    ]
}

/// `|l2| / omega = k (s + k mu)` for the model (the fast mode's rate per unit bowl speed).
pub fn fast_rate_per_omega(s: &Scene<f64>, model: Model) -> f64 {
    let k = s.k2.sqrt();
    let m = match model {
        Model::Flat => 0.0,
        Model::Coriolis => k * s.mu,
    };
    k * ((1.0 + m * m).sqrt() + m)
}

/// The largest stable `h omega` of a family (None: no bound).
pub fn bound_h_omega(family: ode::Method<f64>, s: &Scene<f64>, model: Model) -> Option<f64> {
    let c = match family {
        ode::Method::Euler { .. } => EULER_REAL_LIMIT,
        ode::Method::Rk4 { .. } => RK4_REAL_LIMIT,
        _ => return None,
    };
    Some(c / fast_rate_per_omega(s, model))
}

fn method(name: &str, h: f64) -> ode::Method<f64> {
    match name {
        "euler" => ode::Method::Euler { step_s: h },
        "semi-implicit-euler" => ode::Method::SemiImplicitEuler { step_s: h },
        _ => ode::Method::Rk4 { step_s: h },
    }
}

/// Steps on the chart: `h omega = 2^(j/4)` from 2^-8 to 2^2.
fn grid() -> Vec<f64> {
    (-32..=8).map(|j| 2f64.powf(f64::from(j) / 4.0)).collect()
}

const FAMILIES: [&str; 3] = ["euler", "semi-implicit-euler", "rk4"];

/// The stability chart and its CSV.
pub fn chart() -> anyhow::Result<(Figure, Table)> {
    let mut table = Table::new(&[
        "scene",
        "method",
        "h_omega",
        "bound_h_omega",
        "outcome",
        "rel_error",
        "rhs_evals",
        "note",
    ]);
    let mut series = Vec::new();
    let mut vlines = Vec::new();
    let mut notes = vec![
        "error of T against the 256-bit reference".to_string(),
        "crosses at the top: step refused by the model".to_string(),
        "(beyond the method's stability bound)".to_string(),
        "dashed verticals: bounds 2/(k(s+k mu)), 2.785/(k(s+k mu))".to_string(),
    ];
    for (si, sc) in scenes().iter().enumerate() {
        let s = &sc.scene;
        let rs = RefScene::from(s);
        let rm = RefModel::from(sc.model);
        let RefOutcome::Leaves { time_s: t_ref, .. } = reference::outcome(&rs, rm) else {
            anyhow::bail!("stability scene {} should leave", sc.name);
        };
        notes.push(format!(
            "{}: omega T = {:.2}, |l2|/omega = {:.3}",
            sc.name,
            s.omega_rad_s * t_ref,
            fast_rate_per_omega(s, sc.model)
        ));
        for (fi, fam) in FAMILIES.iter().enumerate() {
            let bound = bound_h_omega(method(fam, 1.0), s, sc.model);
            if let Some(b) = bound {
                vlines.push(VLine {
                    x: b,
                    label: format!(
                        "{} {}",
                        if *fam == "rk4" { "RK4" } else { "Euler" },
                        sc.name
                    ),
                    color: fi,
                });
            }
            let mut pts = Vec::new();
            let mut refused = Vec::new();
            for h_omega in grid() {
                let m = method(fam, h_omega / s.omega_rad_s);
                let (outcome, err, evals, note) = match particle::integrate_constant(s, sc.model, m)
                {
                    Ok(rep) => match rep.outcome {
                        ode::OdeOutcome::Leaves {
                            residence_time_s, ..
                        } => (
                            "leaves",
                            ((residence_time_s - t_ref) / t_ref).abs(),
                            Some(rep.rhs_evaluations),
                            String::new(),
                        ),
                        other => (
                            "other",
                            f64::NAN,
                            Some(rep.rhs_evaluations),
                            super::workprec::methods::ode_outcome_note(&other),
                        ),
                    },
                    Err(particle::OdeError::BeyondStabilityLimit) => (
                        "refused",
                        f64::NAN,
                        None,
                        "beyond the method's stability limit".into(),
                    ),
                    Err(e) => ("error", f64::NAN, None, crate::predict::ode_words(e)),
                };
                table.row(vec![
                    sc.name.into(),
                    (*fam).into(),
                    format!("{h_omega}"),
                    bound.map_or_else(String::new, |b| format!("{b}")),
                    outcome.into(),
                    format!("{err:e}"),
                    evals.map_or_else(String::new, |n| n.to_string()),
                    note,
                ]);
                // NaN (no T) stays NaN: a gap, not a point at the floor.
                let y = if err.is_nan() {
                    f64::NAN
                } else {
                    err.max(super::workprec::ERROR_FLOOR)
                };
                pts.push((h_omega, y));
                if outcome == "refused" {
                    // One row of crosses per method and scene, above the curves.
                    refused.push((h_omega, 10f64.powf(0.5 + 0.25 * (fi + 3 * si) as f64)));
                }
            }
            let style = if si == 0 {
                Mark::LinePoints
            } else {
                Mark::Dashed
            };
            series.push(Series {
                name: format!("{fam} {}", sc.name),
                points: pts,
                mark: style,
                color: fi,
            });
            if !refused.is_empty() {
                series.push(Series {
                    name: format!("{fam} {}: refused", sc.name),
                    points: refused,
                    mark: Mark::Crosses,
                    color: fi,
                });
            }
        }
    }
    Ok((
        Figure {
            hlines: Vec::new(),
            vlines,
            ..Figure::error_in_t(
                "Stability: error in T against step h*omega (fixed-step methods)".into(),
                "step h * omega (dimensionless)",
                series,
                notes,
            )
        },
        table,
    ))
}

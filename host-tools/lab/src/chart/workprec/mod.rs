//! `bowl chart work-precision`: achieved error in the residence time against cost, for every
//! method and setting, on the named scenes of `model_core::particle::named_scenes`.
//!
//! Error: `|T - T_ref| / T_ref` with `T_ref` from [`super::reference`] (256-bit, independent code)
//! evaluated at exactly the inputs the method saw (for f32 methods: the f32-rounded scene, so the
//! error is the method's own, not the rounding of its inputs).
//! Cost: host nanoseconds per call (median, release build recommended), right-hand-side
//! evaluations for the integrators, and executed Cortex-M4F instructions from a QEMU log when given.

use std::collections::BTreeMap;

use model_core::particle::Model;
use model_core::particle::named_scenes::{SCENE_NAMES, scene};

use super::plot::{Figure, Mark, Series};
use super::qemu_log::Counts;
use super::table::Table;
use super::timing::Budget;

pub(crate) mod methods;

pub use methods::*;

/// One measured point.
#[derive(Clone, Debug)]
pub struct Point {
    /// Scene name.
    pub scene: &'static str,
    /// Model.
    pub model: Model,
    /// Method.
    pub method: Method,
    /// The run.
    pub run: Run,
    /// Reference T at the run's inputs (None: the reference says it never leaves).
    pub ref_time_s: Option<f64>,
    /// Relative error (None when either side has no T).
    pub rel_error: Option<f64>,
    /// Host ns per call (median over batches).
    pub host_ns: f64,
    /// Host ns per call (fastest batch).
    pub host_ns_min: f64,
    /// QEMU counts, when the log has `cost::SCENE::MODEL::KEY`.
    pub qemu: Option<Counts>,
}

impl Point {
    /// The QEMU benchmark name of this point.
    pub fn bench_name(&self) -> String {
        format!(
            "cost::{}::{}::{}",
            self.scene,
            model_key(self.model),
            self.method.key()
        )
    }
}

/// Measures every method on every scene and model.
/// Only the methods whose family key is in `families` (all when empty).
pub fn measure(
    budget: Budget,
    qemu: &BTreeMap<String, Counts>,
    families: &[String],
) -> anyhow::Result<Vec<Point>> {
    for f in families {
        if !ALL_FAMILIES.iter().any(|x| x.key() == f) {
            anyhow::bail!(
                "unknown method family `{f}` (known: {})",
                ALL_FAMILIES.map(Family::key).join(", ")
            );
        }
    }
    let mut out = Vec::new();
    // The 256-bit reference is slow; f64 and f32 methods share two distinct input sets.
    let mut refs: BTreeMap<([u64; 6], bool), Option<f64>> = BTreeMap::new();
    for (i, &name) in SCENE_NAMES.iter().enumerate() {
        let s = scene(i);
        for model in [Model::Flat, Model::Coriolis] {
            for m in methods()
                .into_iter()
                .filter(|m| families.is_empty() || families.iter().any(|f| f == m.family.key()))
            {
                let r = run(&m, &s, model)?;
                let x = &r.inputs;
                let key = (
                    [
                        x.omega_rad_s.to_bits(),
                        x.mu.to_bits(),
                        x.g_m_s2.to_bits(),
                        x.k2.to_bits(),
                        x.ri_m.to_bits(),
                        x.rim_radius_m.to_bits(),
                    ],
                    model == Model::Coriolis,
                );
                let ref_time_s = *refs
                    .entry(key)
                    .or_insert_with(|| ref_time(&r.inputs, model));
                let rel_error = match (r.time_s, ref_time_s) {
                    (Some(t), Some(tr)) if tr > 0.0 => Some(((t - tr) / tr).abs()),
                    (Some(t), Some(_)) => Some(t.abs()),
                    _ => None,
                };
                let timing = time(&m, &s, model, budget);
                let mut p = Point {
                    scene: name,
                    model,
                    method: m,
                    run: r,
                    ref_time_s,
                    rel_error,
                    host_ns: timing.median_ns,
                    host_ns_min: timing.min_ns,
                    qemu: None,
                };
                p.qemu = qemu.get(&p.bench_name()).copied();
                out.push(p);
            }
        }
    }
    Ok(out)
}

fn opt(v: Option<f64>) -> String {
    v.map_or_else(|| "".into(), |x| format!("{x:.6e}"))
}

/// The CSV of all points.
pub fn table(points: &[Point]) -> Table {
    let mut t = Table::new(&[
        "scene",
        "model",
        "method",
        "family",
        "precision",
        "setting",
        "w_rad_s",
        "mu",
        "g",
        "k2",
        "ri_m",
        "R_m",
        "residence_time_s",
        "ref_residence_time_s",
        "rel_error",
        "rhs_evals",
        "host_ns_per_call",
        "host_ns_min",
        "qemu_instructions_mean",
        "qemu_instructions_max",
        "note",
    ]);
    for p in points {
        t.row(vec![
            p.scene.into(),
            model_key(p.model).into(),
            p.method.key(),
            p.method.family.key().into(),
            p.method.precision.key().into(),
            p.method.setting(),
            format!("{:.17e}", p.run.inputs.omega_rad_s),
            format!("{:.17e}", p.run.inputs.mu),
            format!("{:.17e}", p.run.inputs.g_m_s2),
            format!("{:.17e}", p.run.inputs.k2),
            format!("{:.17e}", p.run.inputs.ri_m),
            format!("{:.17e}", p.run.inputs.rim_radius_m),
            p.run
                .time_s
                .map_or_else(|| "inf".into(), |x| format!("{x:.17e}")),
            p.ref_time_s
                .map_or_else(|| "inf".into(), |x| format!("{x:.17e}")),
            opt(p.rel_error),
            p.run.rhs_evals.map_or_else(String::new, |n| n.to_string()),
            format!("{:.1}", p.host_ns),
            format!("{:.1}", p.host_ns_min),
            p.qemu.map_or_else(String::new, |c| c.mean.to_string()),
            p.qemu.map_or_else(String::new, |c| c.max.to_string()),
            p.run.note.clone(),
        ]);
    }
    t
}

/// Errors below this are drawn at this value (an exactly right answer has no logarithm).
pub const ERROR_FLOOR: f64 = 1e-17;

/// Which cost goes on the x axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CostAxis {
    /// Host ns per call.
    HostNs,
    /// Right-hand-side evaluations (integrators only).
    RhsEvals,
    /// QEMU instructions (mean over the bench's inputs).
    QemuInstructions,
}

/// `(setting, cost, error)` of one measured point.
type SettingPoint = (f64, f64, f64);

/// Error-against-cost chart of one scene and model.
pub fn figure(points: &[Point], scene: &str, model: Model, axis: CostAxis) -> Figure {
    // Points keep their setting so lines join neighbouring steps/tolerances, not neighbouring
    // costs (host times are noisy; a line sorted by cost would zigzag between settings).
    let mut groups: BTreeMap<(Family, Precision), Vec<SettingPoint>> = BTreeMap::new();
    for p in points
        .iter()
        .filter(|p| p.scene == scene && p.model == model)
    {
        let x = match axis {
            CostAxis::HostNs => Some(p.host_ns),
            CostAxis::RhsEvals => p.run.rhs_evals.map(|n| n as f64),
            CostAxis::QemuInstructions => p.qemu.map(|c| c.mean as f64),
        };
        let Some(x) = x else { continue };
        let y = p.rel_error.map_or(f64::NAN, |e| e.max(ERROR_FLOOR));
        groups
            .entry((p.method.family, p.method.precision))
            .or_default()
            .push((p.method.setting.unwrap_or(0.0), x, y));
    }
    let series = groups
        .into_iter()
        .map(|((family, precision), mut pts)| {
            pts.sort_by(|a, b| b.0.total_cmp(&a.0));
            let pts: Vec<(f64, f64)> = pts.into_iter().map(|(_, x, y)| (x, y)).collect();
            Series {
                name: format!("{} {}", family.key(), precision.key()),
                mark: if pts.len() == 1 {
                    Mark::Points
                } else if precision == Precision::F64 {
                    Mark::LinePoints
                } else {
                    Mark::DashedPoints
                },
                color: if family == Family::Closed {
                    8 + precision as usize
                } else {
                    (family as usize - 1) * 2 + (precision as usize).min(1)
                },
                points: pts,
            }
        })
        .collect();
    let x_label = match axis {
        CostAxis::HostNs => "host time per call (ns, median)",
        CostAxis::RhsEvals => "right-hand-side evaluations",
        CostAxis::QemuInstructions => "Cortex-M4F instructions per call (QEMU)",
    };
    Figure::error_in_t(
        format!("Work-precision: scene {scene}, {} model", model_key(model)),
        x_label,
        series,
        vec![
            "error against a 256-bit reference at the".into(),
            "inputs each method saw (f32: rounded inputs)".into(),
            format!("errors below {ERROR_FLOOR:.0e} drawn at {ERROR_FLOOR:.0e}"),
            "a missing point: the method gave no T".into(),
        ],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every `cost::` QEMU benchmark names a scene and a method the chart measures, so its
    /// count lands in the CSV (a typo would silently drop it).
    #[test]
    fn qemu_cost_bench_names_match_chart_keys() {
        let keys: Vec<String> = methods().iter().map(Method::key).collect();
        let mut n = 0;
        for b in bowl_test_cases::all_benches().filter(|b| b.name.starts_with("cost::")) {
            let parts: Vec<&str> = b.name.split("::").collect();
            assert_eq!(parts.len(), 4, "{}", b.name);
            assert!(SCENE_NAMES.contains(&parts[1]), "{}", b.name);
            assert!(["flat", "coriolis"].contains(&parts[2]), "{}", b.name);
            assert!(
                keys.iter().any(|k| k == parts[3]),
                "{} has no chart method",
                b.name
            );
            n += 1;
        }
        assert!(n >= 30, "{n} cost benches");
    }
}

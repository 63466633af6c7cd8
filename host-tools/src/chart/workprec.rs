//! `bowl chart work-precision`: achieved error in the residence time against cost, for every
//! method and setting, on the named scenes of `bowl_test_cases::cost`.
//!
//! Error: `|T - T_ref| / T_ref` with `T_ref` from [`super::reference`] (256-bit, independent code)
//! evaluated at exactly the inputs the method saw (for f32 methods: the f32-rounded scene, so the
//! error is the method's own, not the rounding of its inputs).
//! Cost: host nanoseconds per call (median, release build recommended), right-hand-side
//! evaluations for the integrators, and executed Cortex-M4F instructions from a QEMU log when given.

use std::collections::BTreeMap;

use bowl_test_cases::cost::{SCENE_NAMES, scene};
use model_core::particle::{Model, Outcome, Scene, residence};

use super::figures::scene_err;
use super::plot::{Figure, Mark, Scale, Series};
use super::qemu_log::Counts;
use super::reference::{self, RefModel, RefOutcome, RefScene};
use super::table::Table;
use super::timing::{Budget, ns_per_call};

/// Number type and maths library a method runs in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Precision {
    /// f64 with libm (the host's analysis type).
    F64,
    /// f32 with libm (and VSQRT on the target): the model's `Real for f32`.
    F32Libm,
}

impl Precision {
    fn key(self) -> &'static str {
        match self {
            Precision::F64 => "f64",
            Precision::F32Libm => "f32-libm",
        }
    }
}

/// The algorithm.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Family {
    /// The model's closed forms (log1p flat form, bracketed Newton for Coriolis).
    Closed,
}

impl Family {
    fn key(self) -> &'static str {
        match self {
            Family::Closed => "closed",
        }
    }
}

/// One method with one setting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Method {
    /// Algorithm.
    pub family: Family,
    /// Number type.
    pub precision: Precision,
}

impl Method {
    /// The setting as `name=value` (step `h*omega=..`, tolerance `tol=..`), empty for closed forms.
    pub fn setting(&self) -> String {
        String::new()
    }

    /// The name used in the CSV and in the QEMU benchmark names (`cost::SCENE::MODEL::KEY`).
    pub fn key(&self) -> String {
        format!("{}-{}", self.family.key(), self.precision.key())
    }
}

/// Every method and setting on the chart.
pub fn methods() -> Vec<Method> {
    let mut v = Vec::new();
    for precision in [Precision::F64, Precision::F32Libm] {
        v.push(Method {
            family: Family::Closed,
            precision,
        });
    }
    v
}

fn model_key(m: Model) -> &'static str {
    match m {
        Model::Flat => "flat",
        Model::Coriolis => "coriolis",
    }
}

fn to_f32(s: &Scene<f64>) -> Scene<f32> {
    Scene {
        omega_rad_s: s.omega_rad_s as f32,
        mu: s.mu as f32,
        g_m_s2: s.g_m_s2 as f32,
        k2: s.k2 as f32,
        ri_m: s.ri_m as f32,
        rim_radius_m: s.rim_radius_m as f32,
    }
}

fn widen(s: &Scene<f32>) -> Scene<f64> {
    Scene {
        omega_rad_s: s.omega_rad_s as f64,
        mu: s.mu as f64,
        g_m_s2: s.g_m_s2 as f64,
        k2: s.k2 as f64,
        ri_m: s.ri_m as f64,
        rim_radius_m: s.rim_radius_m as f64,
    }
}

/// What one run of a method gave.
#[derive(Clone, Debug)]
pub struct Run {
    /// The scene exactly as the method saw it, in f64.
    pub inputs: Scene<f64>,
    /// T, or None when the method reported it could not give one (with `note` saying why).
    pub time_s: Option<f64>,
    /// Right-hand-side evaluations (integrators only).
    pub rhs_evals: Option<u64>,
    /// What the method reported besides T (outcome kind, flags, errors).
    pub note: String,
}

fn outcome_note<T: model_core::Real>(o: &Outcome<T>) -> (Option<f64>, String) {
    match *o {
        Outcome::Leaves {
            residence_time_s,
            ill_conditioned,
            condition_number,
            ..
        } => (
            Some(residence_time_s.to_f64()),
            format!(
                "leaves cond={:.3e}{}",
                condition_number.to_f64(),
                if ill_conditioned {
                    " ill-conditioned"
                } else {
                    ""
                }
            ),
        ),
        Outcome::AlreadyAtRim { .. } => (Some(0.0), "at-rim".into()),
        Outcome::NeverLeaves { near_threshold, .. } => (
            None,
            format!(
                "never-leaves{}",
                if near_threshold {
                    " near-threshold"
                } else {
                    ""
                }
            ),
        ),
    }
}

/// Runs `method` once on `s`.
pub fn run(method: &Method, s: &Scene<f64>, model: Model) -> anyhow::Result<Run> {
    match (method.family, method.precision) {
        (Family::Closed, Precision::F64) => {
            let o = residence(s, model).map_err(scene_err)?;
            let (time_s, note) = outcome_note(&o);
            Ok(Run {
                inputs: *s,
                time_s,
                rhs_evals: None,
                note,
            })
        }
        (Family::Closed, Precision::F32Libm) => {
            let s32 = to_f32(s);
            let o = residence(&s32, model).map_err(scene_err)?;
            let (time_s, note) = outcome_note(&o);
            Ok(Run {
                inputs: widen(&s32),
                time_s,
                rhs_evals: None,
                note,
            })
        }
    }
}

/// Host nanoseconds per call of `method` on `s`.
pub fn time(method: &Method, s: &Scene<f64>, model: Model, budget: Budget) -> f64 {
    match (method.family, method.precision) {
        (Family::Closed, Precision::F64) => ns_per_call(budget, || residence(s, model)),
        (Family::Closed, Precision::F32Libm) => {
            let s32 = to_f32(s);
            ns_per_call(budget, || residence(&s32, model))
        }
    }
}

fn ref_time(s: &Scene<f64>, model: Model) -> Option<f64> {
    let rs = RefScene {
        omega_rad_s: s.omega_rad_s,
        mu: s.mu,
        g_m_s2: s.g_m_s2,
        k2: s.k2,
        start_radius_m: s.ri_m,
        rim_radius_m: s.rim_radius_m,
    };
    let m = match model {
        Model::Flat => RefModel::Flat,
        Model::Coriolis => RefModel::Coriolis,
    };
    match reference::outcome(&rs, m) {
        RefOutcome::Leaves { time_s, .. } => Some(time_s),
        RefOutcome::AtRim => Some(0.0),
        RefOutcome::NeverLeaves => None,
    }
}

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
    /// Host ns per call.
    pub host_ns: f64,
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
pub fn measure(budget: Budget, qemu: &BTreeMap<String, Counts>) -> anyhow::Result<Vec<Point>> {
    let mut out = Vec::new();
    for (i, &name) in SCENE_NAMES.iter().enumerate() {
        let s = scene(i);
        for model in [Model::Flat, Model::Coriolis] {
            for m in methods() {
                let r = run(&m, &s, model)?;
                let ref_time_s = ref_time(&r.inputs, model);
                let rel_error = match (r.time_s, ref_time_s) {
                    (Some(t), Some(tr)) if tr > 0.0 => Some(((t - tr) / tr).abs()),
                    (Some(t), Some(_)) => Some(t.abs()),
                    _ => None,
                };
                let host_ns = time(&m, &s, model, budget);
                let mut p = Point {
                    scene: name,
                    model,
                    method: m,
                    run: r,
                    ref_time_s,
                    rel_error,
                    host_ns,
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

/// Error-against-cost chart of one scene and model.
pub fn figure(points: &[Point], scene: &str, model: Model, axis: CostAxis) -> Figure {
    let mut groups: BTreeMap<(Family, Precision), Vec<(f64, f64)>> = BTreeMap::new();
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
            .push((x, y));
    }
    let series = groups
        .into_iter()
        .map(|((family, precision), mut pts)| {
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            Series {
                name: format!("{} {}", family.key(), precision.key()),
                mark: if pts.len() == 1 {
                    Mark::Points
                } else if precision == Precision::F64 {
                    Mark::LinePoints
                } else {
                    Mark::Dashed
                },
                color: family as usize * 2 + precision as usize,
                points: pts,
            }
        })
        .collect();
    let x_label = match axis {
        CostAxis::HostNs => "host time per call (ns, median)",
        CostAxis::RhsEvals => "right-hand-side evaluations",
        CostAxis::QemuInstructions => "Cortex-M4F instructions per call (QEMU)",
    };
    Figure {
        title: format!("Work-precision: scene {scene}, {} model", model_key(model)),
        x_label: x_label.into(),
        y_label: "relative error in residence time T".into(),
        x_scale: Scale::Log,
        y_scale: Scale::Log,
        series,
        vlines: vec![],
        notes: vec![
            "error against a 256-bit reference at the".into(),
            "inputs each method saw (f32: rounded inputs)".into(),
            format!("errors below {ERROR_FLOOR:.0e} drawn at {ERROR_FLOOR:.0e}"),
            "a missing point: the method gave no T".into(),
        ],
    }
}

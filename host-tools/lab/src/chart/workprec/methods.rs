//! The methods of the work-precision chart: each family and setting, run on a scene (its
//! residence time and the note on its outcome), timed on the host, and the reference at the
//! inputs it saw.

use model_core::Real;
use model_core::ode;
use model_core::particle::{self, Model, Outcome, Scene, residence};
use model_core::real::micro::{MicroF32, MicroF32HwSqrt};

use crate::chart::figures::scene_err;
use crate::chart::reference::{self, RefModel, RefOutcome, RefScene};
use crate::chart::timing::{Budget, Timing, ns_per_call};

/// Number type and maths library a method runs in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Precision {
    /// f64 with libm (the host's analysis type).
    F64,
    /// f32 as the model's `Real for f32` computes it: libm, VSQRT on the target, and the
    /// project's own `ln_1p` (model_core::real::log1p); the name is the historical one.
    F32Libm,
    /// f32 with micromath's functions, its rough `sqrt` included (`MicroF32`).
    F32Micromath,
    /// f32 with micromath's functions but the correctly rounded square root (`MicroF32HwSqrt`).
    F32MicromathHwSqrt,
}

impl Precision {
    pub fn key(self) -> &'static str {
        match self {
            Precision::F64 => "f64",
            Precision::F32Libm => "f32-libm",
            Precision::F32Micromath => "f32-micromath",
            Precision::F32MicromathHwSqrt => "f32-micromath-hwsqrt",
        }
    }
}

/// The algorithm.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Family {
    /// The model's closed forms (log1p flat form, bracketed Newton for Coriolis).
    Closed,
    /// Explicit Euler, fixed step.
    Euler,
    /// Semi-implicit Euler, fixed step.
    SemiImplicitEuler,
    /// Classical RK4, fixed step.
    Rk4,
    /// Adaptive Dormand-Prince 5(4).
    Dp54,
}

/// Every family, for option checking.
pub const ALL_FAMILIES: [Family; 5] = [
    Family::Closed,
    Family::Euler,
    Family::SemiImplicitEuler,
    Family::Rk4,
    Family::Dp54,
];

impl Family {
    /// Short name used in keys and legends.
    pub fn key(self) -> &'static str {
        match self {
            Family::Closed => "closed",
            Family::Euler => "euler",
            Family::SemiImplicitEuler => "semi-implicit-euler",
            Family::Rk4 => "rk4",
            Family::Dp54 => "dp54",
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
    /// Fixed-step methods: the step as `h omega` (dimensionless); DP5(4): the tolerance
    /// (rtol = tol, atol = tol R for r and tol omega R for r', see `crate::predict::ode::dp54`);
    /// closed forms: none.
    pub setting: Option<f64>,
}

impl Method {
    /// The setting as `h*omega=..` or `tol=..`, empty for closed forms.
    pub fn setting(&self) -> String {
        match (self.family, self.setting) {
            (Family::Dp54, Some(t)) => format!("tol={t:e}"),
            (_, Some(h)) => format!("h*omega={h}"),
            (_, None) => String::new(),
        }
    }

    /// The name used in the CSV and in the QEMU benchmark names (`cost::SCENE::MODEL::KEY`):
    /// `rk4-f32-libm-h0.125`, `dp54-f64-tol1e-6`, `closed-f64`.
    pub fn key(&self) -> String {
        let base = format!("{}-{}", self.family.key(), self.precision.key());
        match (self.family, self.setting) {
            (Family::Dp54, Some(t)) => format!("{base}-tol{t:e}"),
            (_, Some(h)) => format!("{base}-h{h}"),
            (_, None) => base,
        }
    }
}

/// Steps `h omega = 2^-k` for `k` in the range.
fn halvings(from: i32, to: i32) -> impl Iterator<Item = f64> {
    (from..=to).map(|k| 2f64.powi(-k))
}

/// Every method and setting on the chart.
pub fn methods() -> Vec<Method> {
    let mut v = Vec::new();
    let mut add = |family, precision, setting| {
        v.push(Method {
            family,
            precision,
            setting,
        })
    };
    for precision in [Precision::F64, Precision::F32Libm] {
        add(Family::Closed, precision, None);
        for h in halvings(1, 12) {
            add(Family::Euler, precision, Some(h));
            add(Family::SemiImplicitEuler, precision, Some(h));
        }
        for h in halvings(0, 10) {
            add(Family::Rk4, precision, Some(h));
        }
        let tols: &[f64] = match precision {
            Precision::F64 => &[
                1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13,
            ],
            _ => &[1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7],
        };
        for &t in tols {
            add(Family::Dp54, precision, Some(t));
        }
    }
    // micromath changes only the transcendental functions, which the integrators' steps do not
    // call: the closed forms are where it can pay (or cost).
    add(Family::Closed, Precision::F32Micromath, None);
    add(Family::Closed, Precision::F32MicromathHwSqrt, None);
    v
}

/// The model's ODE method for `m` on scene `s` (step in seconds from `h omega`).
fn ode_method<T: Real>(m: &Method, s: &Scene<T>) -> Option<ode::Method<T>> {
    let x = T::from_f64(m.setting?);
    let h = x / s.omega_rad_s;
    Some(match m.family {
        Family::Closed => return None,
        Family::Euler => ode::Method::Euler { step_s: h },
        Family::SemiImplicitEuler => ode::Method::SemiImplicitEuler { step_s: h },
        Family::Rk4 => ode::Method::Rk4 { step_s: h },
        Family::Dp54 => crate::predict::ode::dp54(x, s),
    })
}

fn ode_run<T: Real>(m: &Method, s: &Scene<T>, model: Model) -> Run {
    let inputs = s.to_f64();
    let Some(method) = ode_method(m, s) else {
        return Run {
            inputs,
            time_s: None,
            rhs_evals: None,
            note: "no ODE method".into(),
        };
    };
    match particle::integrate_constant(s, model, method) {
        Ok(rep) => {
            let time_s = match rep.outcome {
                ode::OdeOutcome::Leaves {
                    residence_time_s, ..
                } => Some(residence_time_s.to_f64()),
                ode::OdeOutcome::AlreadyAtRim { .. } => Some(0.0),
                _ => None,
            };
            let note = ode_outcome_note(&rep.outcome);
            Run {
                inputs,
                time_s,
                rhs_evals: Some(u64::from(rep.rhs_evaluations)),
                note: format!("{note} steps={} rejected={}", rep.steps, rep.rejected_steps),
            }
        }
        Err(e) => Run {
            inputs,
            time_s: None,
            rhs_evals: None,
            note: format!("refused: {}", crate::predict::ode_words(e)),
        },
    }
}

pub(super) fn model_key(m: Model) -> &'static str {
    match m {
        Model::Flat => "flat",
        Model::Coriolis => "coriolis",
    }
}

/// The scene in another number type (rounded to nearest).
fn narrow<T: Real>(s: &Scene<f64>) -> Scene<T> {
    Scene {
        omega_rad_s: T::from_f64(s.omega_rad_s),
        mu: T::from_f64(s.mu),
        g_m_s2: T::from_f64(s.g_m_s2),
        k2: T::from_f64(s.k2),
        ri_m: T::from_f64(s.ri_m),
        rim_radius_m: T::from_f64(s.rim_radius_m),
    }
}

/// The closed forms in number type `T`.
fn closed_run<T: Real>(s: &Scene<f64>, model: Model) -> anyhow::Result<Run> {
    let st = narrow::<T>(s);
    let o = residence(&st, model).map_err(scene_err)?;
    let (time_s, note) = outcome_note(&o);
    Ok(Run {
        inputs: st.to_f64(),
        time_s,
        rhs_evals: None,
        note,
    })
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

fn outcome_note<T: Real>(o: &Outcome<T>) -> (Option<f64>, String) {
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
        (Family::Closed, Precision::F64) => closed_run::<f64>(s, model),
        (Family::Closed, Precision::F32Libm) => closed_run::<f32>(s, model),
        (Family::Closed, Precision::F32Micromath) => closed_run::<MicroF32>(s, model),
        (Family::Closed, Precision::F32MicromathHwSqrt) => closed_run::<MicroF32HwSqrt>(s, model),
        (_, Precision::F64) => Ok(ode_run(method, s, model)),
        (_, Precision::F32Libm) => Ok(ode_run(method, &narrow::<f32>(s), model)),
        (_, Precision::F32Micromath) => Ok(ode_run(method, &narrow::<MicroF32>(s), model)),
        (_, Precision::F32MicromathHwSqrt) => {
            Ok(ode_run(method, &narrow::<MicroF32HwSqrt>(s), model))
        }
    }
}

/// Host ns per call of `method` in number type `T`.
fn time_in<T: Real>(method: &Method, s: &Scene<f64>, model: Model, budget: Budget) -> Timing {
    let st = narrow::<T>(s);
    if method.family == Family::Closed {
        return ns_per_call(budget, || residence(&st, model));
    }
    match ode_method(method, &st) {
        Some(m) => ns_per_call(budget, || particle::integrate_constant(&st, model, m)),
        None => Timing {
            median_ns: f64::NAN,
            min_ns: f64::NAN,
        },
    }
}

/// Host nanoseconds per call of `method` on `s`.
pub fn time(method: &Method, s: &Scene<f64>, model: Model, budget: Budget) -> Timing {
    match method.precision {
        Precision::F64 => time_in::<f64>(method, s, model, budget),
        Precision::F32Libm => time_in::<f32>(method, s, model, budget),
        Precision::F32Micromath => time_in::<MicroF32>(method, s, model, budget),
        Precision::F32MicromathHwSqrt => time_in::<MicroF32HwSqrt>(method, s, model, budget),
    }
}

pub(super) fn ref_time(s: &Scene<f64>, model: Model) -> Option<f64> {
    let rs = RefScene::from(s);
    let m = RefModel::from(model);
    match reference::outcome(&rs, m) {
        RefOutcome::Leaves { time_s, .. } => Some(time_s),
        RefOutcome::AtRim => Some(0.0),
        RefOutcome::NeverLeaves => None,
    }
}

/// An integration's outcome as the charts' CSV notes say it (`leaves`, `at-rim`,
/// `never-leaves`, `not-left-by T s`), never a Rust name.
pub(crate) fn ode_outcome_note<T: Real>(o: &ode::OdeOutcome<T>) -> String {
    match o {
        ode::OdeOutcome::Leaves { .. } => "leaves".into(),
        ode::OdeOutcome::AlreadyAtRim { .. } => "at-rim".into(),
        ode::OdeOutcome::NeverLeaves => "never-leaves".into(),
        ode::OdeOutcome::NotLeftBy { horizon_s, .. } => {
            format!("not-left-by {:.3e} s", horizon_s.to_f64())
        }
    }
}

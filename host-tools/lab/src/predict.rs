//! `bowl predict`: residence time and exit velocities of a particle (paper Eq. 5 to 12, corrected
//! per docs/model.md), for one scene from flags or for every row of a CSV file.
//!
//! The batch format and its all-or-nothing output: [`batch`].

use anyhow::{Result, anyhow};
use model_core::particle::{self, Model, Outcome, Scene};

mod batch;
pub(crate) mod bowl;
mod bowl_setup;
mod choice;
mod ends;
mod flags;
mod gave_up;
pub(crate) mod ode;
mod paper_text;
mod refusals;
mod release_json;
mod rolling;
mod rolling_words;
mod speed_range;
mod spin_up;
mod target;
mod throughput;
mod trace;
mod validity;
pub(crate) mod whole;

pub use bowl::BowlInputs;
pub use ends::{Ends, Leaves};
pub use flags::Given;
pub use refusals::ode as ode_words;
pub use refusals::scene as scene_words;
pub use rolling::RollingInputs;
pub use rolling::words as rolling_words;
pub use target::RunsOn;

/// Which model(s) to evaluate (`--model`; its help is the binary's).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModelChoice {
    /// The chooser picks flat or Coriolis.
    Auto,
    /// No Coriolis term.
    Flat,
    /// With the Coriolis term.
    Coriolis,
    /// Flat and Coriolis.
    Both,
    /// The tilted, precessing bowl (docs/model.md §9).
    Rolling,
    /// The real bowl (docs/model.md §10).
    Bowl,
}

/// How to compute the residence time (`--method`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MethodChoice {
    /// Exact to rounding.
    Closed,
    /// Explicit Euler.
    Euler,
    /// Symplectic Euler.
    SemiImplicit,
    /// Runge-Kutta 4.
    Rk4,
    /// Dormand-Prince 5(4).
    Dp54,
}

/// The inputs of `bowl predict` (the binary's flags, typed).
#[derive(Debug, Clone)]
pub struct Inputs {
    /// Combined bowl speed omega (paper Eq. 2), rad/s.
    pub omega_rad_s: f64,
    /// Effective rolling resistance coefficient mu (the paper's literal 0.4 makes nothing move).
    pub mu: f64,
    /// Start radius ri, m (the particle starts at rest).
    pub ri_m: f64,
    /// Rim radius R, m (0.1 m: a 200 mm bowl, reading the paper's sizes as diameters).
    pub rim_radius_m: f64,
    /// Gravity, m/s^2.
    pub g: f64,
    /// k2 = m rp^2 / (I + m rp^2): 5/7 solid sphere, 3/5 hollow.
    pub k2: f64,
    /// Model: auto (the chooser), flat, coriolis, both or rolling.
    pub model: ModelChoice,
    /// The chooser: relative tolerance on T (0.01 = 1 %).
    pub tolerance: Option<f64>,
    /// The chooser: the parameters' uncertainty, `mu=REL,radius_m=M,omega=REL` (default
    /// mu=0.2,radius_m=0.001,omega=0.01); the tolerance is a tenth of the spread it causes in T.
    pub uncertainty: Option<String>,
    /// The bowl speed from a logged run (bowl monitor --log, bowl replay --csv): the chooser
    /// decides between the closed form at the mean speed and an integrator over the trace.
    pub omega_trace: Option<std::path::PathBuf>,
    /// With --omega-trace: the device time of the release, ms (default: the log's first row).
    pub release_at_ms: Option<f64>,
    /// A spin-up, as a tuned speed loop drives it: the bowl starts at this speed, rad/s, and
    /// approaches --omega-rad-s with --time-constant-s; the particle is released at t = 0.
    /// The chooser picks the model and the integrator (from its precomputed error table when
    /// --tolerance is given).
    pub spin_up_from_rad_s: Option<f64>,
    /// With --spin-up-from-rad-s: the spin-up's time constant, s.
    pub time_constant_s: Option<f64>,
    /// Method: closed form or one of the integrators.
    pub method: MethodChoice,
    /// Fixed step of euler / semi-implicit / rk4, s (default: 0.01 / omega; with the rolling
    /// model's rk4 0.001 s, the bowl model's 0.0001 s).
    pub step_s: Option<f64>,
    /// Relative tolerance of dp54.
    pub tol: f64,
    /// Instead of the residence time: the bowl speed that gives this residence time, s.
    pub target_time_s: Option<f64>,
    /// The chooser: where the chosen plan runs: host (f64, priced in ns) or mcu (the
    /// Cortex-M4F: f32, priced in instructions).
    pub target: RunsOn,
    /// Print JSON instead of text.
    pub json: bool,
    /// Batch mode: read scenes from this CSV file (see the module docs for the columns).
    pub batch: Option<std::path::PathBuf>,
    /// Batch mode: write results to this CSV file.
    pub out: Option<std::path::PathBuf>,
    /// Batch mode: also measure the closed forms' throughput over the file's scenes (the time
    /// alone, ns per scene on one thread and on every core; JSON on standard output).
    pub throughput: bool,
    /// Batch mode: write every row, with a `status` column (`ok` or why the row was refused),
    /// instead of nothing when a row is refused; the exit status is still 1 if any row was.
    pub keep_going: bool,
    /// The rolling model's own flags.
    pub rolling: rolling::RollingInputs,
    /// The bowl model's own flags.
    pub bowl: bowl::BowlInputs,
    /// Which of the flags with a default were typed.
    pub given: flags::Given,
}

/// One computed result, whatever the method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prediction {
    /// The outcome (closed forms and integrators alike).
    pub outcome: Outcome<f64>,
    /// Right-hand-side evaluations (0 for closed forms).
    pub rhs_evaluations: u64,
    /// Steps taken (0 for closed forms).
    pub steps: u64,
    /// An integrator's answer against the closed form of the same scene: `None` for the
    /// closed form itself.
    pub check: Option<ode::StepCheck>,
}

pub(crate) fn model_name(m: Model) -> &'static str {
    match m {
        Model::Flat => "flat",
        Model::Coriolis => "coriolis",
    }
}

pub(crate) fn method_name(m: MethodChoice) -> &'static str {
    match m {
        MethodChoice::Closed => "closed",
        MethodChoice::Euler => "euler",
        MethodChoice::SemiImplicit => "semi-implicit",
        MethodChoice::Rk4 => "rk4",
        MethodChoice::Dp54 => "dp54",
    }
}

/// A method and its settings (`--method`, `--step-s`, `--tol`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MethodSettings {
    /// Closed form or one of the integrators.
    pub method: MethodChoice,
    /// Fixed step of euler / semi-implicit / rk4, s (`None`: 0.01 / omega).
    pub step_s: Option<f64>,
    /// Relative tolerance of dp54.
    pub tol: f64,
}

impl Inputs {
    /// `--method`, `--step-s` and `--tol`.
    pub fn method_settings(&self) -> MethodSettings {
        MethodSettings {
            method: self.method,
            step_s: self.step_s,
            tol: self.tol,
        }
    }
}

/// Computes one scene with one model and method.
pub fn predict(scene: &Scene<f64>, model: Model, how: &MethodSettings) -> Result<Prediction> {
    match how.method {
        MethodChoice::Closed => {
            let outcome =
                particle::residence(scene, model).map_err(|e| anyhow!(refusals::scene(e)))?;
            Ok(Prediction {
                outcome,
                rhs_evaluations: 0,
                steps: 0,
                check: None,
            })
        }
        _ => ode::predict(scene, model, how),
    }
}

/// Runs `bowl predict`.
pub fn run(args: &Inputs) -> Result<()> {
    if args.spin_up_from_rad_s.is_some()
        && (args.model != ModelChoice::Auto || args.method != MethodChoice::Closed)
    {
        anyhow::bail!(
            "--spin-up-from-rad-s lets the chooser pick the model and the method: leave out \
             --model and --method (give --tolerance or --uncertainty instead)"
        );
    }
    flags::refuse_unused(args)?;
    if args.model == ModelChoice::Rolling {
        return rolling::run(args, &args.rolling);
    }
    if args.model == ModelChoice::Bowl {
        return bowl::run(args, &args.rolling, &args.bowl);
    }
    if args.model == ModelChoice::Auto && whole::wanted(args) {
        return whole::run(args);
    }
    if whole::wanted(args) {
        // The paper's 1-D models know one combined speed on a level bowl: a tilt, the two
        // motor speeds or a rig file would otherwise be ignored without a word (the default
        // omega and R answered instead).
        anyhow::bail!(
            "--model {} is the paper's level bowl at one combined speed (--omega-rad-s, \
             --rim-radius-m): it takes no --axes-angle-deg, --precession-rad-s, --spin-rad-s \
             or --rig-file. Leave out --model (the chooser picks a tilted-bowl model), or \
             give --model rolling or bowl for the tilted, precessing bowl",
            match args.model {
                ModelChoice::Flat => "flat",
                ModelChoice::Coriolis => "coriolis",
                _ => "both",
            }
        );
    }
    if let (Some(input), Some(output)) = (&args.batch, &args.out) {
        return batch::run(input, output, args);
    }
    let scene = Scene {
        omega_rad_s: args.omega_rad_s,
        mu: args.mu,
        g_m_s2: args.g,
        k2: args.k2,
        ri_m: args.ri_m,
        rim_radius_m: args.rim_radius_m,
    };
    let need = choice::need(args.tolerance, args.uncertainty.as_deref())?;
    if let Some(path) = &args.omega_trace {
        if args.model != ModelChoice::Auto || args.method != MethodChoice::Closed {
            anyhow::bail!(
                "--omega-trace lets the chooser pick the model and the method: leave out \
                 --model and --method (give --tolerance or --uncertainty instead)"
            );
        }
        return trace::run(
            &scene,
            path,
            args.release_at_ms,
            &need,
            choice::states_omega(args.uncertainty.as_deref())?,
            args.target,
            args.json,
            args.rolling.sliding_mu(),
        );
    }
    if let (Some(start), Some(tau)) = (args.spin_up_from_rad_s, args.time_constant_s) {
        return spin_up::run(
            &scene,
            start,
            tau,
            &need,
            args.target,
            args.json,
            args.rolling.sliding_mu(),
        );
    }
    refusals::check(&scene)?;
    const BOTH: &[Model] = &[Model::Flat, Model::Coriolis];
    let mut chosen = None;
    let models: &[Model] = match args.model {
        ModelChoice::Flat => &[Model::Flat],
        ModelChoice::Coriolis => &[Model::Coriolis],
        ModelChoice::Both => BOTH,
        ModelChoice::Auto if args.target_time_s.is_some() => BOTH,
        ModelChoice::Auto => match target::constant(&scene, &need, args.target) {
            Ok(c) => {
                chosen = Some(c);
                match c.model {
                    Model::Flat => &[Model::Flat],
                    Model::Coriolis => &[Model::Coriolis],
                }
            }
            // Nothing to choose between: both models say so below.
            Err(model_core::choose::ChooseError::DoesNotLeave) => BOTH,
            Err(e) => anyhow::bail!(choice::error_words(e)),
        },
        ModelChoice::Rolling => return rolling::run(args, &args.rolling),
        ModelChoice::Bowl => return bowl::run(args, &args.rolling, &args.bowl),
    };
    if let Some(target) = args.target_time_s {
        return run_inverse(&scene, models, target, args);
    }
    let mut rows = Vec::new();
    for &model in models {
        let p = predict(&scene, model, &args.method_settings())?;
        if let Some(warning) = p.check.as_ref().and_then(ode::StepCheck::warning) {
            eprintln!("warning: {} model: {warning}", model_name(model));
        }
        rows.push((model, p));
    }
    let sliding_mu = args.rolling.sliding_mu();
    let validity: Vec<_> = rows
        .iter()
        .map(|(_, p)| validity::paper(&scene, &p.outcome, sliding_mu))
        .collect();
    if args.json {
        let results: Vec<_> = rows
            .iter()
            .zip(&validity)
            .map(|((m, p), v)| {
                let mut r = json_result(*m, args.method, p);
                v.add_to(&mut r);
                r
            })
            .collect();
        let mut v = serde_json::json!({ "scene": json_scene(&scene), "results": results });
        if let (Some(c), Some(obj)) = (&chosen, v.as_object_mut()) {
            obj.insert("choice".into(), choice::json(c, args.target));
        }
        println!("{v}");
    } else {
        for ((m, _), v) in rows.iter().zip(&validity) {
            if let Some(line) = v.text_line(model_name(*m)) {
                println!("{line}");
            }
        }
        println!("{}", paper_text::describe_scene(&scene));
        if let Some(c) = &chosen {
            println!(
                "{}\n  (--model flat, coriolis or both to override)",
                choice::describe(c, &need, args.target)
            );
        }
        for (m, p) in &rows {
            println!("{}", paper_text::describe(&scene, *m, args.method, p));
        }
    }
    Ok(())
}

fn json_scene(s: &Scene<f64>) -> serde_json::Value {
    serde_json::json!({
        "omega_rad_s": s.omega_rad_s, "mu": s.mu, "g_m_s2": s.g_m_s2, "k2": s.k2,
        "ri_m": s.ri_m, "rim_radius_m": s.rim_radius_m,
        "equilibrium_radius_m": finite_or_null(s.equilibrium_radius_m()),
    })
}

fn finite_or_null(x: f64) -> serde_json::Value {
    if x.is_finite() {
        serde_json::json!(x)
    } else {
        serde_json::Value::Null
    }
}

fn json_result(model: Model, method: MethodChoice, p: &Prediction) -> serde_json::Value {
    let mut base = serde_json::json!({
        "model": model_name(model), "method": method_name(method),
        "rhs_evaluations": p.rhs_evaluations, "steps": p.steps,
    });
    if let (Some(c), Some(obj)) = (&p.check, base.as_object_mut()) {
        obj.insert(
            "error_vs_closed_form".into(),
            c.relative_error
                .map_or(serde_json::Value::Null, |e| serde_json::json!(e)),
        );
        obj.insert("step_warning".into(), serde_json::json!(c.warning()));
    }
    let extra = match Ends::from(p.outcome) {
        Ends::Leaves(l) => serde_json::json!({
            "outcome": "leaves", "residence_time_s": l.residence_time_s,
            "exit_radial_velocity_m_s": l.exit_radial_velocity_m_s,
            "exit_total_velocity_m_s": l.exit_total_velocity_m_s,
            "condition_number": l.condition_number, "ill_conditioned": l.ill_conditioned,
        }),
        Ends::AtRim {
            exit_total_velocity_m_s,
        } => serde_json::json!({
            "outcome": "already_at_rim", "residence_time_s": 0.0,
            "exit_radial_velocity_m_s": 0.0,
            "exit_total_velocity_m_s": exit_total_velocity_m_s,
        }),
        Ends::Never {
            equilibrium_radius_m,
            near_threshold,
        } => serde_json::json!({
            "outcome": "never_leaves", "residence_time_s": null,
            "equilibrium_radius_m": finite_or_null(equilibrium_radius_m),
            "near_threshold": near_threshold,
        }),
    };
    let mut v = base;
    if let (Some(obj), serde_json::Value::Object(more)) = (v.as_object_mut(), extra) {
        obj.extend(more);
    }
    v
}

/// The bowl speed that gives `target` s, for each of `models`; each answer carries whether the
/// model holds at that speed (`valid`, `invalid_reason`; the text says it first), judged as the
/// forward answer at that speed is: the speed for a short T often makes the granule slide, and
/// the inverse said nothing of it while `--omega-rad-s` at the same speed said NOT VALID.
fn run_inverse(scene: &Scene<f64>, models: &[Model], target: f64, args: &Inputs) -> Result<()> {
    let mut out = Vec::new();
    for &model in models {
        let w = particle::omega_for_residence_time(scene, model, target).map_err(|e| {
            anyhow!(
                "no bowl speed for T = {target} s ({} model): {}",
                model_name(model),
                refusals::inverse(e, target)
            )
        })?;
        let validity = validity::paper_up_to(scene, model, w, args.rolling.sliding_mu());
        out.push((model, w, validity));
    }
    if args.json {
        let v: Vec<_> = out
            .iter()
            .map(|(m, w, validity)| {
                let mut r = serde_json::json!({"model": model_name(*m), "target_time_s": target, "omega_rad_s": w});
                validity.add_to(&mut r);
                r
            })
            .collect();
        println!(
            "{}",
            serde_json::json!({ "scene": json_scene(scene), "inverse": v })
        );
    } else {
        for (m, _, validity) in &out {
            if let Some(line) = validity.text_line(model_name(*m)) {
                println!("{line}");
            }
        }
        for (m, w, _) in out {
            println!(
                "{:<8} omega = {w:.9} rad/s gives T = {target} s",
                model_name(m)
            );
        }
    }
    Ok(())
}

//! `bowl predict`: residence time and exit velocities of a particle (paper Eq. 5 to 12, corrected
//! per docs/model.md), for one scene from flags or for every row of a CSV file.
//!
//! The batch format and its all-or-nothing output: [`batch`].

use anyhow::{Result, anyhow};
use model_core::particle::{self, Model, Outcome, Scene};

mod batch;
mod bowl;
mod choice;
pub(crate) mod ode;
mod refusals;
mod rolling;
mod spin_up;
mod target;
mod throughput;
mod trace;
mod validity;

pub use refusals::scene as scene_words;
pub use rolling::words as rolling_words;

/// Which model(s) to evaluate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ModelChoice {
    /// The chooser picks the least model the scene needs (the tolerance from --tolerance or
    /// --uncertainty) and says why.
    Auto,
    /// Paper Eq. 5 to 7: no Coriolis term.
    Flat,
    /// Paper Eq. 9 to 11 with the corrected A, B.
    Coriolis,
    /// Both, side by side.
    Both,
    /// The granule rolling on the tilted, precessing bowl (docs/model.md §9): needs
    /// --precession-rad-s, --spin-rad-s and --axes-angle-deg.
    Rolling,
    /// The granule rolling or sliding in the real bowl, wall and lip included (docs/model.md
    /// §10): the rolling model's flags and --sliding-mu, --wall-angle-deg, --wall-height-m,
    /// --fillet-radius-m, --restitution, --max-time-s.
    Bowl,
}

/// How to compute the residence time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodChoice {
    /// The closed forms (log1p / bracketed Newton): exact to rounding.
    Closed,
    /// Explicit Euler with fixed step --step-s.
    Euler,
    /// Semi-implicit (symplectic) Euler with fixed step --step-s.
    SemiImplicit,
    /// Classical Runge-Kutta 4 with fixed step --step-s.
    Rk4,
    /// Adaptive Dormand-Prince 5(4) with tolerance --tol, dense-output event location.
    Dp54,
}

/// Flags of `bowl predict`.
#[derive(clap::Args)]
pub struct Args {
    /// Combined bowl speed omega (paper Eq. 2), rad/s.
    #[arg(long, visible_alias = "w-rad-s", default_value_t = 3.0)]
    omega_rad_s: f64,
    /// Effective rolling resistance coefficient mu (the paper's literal 0.4 makes nothing move).
    #[arg(long, default_value_t = 0.029)]
    mu: f64,
    /// Start radius ri, m (the particle starts at rest).
    #[arg(long, default_value_t = 0.05)]
    ri_m: f64,
    /// Rim radius R, m (0.1 m: a 200 mm bowl, reading the paper's sizes as diameters).
    #[arg(long, visible_alias = "r-m", default_value_t = 0.1)]
    rim_radius_m: f64,
    /// Gravity, m/s^2.
    #[arg(long, default_value_t = 9.81)]
    g: f64,
    /// k2 = m rp^2 / (I + m rp^2): 5/7 solid sphere, 3/5 hollow.
    #[arg(long, default_value_t = 5.0 / 7.0)]
    k2: f64,
    /// Model: auto (the chooser), flat, coriolis, both or rolling.
    #[arg(long, value_enum, default_value_t = ModelChoice::Auto)]
    model: ModelChoice,
    /// The chooser: relative tolerance on T (0.01 = 1 %).
    #[arg(long, conflicts_with = "uncertainty")]
    tolerance: Option<f64>,
    /// The chooser: the parameters' uncertainty, `mu=REL,radius_m=M,omega=REL` (default
    /// mu=0.2,radius_m=0.001,omega=0.01); the tolerance is a tenth of the spread it causes in T.
    #[arg(long, value_name = "mu=REL,radius_m=M,omega=REL")]
    uncertainty: Option<String>,
    /// The bowl speed from a logged run (bowl monitor --log, bowl replay --csv): the chooser
    /// decides between the closed form at the mean speed and an integrator over the trace.
    #[arg(long, value_name = "RUN.csv")]
    omega_trace: Option<std::path::PathBuf>,
    /// With --omega-trace: the device time of the release, ms (default: the log's first row).
    #[arg(long, requires = "omega_trace")]
    release_at_ms: Option<f64>,
    /// A spin-up, as a tuned speed loop drives it: the bowl starts at this speed, rad/s, and
    /// approaches --omega-rad-s with --time-constant-s; the particle is released at t = 0.
    /// The chooser picks the model and the integrator (from its precomputed error table when
    /// --tolerance is given).
    #[arg(
        long,
        requires = "time_constant_s",
        conflicts_with_all = ["omega_trace", "batch", "target_time_s"]
    )]
    spin_up_from_rad_s: Option<f64>,
    /// With --spin-up-from-rad-s: the spin-up's time constant, s.
    #[arg(long, requires = "spin_up_from_rad_s")]
    time_constant_s: Option<f64>,
    /// Method: closed form or one of the integrators.
    #[arg(long, value_enum, default_value_t = MethodChoice::Closed)]
    method: MethodChoice,
    /// Fixed step of euler / semi-implicit / rk4, s (default: 0.01 / omega).
    #[arg(long, visible_alias = "step")]
    step_s: Option<f64>,
    /// Relative tolerance of dp54.
    #[arg(long, default_value_t = 1e-9)]
    tol: f64,
    /// Instead of the residence time: the bowl speed that gives this residence time, s.
    #[arg(long)]
    target_time_s: Option<f64>,
    /// The chooser: where the chosen plan runs: host (f64, priced in ns) or mcu (the
    /// Cortex-M4F: f32, priced in instructions).
    #[arg(long, value_enum, default_value_t = target::RunsOn::Host)]
    target: target::RunsOn,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    /// Batch mode: read scenes from this CSV file (see the module docs for the columns).
    #[arg(long, requires = "out")]
    batch: Option<std::path::PathBuf>,
    /// Batch mode: write results to this CSV file.
    #[arg(long, requires = "batch")]
    out: Option<std::path::PathBuf>,
    /// Batch mode: also measure the closed forms' throughput over the file's scenes (the time
    /// alone, ns per scene on one thread and on every core; JSON on standard output).
    #[arg(long, requires = "batch")]
    throughput: bool,
    /// Batch mode: write every row, with a `status` column (`ok` or why the row was refused),
    /// instead of nothing when a row is refused; the exit status is still 1 if any row was.
    #[arg(long, requires = "batch")]
    keep_going: bool,
    /// The rolling model's own flags.
    #[command(flatten)]
    rolling: rolling::RollingArgs,
    /// The bowl model's own flags.
    #[command(flatten)]
    bowl: bowl::BowlArgs,
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

fn method_name(m: MethodChoice) -> &'static str {
    match m {
        MethodChoice::Closed => "closed",
        MethodChoice::Euler => "euler",
        MethodChoice::SemiImplicit => "semi-implicit",
        MethodChoice::Rk4 => "rk4",
        MethodChoice::Dp54 => "dp54",
    }
}

/// Computes one scene with one model and method.
pub fn predict(
    scene: &Scene<f64>,
    model: Model,
    method: MethodChoice,
    step_s: Option<f64>,
    tol: f64,
) -> Result<Prediction> {
    match method {
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
        other => ode::predict(scene, model, other, step_s, tol),
    }
}

/// Runs `bowl predict`.
pub fn run(args: &Args) -> Result<()> {
    if args.spin_up_from_rad_s.is_some()
        && (args.model != ModelChoice::Auto || args.method != MethodChoice::Closed)
    {
        anyhow::bail!(
            "--spin-up-from-rad-s lets the chooser pick the model and the method: leave out \
             --model and --method (give --tolerance or --uncertainty instead)"
        );
    }
    if args.model == ModelChoice::Rolling {
        return rolling::run(args, &args.rolling);
    }
    if args.model == ModelChoice::Bowl {
        return bowl::run(args, &args.rolling, &args.bowl);
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
        return run_inverse(&scene, models, target, args.json);
    }
    let mut rows = Vec::new();
    for &model in models {
        let p = predict(&scene, model, args.method, args.step_s, args.tol)?;
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
            if let Some(line) = v.text_line() {
                println!("{} model {line}", model_name(*m));
            }
        }
        println!("{}", describe_scene(&scene));
        if let Some(c) = &chosen {
            println!(
                "{}\n  (--model flat, coriolis or both to override)",
                choice::describe(c, &need, args.target)
            );
        }
        for (m, p) in &rows {
            println!("{}", describe(&scene, *m, args.method, p));
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
    let extra = match p.outcome {
        Outcome::Leaves {
            residence_time_s,
            exit_radial_velocity_m_s,
            exit_total_velocity_m_s,
            condition_number,
            ill_conditioned,
        } => serde_json::json!({
            "outcome": "leaves", "residence_time_s": residence_time_s,
            "exit_radial_velocity_m_s": exit_radial_velocity_m_s,
            "exit_total_velocity_m_s": exit_total_velocity_m_s,
            "condition_number": condition_number, "ill_conditioned": ill_conditioned,
        }),
        Outcome::AlreadyAtRim {
            exit_total_velocity_m_s,
        } => serde_json::json!({
            "outcome": "already_at_rim", "residence_time_s": 0.0,
            "exit_radial_velocity_m_s": 0.0,
            "exit_total_velocity_m_s": exit_total_velocity_m_s,
        }),
        Outcome::NeverLeaves {
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

fn describe_scene(s: &Scene<f64>) -> String {
    format!(
        "scene: omega {} rad/s, mu {}, g {} m/s^2, k2 {:.6}, ri {} m, R {} m; equilibrium radius a = mu g / omega^2 = {:.6} m",
        s.omega_rad_s,
        s.mu,
        s.g_m_s2,
        s.k2,
        s.ri_m,
        s.rim_radius_m,
        s.equilibrium_radius_m()
    )
}

fn describe(scene: &Scene<f64>, model: Model, method: MethodChoice, p: &Prediction) -> String {
    let head = format!("{:<8} {:<13}", model_name(model), method_name(method));
    let cost = if p.rhs_evaluations > 0 {
        format!(
            " [{} steps, {} rhs evaluations]",
            p.steps, p.rhs_evaluations
        )
    } else {
        String::new()
    };
    match p.outcome {
        Outcome::Leaves {
            residence_time_s,
            exit_radial_velocity_m_s,
            exit_total_velocity_m_s,
            condition_number,
            ill_conditioned,
        } => format!(
            "{head} leaves after T = {residence_time_s:.9} s; exit radial {exit_radial_velocity_m_s:.6} m/s, total {exit_total_velocity_m_s:.6} m/s; condition {condition_number:.3}{}{cost}",
            if ill_conditioned {
                " (ILL-CONDITIONED: start just above the threshold a)"
            } else {
                ""
            }
        ),
        Outcome::AlreadyAtRim {
            exit_total_velocity_m_s,
        } => {
            format!("{head} starts at the rim: T = 0, exit total {exit_total_velocity_m_s:.6} m/s")
        }
        Outcome::NeverLeaves {
            equilibrium_radius_m,
            near_threshold,
        } => format!(
            "{head} NEVER LEAVES: {}{}",
            refusals::what_holds(scene, equilibrium_radius_m),
            if near_threshold {
                " (within rounding of the threshold)"
            } else {
                ""
            }
        ),
    }
}

fn run_inverse(scene: &Scene<f64>, models: &[Model], target: f64, json: bool) -> Result<()> {
    let mut out = Vec::new();
    for &model in models {
        let w = particle::omega_for_residence_time(scene, model, target).map_err(|e| {
            anyhow!(
                "no bowl speed for T = {target} s ({} model): {}",
                model_name(model),
                refusals::inverse(e, target)
            )
        })?;
        out.push((model, w));
    }
    if json {
        let v: Vec<_> = out
            .iter()
            .map(|(m, w)| serde_json::json!({"model": model_name(*m), "target_time_s": target, "omega_rad_s": w}))
            .collect();
        println!(
            "{}",
            serde_json::json!({ "scene": json_scene(scene), "inverse": v })
        );
    } else {
        for (m, w) in out {
            println!(
                "{:<8} omega = {w:.9} rad/s gives T = {target} s",
                model_name(m)
            );
        }
    }
    Ok(())
}

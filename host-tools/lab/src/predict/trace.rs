//! `bowl predict --omega-trace run.csv`: the bowl speed of a logged run (`bowl monitor --log`,
//! `bowl replay --csv`, the demo's telemetry.csv: the `bowl_mrad_s` column against
//! `device_time_ms`), from the release on, as the speed the particle sees.

use std::path::Path;

use anyhow::{Context, Result, anyhow, bail};

/// The trace from the release: times (s after it) and bowl speeds (rad/s).
pub struct Trace {
    /// Seconds after the release.
    pub times_s: Vec<f64>,
    /// Combined bowl speed omega (paper Eq. 2), rad/s.
    pub omega_rad_s: Vec<f64>,
    /// Device time of the release, ms.
    pub release_ms: f64,
}

/// Reads the rows of one boot from `release_ms` on (default: the log's first telemetry row).
pub fn read(path: &Path, release_ms: Option<f64>) -> Result<Trace> {
    let mut log = rig_client::telemetry_csv::LogReader::open(path)?;
    let (time, omega) = (log.column("device_time_ms")?, log.column("bowl_mrad_s")?);
    let boot_col = log.optional("boot");
    let mut trace = Trace {
        times_s: Vec::new(),
        omega_rad_s: Vec::new(),
        release_ms: f64::NAN,
    };
    let mut boot: Option<String> = None;
    for (i, record) in log.reader.records().enumerate() {
        let line = i + 2;
        let r = record.with_context(|| format!("{}: line {line}", path.display()))?;
        let cell = |k: usize| r.get(k).unwrap_or("").trim();
        // Link event rows carry no telemetry.
        let (Ok(t_ms), Ok(w_mrad_s)) = (cell(time).parse::<f64>(), cell(omega).parse::<f64>())
        else {
            continue;
        };
        if release_ms.is_some_and(|at| t_ms < at) {
            continue;
        }
        let this_boot = boot_col.map(|k| cell(k).to_string()).unwrap_or_default();
        match &boot {
            None => {
                trace.release_ms = release_ms.unwrap_or(t_ms);
                boot = Some(this_boot);
            }
            // The rig restarted: its speed after that is another run.
            Some(b) if *b != this_boot => break,
            Some(_) => {}
        }
        let t_s = (t_ms - trace.release_ms) / 1000.0;
        if trace.times_s.last().is_some_and(|&last| t_s <= last) {
            bail!(
                "{}: line {line}: device time {t_ms} ms does not follow the row before",
                path.display()
            );
        }
        trace.times_s.push(t_s);
        trace.omega_rad_s.push(w_mrad_s / 1000.0);
    }
    if trace.times_s.is_empty() {
        bail!(
            "{}: no telemetry rows{}",
            path.display(),
            release_ms.map_or(String::new(), |at| format!(" at or after {at} ms"))
        );
    }
    // The first row may come after the release: its speed holds from the release on.
    if trace.times_s[0] > 0.0 {
        trace.times_s.insert(0, 0.0);
        let w0 = trace.omega_rad_s[0];
        trace.omega_rad_s.insert(0, w0);
    }
    Ok(trace)
}

/// Runs `bowl predict --omega-trace`: the chooser picks the model and the method for the
/// trace, and the chosen plan computes the residence time; `sliding_mu` judges whether the
/// paper's rolling holds up to the trace's top speed.
#[allow(clippy::too_many_arguments)]
pub fn run(
    scene: &model_core::particle::Scene<f64>,
    path: &Path,
    release_ms: Option<f64>,
    need: &model_core::choose::Need<f64>,
    omega_stated: bool,
    runs_on: super::target::RunsOn,
    json: bool,
    sliding_mu: f64,
) -> Result<()> {
    use model_core::choose::{LOGGED_SPEED_RESOLUTION_RAD_S, Need, Plan, SampledOmega, TraceError};
    use model_core::particle;

    scene
        .validate_except_omega()
        .map_err(|e| anyhow!(super::refusals::scene(e)))?;
    let trace = read(path, release_ms)?;
    let profile = SampledOmega::new(&trace.times_s, &trace.omega_rad_s).map_err(|e| match e {
        TraceError::Empty => anyhow!("{}: no speed samples", path.display()),
        TraceError::TimeNotIncreasing { index } => anyhow!(
            "{}: sample {index}: the device time does not increase",
            path.display()
        ),
        TraceError::BadSpeed { index } => anyhow!(
            "{}: sample {index}: the bowl speed is negative or not a number",
            path.display()
        ),
    })?;
    // The speed the particle saw is known as well as the trace measured it: that, not the
    // loop's default 1 %, is omega's uncertainty unless --uncertainty states one.
    // Judged over twice a first estimate of the residence time (the whole trace without one
    // or beyond its end).
    let window_s = model_core::choose::residence_estimate_s(scene, &profile)
        .map_or(f64::INFINITY, |t| 2.0 * t);
    let measured = profile.measurement(LOGGED_SPEED_RESOLUTION_RAD_S, window_s);
    let measured_is_used = matches!(need, Need::Uncertainty(_)) && !omega_stated;
    let need = match *need {
        Need::Uncertainty(k) if measured_is_used => {
            Need::Uncertainty(model_core::choose::Knowledge {
                omega_rel: measured.relative,
                ..k
            })
        }
        other => other,
    };
    let choice = super::target::trace(
        scene,
        &need,
        &profile,
        &trace.times_s,
        &trace.omega_rad_s,
        runs_on,
    )
    .map_err(|e| match e {
        super::target::TraceChoiceError::Choose(e) => anyhow!(super::choice::error_words(e)),
        super::target::TraceChoiceError::Trace(TraceError::TimeNotIncreasing { index }) => {
            anyhow!(
                "{}: sample {index}: in f32, as the Cortex-M4F holds it, its time is not after \
                 the one before (closer than f32 can tell apart there): use --target host",
                path.display()
            )
        }
        super::target::TraceChoiceError::Trace(_) => anyhow!(
            "{}: the trace does not fit in f32 as the Cortex-M4F holds it: use --target host",
            path.display()
        ),
    })?;
    // Where the plan is a DP5(4) run the pilot made, the pilot's finer one (f64, on the host)
    // answers within the plan's budget: the plan needs no run of its own.
    let answered = match runs_on {
        super::target::RunsOn::Host => choice.answer_s,
        super::target::RunsOn::Mcu => None,
    };
    let time_s = match choice.plan {
        Plan::ClosedForm => 0.0,
        Plan::ClosedFormAtMeanSpeed { omega_rad_s } => {
            let at_mean = particle::Scene {
                omega_rad_s,
                ..*scene
            };
            particle::residence(&at_mean, choice.model)
                .map_err(|e| anyhow!(super::refusals::scene(e)))?
                .residence_time_s()
        }
        Plan::Integrate(method) => match answered {
            Some(t) => t,
            None => super::ode::plan_time_s(scene, choice.model, &profile, method)?,
        },
    };
    let (lo, hi) = trace
        .omega_rad_s
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), &w| {
            (lo.min(w), hi.max(w))
        });
    let covered_s = trace.times_s.last().copied().unwrap_or(0.0);
    // Past the trace's end the whole trace was judged.
    let window_s = if window_s < covered_s {
        window_s
    } else {
        f64::INFINITY
    };
    let validity = super::validity::paper_up_to(scene, choice.model, hi, sliding_mu);
    let head = serde_json::json!({
        "trace": {
            "file": path.display().to_string(), "samples": trace.times_s.len(),
            "release_device_ms": trace.release_ms, "covers_s": covered_s,
            "omega_min_rad_s": lo, "omega_max_rad_s": hi,
            "measurement": {
                "rounding_rad_s": measured.rounding_rad_s,
                "scatter_rad_s": measured.scatter_rad_s,
                "mean_rad_s": measured.mean_rad_s,
                "relative": measured.relative,
                "used_as_omega_uncertainty": measured_is_used,
                "judged_over_s": window_s.min(covered_s),
            },
        },
        "residence_time_from_choosing": answered.is_some(),
    });
    let choice_json = super::choice::json(&choice, runs_on);
    if validity.start_answer(json, choice.model, head, choice_json, time_s) {
        println!(
            "trace: {}, {} samples from device time {} ms over {covered_s:.3} s, bowl speed \
             {lo:.3} to {hi:.3} rad/s (held at the last sample after that)",
            path.display(),
            trace.times_s.len(),
            trace.release_ms
        );
        println!(
            "{}",
            measurement_words(&measured, window_s, measured_is_used, &need, omega_stated)
        );
        println!("{}", super::choice::describe(&choice, &need, runs_on));
        if answered.is_some() {
            println!(
                "  T below comes from the choosing runs (their DP5(4) run at a tenth of the plan's \
                 rtol): the plan needed no run of its own"
            );
        }
        println!("{}", super::ode::plan_time_line(choice.model, time_s));
    }
    Ok(())
}

/// How well the trace knows the speed, and what the chooser made of it.
fn measurement_words(
    m: &model_core::choose::TraceMeasurement<f64>,
    judged_over_s: f64,
    used: bool,
    need: &model_core::choose::Need<f64>,
    omega_stated: bool,
) -> String {
    use model_core::choose::Need;
    let over = if judged_over_s.is_finite() {
        format!("over its first {judged_over_s:.3} s (twice a first estimate of T)")
    } else {
        "over the whole trace".into()
    };
    let known = format!(
        "{over} the trace knows the speed to +-{:.3} % of its mean {:.3} rad/s (+-{:.1} \
         mrad/s logged to whole mrad/s, {:.2} mrad/s RMS scatter about its neighbours' line)",
        100.0 * m.relative,
        m.mean_rad_s,
        1e3 * m.rounding_rad_s,
        1e3 * m.scatter_rad_s
    );
    match need {
        _ if used => format!("{known}: that is omega's uncertainty below"),
        Need::Uncertainty(_) if omega_stated => {
            format!("{known}; --uncertainty states omega's instead")
        }
        Need::Tolerance(t) if *t < 0.1 * m.relative => format!(
            "{known}: T is computed to the tolerance on the trace as logged, but a tolerance \
             below a tenth of that is finer than the speed the particle saw is known"
        ),
        _ => known,
    }
}

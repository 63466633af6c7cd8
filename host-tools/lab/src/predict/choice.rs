//! `bowl predict`'s default: the chooser (`model_core::choose`) picks the model and says why.
//!
//! The tolerance comes from `--tolerance REL`, or from the parameters' uncertainty
//! (`--uncertainty mu=0.2,radius_m=0.001,omega=0.01`, those values by default: the effective
//! resistance is a fit known to about 20 %, the radii to a millimetre, the speed loop holds 1 %).

use anyhow::{Result, anyhow, bail};
use model_core::choose::{Choice, ChooseError, Knowledge, Need, Plan, Source};
use model_core::ode::Method;
use model_core::particle::Model;

use super::target::RunsOn;
use super::{model_name, refusals};

/// The parameters' uncertainty used when neither `--tolerance` nor `--uncertainty` is given.
pub const DEFAULT_KNOWLEDGE: Knowledge<f64> = Knowledge {
    mu_rel: 0.2,
    radius_m: 0.001,
    omega_rel: 0.01,
};

/// `--uncertainty mu=REL,radius_m=M,omega=REL` (keys left out keep their defaults).
pub fn parse_uncertainty(spec: &str) -> Result<Knowledge<f64>> {
    parse_uncertainty_keys(spec).map(|(k, _)| k)
}

/// True when `--uncertainty` states the speed's uncertainty itself (`omega=`); otherwise a
/// logged trace's own measurement takes the default's place.
pub fn states_omega(uncertainty: Option<&str>) -> Result<bool> {
    uncertainty.map_or(Ok(false), |spec| {
        parse_uncertainty_keys(spec).map(|(_, omega)| omega)
    })
}

/// [`parse_uncertainty`], and whether `omega` was among the keys.
fn parse_uncertainty_keys(spec: &str) -> Result<(Knowledge<f64>, bool)> {
    let mut k = DEFAULT_KNOWLEDGE;
    let mut omega_given = false;
    for part in spec.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (key, value) = part.split_once('=').ok_or_else(|| {
            anyhow!("--uncertainty: `{part}` is not KEY=VALUE (keys: mu, radius_m, omega)")
        })?;
        let x: f64 = value
            .trim()
            .parse()
            .map_err(|_| anyhow!("--uncertainty: {key} = {value:?} is not a number"))?;
        if !(x.is_finite() && x >= 0.0) {
            bail!("--uncertainty: {key} = {x} must be zero or positive");
        }
        // mu and omega are relative: beyond 1 (100 %) the low end is a negative resistance
        // or speed, and the spread of T comes out infinite.
        if matches!(key.trim(), "mu" | "omega") && x > 1.0 {
            bail!(
                "--uncertainty: {key} = {x} is a relative uncertainty and must be at most 1 \
                 (100 %); e.g. mu=0.2 for +-20 %"
            );
        }
        match key.trim() {
            "mu" => k.mu_rel = x,
            "radius_m" => k.radius_m = x,
            "omega" => {
                k.omega_rel = x;
                omega_given = true;
            }
            other => bail!(
                "--uncertainty: unknown key `{other}` (keys: mu (relative), radius_m (m), \
                 omega (relative))"
            ),
        }
    }
    Ok((k, omega_given))
}

/// What the answer must meet, from the flags.
pub fn need(tolerance: Option<f64>, uncertainty: Option<&str>) -> Result<Need<f64>> {
    match (tolerance, uncertainty) {
        (Some(_), Some(_)) => bail!(
            "give --tolerance or --uncertainty, not both: the tolerance is either stated or \
             derived from the uncertainty"
        ),
        (Some(t), None) if t.is_finite() && t > 0.0 && t <= 0.1 => Ok(Need::Tolerance(t)),
        (Some(t), None) => bail!(
            "--tolerance {t}: a relative tolerance on T between 0 and 0.1 (0.01 = 1 %), \
             excluding 0"
        ),
        (None, Some(spec)) => Ok(Need::Uncertainty(parse_uncertainty(spec)?)),
        (None, None) => Ok(Need::Uncertainty(DEFAULT_KNOWLEDGE)),
    }
}

/// Why the chooser could not choose, in plain words.
pub fn error_words(e: ChooseError) -> String {
    match e {
        ChooseError::Scene(s) => refusals::scene(s),
        ChooseError::InvalidKnowledge => {
            "the tolerance or an uncertainty is not a finite, non-negative number".into()
        }
        ChooseError::DoesNotLeave => {
            "at these parameters the particle never leaves: there is no residence time to \
             compute"
                .into()
        }
        ChooseError::Ode(_) => "an integration failed while calibrating the methods".into(),
        ChooseError::NoMethodMeetsTolerance => {
            "no integrator met the tolerance within the step limit: ask for a looser \
             --tolerance"
                .into()
        }
    }
}

/// The plan in words: `closed form`, `rk4, step 2.1 ms`, ...
pub fn plan_words(plan: &Plan<f64>) -> String {
    match plan {
        Plan::ClosedForm => "closed form".into(),
        Plan::ClosedFormAtMeanSpeed { omega_rad_s } => {
            format!("closed form at the trace's mean speed {omega_rad_s:.6} rad/s")
        }
        Plan::Integrate(Method::Rk4 { step_s }) => format!("rk4, step {:.3} ms", step_s * 1e3),
        Plan::Integrate(Method::SemiImplicitEuler { step_s }) => {
            format!("semi-implicit euler, step {:.3} ms", step_s * 1e3)
        }
        Plan::Integrate(Method::Euler { step_s }) => {
            format!("euler, step {:.3} ms", step_s * 1e3)
        }
        Plan::Integrate(Method::Dp54 { rtol, .. }) => format!("dp54, rtol {rtol:.1e}"),
    }
}

/// `x` in percent: three decimals, or two significant digits below 0.01 % (a tolerance of
/// 1e-6 must not read as 0.000 %).
/// A relative value as a percentage that keeps its digits at the small end (a tolerance of
/// 1e-9 printed with two decimals read "0.00 %").
pub(crate) fn percent(x: f64) -> String {
    let p = 100.0 * x;
    if p != 0.0 && p.abs() < 0.01 {
        format!("{p:.1e} %")
    } else {
        format!("{p:.3} %")
    }
}

/// True when the parameters' uncertainty moves `T` more than the Coriolis term does: the
/// paper's flat-bowl idealisation is then not the largest error.
pub fn coriolis_below_uncertainty(c: &Choice<f64>) -> bool {
    c.spread_rel.is_some_and(|s| c.coriolis_effect_rel <= s)
}

/// The error the choice claims, relative: the method's (integrator or closed form), the model's
/// own (for the flat model, the Coriolis term it leaves out), and their sum, the bound on T's
/// error against the Coriolis model that the tolerance is about.
pub fn claimed_error(c: &Choice<f64>) -> (f64, f64, f64) {
    let method = if matches!(c.plan, Plan::ClosedForm) {
        0.0
    } else {
        c.estimated_error_rel
    };
    let model = if c.model == Model::Flat {
        c.coriolis_effect_rel
    } else {
        0.0
    };
    (method, model, method + model)
}

/// The choice and its reasons, for the text output.
pub fn describe(c: &Choice<f64>, need: &Need<f64>, runs_on: RunsOn) -> String {
    let tolerance = match (need, c.spread_rel) {
        (Need::Uncertainty(k), Some(spread)) if spread.is_finite() => format!(
            "the tolerance {}, a tenth of the {} spread of T over the parameters' uncertainty \
             (mu +-{:.0} %, radii +-{} mm, omega +-{:.1} %)",
            percent(c.tolerance_rel),
            percent(spread),
            100.0 * k.mu_rel,
            1e3 * k.radius_m,
            100.0 * k.omega_rel
        ),
        // An uncertainty that lets the granule stay in the bowl spreads T without bound: said
        // so, not "the inf % spread" (nor "asked for": nothing was asked).
        (Need::Uncertainty(k), _) => format!(
            "the tolerance {}, the chooser's largest: the parameters' uncertainty (mu +-{:.0} %, \
             radii +-{} mm, omega +-{:.1} %) spreads T without bound (within it the granule may \
             never leave)",
            percent(c.tolerance_rel),
            100.0 * k.mu_rel,
            1e3 * k.radius_m,
            100.0 * k.omega_rel
        ),
        (Need::Tolerance(asked), _) if c.tolerance_rel > *asked * (1.0 + 1e-6) => format!(
            "the tolerance {} ({:.2e} asked for, raised to 64 rounding units of the precision \
             the plan runs in)",
            percent(c.tolerance_rel),
            asked
        ),
        _ => format!("the tolerance {} asked for", percent(c.tolerance_rel)),
    };
    let why = if c.model == Model::Flat {
        format!(
            "the Coriolis term changes T by {}, within {tolerance}",
            percent(c.coriolis_effect_rel)
        )
    } else if c.coriolis_effect_rel > c.tolerance_rel {
        format!(
            "the Coriolis term changes T by {}, more than {tolerance}",
            percent(c.coriolis_effect_rel)
        )
    } else {
        format!(
            "the Coriolis term changes T by {}, within {tolerance} but more than the half of it \
             left once the integrator's own error is budgeted",
            percent(c.coriolis_effect_rel)
        )
    };
    let mut out = format!(
        "chosen: {} model, {} ({why})",
        model_name(c.model),
        plan_words(&c.plan)
    );
    let (method_error, model_error, total) = claimed_error(c);
    if !matches!(c.plan, Plan::ClosedForm) {
        let predicted_by = match c.source {
            Source::Table => "the precomputed error table predicts it",
            Source::PilotRuns | Source::ClosedForms => "the pilot runs predict it",
        };
        out += &format!(
            "\n  the method's error as {predicted_by}: {method_error:.2e} ({} right-hand-side \
             evaluations; choosing ran {})",
            c.rhs_evaluations, c.choosing_evaluations
        );
    }
    if model_error > 0.0 {
        out += &format!(
            "\n  the flat model's own error (the Coriolis term it leaves out): {model_error:.2e}; \
             error of T in all: up to {total:.2e}"
        );
    }
    out += &format!("\n  chosen {}", c.source.describe());
    if c.source == Source::Table {
        out += if c.choosing_evaluations == 0 {
            ", without running the scene"
        } else {
            " (the runs were the spread's, for the tolerance)"
        };
    }
    out += &format!(
        "\n  predicted cost {:.0} {} {} (measured table: docs/model.md, the chooser)",
        c.predicted_cost,
        runs_on.target().unit(),
        match runs_on {
            RunsOn::Host => "on the host, f64",
            RunsOn::Mcu => "on the Cortex-M4F, f32 (T below is still computed on the host)",
        }
    );
    if coriolis_below_uncertainty(c) {
        out += "\n  the Coriolis term is below the uncertainty here: the parameters' uncertainty \
                moves T more than the paper's flat-bowl idealisation does";
    }
    out
}

/// The method's name, as `--method` spells it.
fn method_token(plan: &Plan<f64>) -> &'static str {
    match plan {
        Plan::ClosedForm | Plan::ClosedFormAtMeanSpeed { .. } => "closed",
        Plan::Integrate(Method::Rk4 { .. }) => "rk4",
        Plan::Integrate(Method::SemiImplicitEuler { .. }) => "semi-implicit",
        Plan::Integrate(Method::Euler { .. }) => "euler",
        Plan::Integrate(Method::Dp54 { .. }) => "dp54",
    }
}

/// The choice as JSON.
pub fn json(c: &Choice<f64>, runs_on: RunsOn) -> serde_json::Value {
    let setting = match c.plan {
        Plan::Integrate(
            Method::Rk4 { step_s }
            | Method::SemiImplicitEuler { step_s }
            | Method::Euler { step_s },
        ) => serde_json::json!({ "step_s": step_s }),
        Plan::Integrate(Method::Dp54 { rtol, atol }) => {
            serde_json::json!({ "rtol": rtol, "atol": atol })
        }
        Plan::ClosedFormAtMeanSpeed { omega_rad_s } => {
            serde_json::json!({ "mean_omega_rad_s": omega_rad_s })
        }
        Plan::ClosedForm => serde_json::Value::Null,
    };
    serde_json::json!({
        "model": model_name(c.model),
        "method": method_token(&c.plan),
        "setting": setting,
        "tolerance_rel": c.tolerance_rel,
        "spread_rel": c.spread_rel.filter(|s| s.is_finite()),
        "coriolis_effect_rel": c.coriolis_effect_rel,
        "coriolis_below_uncertainty": coriolis_below_uncertainty(c),
        "estimated_error_rel": claimed_error(c).2,
        "method_error_rel": claimed_error(c).0,
        "model_error_rel": claimed_error(c).1,
        "rhs_evaluations": c.rhs_evaluations,
        "choosing_evaluations": c.choosing_evaluations,
        "source": c.source.name(),
        "target": match runs_on { RunsOn::Host => "host", RunsOn::Mcu => "mcu" },
        "predicted_cost": c.predicted_cost,
        "predicted_cost_unit": runs_on.target().unit(),
        "reason": describe_reason(c),
    })
}

fn describe_reason(c: &Choice<f64>) -> String {
    if c.model == Model::Flat {
        "the Coriolis term is within the tolerance".into()
    } else {
        "the Coriolis term exceeds the tolerance".into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uncertainty_specs_parse_and_bad_ones_are_named() {
        let k = parse_uncertainty("mu=0.1, omega=0.02").unwrap();
        assert_eq!((k.mu_rel, k.radius_m, k.omega_rel), (0.1, 0.001, 0.02));
        assert!(states_omega(Some("mu=0.1, omega=0.02")).unwrap());
        assert!(!states_omega(Some("mu=0.1")).unwrap());
        assert!(!states_omega(None).unwrap());
        let e = parse_uncertainty("rpm=3").unwrap_err().to_string();
        assert!(e.contains("unknown key `rpm`"), "{e}");
        let e = parse_uncertainty("mu=-1").unwrap_err().to_string();
        assert!(e.contains("mu = -1 must be zero or positive"), "{e}");
        let e = need(Some(0.5), None).unwrap_err().to_string();
        assert!(e.contains("between 0 and 0.1"), "{e}");
        assert!(need(Some(0.01), Some("mu=0.1")).is_err());
    }
}

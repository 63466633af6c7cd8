//! `bowl predict --omega-trace` end to end: runs the built binary on logged speed traces and
//! checks its answer against the residence time on the trace's own samples (the shared
//! independent reference); and `--target mcu`, whose chooser is checked on a trace too. (Single
//! scenes and batches are in predict.rs.)

mod common;

use std::process::Output;

use common::{bowl, json, success_json, temp};

/// A telemetry log with the bowl speed `omega(t)` every 20 ms for `seconds`.
fn write_trace(path: &std::path::Path, seconds: f64, omega: impl Fn(f64) -> f64) {
    let mut text = String::from("boot,device_time_ms,bowl_mrad_s,event\n");
    let n = (seconds / 0.02) as usize;
    for i in 0..=n {
        let t = i as f64 * 0.02;
        text += &format!("1,{},{:.0},\n", 1000 + i * 20, omega(t) * 1000.0);
    }
    text += ",,,link lost\n";
    std::fs::write(path, text).unwrap();
}

/// The residence time on a piecewise-linear speed trace (the log's samples, in rad/s, every
/// 20 ms): the shared independent reference on the trace's own interpolation.
fn reference_time(samples: &[f64], coriolis: bool) -> f64 {
    let w = |t: f64| {
        let x = t / 0.02;
        let i = (x.floor() as usize).min(samples.len() - 1);
        let j = (i + 1).min(samples.len() - 1);
        samples[i] + (samples[j] - samples[i]) * (x - i as f64)
    };
    common::reference_residence_s(w, 0.029, 0.05, 0.1, coriolis)
}

/// A spin-up from 0.5 to 3 rad/s with time constant 0.3 s, rad/s at `t` s.
fn spin_up(t: f64) -> f64 {
    3.0 + (0.5 - 3.0) * (-t / 0.3).exp()
}

/// `bowl predict --omega-trace LOG EXTRA...` on a log of `omega(t)` for 3 s (named `name` in
/// the temporary folder, removed after the run).
fn predict_on_trace(name: &str, omega: impl Fn(f64) -> f64, extra: &[&str]) -> Output {
    let path = temp(name);
    write_trace(&path, 3.0, omega);
    let mut args = vec!["predict", "--omega-trace", path.to_str().unwrap()];
    args.extend_from_slice(extra);
    let out = bowl(&args);
    let _ = std::fs::remove_file(&path);
    out
}

/// `bowl predict --omega-trace` on a log of `omega(t)` (3 s at 50 Hz, mrad/s as logged) with
/// `tolerance` and the `extra` flags: its JSON, its T and the reference's T on the same logged
/// samples.
fn trace_prediction(
    name: &str,
    omega: impl Fn(f64) -> f64,
    tolerance: &str,
    extra: &[&str],
) -> (serde_json::Value, f64, f64) {
    let mut flags = vec!["--tolerance", tolerance, "--json"];
    flags.extend_from_slice(extra);
    let out = predict_on_trace(name, &omega, &flags);
    let v = success_json(
        &out,
        &format!("bowl predict --omega-trace {name} {flags:?}"),
    );
    let samples: Vec<f64> = (0..=150)
        .map(|i| (omega(i as f64 * 0.02) * 1000.0).round() / 1000.0)
        .collect();
    let want = reference_time(&samples, v["choice"]["model"] == "coriolis");
    let got = v["residence_time_s"].as_f64().unwrap();
    (v, got, want)
}

#[test]
fn a_logged_speed_trace_is_predicted_within_the_tolerance() {
    // A settled loop with 0.5 % ripple: the closed form at the mean speed is enough.
    let ripple = |t: f64| 3.0 * (1.0 + 0.005 * (7.0 * std::f64::consts::TAU * t).sin());
    let (v, got, want) = trace_prediction("steady.csv", ripple, "1e-3", &[]);
    assert_eq!(v["choice"]["method"], "closed", "{v}");
    assert!((got - want).abs() <= 1e-3 * want, "{got} vs {want}");
    assert_eq!(v["residence_time_from_choosing"], false, "{v}");
    // A spin-up from 0.5 to 3 rad/s: the particle waits for the speed, then leaves while it
    // still rises; an integrator over the trace is needed for 1e-5.
    let (v, got, want) = trace_prediction("spin-up.csv", spin_up, "1e-5", &[]);
    assert_ne!(v["choice"]["method"], "closed", "{v}");
    assert!((got - want).abs() <= 1e-5 * want, "{got} vs {want}: {v}");
    // The pilot's finer DP5(4) run answered: the plan was not run again.
    assert_eq!(v["choice"]["method"], "dp54", "{v}");
    assert_eq!(v["residence_time_from_choosing"], true, "{v}");
    // --model with a trace is refused in words.
    let out = predict_on_trace("spin-up.csv", spin_up, &["--model", "flat"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("leave out --model"));
}

/// A trace's own measurement uncertainty takes the place of the default 1 % on omega: a
/// settled trace alternating +-40 mrad/s (each sample 80 mrad/s off its neighbours' line,
/// which independent noise of RMS 80 / sqrt(1.5) mrad/s would be on average) is known to
/// (0.5 + 80 / sqrt(1.5)) mrad/s over 3 rad/s, and that widens T's spread against the same
/// trace with `--uncertainty omega=0` by what the closed form says the speed's uncertainty
/// moves T; a stated omega is kept.
#[test]
fn a_traces_own_measurement_enters_the_tolerance() {
    let noisy = temp("noisy.csv");
    write_trace(&noisy, 3.0, |t| {
        let i = (t / 0.02).round() as i64;
        3.0 + if i % 2 == 0 { 0.04 } else { -0.04 }
    });
    let spec = |extra: &[&str]| {
        let mut a = vec![
            "predict",
            "--omega-trace",
            noisy.to_str().unwrap(),
            "--json",
        ];
        a.extend_from_slice(extra);
        json(&a)
    };
    let by_default = spec(&[]);
    let m = &by_default["trace"]["measurement"];
    assert_eq!(m["used_as_omega_uncertainty"], true, "{by_default}");
    let scatter = 0.08 / 1.5f64.sqrt();
    assert!(
        (m["scatter_rad_s"].as_f64().unwrap() - scatter).abs() < 1e-9,
        "{m}"
    );
    let want = (0.0005 + scatter) / 3.0;
    assert!((m["relative"].as_f64().unwrap() - want).abs() < 1e-6, "{m}");
    let without = spec(&["--uncertainty", "omega=0"]);
    assert_eq!(
        without["trace"]["measurement"]["used_as_omega_uncertainty"],
        false
    );
    let spread = |v: &serde_json::Value| v["choice"]["spread_rel"].as_f64().unwrap();
    // The spread's omega term, from the closed form (the trace is settled at 3 rad/s): the
    // larger change of T with the speed at either end of its range.
    let t_at = |w: f64| {
        let scene = model_core::particle::Scene {
            omega_rad_s: w,
            mu: 0.029,
            g_m_s2: 9.81,
            k2: 5.0 / 7.0,
            ri_m: 0.05,
            rim_radius_m: 0.1,
        };
        model_core::particle::residence(&scene, model_core::particle::Model::Coriolis)
            .unwrap()
            .residence_time_s()
    };
    let term = [1.0 - want, 1.0 + want]
        .map(|f| (t_at(3.0 * f) - t_at(3.0)).abs() / t_at(3.0))
        .into_iter()
        .fold(0.0, f64::max);
    let added = spread(&by_default) - spread(&without);
    assert!((added - term).abs() <= 0.05 * term, "{added} vs {term}");
    let text =
        String::from_utf8(bowl(&["predict", "--omega-trace", noisy.to_str().unwrap()]).stdout)
            .unwrap();
    assert!(text.contains("that is omega's uncertainty below"), "{text}");
    let _ = std::fs::remove_file(noisy);
}

/// `--target mcu`: the chooser decides in f32 and prices on the Cortex-M4F table; a tolerance
/// below what f32 holds is raised to 64 of its rounding units, and says so; a trace still gets
/// a plan that meets the tolerance.
#[test]
fn the_chooser_prices_for_the_mcu_in_f32() {
    use model_core::choose::{Plan, Target, plan_cost};
    let host = json(&["predict", "--tolerance", "1e-6", "--json"]);
    let mcu = json(&[
        "predict",
        "--tolerance",
        "1e-6",
        "--target",
        "mcu",
        "--json",
    ]);
    assert_eq!(host["choice"]["target"], "host");
    assert_eq!(host["choice"]["predicted_cost_unit"], "ns");
    assert_eq!(mcu["choice"]["target"], "mcu");
    assert_eq!(mcu["choice"]["predicted_cost_unit"], "instructions");
    let floor = f64::from(64.0 * f32::EPSILON);
    let tol = mcu["choice"]["tolerance_rel"].as_f64().unwrap();
    assert!((tol - floor).abs() < 1e-12, "{tol} vs {floor}");
    assert_eq!(host["choice"]["tolerance_rel"].as_f64().unwrap(), 1e-6);
    let cost = mcu["choice"]["predicted_cost"].as_f64().unwrap();
    assert_eq!(cost, plan_cost(&Plan::<f32>::ClosedForm, 0, Target::Mcu));
    let text =
        String::from_utf8(bowl(&["predict", "--tolerance", "1e-6", "--target", "mcu"]).stdout)
            .unwrap();
    assert!(
        text.contains("raised to 64 rounding units") && text.contains("Cortex-M4F"),
        "{text}"
    );
    // A spin-up trace for the MCU at 1e-4: a plan that meets it on the logged samples.
    let (v, got, want) = trace_prediction("mcu-spin-up.csv", spin_up, "1e-4", &["--target", "mcu"]);
    assert_eq!(v["choice"]["target"], "mcu", "{v}");
    assert!((got - want).abs() <= 1e-4 * want, "{got} vs {want}: {v}");
}

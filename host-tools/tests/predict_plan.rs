//! One tolerance, one plan: `bowl predict --method dp54 --tol T` integrates the work-precision
//! chart's scene exactly as the chart does (the same evaluations, the same T to the last digit),
//! read against the chart's committed table, docs/charts/work-precision.csv.

mod common;

use common::{bowl, json, stdout};

#[test]
fn the_cli_and_the_chart_run_the_same_dp54_plan() {
    let csv = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../docs/charts/work-precision.csv"
    ))
    .unwrap();
    let mut rdr = csv::Reader::from_reader(csv.as_bytes());
    let header = rdr.headers().unwrap().clone();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let mut checked = 0;
    for row in rdr.records().map(Result::unwrap) {
        if &row[col("scene")] != "paper" || !row[col("method")].starts_with("dp54-f64-tol") {
            continue;
        }
        let tol = row[col("setting")].trim_start_matches("tol=").to_string();
        let v = json(&[
            "predict",
            "--model",
            &row[col("model")],
            "--method",
            "dp54",
            "--tol",
            &tol,
            "--omega-rad-s",
            "3.6",
            "--ri-m",
            "0.0375",
            "--rim-radius-m",
            "0.075",
            "--json",
        ]);
        let r = &v["results"][0];
        let chart_evals: u64 = row[col("rhs_evals")].parse().unwrap();
        assert_eq!(
            r["rhs_evaluations"].as_u64(),
            Some(chart_evals),
            "tol {tol}: {r}"
        );
        let chart_t: f64 = row[col("residence_time_s")].parse().unwrap();
        assert_eq!(
            r["residence_time_s"].as_f64(),
            Some(chart_t),
            "tol {tol}: {r}"
        );
        checked += 1;
    }
    assert!(checked >= 4, "{checked} dp54 rows of the paper scene");
}

/// The chooser chart's DP5(4) plans (its not-choosing baseline, its reference, its brute-force
/// grid) are the plan `bowl predict --method dp54 --tol` runs at the same tolerance: on the
/// chart's scenes at their final speed held, the same evaluations and the same T to the last
/// digit, for each of the chart's tolerances.
#[test]
fn the_cli_and_the_chooser_chart_run_the_same_dp54_plan() {
    use lab::chart::chooser::{not_choosing, time};
    use model_core::ode::{Method, SpinUp};
    use model_core::particle::{Model, Scene};
    let mut checked = 0;
    for (mu, omega, model) in [
        (0.01, 3.0, Model::Flat),
        (0.029, 3.0, Model::Coriolis),
        (0.1, 6.0, Model::Coriolis),
    ] {
        // The chart's scene (docs/charts/chooser.csv), its speed held: the CLI's constant speed.
        let s = Scene {
            omega_rad_s: omega,
            mu,
            g_m_s2: 9.81,
            k2: 5.0 / 7.0,
            ri_m: 0.05,
            rim_radius_m: 0.1,
        };
        let held = SpinUp {
            start_rad_s: omega,
            final_rad_s: omega,
            time_constant_s: 0.3,
        };
        for tolerance in [1e-3, 1e-5, 1e-7] {
            let plan = not_choosing(tolerance, &s);
            let Method::Dp54 { rtol, .. } = plan else {
                panic!("the baseline is DP5(4): {plan:?}");
            };
            let (t, evals) = time(&s, model, &held, plan);
            let name = format!("{model:?}").to_lowercase();
            let out = bowl(&[
                "predict",
                "--model",
                &name,
                "--method",
                "dp54",
                "--tol",
                &format!("{rtol:e}"),
                &format!("--omega-rad-s={omega}"),
                &format!("--mu={mu}"),
                "--ri-m",
                "0.05",
                "--rim-radius-m",
                "0.1",
                "--json",
            ]);
            let text = stdout(&out);
            let v: serde_json::Value = serde_json::from_str(&text).expect(&text);
            let r = &v["results"][0];
            let what = format!("{name} mu {mu} omega {omega} tolerance {tolerance:e}: {r}");
            assert_eq!(
                r["rhs_evaluations"].as_u64(),
                Some(u64::from(evals)),
                "{what}"
            );
            // T from the printed digits (serde_json's own reading may be an ulp off).
            let printed = text
                .split("\"residence_time_s\":")
                .nth(1)
                .and_then(|rest| rest.split([',', '}', '\n']).next())
                .map(|digits| digits.trim().parse::<f64>().unwrap());
            assert_eq!(printed, Some(t), "{what}");
            checked += 1;
        }
    }
    assert_eq!(checked, 9);
}

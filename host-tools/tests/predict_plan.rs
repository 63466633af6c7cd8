//! One tolerance, one plan: `bowl predict --method dp54 --tol T` integrates the work-precision
//! chart's scene exactly as the chart does (the same evaluations, the same T to the last digit),
//! read against the chart's committed table, docs/charts/work-precision.csv.

mod common;

use common::json;

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

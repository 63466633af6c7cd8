//! The chooser's cost table (model-core/src/choose/cost_table.rs) is what `bowl chart costs`
//! makes of the committed measurements (docs/charts/work-precision.csv): regenerate both with
//! docs/charts/generate.sh, never edit the table by hand.

mod common;

#[test]
fn the_committed_cost_table_is_the_fit_of_the_committed_measurements() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let dir = common::temp_dir("cost-table");
    let out = dir.join("cost_table.rs");
    let run = common::bowl(&[
        "chart",
        "costs",
        "--csv",
        &format!("{root}/docs/charts/work-precision.csv"),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", common::stdout(&run));
    let made = std::fs::read_to_string(&out).unwrap();
    let committed =
        std::fs::read_to_string(format!("{root}/model-core/src/choose/cost_table.rs")).unwrap();
    assert_eq!(
        made, committed,
        "the cost table is stale: run docs/charts/generate.sh (or bowl chart costs)"
    );
    // On the target a DP5(4) evaluation costs more than an RK4 one (its bookkeeping): the
    // reason evaluations alone rank plans wrongly.
    let per_eval = |name: &str| -> f64 {
        let line = made
            .lines()
            .find(|l| l.contains(&format!("pub const {name}:")))
            .unwrap();
        let at = line.find("per_eval: ").unwrap() + "per_eval: ".len();
        line[at..].trim_end_matches(" };").parse().unwrap()
    };
    assert!(per_eval("MCU_DP54") > 2.0 * per_eval("MCU_RK4"), "{made}");
}

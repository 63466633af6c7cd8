//! The chooser's error table (model-core/src/choose/error_table.bin) is what
//! `bowl chart error-table` measures: regenerate it with docs/charts/generate.sh (or that
//! command) whenever the integrators or the grid change, never edit it by hand.

mod common;

#[test]
fn the_committed_error_table_is_what_the_command_measures() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let dir = common::temp_dir("error-table");
    let out = dir.join("error_table.bin");
    let run = common::bowl(&["chart", "error-table", "--out", out.to_str().unwrap()]);
    assert!(run.status.success(), "{}", common::stdout(&run));
    let made = std::fs::read(&out).unwrap();
    let committed = std::fs::read(format!("{root}/model-core/src/choose/error_table.bin")).unwrap();
    assert_eq!(made.len(), committed.len(), "the table's size changed");
    let differ = made.iter().zip(&committed).filter(|(a, b)| a != b).count();
    assert_eq!(
        differ, 0,
        "{differ} values of the error table are stale: run docs/charts/generate.sh (or bowl \
         chart error-table --out model-core/src/choose/error_table.bin)"
    );
    // Every value the table holds was measured: none of its points is left at "not measured"
    // where a particle leaves (the grid keeps q below 1).
    let unmeasured = made.iter().filter(|&&b| b == 0).count();
    assert_eq!(unmeasured, 0, "{unmeasured} points not measured");
}

//! `bowl chart scipy`: draws the comparison CSV of tests/scipy/compare.py, and says which line
//! of a malformed one is wrong.

mod common;

use std::path::Path;
use std::process::Output;

use common::{bowl, temp_dir};

/// `bowl chart scipy --csv CSV --out OUT EXTRA...`.
fn chart_scipy(csv: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "chart",
        "scipy",
        "--csv",
        csv.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    bowl(&args)
}

const HEADER: &str = "scene,model,who,method,setting,rel_error,rhs_evals,ns_per_call\n";

#[test]
fn draws_both_cost_axes() {
    let d = temp_dir("chart-scipy-ok");
    let csv = d.join("c.csv");
    let rows = "paper,coriolis,scipy,RK45,rtol=1e-6,5e-7,50,3e6\n\
                paper,coriolis,scipy,RK45,rtol=1e-8,6e-9,110,6e6\n\
                paper,coriolis,ours,dp54,tol=1e-6,5e-7,55,2e3\n\
                paper,coriolis,ours,dp54,tol=1e-8,6e-9,115,4e3\n\
                paper,flat,ours,dp54,tol=1e-8,6e-9,115,4e3\n";
    std::fs::write(&csv, format!("{HEADER}{rows}")).unwrap();
    let out = d.join("s.svg");
    let o = chart_scipy(&csv, &out, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["s.svg", "s.png", "s-time.svg", "s-time.png"] {
        assert!(d.join(f).exists(), "{f}");
    }
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(
        svg.contains("scipy RK45") && svg.contains("ours dp54"),
        "legend"
    );
}

#[test]
fn a_short_row_names_its_line() {
    let d = temp_dir("chart-scipy-bad");
    let csv = d.join("c.csv");
    std::fs::write(&csv, format!("{HEADER}paper,coriolis,scipy,RK45\n")).unwrap();
    let o = chart_scipy(&csv, &d.join("s.svg"), &[]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("line 2"), "{err}");
}

#[test]
fn an_absent_scene_is_an_error_not_an_empty_chart() {
    let d = temp_dir("chart-scipy-none");
    let csv = d.join("c.csv");
    std::fs::write(
        &csv,
        format!("{HEADER}paper,flat,ours,dp54,tol=1e-8,6e-9,115,4e3\n"),
    )
    .unwrap();
    let o = chart_scipy(&csv, &d.join("s.svg"), &["--scene", "nowhere"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("no rows for scene `nowhere`"));
}

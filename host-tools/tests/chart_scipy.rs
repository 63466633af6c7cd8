//! `bowl chart scipy`: draws the comparison CSV of tests/scipy/compare.py, and says which line
//! of a malformed one is wrong.

use std::process::Command;

fn dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("bowl-chart-scipy-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn bowl(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_bowl"))
        .args(args)
        .output()
        .unwrap()
}

const HEADER: &str = "scene,model,who,method,setting,rel_error,rhs_evals,ns_per_call\n";

#[test]
fn draws_both_cost_axes() {
    let d = dir("ok");
    let csv = d.join("c.csv");
    let rows = "paper,coriolis,scipy,RK45,rtol=1e-6,5e-7,50,3e6\n\
                paper,coriolis,scipy,RK45,rtol=1e-8,6e-9,110,6e6\n\
                paper,coriolis,ours,dp54,tol=1e-6,5e-7,55,2e3\n\
                paper,coriolis,ours,dp54,tol=1e-8,6e-9,115,4e3\n\
                paper,flat,ours,dp54,tol=1e-8,6e-9,115,4e3\n";
    std::fs::write(&csv, format!("{HEADER}{rows}")).unwrap();
    let out = d.join("s.svg");
    let o = bowl(&[
        "chart",
        "scipy",
        "--csv",
        csv.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
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
    let d = dir("bad");
    let csv = d.join("c.csv");
    std::fs::write(&csv, format!("{HEADER}paper,coriolis,scipy,RK45\n")).unwrap();
    let o = bowl(&[
        "chart",
        "scipy",
        "--csv",
        csv.to_str().unwrap(),
        "--out",
        d.join("s.svg").to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("line 2"), "{err}");
}

#[test]
fn an_absent_scene_is_an_error_not_an_empty_chart() {
    let d = dir("none");
    let csv = d.join("c.csv");
    std::fs::write(
        &csv,
        format!("{HEADER}paper,flat,ours,dp54,tol=1e-8,6e-9,115,4e3\n"),
    )
    .unwrap();
    let o = bowl(&[
        "chart",
        "scipy",
        "--csv",
        csv.to_str().unwrap(),
        "--out",
        d.join("s.svg").to_str().unwrap(),
        "--scene",
        "nowhere",
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("no rows for scene `nowhere`"));
}

//! `bowl sim family`: the family targets of docs/control.md, and the same family failing without feedback.

mod common;

use common::bowl;

fn run(args: &[&str]) -> (bool, String, String) {
    let out = bowl(args);
    (
        out.status.success(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

fn f(v: &serde_json::Value, key: &str) -> f64 {
    v[key].as_f64().unwrap_or(f64::INFINITY)
}

#[test]
fn fifty_plants_meet_the_family_targets_with_no_false_fault() {
    let (ok, out, _) = run(&["sim", "family"]);
    assert!(ok);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["plants"], 50);
    assert_eq!(v["faulted_plants"], 0);
    assert_eq!(v["commissioning_failures"], 0);
    let w = &v["worst"];
    assert!(f(w, "overshoot_pct") <= 5.0, "{w}");
    assert!(f(w, "settling_time_s") <= 4.0, "{w}");
    assert!(f(w, "steady_state_error_pct") <= 1.0, "{w}");
    let m = &v["median"];
    assert!(f(m, "settling_time_s") <= f(w, "settling_time_s"));
}

#[test]
fn feedforward_alone_fails_the_family() {
    // A smaller family is enough to show the failure (and keeps the debug test quick).
    let (ok, out, _) = run(&[
        "sim",
        "family",
        "--no-feedback",
        "--plants",
        "12",
        "--allow-small",
    ]);
    assert!(ok);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["feedback"], false);
    let w = &v["worst"];
    let fails = f(w, "steady_state_error_pct") > 1.0
        || f(w, "settling_time_s") > 4.0
        || f(w, "overshoot_pct") > 5.0;
    assert!(fails, "feedforward alone passed: {w}");
}

#[test]
fn fewer_than_fifty_plants_is_refused() {
    let (ok, _, err) = run(&["sim", "family", "--plants", "10"]);
    assert!(!ok);
    assert!(err.contains("at least 50"), "{err}");
}

//! `bowl sim commission`: identified models against the simulator's true ones.

mod common;

use common::bowl;

#[test]
fn commissioning_identifies_both_axes() {
    let out = bowl(&["sim", "commission"]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["state"], "Idle");
    for axis in v["axes"].as_array().unwrap() {
        let g = |k: &str| axis[k].as_f64().unwrap();
        let rel = |a: f64, b: f64| (a - b).abs() / b;
        assert!(
            rel(g("volts_per_rad_s"), g("true_volts_per_rad_s")) < 0.03,
            "{axis}"
        );
        assert!(
            (g("friction_duty") - g("true_friction_duty")).abs() < 0.01,
            "{axis}"
        );
        assert!(
            rel(g("time_constant_s"), g("true_time_constant_s")) < 0.5,
            "{axis}"
        );
    }
}

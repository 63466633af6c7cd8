//! `bowl sim commission`: identified models against the simulator's true ones.

mod common;

use common::bowl;

#[test]
fn commissioning_identifies_both_axes() {
    let out = bowl(&["sim", "commission"]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["state"], "idle");
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
        // The search's duty at the first edge bounds the breakaway duty from above.
        assert!(g("breakaway_duty") > g("true_breakaway_duty"), "{axis}");
    }
    // The spin's reaction on the rod, measured on the precession axis (2.9 % off here).
    let p = &v["axes"][0];
    let r = |k: &str| p[k].as_f64().unwrap();
    assert!(
        (r("reaction_duty_s2_per_rad") / r("true_reaction_duty_s2_per_rad") - 1.0).abs() < 0.05,
        "{p}"
    );
}

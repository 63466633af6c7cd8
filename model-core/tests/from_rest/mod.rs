//! A family plant commissioned, loaded with its material and stepped from rest to 1 rad/s,
//! shared by the control tests of the start from rest.

use model_core::control::ControllerConfig;
use model_core::sim::experiments::commissioned_transition;

/// Commissions `rig` (seed `seed`), pours its material in and steps both axes from rest to
/// 1 rad/s with no fault: the rod's step report.
pub fn rod_from_rest_to_1_rad_s(
    rig: model_core::sim::PlantParams,
    seed: u32,
) -> model_core::sim::StepReport {
    from_rest_to_1_rad_s(rig, seed)[0]
}

/// As [`rod_from_rest_to_1_rad_s`], both axes' step reports.
pub fn from_rest_to_1_rad_s(
    rig: model_core::sim::PlantParams,
    seed: u32,
) -> [model_core::sim::StepReport; 2] {
    from_rest_to(rig, seed, 1.0)
}

/// As [`from_rest_to_1_rad_s`], to `target_rad_s` on both axes.
pub fn from_rest_to(
    rig: model_core::sim::PlantParams,
    seed: u32,
    target_rad_s: f32,
) -> [model_core::sim::StepReport; 2] {
    let load = [rig.axes[0].load_step_nm, rig.axes[1].load_step_nm];
    let config = ControllerConfig::nominal();
    let o = commissioned_transition(rig, config, seed, 0.0, target_rad_s, true, load);
    assert!(o.commissioned && o.fault.is_none(), "{:?}", o.fault);
    o.reports
}

/// `axis` settled within 2 % of 1 rad/s by `within_s` and never passed it by more than 2 %.
pub fn assert_settled_within_2_pct_by(r: model_core::sim::StepReport, within_s: f32, axis: &str) {
    assert!(
        r.settled && r.settling_time_s <= within_s && r.overshoot <= 0.02,
        "{axis} settled within 2 % of 1 rad/s at {:.2} s, {:.2} % past it (settled: {})",
        r.settling_time_s,
        r.overshoot * 100.0,
        r.settled
    );
}

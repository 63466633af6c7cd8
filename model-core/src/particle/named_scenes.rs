//! The named scenes of the work-precision chart (`bowl chart work-precision`) and of the
//! Cortex-M4F cost benchmarks (`tests/cases`, `cost::SCENE::MODEL::METHOD`): defined here once,
//! so the host and the target measure the same inputs.

use super::Scene;

/// Names of the chart's scenes, in the order of [`scene`].
pub const SCENE_NAMES: [&str; 3] = ["paper", "near-threshold", "near-rim"];

/// Relative distance above the threshold `ri = a (1 + d)` of the "near-threshold" scene:
/// condition number of T about `1/(d ln x)`, a few thousand.
pub const NEAR_THRESHOLD_D: f64 = 1e-4;
/// Relative distance below the rim `ri = R (1 - e)` of the "near-rim" scene, where the naive
/// `acosh(1 + x)` loses about half the digits.
pub const NEAR_RIM_E: f64 = 1e-5;

/// The chart's named scenes in f64.
///
/// * `paper`: 3.6 rad/s (the paper's top speed, its Fig. 5) in a 150 mm bowl read as a diameter
///   (rim radius 75 mm), start radius R/2, effective rolling resistance 0.029, g 9.81, k2 5/7.
/// * `near-threshold`: the same with the start radius just above the equilibrium radius `a`.
/// * `near-rim`: the same with the start radius just inside the rim.
///
/// Out-of-range indices give the `paper` scene.
pub const fn scene(i: usize) -> Scene<f64> {
    let paper = Scene {
        omega_rad_s: 3.6,
        mu: 0.029,
        g_m_s2: 9.81,
        k2: 5.0 / 7.0,
        ri_m: 0.0375,
        rim_radius_m: 0.075,
    };
    match i {
        1 => {
            let a = paper.mu * paper.g_m_s2 / (paper.omega_rad_s * paper.omega_rad_s);
            Scene {
                ri_m: a * (1.0 + NEAR_THRESHOLD_D),
                ..paper
            }
        }
        2 => Scene {
            ri_m: paper.rim_radius_m * (1.0 - NEAR_RIM_E),
            ..paper
        },
        _ => paper,
    }
}

/// The scene rounded to f32, as the target sees it.
pub const fn scene_f32(i: usize) -> Scene<f32> {
    scene(i).to_f32()
}

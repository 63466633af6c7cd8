//! f32 with libm against f32 with micromath: accuracy of the residence time over a grid,
//! measured against the f64 closed forms (themselves within ~4e-16 x condition of a 320-bit
//! reference, see `accuracy.rs`). Run with `--nocapture` for the figures.
#![cfg(feature = "micromath")]

use model_core::Real;
use model_core::particle::{Model, Scene, residence};
use model_core::real::micro::{MicroF32, MicroF32HwSqrt};

fn grid() -> Vec<Scene<f64>> {
    let mut out = Vec::new();
    for &w in &[1.8, 2.5, 3.0, 3.6, 5.0] {
        for &mu in &[0.0, 0.01, 0.029] {
            for &ri in &[0.05, 0.07, 0.09, 0.0999] {
                let s = Scene {
                    omega_rad_s: w,
                    mu,
                    g_m_s2: 9.81,
                    k2: 5.0 / 7.0,
                    ri_m: ri,
                    rim_radius_m: 0.1,
                };
                if ri > s.equilibrium_radius_m() * 1.1 {
                    out.push(s);
                }
            }
        }
    }
    out
}

/// Worst relative error of T in type `T` (inputs rounded to f32 first) against f64 on the
/// f32-rounded inputs.
fn worst<T: Real>(model: Model) -> f64 {
    let mut worst: f64 = 0.0;
    for s in grid() {
        let r32 = |x: f64| x as f32 as f64;
        let exact = Scene {
            omega_rad_s: r32(s.omega_rad_s),
            mu: r32(s.mu),
            g_m_s2: r32(s.g_m_s2),
            k2: r32(s.k2),
            ri_m: r32(s.ri_m),
            rim_radius_m: r32(s.rim_radius_m),
        };
        let want = residence(&exact, model).unwrap().residence_time_s();
        let narrow = Scene {
            omega_rad_s: T::from_f64(exact.omega_rad_s),
            mu: T::from_f64(exact.mu),
            g_m_s2: T::from_f64(exact.g_m_s2),
            k2: T::from_f64(exact.k2),
            ri_m: T::from_f64(exact.ri_m),
            rim_radius_m: T::from_f64(exact.rim_radius_m),
        };
        let got = residence(&narrow, model)
            .unwrap()
            .residence_time_s()
            .to_f64();
        worst = worst.max(((got - want) / want).abs());
    }
    worst
}

#[test]
fn libm_meets_the_f32_target_micromath_does_not() {
    for model in [Model::Flat, Model::Coriolis] {
        let libm = worst::<f32>(model);
        let micro_hw = worst::<MicroF32HwSqrt>(model);
        let micro = worst::<MicroF32>(model);
        println!(
            "{model:?}: worst relative error of T: f32+libm {libm:.2e}, \
             f32+micromath (VSQRT) {micro_hw:.2e}, f32+micromath (its sqrt) {micro:.2e}"
        );
        assert!(libm < 2e-6 * 3.0, "libm {libm}");
        assert!(micro_hw > 10.0 * libm && micro > 10.0 * libm);
    }
}

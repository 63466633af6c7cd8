//! Quick throughput check of the batch closed forms (`particle::residence_times_s`) with AVX2,
//! for working on the lanes without building `bowl`: the paper's range and leaving-only scenes,
//! ns per scene, best of 15 passes. `cargo run --release -p model-core --example batch_throughput`
//! (the figures in docs come from `tests/scipy/compare.sh --batch-only`).

use model_core::particle::{Model, Scene, SceneError, residence_times_s};
use std::time::Instant;

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn avx2(scenes: &[Scene<f64>], model: Model, out: &mut [Result<f64, SceneError>]) {
    residence_times_s(scenes, model, out);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn avx512(scenes: &[Scene<f64>], model: Model, out: &mut [Result<f64, SceneError>]) {
    residence_times_s(scenes, model, out);
}

fn times(scenes: &[Scene<f64>], model: Model, out: &mut [Result<f64, SceneError>]) {
    #[cfg(target_arch = "x86_64")]
    if std::env::var_os("AVX512").is_some() && std::is_x86_feature_detected!("avx512f") {
        // SAFETY: the processor has just reported AVX-512F.
        unsafe { avx512(scenes, model, out) };
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor has just reported AVX2.
        unsafe { avx2(scenes, model, out) };
        return;
    }
    residence_times_s(scenes, model, out);
}

fn uniform(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// A scene on Earth with a solid sphere (the defaults' g and k2).
fn scene(omega_rad_s: f64, mu: f64, ri_m: f64, rim_radius_m: f64) -> Scene<f64> {
    Scene {
        omega_rad_s,
        mu,
        ri_m,
        rim_radius_m,
        ..Scene::default()
    }
}

fn main() {
    let n = 100_000;
    let mut state = 7u64;
    let paper: Vec<Scene<f64>> = (0..n)
        .map(|_| {
            let (w, mu, rim) = (
                1.0 + 2.6 * uniform(&mut state),
                0.029 + 0.371 * uniform(&mut state),
                0.075 + 0.075 * uniform(&mut state),
            );
            scene(w, mu, uniform(&mut state) * rim, rim)
        })
        .collect();
    let leaving: Vec<Scene<f64>> = (0..n)
        .map(|_| {
            let (w, mu) = (2.5 + 3.5 * uniform(&mut state), 0.1 * uniform(&mut state));
            let a = mu * 9.81 / (w * w);
            let low = (1.1 * a).max(0.01);
            scene(
                w,
                mu,
                (low + uniform(&mut state) * (0.095 - low)).min(0.095),
                0.1,
            )
        })
        .collect();
    let mut out = vec![Ok(0.0); n];
    // An optional argument picks the runs whose name holds it (e.g. `leaving only Flat`).
    let only = std::env::args().nth(1).unwrap_or_default();
    for (regime, scenes) in [("paper range", &paper), ("leaving only", &leaving)] {
        for model in [Model::Flat, Model::Coriolis] {
            if !format!("{regime} {model:?}").contains(&only) {
                continue;
            }
            let mut best = f64::INFINITY;
            for _ in 0..15 {
                let t0 = Instant::now();
                for _ in 0..5 {
                    times(std::hint::black_box(scenes), model, &mut out);
                    std::hint::black_box(&mut out);
                }
                best = best.min(t0.elapsed().as_secs_f64() * 1e9 / (5 * n) as f64);
            }
            println!("{regime:12} {model:?}: {best:.2} ns a scene");
        }
    }
}

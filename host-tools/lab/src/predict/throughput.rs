//! `bowl predict --batch IN --out OUT --throughput`: how fast the closed forms run over the
//! file's scenes, per model, as the time alone (`particle::residence_times_s`, what a vectorised
//! numpy closed form computes too): nanoseconds per scene on one thread and on every core.
//! tests/scipy/compare.sh puts it beside numpy on the same scenes in the same run.
//!
//! Each figure is the best of [`REPEATS`] passes over the scenes, each pass at least
//! [`MIN_PASS_S`] long (the scenes repeated as often as that needs): the least disturbed
//! measurement of the machine's throughput, as `timeit` takes it.

use std::time::Instant;

use model_core::particle::{Model, Scene, SceneError, residence_times_s};
use serde_json::{Value, json};

/// Passes measured; the fastest counts.
const REPEATS: usize = 15;
/// Shortest pass, s.
const MIN_PASS_S: f64 = 0.05;

/// `particle::residence_times_s` compiled for the widest SIMD this processor has: AVX-512
/// (eight f64 lanes) or AVX2 (four) where the processor reports it, otherwise the build's
/// baseline (SSE2, two). The answers are the same bit for bit (no contraction into fused
/// multiply-adds). AVX-512 took the leaving scenes from 9.4 to 6.8 ns (flat) and from 39 to
/// 27.5 ns (Coriolis) a scene on this AMD EPYC (`model-core/examples/batch_throughput.rs`).
pub fn times_s(scenes: &[Scene<f64>], model: Model, out: &mut [Result<f64, SceneError>]) {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx512f") {
        // SAFETY: the processor has just reported AVX-512F, the only feature the function
        // enables.
        unsafe { times_s_avx512(scenes, model, out) };
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor has just reported AVX2, the only feature the function enables.
        unsafe { times_s_avx2(scenes, model, out) };
        return;
    }
    residence_times_s(scenes, model, out);
}

/// The batch form with AVX-512F enabled (inlined here, so its lanes compile to 512-bit
/// instructions).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn times_s_avx512(scenes: &[Scene<f64>], model: Model, out: &mut [Result<f64, SceneError>]) {
    residence_times_s(scenes, model, out);
}

/// The batch form with AVX2 enabled (it is inlined here, so its lanes compile to 256-bit
/// instructions).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn times_s_avx2(scenes: &[Scene<f64>], model: Model, out: &mut [Result<f64, SceneError>]) {
    residence_times_s(scenes, model, out);
}

/// The time alone for every scene of `scenes` ([`times_s`], the batch form), `rounds` times,
/// as numpy's side computes its array and nothing more; the answers pass through `black_box`
/// so none is optimised away. Returns the sum of the last round's times.
fn pass(scenes: &[Scene<f64>], model: Model, rounds: usize) -> f64 {
    let mut answers = vec![Ok(0.0); scenes.len()];
    for _ in 0..rounds {
        times_s(std::hint::black_box(scenes), model, &mut answers);
        std::hint::black_box(&mut answers);
    }
    answers.iter().filter_map(|a| a.ok()).sum::<f64>()
}

/// Nanoseconds per scene over `threads` threads (the scenes split evenly between them).
fn ns_per_scene(scenes: &[Scene<f64>], model: Model, threads: usize) -> f64 {
    if scenes.is_empty() {
        return f64::NAN;
    }
    // Rounds per pass: doubled until one pass on one thread lasts MIN_PASS_S (as timeit's
    // autorange), then scaled by the threads so each thread's share lasts as long.
    let mut rounds = 1usize;
    loop {
        let t0 = Instant::now();
        std::hint::black_box(pass(scenes, model, rounds));
        if t0.elapsed().as_secs_f64() >= MIN_PASS_S || rounds >= 1 << 30 {
            break;
        }
        rounds *= 2;
    }
    let rounds = rounds * threads;
    let chunk = scenes.len().div_ceil(threads);
    let mut best = f64::INFINITY;
    for _ in 0..REPEATS {
        let start = Instant::now();
        std::thread::scope(|scope| {
            for part in scenes.chunks(chunk) {
                scope.spawn(move || std::hint::black_box(pass(part, model, rounds)));
            }
        });
        let ns = start.elapsed().as_secs_f64() * 1e9 / (scenes.len() * rounds) as f64;
        best = best.min(ns);
    }
    best
}

/// The throughput figures of `rows` as JSON: per model, scenes, ns per scene on one thread and
/// on every core, and the cores used.
pub fn measure(rows: &[(Model, Scene<f64>)]) -> Value {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut out = serde_json::Map::new();
    for (model, name) in [(Model::Flat, "flat"), (Model::Coriolis, "coriolis")] {
        let scenes: Vec<Scene<f64>> = rows
            .iter()
            .filter(|(m, _)| *m == model)
            .map(|(_, s)| *s)
            .collect();
        if scenes.is_empty() {
            continue;
        }
        out.insert(
            name.into(),
            json!({
                "scenes": scenes.len(),
                "ns_per_scene_one_thread": ns_per_scene(&scenes, model, 1),
                "ns_per_scene_all_cores": ns_per_scene(&scenes, model, threads),
                "threads": threads,
            }),
        );
    }
    Value::Object(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use model_core::particle::residence_time_s;
    use proptest::prelude::*;

    /// Physical scenes mostly, with rim starts, scenes that never leave and any finite values
    /// mixed in, so that regular and irregular scenes share the SIMD lanes.
    fn scene() -> impl Strategy<Value = Scene<f64>> {
        let any = || prop::num::f64::NORMAL | prop::num::f64::ZERO | prop::num::f64::SUBNORMAL;
        prop_oneof![
            4 => (0.5f64..20.0, 0.0f64..0.5, 0.0f64..0.35, 0.05f64..0.3).prop_map(
                |(omega_rad_s, mu, ri_m, rim_radius_m)| Scene {
                    omega_rad_s, mu, g_m_s2: 9.81, k2: 5.0 / 7.0, ri_m, rim_radius_m,
                }
            ),
            1 => (any(), any(), any(), any(), any(), any()).prop_map(
                |(omega_rad_s, mu, g_m_s2, k2, ri_m, rim_radius_m)| Scene {
                    omega_rad_s, mu, g_m_s2, k2, ri_m, rim_radius_m,
                }
            ),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]
        /// The host's widest-SIMD batch (AVX2 where the processor has it) gives every scene
        /// the one-scene answer bit for bit, errors included.
        #[test]
        fn widest_simd_batch_is_the_one_scene_answer(
            scenes in prop::collection::vec(scene(), 0..70)
        ) {
            for model in [Model::Flat, Model::Coriolis] {
                let mut out = vec![Ok(-1.0); scenes.len()];
                times_s(&scenes, model, &mut out);
                for (s, got) in scenes.iter().zip(&out) {
                    let want = residence_time_s(s, model);
                    let same = match (got, &want) {
                        (Ok(a), Ok(b)) => a.to_bits() == b.to_bits(),
                        _ => got == &want,
                    };
                    prop_assert!(same, "{:?} {:?}: batch {:?}, one scene {:?}", model, s, got, want);
                }
            }
        }
    }
}

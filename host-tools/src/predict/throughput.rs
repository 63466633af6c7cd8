//! `bowl predict --batch IN --out OUT --throughput`: how fast the closed forms run over the
//! file's scenes, per model, as the time alone (`particle::residence_times_s`, what a vectorised
//! numpy closed form computes too): nanoseconds per scene on one thread and on every core.
//! tests/scipy/compare.sh puts it beside numpy on the same scenes in the same run.
//!
//! Each figure is the best of [`REPEATS`] passes over the scenes, each pass at least
//! [`MIN_PASS_S`] long (the scenes repeated as often as that needs): the least disturbed
//! measurement of the machine's throughput, as `timeit` takes it.

use std::time::Instant;

use model_core::particle::{Model, Scene, residence_times_s};
use serde_json::{Value, json};

/// Passes measured; the fastest counts.
const REPEATS: usize = 15;
/// Shortest pass, s.
const MIN_PASS_S: f64 = 0.05;

/// The time alone for every scene of `scenes` (`particle::residence_times_s`, the batch form),
/// `rounds` times; returns a sum so nothing is optimised away.
fn pass(scenes: &[Scene<f64>], model: Model, rounds: usize) -> f64 {
    let mut answers = vec![Ok(0.0); scenes.len()];
    let mut sum = 0.0;
    for _ in 0..rounds {
        residence_times_s(std::hint::black_box(scenes), model, &mut answers);
        sum += answers.iter().filter_map(|a| a.ok()).sum::<f64>();
    }
    sum
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

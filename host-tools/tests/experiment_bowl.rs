//! A simulated rig whose granules follow the bowl model (`[particle] model = "bowl"`,
//! docs/rigs/bowl-60deg.toml): each release leaves when `bowl predict --model bowl` says for the
//! same scene and azimuth, and `bowl experiment` then `bowl fit --bowl-walls` on such a rig find
//! its true `mu_s` and its wall.

mod common;

use std::path::{Path, PathBuf};

use common::{bowl, success_json};
use model_core::binding::Injector;
use model_core::sim::granule::ParticleParams;
use model_core::wire::GateKind;
use virtual_rig::World;

/// The worked example's rig file.
fn rig_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/rigs/bowl-60deg.toml")
}

/// Its one rig's granule truth.
fn truth() -> ParticleParams {
    let rigs = rig_file::load(&rig_path()).unwrap();
    rigs[0].particle.unwrap()
}

/// At constant motor speeds (no plant: the world stepped at 1 ms with the speeds given), the
/// exit gate minus the release gate is the bowl model's T for that release's azimuth, as
/// `bowl predict --model bowl --rig-file` computes it from the same rig file: to the gate's
/// microsecond. Speeds equal, unequal and with the spin reversed; the rig's gate jitter off.
#[test]
fn a_release_in_the_bowl_leaves_when_bowl_predict_says() {
    let mut particle = truth();
    particle.gate_jitter_s = 0.0;
    let b = particle
        .bowl
        .expect("the example's granules follow the bowl model");
    let mut world = World::new(particle, 7, b.axes_angle_rad);
    let mut now_us = 1_000_000u32;
    for speeds in [[1.2, 1.2], [2.5, 1.4], [1.8, -0.9]] {
        world.release().unwrap();
        let (mut released, mut left) = (None, None);
        for _ in 0..5_000 {
            world.step(speeds, now_us, 1e-3);
            now_us += 1000;
            while let Some(e) = world.gate_event() {
                match e.kind {
                    GateKind::Release => released = Some(e.time_us),
                    GateKind::Exit => left = Some(e.time_us),
                }
            }
            if left.is_some() {
                break;
            }
        }
        let simulated = f64::from(left.unwrap() - released.unwrap()) * 1e-6;
        let drawn = world.last_bowl_release().unwrap();
        let (w1, w2, beta) = (
            format!("--precession-rad-s={:e}", speeds[0]),
            format!("--spin-rad-s={:e}", speeds[1]),
            format!("{:e}", drawn.azimuth_rad.to_degrees()),
        );
        let (mu, mu_s, ri, k2) = (
            particle.mu.to_string(),
            b.sliding_mu.to_string(),
            particle.release_radius_m.to_string(),
            particle.k2.to_string(),
        );
        let out = bowl(&[
            "predict",
            "--model",
            "bowl",
            "--rig-file",
            rig_path().to_str().unwrap(),
            &w1,
            &w2,
            "--mu",
            &mu,
            "--sliding-mu",
            &mu_s,
            "--ri-m",
            &ri,
            "--k2",
            &k2,
            "--release-azimuth-deg",
            &beta,
            "--max-time-s",
            "60",
            "--speed-range",
            "false",
            "--json",
        ]);
        let v = success_json(&out, "bowl predict --model bowl");
        let predicted = v["per_release"][0]["residence_time_s"].as_f64().unwrap();
        assert!(
            (simulated - predicted).abs() <= 0.5e-6 + 1e-9,
            "speeds {speeds:?}, azimuth {beta} deg: simulated {simulated} s, predicted {predicted} s"
        );
        assert!(predicted > 0.05 && predicted < 1.0, "{predicted}");
    }
}

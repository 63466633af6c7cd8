//! Why the flat batch leaving only is not 2x numpy (docs/model.md, "Batch throughput beside
//! numpy"): on the same leaving scenes as `batch_throughput`, compiled for AVX-512 (8 lanes of
//! f64), ns per scene, best of 30 passes of 10 rounds, in one run:
//!
//! 1. the divider alone: one f64 division, one square root, and the six divisions and two square
//!    roots a scene of the one-scene order, over independent elements (its throughput floor);
//! 2. the flat form's arithmetic alone in the one-scene order (`Real::sqrt`, `ln_1p_in_domain`,
//!    no validity tests, no answer stores), arrays of each input (the best layout for lanes);
//! 3. the same with shared reciprocals (one division for `x` and `1 / (k omega)`, one for
//!    `ln_1p`'s two quotients): 2 divisions, different bits from the one-scene form;
//! 4. the batch itself (`particle::residence_times_s`, what `bowl predict --batch --throughput`
//!    times).
//!
//! `cargo run --release -p model-core --example batch_floor` (x86-64 with AVX-512F).

use model_core::Real;
use model_core::particle::{Model, Scene, SceneError, residence_times_s};
use std::time::Instant;

/// One scene's inputs, an array each.
struct Inputs {
    omega: Vec<f64>,
    mu: Vec<f64>,
    g: Vec<f64>,
    k2: Vec<f64>,
    ri: Vec<f64>,
    rim: Vec<f64>,
}

fn uniform(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// The leaving-only regime of tests/scipy/batch.py: omega 2.5 to 6 rad/s, mu 0 to 0.1, rim
/// 0.1 m, the start at least 10 % above the equilibrium radius.
fn leaving(n: usize) -> Vec<Scene<f64>> {
    let mut state = 7u64;
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let (w, mu) = (2.5 + 3.5 * uniform(&mut state), 0.1 * uniform(&mut state));
        let a = mu * 9.81 / (w * w);
        let low = (1.1 * a).max(0.01);
        let ri = (low + uniform(&mut state) * (0.095 - low)).min(0.095);
        if ri > 1.05 * a {
            out.push(Scene {
                omega_rad_s: w,
                mu,
                ri_m: ri,
                rim_radius_m: 0.1,
                ..Scene::default()
            });
        }
    }
    out
}

/// 6 divisions and 2 square roots an element (`DIVS`, `SQRTS` of them), independent.
#[target_feature(enable = "avx512f")]
fn divider<const DIVS: usize, const SQRTS: usize>(s: &Inputs, out: &mut [f64]) {
    let n = out.len();
    let (x, y, z) = (&s.omega[..n], &s.ri[..n], &s.k2[..n]);
    for i in 0..n {
        let (x, y, z) = (x[i], y[i], z[i]);
        let quotients = [x / y, y / z, z / x, x / z, z / y, y / x];
        let mut r = quotients[..DIVS].iter().sum::<f64>();
        if SQRTS >= 1 {
            r += Real::sqrt(x);
        }
        if SQRTS >= 2 {
            r += Real::sqrt(y);
        }
        out[i] = r;
    }
}

/// The flat form's arithmetic in the one-scene order (`flat_batch.rs`): 6 divisions, 2 roots.
#[target_feature(enable = "avx512f")]
fn one_scene_order(s: &Inputs, out: &mut [f64]) {
    let n = out.len();
    let (w_, mu_, g_, k2_, ri_, r_) = (
        &s.omega[..n],
        &s.mu[..n],
        &s.g[..n],
        &s.k2[..n],
        &s.ri[..n],
        &s.rim[..n],
    );
    for i in 0..n {
        let (omega, mu, g, k2, ri, rim) = (w_[i], mu_[i], g_[i], k2_[i], ri_[i], r_[i]);
        let a = mu * g / omega / omega;
        let x = (rim - ri) / (ri - a);
        let w = Real::sqrt(x * (x + 2.0));
        out[i] = (x + w).ln_1p_in_domain() / (Real::sqrt(k2) * omega);
    }
}

/// The same with shared reciprocals: 2 divisions, 2 roots (`ln_1p` written out with one
/// division for its correction and its `s = f / (2 + f)`).
#[target_feature(enable = "avx512f")]
fn shared_reciprocals(s: &Inputs, out: &mut [f64]) {
    let n = out.len();
    let (w_, mu_, g_, k2_, ri_, r_) = (
        &s.omega[..n],
        &s.mu[..n],
        &s.g[..n],
        &s.k2[..n],
        &s.ri[..n],
        &s.rim[..n],
    );
    for i in 0..n {
        let (omega, mu, g, k2, ri, rim) = (w_[i], mu_[i], g_[i], k2_[i], ri_[i], r_[i]);
        let w2 = omega * omega;
        let d = ri * w2 - mu * g;
        let k_omega = Real::sqrt(k2) * omega;
        let inv = 1.0 / (d * k_omega);
        let x = (rim - ri) * w2 * k_omega * inv;
        let y = x + Real::sqrt(x * (x + 2.0));
        out[i] = ln_1p_one_division(y) * (d * inv);
    }
}

/// `real/log1p.rs`'s f64 `ln_1p_in_domain` with its two quotients over one division.
#[inline(always)]
fn ln_1p_one_division(y: f64) -> f64 {
    const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
    const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
    const LG: [f64; 7] = [
        f64::from_bits(0x3fe5_5555_5555_5593),
        f64::from_bits(0x3fd9_9999_9997_fa04),
        f64::from_bits(0x3fd2_4924_9422_9359),
        f64::from_bits(0x3fcc_71c5_1d8e_78af),
        f64::from_bits(0x3fc7_4664_96cb_03de),
        f64::from_bits(0x3fc3_9a09_d078_c69f),
        f64::from_bits(0x3fc2_f112_df3e_5244),
    ];
    let u = 1.0 + y;
    let ix = u
        .to_bits()
        .wrapping_add(0x3ff0_0000_0000_0000 - 0x3fe6_a09e_0000_0000);
    let k = f64::from_bits((ix >> 52) | 0x4330_0000_0000_0000) - (4_503_599_627_370_496.0 + 1023.0);
    let f = f64::from_bits((ix & 0x000f_ffff_ffff_ffff).wrapping_add(0x3fe6_a09e_0000_0000)) - 1.0;
    let q = 1.0 / (u * (2.0 + f));
    let c = (y - (u - 1.0)) * (2.0 + f) * q;
    let s = f * u * q;
    let z = s * s;
    let w = z * z;
    let t1 = w * (LG[1] + w * (LG[3] + w * LG[5]));
    let t2 = z * (LG[0] + w * (LG[2] + w * (LG[4] + w * LG[6])));
    let hfsq = 0.5 * f * f;
    s * (hfsq + t1 + t2) + (k * LN2_LO + c) - hfsq + f + k * LN2_HI
}

#[target_feature(enable = "avx512f")]
fn batch(scenes: &[Scene<f64>], out: &mut [Result<f64, SceneError>]) {
    residence_times_s(scenes, Model::Flat, out);
}

/// Best ns per element of `f` over 30 passes of 10 rounds.
fn best(n: usize, mut f: impl FnMut()) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..30 {
        let t0 = Instant::now();
        for _ in 0..10 {
            f();
        }
        best = best.min(t0.elapsed().as_secs_f64() * 1e9 / (10 * n) as f64);
    }
    best
}

fn main() {
    if !std::is_x86_feature_detected!("avx512f") {
        println!("this processor has no AVX-512F: nothing measured");
        return;
    }
    let scenes = leaving(100_000);
    let n = scenes.len();
    let inputs = Inputs {
        omega: scenes.iter().map(|s| s.omega_rad_s).collect(),
        mu: scenes.iter().map(|s| s.mu).collect(),
        g: scenes.iter().map(|s| s.g_m_s2).collect(),
        k2: scenes.iter().map(|s| s.k2).collect(),
        ri: scenes.iter().map(|s| s.ri_m).collect(),
        rim: scenes.iter().map(|s| s.rim_radius_m).collect(),
    };
    let mut out = vec![0.0; n];
    let mut answers = vec![Ok(0.0); n];
    // SAFETY (every `unsafe` below): the processor has reported AVX-512F, the only feature the
    // functions enable.
    let mut run = |name: &str, f: &mut dyn FnMut(&Inputs, &mut [f64])| {
        let ns = best(n, || {
            f(std::hint::black_box(&inputs), &mut out);
            std::hint::black_box(&mut out);
        });
        println!("{name:58} {ns:.2} ns a scene");
    };
    run("divider: 1 division", &mut |s, o| unsafe {
        divider::<1, 0>(s, o)
    });
    run("divider: 1 square root", &mut |s, o| unsafe {
        divider::<0, 1>(s, o)
    });
    run(
        "divider: 6 divisions + 2 square roots",
        &mut |s, o| unsafe { divider::<6, 2>(s, o) },
    );
    run(
        "divider: 2 divisions + 2 square roots",
        &mut |s, o| unsafe { divider::<2, 2>(s, o) },
    );
    run(
        "flat arithmetic alone, one-scene order (6 div, 2 sqrt)",
        &mut |s, o| unsafe { one_scene_order(s, o) },
    );
    run(
        "flat arithmetic alone, shared reciprocals (2 div, 2 sqrt)",
        &mut |s, o| unsafe { shared_reciprocals(s, o) },
    );
    let ns = best(n, || {
        unsafe { batch(std::hint::black_box(&scenes), &mut answers) };
        std::hint::black_box(&mut answers);
    });
    println!(
        "{:58} {ns:.2} ns a scene",
        "the batch (residence_times_s, AVX-512)"
    );
}

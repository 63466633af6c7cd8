//! The flat model's residence time (paper Eq. 6) over a batch of scenes, written in lanes that
//! the compiler turns into SIMD instructions.
//!
//! The one-scene path ([`super::residence_time_s`]) branches on every check before its one
//! square root, logarithm and divisions; numpy's vectorised closed form runs four scenes per
//! instruction. Here the arithmetic of [`LANES`] scenes runs first with no branch (a scene that
//! is not regular computes a meaningless number, never a panic), then each scene is answered:
//! a regular one (valid, inside the rim, above the equilibrium radius, `x` below
//! `1/epsilon`, finite time) with the lane's time, which is the one-scene time bit for bit
//! (the same operations in the same order, no contraction), every other one by the one-scene
//! path itself.

use super::{Model, Scene, SceneError, residence_time_s};
use crate::Real;

/// Scenes per group: two AVX2 registers of f64 (four of f32), enough to hide the latency of
/// the divisions.
const LANES: usize = 8;

/// [`residence_time_s`] with [`Model::Flat`] for every scene, into `out` (as many answers as
/// both have). Inlined so that a caller compiled for wider SIMD (the host's AVX2 path)
/// compiles the lanes for it too.
#[inline(always)]
pub(crate) fn times_s<T: Real>(scenes: &[Scene<T>], out: &mut [Result<T, SceneError>]) {
    let n = scenes.len().min(out.len());
    let (scenes, out) = (&scenes[..n], &mut out[..n]);
    let mut groups = scenes.chunks_exact(LANES);
    let mut answers = out.chunks_exact_mut(LANES);
    for (group, answer) in (&mut groups).zip(&mut answers) {
        lanes(group, answer);
    }
    for (scene, answer) in groups
        .remainder()
        .iter()
        .zip(answers.into_remainder().iter_mut())
    {
        *answer = residence_time_s(scene, Model::Flat);
    }
}

/// One group of exactly [`LANES`] scenes.
#[inline(always)]
fn lanes<T: Real>(group: &[Scene<T>], out: &mut [Result<T, SceneError>]) {
    let mut time = [T::ZERO; LANES];
    let mut regular = [false; LANES];
    for ((scene, time), regular) in group.iter().zip(&mut time).zip(&mut regular) {
        // As `Scene::equilibrium_radius_m`, `before_model` and `flat::time`, in their order.
        let omega = scene.omega_rad_s;
        let a = scene.mu * scene.g_m_s2 / omega / omega;
        let num = scene.rim_radius_m - scene.ri_m;
        let den = scene.ri_m - a;
        let x = num / den;
        let w = (x * (x + T::TWO)).sqrt();
        let k_omega = scene.k2.sqrt() * omega;
        *time = (x + w).ln_1p_in_domain() / k_omega;
        // `&`, not `&&`: every test on every lane, no branch.
        let valid = scene.mu.is_nonneg_finite()
            & scene.g_m_s2.is_nonneg_finite()
            & scene.k2.is_in_unit_interval()
            & scene.ri_m.is_nonneg_finite()
            & scene.rim_radius_m.is_nonneg_finite()
            & omega.is_nonneg_finite();
        *regular = valid
            & (omega > T::ZERO)
            & (scene.ri_m < scene.rim_radius_m)
            & (scene.ri_m > a)
            & (x < T::ONE / T::EPSILON)
            & time.is_finite();
    }
    for (((scene, answer), time), regular) in group.iter().zip(out).zip(time).zip(regular) {
        // Two stores, not one of a merged value: the merge went through the stack byte by
        // byte and stalled every store after it.
        if regular {
            *answer = Ok(time);
        } else {
            *answer = residence_time_s(scene, Model::Flat);
        }
    }
}

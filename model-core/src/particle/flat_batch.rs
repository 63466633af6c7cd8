//! The flat model's residence time (paper Eq. 6) over a batch of scenes, written in lanes that
//! the compiler turns into SIMD instructions: the costly lanes of [`super::batch`], for the
//! scenes its cheap pass did not settle.
//!
//! The one-scene path ([`super::residence_time_s`]) branches on every check before its one
//! square root, logarithm and divisions; numpy's vectorised closed form runs four scenes per
//! instruction. Here the arithmetic of [`LANES`] scenes runs first with no branch (a scene that
//! is not regular computes a meaningless number, never a panic), then each scene is answered:
//! a regular one (valid, inside the rim, above the equilibrium radius, `x` below
//! `1/epsilon`, finite time) with the lane's time, which is the one-scene time bit for bit
//! (the same operations in the same order, no contraction), every other one by the one-scene
//! path itself.

use super::batch::{Costly, LANES, answer};
use super::{Model, Scene, SceneError};
use crate::Real;

/// The flat model's costly lanes for [`super::batch::times_s`].
pub(crate) struct Flat;

impl Costly for Flat {
    const MODEL: Model = Model::Flat;

    /// One group of exactly [`LANES`] scenes.
    #[inline(always)]
    fn lanes<T: Real>(
        group: &[Scene<T>; LANES],
        out: &mut [Result<T, SceneError>; LANES],
    ) -> usize {
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
            let valid = scene.is_valid();
            let inside = scene.ri_m < scene.rim_radius_m;
            *regular = valid
                & (omega > T::ZERO)
                & inside
                & (scene.ri_m > a)
                & (x < T::ONE / T::EPSILON)
                & time.is_finite();
        }
        answer(group, out, time, regular, Model::Flat)
    }
}

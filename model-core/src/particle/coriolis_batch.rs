//! The Coriolis model's residence time (paper Eq. 10, 11, corrected as in docs/model.md §3)
//! over a batch of f64 scenes, written in lanes that the compiler turns into SIMD instructions.
//!
//! On the rig's scenes the one-scene root search ([`super::coriolis::solve_u`]) ends after its
//! first evaluation: the perturbative start, one Halley step, and where that is not yet within
//! rounding Newton on `F`'s expansion at the same point
//! ([`super::coriolis::local_root_parts`]). Here that path runs for [`LANES`] scenes at once
//! with no branch (every test with `&`, every `if` a selection; a scene off the path computes
//! a meaningless number, never a panic), then each scene is answered: one that stayed on the
//! path with its lane's time, which is the one-scene time bit for bit (the same operations in
//! the same order, no contraction), every other one by the one-scene path itself.

use super::batch::{Costly, LANES, answer};
use super::coriolis::{LocalRoot, PERTURBATIVE_M, local_root_parts};
use super::{Model, Scene, SceneError, Shape};
use crate::Real;
use crate::real::exp::phi_terms_f64;

/// Largest `|z|` whose `e^z` the lanes compute ([`Real::exp_in_domain`]).
const EXP_DOMAIN: f64 = 700.0;

/// The Coriolis model's costly lanes for [`super::batch::times_s`] (f64: the f32 batch follows
/// the one-scene search, see [`super::residence_times_s`]).
pub(crate) struct Coriolis;

impl Costly for Coriolis {
    const MODEL: Model = Model::Coriolis;

    #[inline(always)]
    fn lanes<T: Real>(
        group: &[Scene<T>; LANES],
        out: &mut [Result<T, SceneError>; LANES],
    ) -> usize {
        lanes(group, out)
    }
}

/// `(phi(z), expm1(z))` as [`super::phi::phi_expm1`] computes them in f64, both ways and then
/// selected, for `|z| <= EXP_DOMAIN`.
#[inline(always)]
fn phi_expm1<T: Real>(z: T) -> (T, T) {
    let phi_series = z * z * T::HALF * T::from_f64(phi_terms_f64(z.to_f64()));
    let e = z.exp_in_domain() - T::ONE;
    if z.abs() < T::ONE {
        (phi_series, phi_series + z)
    } else {
        (e - z, e)
    }
}

/// One group of exactly [`LANES`] scenes; returns how many leave on the lanes' path (the
/// others are at the rim, held, or went to the one-scene path).
#[inline(always)]
fn lanes<T: Real>(group: &[Scene<T>; LANES], out: &mut [Result<T, SceneError>; LANES]) -> usize {
    let mut time = [T::ZERO; LANES];
    let mut regular = [false; LANES];
    for ((scene, time), regular) in group.iter().zip(&mut time).zip(&mut regular) {
        // As `before_model`, `Setup::new` with `Shape::new` (m <= 1), `start` (perturbative,
        // x below 1/epsilon) and the first `Search::step`, in their order.
        let omega = scene.omega_rad_s;
        let a = scene.mu * scene.g_m_s2 / omega / omega;
        let k = scene.k2.sqrt();
        let m = k * scene.mu;
        let shape = Shape::coriolis(k, m, (T::ONE + m * m).sqrt());
        let den = scene.ri_m - a;
        let rise = scene.rim_radius_m - scene.ri_m;
        let x = rise / den;
        let m_start = T::TWO * shape.a_coef - T::ONE;
        let w = (x * (x + T::TWO)).sqrt();
        let u0 = (x + w).ln_1p_in_domain();
        let decay = u0 / ((T::ONE + x + w) * w);
        let u = (u0 - m_start * (T::ONE - decay)).max(T::ZERO);
        let e = shape.eval_parts_by(u, phi_expm1);
        let below = e.f < x;
        let lower = if below { u } else { T::ZERO };
        let upper = if below { T::INFINITY } else { u };
        let far = T::from_f64(4.0);
        let per_fp = T::ONE / e.fp;
        let d = (e.f - x) * per_fp;
        let half_curv = T::HALF * e.fpp * per_fp;
        let bend = d * half_curv;
        let step = d / (T::ONE - bend);
        let next = (u - step).max(lower).min(upper);
        let c = (e.fppp * T::from_f64(1.0 / 6.0) * per_fp - half_curv * half_curv).abs();
        let converged = c * step * step * step.abs() <= T::from_f64(0.25) * T::EPSILON * next;
        let LocalRoot { root, found } =
            local_root_parts(&shape, &e, u, e.f - x, next - u, half_curv);
        let u_end = if converged { next } else { root };
        *time = u_end / (shape.c1 * omega);
        // `&`, not `&&`: every test on every lane, no branch.
        let valid = scene.is_valid();
        let inside = scene.ri_m < scene.rim_radius_m;
        let exp_domain = T::from_f64(EXP_DOMAIN);
        *regular = valid
            & (omega > T::ZERO)
            & inside
            & (scene.ri_m > a)
            & (m <= T::ONE)
            & shape.q.is_finite()
            & (shape.c1 > T::ZERO)
            & (shape.b_coef > T::ZERO)
            & (x < T::ONE / T::EPSILON)
            & (m_start < T::from_f64(PERTURBATIVE_M))
            & (w > T::ZERO)
            & (shape.q * u <= exp_domain)
            & (u <= exp_domain)
            & e.fpp.is_finite()
            & (e.fp > T::ZERO)
            & !((u > T::ONE) & ((e.f > far * x) | (x > far * e.f)))
            & (bend.abs() < T::HALF)
            & (converged | (found & (root >= lower) & (root <= upper)))
            & time.is_finite();
    }
    answer(group, out, time, regular, Model::Coriolis)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::particle::residence_time_s;

    /// The rig's scenes (mu up to 0.1, the equilibrium radius 2..92 % of the rim's, released
    /// anywhere between) stay on the lanes' path, each with the one-scene answer bit for bit:
    /// a change that sent them to the one-scene path would still give the right answers, only
    /// slowly. (Above `k mu` of about 0.26 the search starts elsewhere and the lanes step
    /// aside.)
    #[test]
    fn the_rigs_scenes_are_answered_by_the_lanes() {
        let mut next = crate::particle::tests::uniform_stream(12345);
        let mut answered = 0;
        let groups = 200;
        for _ in 0..groups {
            let group: [Scene<f64>; LANES] = core::array::from_fn(|_| {
                // The equilibrium radius a share of the rim's, the release between them.
                let rim_radius_m = 0.05 + 0.25 * next();
                let a = rim_radius_m * (0.02 + 0.9 * next());
                let mu = 0.1 * next();
                Scene {
                    omega_rad_s: (mu * 9.81 / a).sqrt(),
                    mu,
                    g_m_s2: 9.81,
                    k2: 5.0 / 7.0,
                    ri_m: a + (rim_radius_m - a) * (0.01 + 0.98 * next()),
                    rim_radius_m,
                }
            });
            let mut out = [Ok(-1.0); LANES];
            answered += lanes(&group, &mut out);
            for (s, got) in group.iter().zip(&out) {
                let want = residence_time_s(s, Model::Coriolis);
                assert!(want.is_ok(), "{s:?}");
                assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "{s:?}");
            }
        }
        assert_eq!(answered, groups * LANES);
    }
}

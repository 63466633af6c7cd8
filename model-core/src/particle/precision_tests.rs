//! The particle model at the edges of its number type: the f32 inverse against the f64 forward
//! model, exit speeds whose squares overflow, targets beyond the precision, the smallest start
//! radius and exit speeds far from the rim.

use super::tests::{leaves, scene};
use super::*;
use crate::Real;
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]
    /// f32 inverse: the speed it returns, put through the f64 forward model with the same f32
    /// inputs, gives the target within 4 f32 epsilons x condition (measured worst 2.8 over 20,000 random scenes) (or it says BeyondPrecision, only where
    /// the needed start lies within f32 rounding of the threshold).
    #[test]
    fn f32_inverse_round_trips_through_f64(mu in 0.0f32..0.3, ri_frac in 0.01f32..0.999,
                                           rim in 0.05f32..0.3, target in 0.01f32..30.0) {
        let s = Scene { omega_rad_s: 0.0f32, mu, g_m_s2: 9.81, k2: 5.0 / 7.0, ri_m: ri_frac * rim, rim_radius_m: rim };
        let wide = Scene { omega_rad_s: 0.0f64, mu: mu as f64, g_m_s2: 9.81f32 as f64, k2: (5.0f32 / 7.0) as f64,
                           ri_m: s.ri_m as f64, rim_radius_m: rim as f64 };
        for model in [Model::Flat, Model::Coriolis] {
            let sh = Shape::new(&wide, model).unwrap();
            let z_th = sh.c1 * (wide.mu * wide.g_m_s2 / wide.ri_m).sqrt() * target as f64;
            let w = match omega_for_residence_time(&s, model, target) {
                Ok(w) => w,
                Err(InverseError::BeyondPrecision) => {
                    // Only where the f64 answer puts the threshold a within f32 rounding of ri
                    // (the f32 check uses 8 epsilons; its own iterate may sit a few ulps off).
                    let w64 = match omega_for_residence_time(&wide, model, target as f64) {
                        Ok(w) => w,
                        // Beyond f64's precision too, so certainly beyond f32's.
                        Err(InverseError::BeyondPrecision) => continue,
                        Err(e) => panic!("f64: {e:?} at z_th {z_th}"),
                    };
                    let a = wide.mu * wide.g_m_s2 / (w64 * w64);
                    let gap = (wide.ri_m - a) / wide.ri_m;
                    prop_assert!(gap <= 32.0 * f64::from(f32::EPSILON),
                                 "BeyondPrecision with ri {gap:e} above a (z_th {z_th})");
                    continue;
                }
                Err(e) => panic!("{e:?} at z_th {z_th}"),
            };
            let back = residence(&Scene { omega_rad_s: w as f64, ..wide }, model).unwrap();
            let (t, c) = match back { Outcome::Leaves { residence_time_s, condition_number, .. } => (residence_time_s, condition_number), o => panic!("{o:?}") };
            prop_assert!((t - target as f64).abs() <= 4.0 * f64::from(f32::EPSILON) * c * target as f64, "{:?}: {} vs {} (cond {})", model, t, target, c);
        }
    }
}

/// Paper Eq. 12 at magnitudes where `r'^2` overflows f32 but the total speed does not: the
/// total must come out, not an out-of-range error (f32 has no magnitude limits, see
/// `magnitude_limits`).
#[test]
fn total_exit_speed_does_not_overflow_in_its_squares() {
    let s = Scene::<f32> {
        omega_rad_s: 1e19,
        mu: 0.0,
        g_m_s2: 9.81,
        k2: 5.0 / 7.0,
        ri_m: 1.0,
        rim_radius_m: 2.0,
    };
    // r' = (ri - a) k omega sinh(k omega T) = k omega sqrt(3) ~ 1.46e19, omega R = 2e19: each
    // square is ~1e38..4e38, their sum overflows f32 (3.4e38); the total is ~2.5e19.
    match residence(&s, Model::Flat) {
        Ok(Outcome::Leaves {
            exit_radial_velocity_m_s: v,
            exit_total_velocity_m_s: total,
            ..
        }) => {
            let expected = (f64::from(v).powi(2) + 4e38).sqrt();
            assert!(
                ((f64::from(total) - expected) / expected).abs() < 1e-6,
                "{total} vs {expected}"
            );
        }
        other => panic!("{other:?}"),
    }
}

/// A target so long that only a speed within rounding of the threshold gives it (the largest
/// finite target is the extreme case) is refused in both precisions; it used to return
/// 3.37 rad/s, at which the forward model gives 0.62 s.
#[test]
fn inverse_refuses_targets_beyond_the_precision() {
    let s64 = Scene::<f64>::default();
    let s32 = Scene::<f32>::default();
    for model in [Model::Flat, Model::Coriolis] {
        for t in [f64::MAX, 1e300, 1e6, 100.0] {
            assert_eq!(
                omega_for_residence_time(&s64, model, t),
                Err(InverseError::BeyondPrecision),
                "f64 {model:?} {t}"
            );
        }
        for t in [f32::MAX, 1e30, 1e4] {
            assert_eq!(
                omega_for_residence_time(&s32, model, t),
                Err(InverseError::BeyondPrecision),
                "f32 {model:?} {t}"
            );
        }
        // Within the precision, the forward model at the answer gives the target back.
        let w = omega_for_residence_time(&s64, model, 5.0).unwrap();
        let back = residence(
            &Scene {
                omega_rad_s: w,
                ..s64
            },
            model,
        )
        .unwrap()
        .residence_time_s();
        assert!((back - 5.0).abs() < 1e-9, "{model:?}: {back}");
    }
}

/// A start radius (or `ri - a`) so small that `x = (R - ri)/(ri - a)` is beyond `1/epsilon`,
/// down to the smallest magnitude taken ([`magnitude_limits`]): the Coriolis model must answer
/// as the flat one does (it once returned OutOfRange where `x` overflowed). Reference: for such
/// `x`, `e^{-q u}` vanishes and `F(u) = x` gives `u = ln(x / A)`, so at `mu -> 0` (`A = 1/2`)
/// `T = ln(2 (R - ri)/(ri - a)) / (k omega)`, formed here with logarithms of the parts. A
/// subnormal start radius, where `x` itself would overflow, is refused.
#[test]
fn coriolis_copes_with_the_smallest_start_radius() {
    let (omega, g, k2, rim) = (10.0f64, 9.81, 5.0 / 7.0, 0.1);
    for (ri, mu) in [
        (1e-75f64, 0.0),
        (3e-70, 0.0),
        (1e-70, 1e-75),
        (1e-60, 1e-62),
    ] {
        let s = scene(omega, mu, ri, rim);
        let a = mu * g / (omega * omega);
        let t_ref = (2.0f64.ln() + (rim - ri).ln() - (ri - a).ln()) / (k2.sqrt() * omega);
        for model in [Model::Flat, Model::Coriolis] {
            let (t, v, _) = leaves(residence(&s, model).unwrap());
            assert!(
                (t - t_ref).abs() <= 4.0 * f64::EPSILON * t_ref,
                "{model:?} ri {ri:e}: {t} vs {t_ref}"
            );
            let v_ref = k2.sqrt() * omega * rim;
            assert!(
                (v - v_ref).abs() <= 4.0 * f64::EPSILON * v_ref,
                "{model:?} ri {ri:e}: v {v} vs {v_ref}"
            );
        }
    }
    for ri in [1e-310f64, 5e-324] {
        let s = scene(omega, 0.0, ri, rim);
        assert_eq!(
            residence(&s, Model::Coriolis),
            Err(SceneError::ExtremeMagnitude(Input::StartRadius))
        );
    }
    // f32 has no magnitude limits: a subnormal start radius is answered.
    for ri in [1e-40f32, 1e-45] {
        let s = Scene {
            omega_rad_s: 10.0f32,
            mu: 0.0,
            g_m_s2: 9.81,
            k2: 5.0 / 7.0,
            ri_m: ri,
            rim_radius_m: 0.1,
        };
        let t_ref = ((2.0 * 0.1f64).ln() - f64::from(ri).ln()) / ((5.0f64 / 7.0).sqrt() * 10.0);
        match residence(&s, Model::Coriolis).unwrap() {
            Outcome::Leaves {
                residence_time_s: t,
                ..
            } => {
                let err = (f64::from(t) - t_ref).abs() / t_ref;
                assert!(
                    err <= 4.0 * f64::from(f32::EPSILON),
                    "f32 ri {ri:e}: {t} vs {t_ref}"
                );
            }
            o => panic!("f32 ri {ri:e}: {o:?}"),
        }
    }
}

/// The exit radial speed through `F'(u) = x - (A + B) expm1(-q u)` keeps full precision where
/// `u` is large (it once lost about `u` ulps through `e^u`). Reference: for `u` near 25,
/// `e^{-q u} < 1e-10`, so `r'(T) = l1 ((R - ri) + (ri - a)(A + B))` to far below an ulp, with `A`,
/// `B`, `l1` written out from docs/model.md §3.
#[test]
fn coriolis_exit_speed_keeps_full_precision_far_from_the_rim() {
    let (omega, g, k2, rim) = (40.0f64, 9.81, 5.0 / 7.0, 0.15);
    for mu in [0.05f64, 0.4, 2.0, 8.0] {
        let a = mu * g / (omega * omega);
        for x in [1e8f64, 1e10, 1e12] {
            // ri - a = (R - ri)/x  =>  ri = (R + a x)/(1 + x).
            let ri = (rim + a * x) / (1.0 + x);
            let s = scene(omega, mu, ri, rim);
            let k = k2.sqrt();
            let m = k * mu;
            let sq = (1.0 + m * m).sqrt();
            let (a_c, b_c) = ((1.0 + m / sq) / 2.0, (1.0 - m / sq) / 2.0);
            let l1 = k * omega / (sq + m);
            let v_ref = l1 * ((rim - ri) + (ri - a) * (a_c + b_c));
            let (_, v, _) = leaves(residence(&s, Model::Coriolis).unwrap());
            assert!(
                (v - v_ref).abs() <= 4.0 * f64::EPSILON * v_ref,
                "mu {mu} x {x:e}: {v} vs {v_ref}"
            );
        }
    }
}

//! Unit tests of the particle model against independent formulas. The high-precision accuracy
//! grid lives in `model-core/tests/`.

use super::*;
use crate::Real;
use proptest::prelude::*;

/// Uniform numbers in [0, 1) from a 64-bit LCG seeded with `seed`: reproducible random
/// scenes for the chooser's and the Coriolis batch's tests.
pub(crate) fn uniform_stream(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A test scene: Earth gravity, a rolling sphere (k2 = 5/7); also used by the ode and choose tests.
pub(crate) fn scene(omega: f64, mu: f64, ri: f64, rim: f64) -> Scene<f64> {
    Scene {
        omega_rad_s: omega,
        mu,
        g_m_s2: 9.81,
        k2: 5.0 / 7.0,
        ri_m: ri,
        rim_radius_m: rim,
    }
}

pub(super) fn leaves(o: Outcome<f64>) -> (f64, f64, f64) {
    match o {
        Outcome::Leaves {
            residence_time_s,
            exit_radial_velocity_m_s,
            condition_number,
            ..
        } => (residence_time_s, exit_radial_velocity_m_s, condition_number),
        other => panic!("expected Leaves, got {other:?}"),
    }
}

#[test]
fn corrected_coefficients_are_exact_at_mu_0_2() {
    // docs/model.md §3 check value: mu = 0.2, k2 = 5/7 -> l1 = 5 omega/7, l2 = -omega, A = 7/12.
    let s = scene(2.0, 0.2, 0.05, 0.1);
    let sh = Shape::new(&s, Model::Coriolis).unwrap();
    assert!((sh.c1 - 5.0 / 7.0).abs() < 1e-15);
    assert!((sh.c1 * sh.q - 1.0).abs() < 1e-15);
    assert!((sh.a_coef - 7.0 / 12.0).abs() < 1e-15);
    assert!((sh.b_coef - 5.0 / 12.0).abs() < 1e-15);
    // A + B = 1 and A l1 + B l2 = 0 -> r(0) = ri and r'(0) = 0.
    assert!((sh.a_coef + sh.b_coef - 1.0).abs() < 1e-15);
    assert_eq!(position_m(&s, Model::Coriolis, 0.0), Ok(0.05));
    assert_eq!(radial_velocity_m_s(&s, Model::Coriolis, 0.0), Ok(0.0));
}

#[test]
fn flat_time_matches_acosh_and_energy() {
    for &(w, mu, ri) in &[(3.0, 0.029, 0.05), (1.8, 0.01, 0.04), (3.6, 0.0, 0.001)] {
        let s = scene(w, mu, ri, 0.1);
        let (t, v, _) = leaves(residence(&s, Model::Flat).unwrap());
        let a = mu * 9.81 / (w * w);
        let k = (5.0f64 / 7.0).sqrt();
        let want = ((0.1 - a) / (ri - a)).acosh() / (k * w);
        assert!((t - want).abs() < 1e-13 * want, "{t} vs {want}");
        // Energy: r'^2 = k2 omega^2 ((R - a)^2 - (ri - a)^2).
        let v_want = (5.0 / 7.0 * w * w * ((0.1 - a).powi(2) - (ri - a).powi(2))).sqrt();
        assert!((v - v_want).abs() < 1e-13 * v_want);
        // And the trajectory reaches the rim at T.
        let r = position_m(&s, Model::Flat, t).unwrap();
        assert!((r - 0.1).abs() < 1e-14);
    }
}

#[test]
fn coriolis_effect_is_small_at_mu_0_029() {
    // docs/model.md §6: 0.3 to 2 % at a coefficient near 0.03 for omega >= 1.8.
    for &w in &[1.8, 2.5, 3.6] {
        let s = scene(w, 0.029, 0.09, 0.1);
        let tf = residence(&s, Model::Flat).unwrap().residence_time_s();
        let tc = residence(&s, Model::Coriolis).unwrap().residence_time_s();
        let ratio = tc / tf;
        assert!(ratio > 1.003 && ratio < 1.03, "ratio {ratio} at {w}");
    }
}

#[test]
fn explicit_outcomes() {
    let paper_literal = scene(3.6, 0.4, 0.05, 0.1);
    assert!(matches!(
        residence(&paper_literal, Model::Coriolis),
        Ok(Outcome::NeverLeaves {
            near_threshold: false,
            ..
        })
    ));
    let at_rim = scene(2.0, 0.029, 0.1, 0.1);
    assert_eq!(
        residence(&at_rim, Model::Flat),
        Ok(Outcome::AlreadyAtRim {
            exit_total_velocity_m_s: 0.2
        })
    );
    let still = scene(0.0, 0.0, 0.05, 0.1);
    assert!(matches!(
        residence(&still, Model::Flat),
        Ok(Outcome::NeverLeaves { .. })
    ));
    assert_eq!(
        residence(&scene(-1.0, 0.0, 0.05, 0.1), Model::Flat),
        Err(SceneError::InvalidOmega)
    );
    assert_eq!(
        residence(&scene(1.0, f64::NAN, 0.05, 0.1), Model::Flat),
        Err(SceneError::InvalidResistance)
    );
    let mut bad_k2 = scene(1.0, 0.0, 0.05, 0.1);
    bad_k2.k2 = 1.5;
    assert_eq!(residence(&bad_k2, Model::Flat), Err(SceneError::InvalidK2));
    assert_eq!(
        position_m(&scene(1.0, 0.0, 0.05, 0.1), Model::Flat, -1.0),
        Err(SceneError::InvalidTime)
    );
}

#[test]
fn condition_number_grows_near_threshold() {
    // ri = a (1 + d): condition about 1/(d ln x).
    let w = 3.0;
    let a = 0.029 * 9.81 / (w * w);
    for &d in &[1e-2, 1e-5, 1e-8] {
        let s = scene(w, 0.029, a * (1.0 + d), 0.1);
        let (_, _, c) = leaves(residence(&s, Model::Flat).unwrap());
        let x = (0.1 - a * (1.0 + d)) / (a * d);
        let approx = 1.0 / (d * x.ln());
        assert!(
            c > 0.5 * approx && c < 3.0 * approx,
            "d {d}: {c} vs {approx}"
        );
    }
}

#[test]
fn inverse_round_trips() {
    for model in [Model::Flat, Model::Coriolis] {
        for &(mu, ri, target) in &[
            (0.029, 0.05, 0.78),
            (0.0, 0.05, 2.0),
            (0.029, 0.099, 0.01),
            (0.2, 0.05, 5.0),
            (0.029, 0.01, 3.0),
        ] {
            let s = scene(0.0, mu, ri, 0.1);
            let w = omega_for_residence_time(&s, model, target).unwrap();
            let back = residence(
                &Scene {
                    omega_rad_s: w,
                    ..s
                },
                model,
            )
            .unwrap();
            let (t, _, c) = leaves(back);
            assert!(
                (t - target).abs() <= 4.0 * f64::EPSILON * c * target,
                "{model:?} {mu} {ri}: {t} vs {target}"
            );
        }
    }
    let s = scene(0.0, 0.029, 0.05, 0.1);
    assert_eq!(
        omega_for_residence_time(&s, Model::Flat, 0.0),
        Err(InverseError::InvalidTarget)
    );
    // 30 s from ri = 0.01 needs ri - a near 1e-60 m: between two adjacent f64 speeds.
    let far = scene(0.0, 0.029, 0.01, 0.1);
    assert_eq!(
        omega_for_residence_time(&far, Model::Flat, 30.0),
        Err(InverseError::BeyondPrecision)
    );
    let rim = scene(0.0, 0.029, 0.1, 0.1);
    assert_eq!(
        omega_for_residence_time(&rim, Model::Flat, 1.0),
        Err(InverseError::AlreadyAtRim)
    );
}

#[test]
fn inverse_is_monotone() {
    let s = scene(0.0, 0.029, 0.05, 0.1);
    let mut last = f64::INFINITY;
    for i in 1..40 {
        let w = omega_for_residence_time(&s, Model::Coriolis, 0.1 * i as f64).unwrap();
        assert!(w < last);
        last = w;
    }
}

fn any_finite_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1.0f64..10.0,
        0.0f64..1e-3,
        (-300i32..300, 0.1f64..10.0).prop_map(|(e, m)| m * 10f64.powi(e)),
        Just(0.0),
    ]
}

/// Every answer is either a finite outcome or the one error the inputs call for: an invalid
/// scene gives exactly the error its validation names, a valid one may only be out of range
/// for the number type (never unconverged, never a silent skip).
/// [`residence_time_s`] gives [`residence`]'s time bit for bit; where the full outcome is out of
/// range (an exit speed that overflows) the time alone may still be finite.
fn check_time_alone<T: Real + core::fmt::Debug>(
    full: Result<Outcome<T>, SceneError>,
    alone: Result<T, SceneError>,
) -> Result<(), TestCaseError> {
    match (full, alone) {
        (Ok(o), Ok(t)) => {
            let want = o.residence_time_s();
            prop_assert!(
                t == want || (t.is_nan() && want.is_nan()),
                "{t:?} vs {want:?}"
            );
        }
        (Err(SceneError::OutOfRange), Ok(t)) => prop_assert!(t.is_finite() && t >= T::ZERO),
        (Err(a), Err(b)) => prop_assert_eq!(a, b),
        (a, b) => prop_assert!(false, "residence {a:?}, residence_time_s {b:?}"),
    }
    Ok(())
}

fn check_outcome<T: Real>(
    valid: Result<(), SceneError>,
    o: Result<Outcome<T>, SceneError>,
) -> Result<(), TestCaseError> {
    let o = match (valid, o) {
        (Err(want), got) => {
            prop_assert_eq!(got.err(), Some(want));
            return Ok(());
        }
        (Ok(()), Err(e)) => {
            prop_assert_eq!(e, SceneError::OutOfRange, "a valid scene failed otherwise");
            return Ok(());
        }
        (Ok(()), Ok(o)) => o,
    };
    match o {
        Outcome::Leaves {
            residence_time_s: t,
            exit_radial_velocity_m_s: v,
            exit_total_velocity_m_s: vt,
            condition_number: c,
            ..
        } => {
            prop_assert!(t.is_finite() && t >= T::ZERO);
            prop_assert!(v.is_finite() && v >= T::ZERO);
            prop_assert!(vt.is_finite() && c.is_finite() && c >= T::ONE);
        }
        Outcome::AlreadyAtRim {
            exit_total_velocity_m_s: v,
        } => prop_assert!(v.is_finite()),
        Outcome::NeverLeaves {
            equilibrium_radius_m: a,
            ..
        } => prop_assert!(!a.is_nan()),
    }
    Ok(())
}

/// `r(t)`, `r'(t)`: finite, or the scene's validation error, or an invalid time, or out of range.
fn check_value<T: Real>(
    valid: Result<(), SceneError>,
    t: T,
    r: Result<T, SceneError>,
) -> Result<(), TestCaseError> {
    match (valid, r) {
        (Ok(()), Ok(v)) => prop_assert!(v.is_finite()),
        (Err(want), Ok(v)) => prop_assert!(false, "invalid scene ({want:?}) answered {v:?}"),
        (Err(want), Err(e)) => prop_assert!(e == want || e == SceneError::InvalidTime, "{e:?}"),
        (Ok(()), Err(e)) if !(t.is_finite() && t >= T::ZERO) => {
            prop_assert_eq!(e, SceneError::InvalidTime)
        }
        (Ok(()), Err(e)) => prop_assert_eq!(e, SceneError::OutOfRange),
    }
    Ok(())
}

/// The inverse answers a finite positive speed or an error that names a reason; an iteration
/// that did not settle is a defect.
fn check_inverse<T: Real>(r: Result<T, InverseError>) -> Result<(), TestCaseError> {
    match r {
        Ok(v) => prop_assert!(v.is_finite() && v > T::ZERO),
        Err(e) => prop_assert_ne!(e, InverseError::NotConverged),
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]
    #[test]
    fn never_nan_or_panic(w in any_finite_f64(), mu in any_finite_f64(), g in any_finite_f64(),
                          k2 in any_finite_f64(), ri in any_finite_f64(), rim in any_finite_f64(),
                          t in any_finite_f64()) {
        let s = Scene { omega_rad_s: w, mu, g_m_s2: g, k2, ri_m: ri, rim_radius_m: rim };
        let s32 = Scene { omega_rad_s: w as f32, mu: mu as f32, g_m_s2: g as f32, k2: k2 as f32,
                          ri_m: ri as f32, rim_radius_m: rim as f32 };
        for model in [Model::Flat, Model::Coriolis] {
            check_outcome(s.validate(), residence(&s, model))?;
            check_outcome(s32.validate(), residence(&s32, model))?;
            check_time_alone(residence(&s, model), residence_time_s(&s, model))?;
            check_time_alone(residence(&s32, model), residence_time_s(&s32, model))?;
            for r in [position_m(&s, model, t), radial_velocity_m_s(&s, model, t)] {
                check_value(s.validate(), t, r)?;
            }
            for r in [position_m(&s32, model, t as f32), radial_velocity_m_s(&s32, model, t as f32)] {
                check_value(s32.validate(), t as f32, r)?;
            }
            check_inverse(omega_for_residence_time(&s, model, t))?;
            check_inverse(omega_for_residence_time(&s32, model, t as f32))?;
        }
    }

    #[test]
    fn inverse_round_trips_on_physical_scenes(mu in 0.0f64..0.3, ri_frac in 0.01f64..0.999,
                                              rim in 0.05f64..0.3, target in 0.01f64..100.0) {
        let s = scene(0.0, mu, ri_frac * rim, rim);
        for model in [Model::Flat, Model::Coriolis] {
            let sh = Shape::new(&s, model).unwrap();
            let z_th = sh.c1 * (mu * 9.81 / s.ri_m).sqrt() * target;
            let w = match omega_for_residence_time(&s, model, target) {
                Ok(w) => w,
                // Only where ri - a would have to be below ~1e-11 ri: e^{z_th} beyond 1/eps.
                Err(InverseError::BeyondPrecision) if z_th > 25.0 => return Ok(()),
                Err(e) => panic!("{e:?} at z_th {z_th}"),
            };
            let back = residence(&Scene { omega_rad_s: w, ..s }, model).unwrap();
            let (t, c) = match back { Outcome::Leaves { residence_time_s, condition_number, .. } => (residence_time_s, condition_number), o => panic!("{o:?}") };
            prop_assert!((t - target).abs() <= 4.0 * f64::EPSILON * c * target, "{:?}: {} vs {}", model, t, target);
        }
    }
}

extern crate std;
use std::vec;
use std::vec::Vec;

/// One scene from six inputs: physical ones mostly, any finite values now and then.
fn batch_scene() -> impl Strategy<Value = Scene<f64>> {
    prop_oneof![
        3 => (0.5f64..20.0, 0.0f64..0.5, 0.001f64..0.3, 0.05f64..0.3)
            .prop_map(|(w, mu, ri, rim)| Scene { omega_rad_s: w, mu, g_m_s2: 9.81, k2: 5.0 / 7.0, ri_m: ri, rim_radius_m: rim }),
        1 => (any_finite_f64(), any_finite_f64(), any_finite_f64(), any_finite_f64(), any_finite_f64(), any_finite_f64())
            .prop_map(|(w, mu, g, k2, ri, rim)| Scene { omega_rad_s: w, mu, g_m_s2: g, k2, ri_m: ri, rim_radius_m: rim }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]
    /// The batch (interleaved root searches) gives every scene exactly the one-scene answer,
    /// errors included, in f64 and f32, whatever the mix of scenes in its lanes.
    #[test]
    fn batch_answers_are_the_one_scene_answers(scenes in prop::collection::vec(batch_scene(), 0..23)) {
        let narrow: Vec<Scene<f32>> = scenes.iter().map(Scene::to_f32).collect();
        for model in [Model::Flat, Model::Coriolis] {
            let mut out = vec![Ok(-1.0); scenes.len()];
            residence_times_s(&scenes, model, &mut out);
            for (s, got) in scenes.iter().zip(&out) {
                let want = residence_time_s(s, model);
                prop_assert!(got == &want || matches!((got, &want), (Ok(a), Ok(b)) if a.is_nan() && b.is_nan()),
                             "{model:?} {s:?}: batch {got:?}, one scene {want:?}");
            }
            let mut out32 = vec![Ok(-1.0f32); narrow.len()];
            residence_times_s(&narrow, model, &mut out32);
            for (s, got) in narrow.iter().zip(&out32) {
                prop_assert_eq!(*got, residence_time_s(s, model), "{:?} {:?}", model, s);
            }
        }
    }
}

/// Long batches through every path of the frame (`batch.rs`): the cheap pass, scenes gathered
/// across groups, whole leaving groups sent straight to the costly lanes and back, invalid and
/// extreme scenes, the remainder; every answer the one-scene answer bit for bit. Runs of the
/// paper's range (96 % never leave), of leaving scenes, and of both mixed.
#[test]
fn long_batches_take_every_path_of_the_frame() {
    let mut next = uniform_stream(31);
    let mut scenes = Vec::new();
    for run in 0..60 {
        let leaving = run % 3 == 1;
        for _ in 0..(40 + (next() * 200.0) as usize) {
            let rim = 0.075 + 0.075 * next();
            let s = if leaving || (run % 3 == 2 && next() < 0.5) {
                let (w, mu) = (2.5 + 3.5 * next(), 0.1 * next());
                let a = mu * 9.81 / (w * w);
                scene(w, mu, a + (rim - a) * (0.001 + 0.998 * next()), rim)
            } else {
                scene(
                    1.0 + 2.6 * next(),
                    0.029 + 0.371 * next(),
                    next() * rim,
                    rim,
                )
            };
            let odd = next();
            scenes.push(if odd < 0.01 {
                Scene { mu: -1.0, ..s }
            } else if odd < 0.02 {
                Scene { ri_m: 1e-300, ..s }
            } else if odd < 0.03 {
                Scene { ri_m: rim, ..s }
            } else if odd < 0.04 {
                // Within rounding of the threshold.
                Scene {
                    ri_m: s.equilibrium_radius_m(),
                    ..s
                }
            } else {
                s
            });
        }
    }
    for model in [Model::Flat, Model::Coriolis] {
        let mut out = vec![Ok(-1.0); scenes.len()];
        residence_times_s(&scenes, model, &mut out);
        for (s, got) in scenes.iter().zip(&out) {
            let want = residence_time_s(s, model);
            assert_eq!(
                got.map(f64::to_bits),
                want.map(f64::to_bits),
                "{model:?} {s:?}"
            );
        }
    }
}

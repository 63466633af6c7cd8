//! The model's closed forms against the independent 256-bit reference, over the whole validated
//! input range (g, k2 and mu far beyond the paper's 9.81, 5/7 and 0.4, starts from just above
//! the equilibrium radius to just below the rim): `|T - T_ref| <= 4 cond eps` with `cond` from
//! the reference ([`super::reference::condition`]), in f64 and in f32 (there against the
//! reference at the f32-rounded inputs).

use model_core::particle::{Model, Outcome, Scene, residence};

use super::reference::{RefModel, RefOutcome, RefScene, condition, outcome};

/// Scenes spread over the validated range: for each (mu, g, k2) the bowl speed puts the
/// equilibrium radius `a` at a fraction of `ri`, so `x = (R - ri)/(ri - a)` runs from 1e-6
/// (a start at the rim) to 1e7 (a start within 1e-8 of the threshold).
fn grid() -> Vec<Scene<f64>> {
    let mut out = Vec::new();
    for &mu in &[0.0f64, 0.029, 0.4, 2.0, 8.0, 20.0] {
        for &(g, k2) in &[(9.81, 5.0 / 7.0), (1.62, 0.4), (24.8, 1.0)] {
            let (ri, rim) = (0.02, 0.1);
            for &x in &[1e-6, 0.3, 4.0, 1e3, 1e7] {
                // ri - a = (R - ri)/x, a = mu g / omega^2.
                let a = ri - (rim - ri) / x;
                let omega = if mu == 0.0 {
                    3.6
                } else if a > 0.0 {
                    (mu * g / a).sqrt()
                } else {
                    continue;
                };
                let rim = if mu == 0.0 { ri + ri * x } else { rim };
                out.push(Scene {
                    omega_rad_s: omega,
                    mu,
                    g_m_s2: g,
                    k2,
                    ri_m: ri,
                    rim_radius_m: rim,
                });
            }
        }
    }
    out
}

fn leaves<T: model_core::Real>(o: Outcome<T>) -> Option<f64> {
    match o {
        Outcome::Leaves {
            residence_time_s, ..
        } => Some(residence_time_s.to_f64()),
        _ => None,
    }
}

#[test]
fn closed_forms_within_four_cond_eps_of_the_reference() {
    let mut checked = 0;
    for s in grid() {
        let reference = RefScene::from(&s);
        for model in [Model::Flat, Model::Coriolis] {
            let rm = RefModel::from(model);
            let RefOutcome::Leaves { time_s: t_ref, .. } = outcome(&reference, rm) else {
                continue;
            };
            let cond = condition(&reference, rm).expect("leaves, so a condition number");
            let got = residence(&s, model).map(leaves);
            let t = match got {
                Ok(Some(t)) => t,
                other => {
                    panic!("{s:?} {model:?}: reference leaves at {t_ref}, model gave {other:?}")
                }
            };
            let err = ((t - t_ref) / t_ref).abs();
            assert!(
                err <= 4.0 * cond * f64::EPSILON,
                "{s:?} {model:?}: T {t} vs {t_ref}: {err:e} > 4 x cond {cond:.3e} x eps"
            );
            checked += 1;

            let s32 = s.to_f32();
            let r32 = RefScene {
                omega_rad_s: f64::from(s32.omega_rad_s),
                mu: f64::from(s32.mu),
                g_m_s2: f64::from(s32.g_m_s2),
                k2: f64::from(s32.k2),
                start_radius_m: f64::from(s32.ri_m),
                rim_radius_m: f64::from(s32.rim_radius_m),
            };
            // In f32 a start within 1e-8 of the threshold cannot be told from it: the model
            // says so (never leaves, near the threshold) or answers within its bound.
            let RefOutcome::Leaves {
                time_s: t32_ref, ..
            } = outcome(&r32, rm)
            else {
                continue;
            };
            let cond32 = condition(&r32, rm).expect("leaves");
            match residence(&s32, model) {
                Ok(o) => match leaves(o) {
                    Some(t) => {
                        let err = ((t - t32_ref) / t32_ref).abs();
                        assert!(
                            err <= 4.0 * cond32 * f64::from(f32::EPSILON),
                            "f32 {s32:?} {model:?}: T {t} vs {t32_ref}: {err:e} > 4 x cond \
                             {cond32:.3e} x eps"
                        );
                    }
                    None => assert!(
                        matches!(
                            o,
                            Outcome::NeverLeaves {
                                near_threshold: true,
                                ..
                            }
                        ),
                        "f32 {s32:?} {model:?}: reference leaves at {t32_ref}, model {o:?}"
                    ),
                },
                Err(e) => panic!("f32 {s32:?} {model:?}: {e:?}, reference {t32_ref}"),
            }
        }
    }
    assert!(checked >= 80, "only {checked} scenes leave");
}

/// The defect an independent check found: for `k mu` above about 4.4 with `x` above about
/// 1e3 the Newton iteration started far up the exponential and returned an unconverged
/// `T = 9.455 s` (exit speed 4e20 m/s) where the answer is 1.7283 s, 0.573 m/s.
#[test]
fn coriolis_at_high_resistance_and_far_from_the_rim() {
    let s = Scene {
        omega_rad_s: 100.0,
        mu: 8.0,
        g_m_s2: 9.81,
        k2: 5.0 / 7.0,
        ri_m: 0.00785,
        rim_radius_m: 0.1,
    };
    let RefOutcome::Leaves {
        time_s,
        radial_velocity_m_s,
    } = outcome(&RefScene::from(&s), RefModel::Coriolis)
    else {
        panic!("leaves");
    };
    assert!((time_s - 1.7283).abs() < 5e-5, "reference T {time_s}");
    let Ok(Outcome::Leaves {
        residence_time_s,
        exit_radial_velocity_m_s,
        ..
    }) = residence(&s, Model::Coriolis)
    else {
        panic!("leaves");
    };
    let cond = condition(&RefScene::from(&s), RefModel::Coriolis).unwrap();
    assert!(((residence_time_s - time_s) / time_s).abs() <= 4.0 * cond * f64::EPSILON);
    assert!(((exit_radial_velocity_m_s - radial_velocity_m_s) / radial_velocity_m_s).abs() < 1e-9);
}

//! The rolling model against its limits with closed forms (docs/model.md §9) and against the
//! reference values of the tilted rig.

use core::ops::ControlFlow;

use super::equations::forces;
use super::*;
use crate::ode::system::{self, Ended};

const FINE: RollingMethod<f64> = RollingMethod::Dp54 { rtol: 1e-12 };

fn leaves(r: RollingReport<f64>) -> f64 {
    match r.outcome {
        RollingOutcome::Leaves {
            residence_time_s, ..
        } => residence_time_s,
        other => panic!("expected to leave: {other:?}"),
    }
}

fn horizontal(omega: f64, ri: f64, rim: f64) -> RollingScene<f64> {
    RollingScene {
        precession_rad_s: 0.0,
        spin_rad_s: omega,
        axes_angle_rad: 0.0,
        rolling_resistance: 0.0,
        ..RollingScene::equal_speeds(omega, 0.0, rim)
    }
    .with_start(ri)
}

impl RollingScene<f64> {
    fn with_start(self, ri: f64) -> Self {
        Self { ri_m: ri, ..self }
    }
}

/// Horizontal disc, no resistance, R = 2 ri: `T Omega = (7/2) acos((18.5 - 4)/17.5) = 2.07986`
/// (the paper's flat model gives `acosh(2)/sqrt(5/7) = 1.55825`, 25 % short).
#[test]
fn horizontal_disc_matches_its_closed_form() {
    for omega in [0.5, 3.6, 10.0] {
        let s = horizontal(omega, 0.05, 0.1);
        let closed = disc_residence_s(omega, 5.0 / 7.0, 0.05, 0.1).unwrap();
        assert!(
            (closed * omega - 2.079_86).abs() < 5e-6,
            "{}",
            closed * omega
        );
        let t = leaves(residence(&s, 0.0, FINE).unwrap());
        assert!(
            ((t - closed) / closed).abs() < 1e-9,
            "{omega}: {t} vs {closed}"
        );
        // The paper's Eq. 7 (flat, mu = 0) for comparison: 25 % short.
        let paper = 2f64.acosh() / (5f64 / 7.0).sqrt() / omega;
        assert!(((closed - paper) / closed - 0.2508).abs() < 1e-3);
    }
}

/// On the horizontal disc the granule's inertial path is a circle at `2 Omega / 7`: it never
/// gets beyond `6 ri`, so a rim at 7 ri is never reached.
#[test]
fn horizontal_disc_never_passes_six_start_radii() {
    let s = horizontal(3.0, 0.01, 0.07);
    assert_eq!(disc_residence_s(3.0, 5.0 / 7.0, 0.01, 0.07), None);
    let r = residence(&s, 0.0, RollingMethod::Dp54 { rtol: 1e-9 }).unwrap();
    assert!(
        matches!(r.outcome, RollingOutcome::NotLeftBy { .. }),
        "{:?}",
        r.outcome
    );
    // Just inside 6 ri it leaves, at the circle's far point: nu T = pi.
    let s = horizontal(3.0, 0.01, 0.0599);
    let t = leaves(residence(&s, 0.0, FINE).unwrap());
    let closed = disc_residence_s(3.0, 5.0 / 7.0, 0.01, 0.0599).unwrap();
    assert!(((t - closed) / closed).abs() < 1e-8, "{t} vs {closed}");
}

/// A constant in-plane force `F`: a tilted bowl that spins but does not precess sees gravity's
/// in-plane part `F = g sin th` fixed in the inertial frame. The rolling granule drifts
/// perpendicular to it at `(5/2) F / (m Omega)`, not downhill; on top of the drift it circles
/// at `(1 - k2) Omega = 2 Omega / 7`, so the drift is measured over whole circles.
#[test]
fn constant_force_drifts_perpendicular_to_it() {
    let th: f64 = 0.05;
    let omega = 6.0;
    let s = RollingScene {
        precession_rad_s: 0.0,
        spin_rad_s: omega,
        axes_angle_rad: th,
        rolling_resistance: 0.0,
        ri_m: 1e-3,
        rim_radius_m: 10.0,
        ..RollingScene::equal_speeds(omega, th, 10.0)
    };
    // Follow the granule in the inertial frame over many turns: its mean velocity there.
    let force = 9.81 * th.sin(); // per unit mass, along the inertial downhill direction
    let expected = 2.5 * force / omega;
    let horizon = 5.0 * core::f64::consts::TAU / (2.0 * omega / 7.0);
    let y0 = [-s.ri_m, 0.0, 0.0, 0.0, 0.0];
    let run = system::dp54(
        |t, y: &State<f64>| forces(&s, t, y).derivative,
        0.0,
        y0,
        1e-11,
        [1e-12, 1e-12, 1e-11, 1e-11, 1e-11],
        1e-4,
        |_, _| (-1.0, 0.0),
        |_, _| ControlFlow::<()>::Continue(()),
        SystemLimits {
            horizon_s: horizon,
            max_steps: 1_000_000,
        },
    )
    .unwrap();
    let Ended::Horizon { y } = run.ended else {
        panic!("{:?}", run.ended)
    };
    // Bowl frame -> inertial: rotate by psi = omega t (the bowl turns at +omega about n).
    let psi = omega * horizon;
    let (c, sn) = (psi.cos(), psi.sin());
    let inertial = [c * y[0] - sn * y[1], sn * y[0] + c * y[1]];
    let start = [-s.ri_m, 0.0];
    let drift = [
        (inertial[0] - start[0]) / horizon,
        (inertial[1] - start[1]) / horizon,
    ];
    // Downhill is -e1 at t = 0 (inertially fixed): the drift is along e2 (or -e2), not e1.
    let along = drift[0].abs();
    let across = drift[1].abs();
    assert!(
        (across - expected).abs() < 2e-3 * expected,
        "drift {across} vs (5/2) F / Omega = {expected}"
    );
    assert!(along < 2e-3 * expected, "downhill part {along}");
}

/// The straight roll down a fixed incline: the full model with no rotation at all.
#[test]
fn fixed_incline_matches_its_closed_form() {
    let th = 30f64.to_radians();
    let s = RollingScene {
        precession_rad_s: 0.0,
        spin_rad_s: 0.0,
        rolling_resistance: 0.02,
        ..RollingScene::equal_speeds(1.0, th, 0.1)
    };
    for deg in [0.0, 45.0, 90.0, 170.0] {
        let beta = f64::to_radians(deg);
        let closed = incline_residence_s(&s, beta).unwrap();
        let t = leaves(residence(&s, beta, FINE).unwrap());
        assert!(
            ((t - closed) / closed).abs() < 1e-9,
            "{deg}: {t} vs {closed}"
        );
    }
    // Resistance above the slope: held.
    let held = RollingScene {
        rolling_resistance: 0.7,
        ..s
    };
    assert_eq!(incline_residence_s(&held, 0.0), None);
    assert_eq!(
        residence(&held, 0.0, FINE).unwrap().outcome,
        RollingOutcome::Held
    );
}

fn reference_scene(th_deg: f64, rim: f64, mu_r: f64, omega: f64) -> RollingScene<f64> {
    RollingScene {
        rolling_resistance: mu_r,
        ..RollingScene::equal_speeds(omega, th_deg.to_radians(), rim)
    }
}

/// The tilted rig's reference values (three digits, from an independent derivation): 60 deg,
/// R 150 mm, mu_r 0.029, |Omega| 3.6: mean 0.211 s in [0.153, 0.287]; 30 deg, R 75 mm,
/// mu_r 0.001, |Omega| 0.5: 0.196 s in [0.146, 0.254]. Every method the chooser may pick agrees
/// with a tight DP5(4) run to 1e-6.
#[test]
fn tilted_rig_reference_values() {
    let cases = [
        (reference_scene(60.0, 0.15, 0.029, 3.6), 0.211, 0.153, 0.287),
        (
            reference_scene(30.0, 0.075, 0.001, 0.5),
            0.196,
            0.146,
            0.254,
        ),
    ];
    for (s, mean, lo, hi) in cases {
        let fine = residence_over_azimuths(&s, FINE).unwrap();
        assert_eq!(fine.left, 12);
        let (m, a, b) = (
            fine.mean_s.unwrap(),
            fine.min_s.unwrap(),
            fine.max_s.unwrap(),
        );
        assert!((m - mean).abs() <= 5e-4, "mean {m} vs {mean}");
        assert!((a - lo).abs() <= 5e-4, "min {a} vs {lo}");
        assert!((b - hi).abs() <= 5e-4, "max {b} vs {hi}");
        for method in [
            RollingMethod::Dp54 { rtol: 1e-8 },
            RollingMethod::Rk4 { step_s: 1e-3 },
        ] {
            let got = residence_over_azimuths(&s, method).unwrap();
            for (x, y) in [
                (got.mean_s.unwrap(), m),
                (got.min_s.unwrap(), a),
                (got.max_s.unwrap(), b),
            ] {
                assert!(((x - y) / y).abs() <= 1e-6, "{method:?}: {x} vs {y}");
            }
        }
    }
}

/// At 60 degrees rolling needs more friction than the measured 0.4 gives: the granule slides
/// there, and the outcome says so; at 30 degrees and low speed it rolls.
#[test]
fn slip_is_reported_where_rolling_needs_too_much_friction() {
    let steep = residence(&reference_scene(60.0, 0.15, 0.029, 3.6), 0.0, FINE).unwrap();
    let RollingOutcome::Leaves {
        max_friction_ratio,
        first_slip_s,
        ..
    } = steep.outcome
    else {
        panic!()
    };
    assert!(
        max_friction_ratio > 0.4 && first_slip_s.is_some(),
        "{max_friction_ratio}"
    );
    let gentle = residence(&reference_scene(30.0, 0.075, 0.001, 0.5), 0.0, FINE).unwrap();
    let RollingOutcome::Leaves {
        max_friction_ratio,
        first_slip_s,
        ..
    } = gentle.outcome
    else {
        panic!()
    };
    assert!(
        max_friction_ratio < 0.4 && first_slip_s.is_none(),
        "{max_friction_ratio}"
    );
}

#[test]
fn bad_inputs_are_named() {
    let s = reference_scene(30.0, 0.075, 0.001, 0.5);
    let bad = RollingScene {
        axes_angle_rad: 2.0,
        ..s
    };
    assert_eq!(bad.validate(), Err(RollingError::InvalidAxesAngle));
    let bad = RollingScene { ri_m: 0.2, ..s };
    assert_eq!(
        residence(&bad, 0.0, FINE),
        Err(RollingError::InvalidRimRadius)
    );
    assert_eq!(
        residence(&s, f64::NAN, FINE),
        Err(RollingError::InvalidAzimuth)
    );
    // Finite but beyond the magnitudes the model computes with (the 1-D scene's limits):
    // refused with the input named, where a speed of 1e200 rad/s used to overflow the step size
    // into an integration error. Zero and the limits themselves are accepted.
    use crate::particle::rolling::RollingInput;
    let (low, high) = crate::particle::magnitude_limits::<f64>();
    for (bad, input) in [
        (
            RollingScene {
                spin_rad_s: -1e200,
                ..s
            },
            RollingInput::Spin,
        ),
        (
            RollingScene {
                precession_rad_s: 1e-100,
                ..s
            },
            RollingInput::Precession,
        ),
        (RollingScene { g_m_s2: 1e80, ..s }, RollingInput::Gravity),
        (
            RollingScene {
                rim_radius_m: 1e76,
                ..s
            },
            RollingInput::RimRadius,
        ),
    ] {
        assert_eq!(bad.validate(), Err(RollingError::ExtremeMagnitude(input)));
        assert_eq!(
            residence(&bad, 0.0, FINE),
            Err(RollingError::ExtremeMagnitude(input))
        );
    }
    for ok in [
        RollingScene {
            spin_rad_s: 0.0,
            ..s
        },
        RollingScene {
            spin_rad_s: -high,
            ..s
        },
        RollingScene {
            precession_rad_s: low,
            ..s
        },
    ] {
        assert_eq!(ok.validate(), Ok(()), "{ok:?}");
    }
}

mod no_panic {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]
        /// Any finite input: an outcome or a named error, never a panic or NaN.
        #[test]
        fn any_finite_scene(
            w1 in -20.0f64..20.0, w2 in -20.0f64..20.0, th in -1.0f64..2.0,
            mu in -0.1f64..1.0, g in -1.0f64..30.0, k2 in -0.5f64..1.5,
            a in 0.0f64..0.01, l in 0.0f64..0.5, ri in -0.01f64..0.2, rim in 0.0f64..0.3,
            beta in -10.0f64..10.0,
        ) {
            let s = RollingScene {
                precession_rad_s: w1, spin_rad_s: w2, axes_angle_rad: th,
                rolling_resistance: mu, sliding_friction: 0.4, g_m_s2: g, k2,
                particle_radius_m: a, rod_length_m: l, ri_m: ri, rim_radius_m: rim,
            };
            if let Ok(RollingReport {
                outcome: RollingOutcome::Leaves { residence_time_s, exit_speed_m_s, .. },
                ..
            }) = residence(&s, beta, RollingMethod::Rk4 { step_s: 1e-3 })
            {
                prop_assert!(residence_time_s.is_finite() && residence_time_s >= 0.0);
                prop_assert!(exit_speed_m_s.is_finite());
            }
        }
    }
}

mod hierarchy_members {
    use super::super::hierarchy::{
        Member, Wanted, cheapest_within, differences, tolerance_from_resistance_uncertainty,
    };
    use super::*;

    /// On the horizontal disc without resistance the disc member is exact and the paper's flat
    /// model is 25 % short; on the 60-degree rig gravity dominates and only the full model (or
    /// the incline, within its own difference) is close.
    #[test]
    fn the_map_says_which_member_stands_in() {
        let disc = horizontal(3.6, 0.05, 0.1);
        let d = differences(&disc, FINE, Wanted::AzimuthMean);
        assert!(d[2].unwrap() < 1e-9, "disc member on the disc: {:?}", d[2]);
        assert!(
            (d[0].unwrap() - 0.2508).abs() < 1e-3,
            "paper flat: {:?}",
            d[0]
        );
        assert_eq!(
            cheapest_within(&disc, 1e-6, FINE, Wanted::AzimuthMean).0,
            Member::HorizontalDisc
        );

        let rig = reference_scene(60.0, 0.15, 0.029, 3.6);
        let d = differences(&rig, FINE, Wanted::AzimuthMean);
        // The paper's models are off by a factor (2x to 20x on the rig's grid).
        let paper_flat = d[0].unwrap_or(f64::INFINITY);
        assert!(
            paper_flat > 0.5,
            "paper flat vs rolling on the rig: {paper_flat}"
        );
        // A 1 % tolerance needs the full model here.
        let (member, diff) = cheapest_within(&rig, 0.01, FINE, Wanted::AzimuthMean);
        assert!(
            member == Member::Full || diff.is_some_and(|x| x <= 0.01),
            "{member:?} {diff:?}"
        );
        // The incline's worst release differs more than its mean (the rotation turns each path;
        // the turns cancel in the mean): a tolerance between the two takes the incline for the
        // mean but not for single releases, where the tilted plane without precession (6.5 %
        // worst on the rig) or the full model must answer.
        let d_mean = differences(&rig, FINE, Wanted::AzimuthMean);
        let d_each = differences(&rig, FINE, Wanted::EachRelease);
        let (mean, each) = (d_mean[3].unwrap(), d_each[3].unwrap());
        assert!(each > mean, "{each} vs {mean}");
        let tol = 0.5 * (mean + each);
        assert_eq!(
            cheapest_within(&rig, tol, FINE, Wanted::AzimuthMean).0,
            Member::FixedIncline
        );
        assert_eq!(
            cheapest_within(&rig, tol, FINE, Wanted::EachRelease).0,
            Member::TiltedPlane
        );
        assert_eq!(
            cheapest_within(&rig, 0.5 * d_each[4].unwrap(), FINE, Wanted::EachRelease).0,
            Member::Full
        );
        // An uncertainty of 0.01 in mu_r moves the mean by 0.3 %, less than the incline's
        // difference (0.8 %): the incline is not enough (the tilted plane, 0.05 %, is). With
        // 0.05 (a resistance known only to its size) the incline is good enough.
        let tight = tolerance_from_resistance_uncertainty(&rig, 0.01, FINE).unwrap();
        assert!(tight < mean, "{tight} vs {mean}");
        assert_eq!(
            cheapest_within(&rig, tight, FINE, Wanted::AzimuthMean).0,
            Member::TiltedPlane
        );
        let tol = tolerance_from_resistance_uncertainty(&rig, 0.05, FINE).unwrap();
        assert!(tol > mean, "{tol} vs {mean}");
        assert_eq!(
            cheapest_within(&rig, tol, FINE, Wanted::AzimuthMean).0,
            Member::FixedIncline
        );
    }
}

/// The same reference values in f32 (the MCU's precision): DP5(4) and RK4 within 1e-6 of the
/// f64 reference.
#[test]
fn tilted_rig_reference_values_in_f32() {
    let cases = [
        reference_scene(60.0, 0.15, 0.029, 3.6),
        reference_scene(30.0, 0.075, 0.001, 0.5),
    ];
    for s in cases {
        let fine = residence_over_azimuths(&s, FINE).unwrap();
        let s32 = RollingScene::<f32> {
            precession_rad_s: s.precession_rad_s as f32,
            spin_rad_s: s.spin_rad_s as f32,
            axes_angle_rad: s.axes_angle_rad as f32,
            rolling_resistance: s.rolling_resistance as f32,
            sliding_friction: s.sliding_friction as f32,
            g_m_s2: s.g_m_s2 as f32,
            k2: s.k2 as f32,
            particle_radius_m: s.particle_radius_m as f32,
            rod_length_m: s.rod_length_m as f32,
            ri_m: s.ri_m as f32,
            rim_radius_m: s.rim_radius_m as f32,
        };
        for method in [
            RollingMethod::Dp54 { rtol: 1e-6f32 },
            RollingMethod::Rk4 { step_s: 1e-3f32 },
        ] {
            let got = residence_over_azimuths(&s32, method).unwrap();
            assert_eq!(got.left, 12);
            for (x, y) in [
                (got.mean_s.unwrap(), fine.mean_s.unwrap()),
                (got.min_s.unwrap(), fine.min_s.unwrap()),
                (got.max_s.unwrap(), fine.max_s.unwrap()),
            ] {
                let e = ((f64::from(x) - y) / y).abs();
                assert!(e <= 1e-6, "f32 {method:?}: {x} vs {y}: {e:e}");
            }
        }
    }
}

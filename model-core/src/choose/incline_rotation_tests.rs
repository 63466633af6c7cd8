//! The second-order rolling incline against its own limits (the measured `c2` it is checked
//! against is in `lab`'s `whole::rotation_orders`).

use super::*;
use crate::particle::rolling::incline_residence_s;

fn rig(tilt_deg: f64, w1: f64, w2: f64) -> RollingScene<f64> {
    RollingScene::with_speeds(w1, w2, tilt_deg.to_radians(), 0.075)
}

#[test]
fn at_rest_it_is_the_incline_and_the_rotation_adds_nothing() {
    for deg in AZIMUTHS_DEG {
        let b = deg.to_radians();
        let s = rig(30.0, 0.0, 0.0);
        let (t0, t1, t2) = release_second_order_s(&s, b).unwrap();
        let want = incline_residence_s(&s, b).unwrap();
        assert!((t0 - want).abs() <= 1e-12 * want, "{deg}: {t0} vs {want}");
        assert_eq!((t1, t2), (0.0, 0.0));
        // With rotation, T0 stays the incline's.
        let s = rig(30.0, 1.8, 1.8);
        let (t0, ..) = release_second_order_s(&s, b).unwrap();
        assert!((t0 - want).abs() <= 1e-12 * want);
    }
}

#[test]
fn the_mirror_holds_and_the_orders_scale() {
    // T(beta, w) = T(-beta, -w) (docs/model.md §12): both orders agree in the mirror; T1 is
    // linear in the speeds, so it is odd in beta (and cancels in the mean), T2 even.
    let (s, m) = (rig(45.0, 2.0, -1.5), rig(45.0, -2.0, 1.5));
    for deg in [30.0f64, 90.0, 150.0] {
        let (_, a1, a2) = release_second_order_s(&s, deg.to_radians()).unwrap();
        let (_, b1, b2) = release_second_order_s(&m, (-deg).to_radians()).unwrap();
        let (_, c1, c2) = release_second_order_s(&s, (-deg).to_radians()).unwrap();
        assert!(
            a1 != 0.0 && (a1 - b1).abs() <= 1e-12 * a1.abs(),
            "{a1} {b1}"
        );
        assert!((a2 - b2).abs() <= 1e-12 * a2.abs(), "{a2} {b2}");
        assert!((a1 + c1).abs() <= 1e-12 * a1.abs() && (a2 - c2).abs() <= 1e-12 * a2.abs());
        // Doubling the speeds doubles T1 and quadruples T2.
        let (_, d1, d2) = release_second_order_s(&rig(45.0, 4.0, -3.0), deg.to_radians()).unwrap();
        assert!((d1 - 2.0 * a1).abs() <= 1e-12 * d1.abs());
        assert!((d2 - 4.0 * a2).abs() <= 1e-12 * d2.abs());
    }
}

#[test]
fn no_drive_or_no_path_gives_none() {
    // Resistance above the tilt's pull: no drive.
    let s = RollingScene {
        rolling_resistance: 2.0,
        ..rig(30.0, 1.0, 1.0)
    };
    assert!(mean_second_order(&s).is_none());
    // Released at the rim: no path.
    let s = RollingScene {
        ri_m: 0.075,
        ..rig(30.0, 1.0, 1.0)
    };
    assert!(mean_second_order(&s).is_none());
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(2000))]
    /// Any finite scene, however extreme: no panic, and what it gives is finite (T0 positive).
    #[test]
    fn any_finite_scene_gives_finite_values_or_none(
        tilt in -10.0f64..10.0, w1 in -1e6f64..1e6, w2 in -1e6f64..1e6,
        mu_r in -1.0f64..2.0, k2 in -1.0f64..2.0, a in -1.0f64..1.0,
        ri in -1.0f64..1.0, rim in -1.0f64..1.0, g in -20.0f64..1e3,
        beta in -10.0f64..10.0, big in proptest::bool::ANY,
    ) {
        let scale = if big { 1e300 } else { 1.0 };
        let s = RollingScene {
            precession_rad_s: w1 * scale,
            spin_rad_s: w2,
            axes_angle_rad: tilt,
            rolling_resistance: mu_r,
            sliding_friction: 0.4,
            g_m_s2: g * scale,
            k2,
            particle_radius_m: a,
            rod_length_m: 0.0,
            ri_m: ri,
            rim_radius_m: rim,
        };
        if let Some((t0, t1, t2)) = release_second_order_s(&s, beta) {
            proptest::prop_assert!(t0.is_finite() && t0 > 0.0 && t1.is_finite() && t2.is_finite());
        }
        if let Some((t0, rel)) = mean_second_order(&s) {
            proptest::prop_assert!(t0.is_finite() && t0 > 0.0 && rel.is_finite());
        }
    }
}

#[test]
fn the_azimuth_table_is_the_azimuths_trigonometry() {
    for (deg, (c, s)) in AZIMUTHS_DEG.iter().zip(AZIMUTH_COS_SIN) {
        let b = deg.to_radians();
        assert!(
            (b.cos() - c).abs() <= 1e-15 && (b.sin() - s).abs() <= 1e-15,
            "{deg}"
        );
    }
    // The mean from the table is the mean of the releases at the azimuths' own angles.
    let s = rig(45.0, 3.6, 3.6);
    let (mean, rel) = mean_second_order(&s).unwrap();
    let (mut t0, mut t2) = (0.0, 0.0);
    for deg in AZIMUTHS_DEG {
        let (a, _, c) = release_second_order_s(&s, deg.to_radians()).unwrap();
        t0 += a;
        t2 += c;
    }
    assert!((mean - t0 / 12.0).abs() <= 1e-14 * mean);
    assert!(
        (rel - t2 / t0).abs() <= 1e-12 * rel.abs(),
        "{rel} {}",
        t2 / t0
    );
}

#[test]
fn the_seven_release_pass_is_the_release_by_release_one_at_any_scale() {
    // The mirror pairs counted twice from the incline's times give the release-by-release sum,
    // for a bowl a million times smaller to a thousand times larger.
    for scale in [1.0, 1e-3, 1e3, 1e-6] {
        let s = RollingScene {
            ri_m: 0.0375 * scale,
            rim_radius_m: 0.075 * scale,
            particle_radius_m: 0.0025 * scale,
            ..rig(30.0, 1.8, -0.9)
        };
        let (_, rel) = mean_second_order(&s).unwrap();
        let (mut t0, mut t2) = (0.0, 0.0);
        for deg in AZIMUTHS_DEG {
            let (a, _, c) = release_second_order_s(&s, deg.to_radians()).unwrap();
            t0 += a;
            t2 += c;
        }
        assert!(
            (rel - t2 / t0).abs() <= 1e-12 * rel.abs(),
            "{scale}: {rel} {}",
            t2 / t0
        );
    }
}

/// The sliding incline's orders (`Orders::sliding`) against their own limits: at rest the
/// sliding incline with no correction; the mirror; `T1` linear and `T2` quadratic in the
/// speeds. The closed form against the disc is `lab`'s
/// `whole::rotation_orders::checks::the_closed_form_sliding_second_order_is_the_discs`.
#[test]
fn the_sliding_incline_keeps_the_limits() {
    let sliding = |w1: f64, w2: f64| RollingScene {
        sliding_friction: 0.4,
        ..rig(60.0, w1, w2)
    };
    let s = sliding(0.0, 0.0);
    assert!(crate::choose::incline::slides_in(
        &s,
        60f64.to_radians().sin(),
        0.5
    ));
    // The sliding incline's time: the rolling form with k2 = 1 and mu_s for the resistance.
    let bare = RollingScene {
        k2: 1.0,
        rolling_resistance: 0.4,
        ..s
    };
    for deg in AZIMUTHS_DEG {
        let b = deg.to_radians();
        let (t0, t1, t2) = release_second_order_s(&s, b).unwrap();
        let want = incline_residence_s(&bare, b).unwrap();
        assert!((t0 - want).abs() <= 1e-12 * want, "{deg}: {t0} vs {want}");
        assert_eq!((t1, t2), (0.0, 0.0));
    }
    let (a, m) = (sliding(2.0, -1.5), sliding(-2.0, 1.5));
    for deg in [30.0f64, 90.0, 150.0] {
        let (_, a1, a2) = release_second_order_s(&a, deg.to_radians()).unwrap();
        let (_, b1, b2) = release_second_order_s(&m, (-deg).to_radians()).unwrap();
        assert!(
            a1 != 0.0 && (a1 - b1).abs() <= 1e-12 * a1.abs(),
            "{a1} {b1}"
        );
        assert!((a2 - b2).abs() <= 1e-12 * a2.abs(), "{a2} {b2}");
        let (_, d1, d2) = release_second_order_s(&sliding(4.0, -3.0), deg.to_radians()).unwrap();
        assert!((d1 - 2.0 * a1).abs() <= 1e-12 * d1.abs());
        assert!((d2 - 4.0 * a2).abs() <= 1e-12 * d2.abs());
    }
}

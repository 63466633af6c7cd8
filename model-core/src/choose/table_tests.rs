//! The table's encoding, its dimensionless scaling and its reach, each against values computed
//! here independently.

use super::*;
use crate::ode::SpinUp;
extern crate std;

#[test]
fn a_byte_stores_its_value_rounded_up_by_less_than_a_twentieth_of_a_decade() {
    let step = libm::pow(10.0, 1.0 / 20.0);
    for k in 0..2000 {
        let v = libm::pow(10.0, -8.9 + 12.0 * f64::from(k) / 2000.0);
        let stored = DECODED[usize::from(encode(v))];
        assert!(stored >= v * (1.0 - 1e-12), "{v:e} -> {stored:e}");
        assert!(stored <= v * step * (1.0 + 1e-12), "{v:e} -> {stored:e}");
        let nearest = DECODED[usize::from(encode_nearest(v))];
        assert!(
            (nearest / v).ln().abs() <= 0.5 * step.ln() + 1e-12,
            "{v:e} -> {nearest:e}"
        );
    }
    // Below the floor: the floor (an error constant read high is safe); beyond the top, NaN,
    // infinite or negative: not measured.
    assert_eq!(encode(1e-12), 1);
    for bad in [1e6, f64::NAN, f64::INFINITY, -1.0] {
        assert_eq!(encode(bad), 0, "{bad}");
    }
}

/// A grid point, put back into metres and seconds (R = 0.1 m, omega_f = 3 rad/s), reads the
/// error constant its byte holds, and that constant is the one measured on the scene in
/// those units: RK4's largest error over the same steps against a DP5(4) at 1e-13, within
/// the byte's rounding.
#[test]
fn a_grid_point_in_metres_and_seconds_reads_what_its_scene_measures() {
    let (rim_m, w_f) = (0.1, 3.0);
    let mut checked = 0;
    for point in (0..POINTS).step_by(2357) {
        let (unit, speed) = scene_at(point);
        let scene = Scene {
            omega_rad_s: w_f,
            mu: unit.mu,
            g_m_s2: unit.g_m_s2 * rim_m * w_f * w_f,
            k2: K2,
            ri_m: unit.ri_m * rim_m,
            rim_radius_m: rim_m,
        };
        let speed = SpinUp {
            start_rad_s: speed.start_rad_s * w_f,
            final_rad_s: w_f,
            time_constant_s: speed.time_constant_s / w_f,
        };
        let Some(reading) = read(&scene, &speed) else {
            continue;
        };
        let reference = residence_s(
            &scene,
            Model::Coriolis,
            &speed,
            Method::Dp54 {
                rtol: 1e-13,
                atol: 1e-18,
            },
        );
        let coarsest = (1.5 / w_f).min(speed.time_constant_s);
        let mut measured = 0.0f64;
        for level in 0..=STEP_LEVELS {
            let h = coarsest * libm::pow(2.0, -f64::from(level) / 4.0);
            let t = residence_s(&scene, Model::Coriolis, &speed, Method::Rk4 { step_s: h });
            measured = measured.max(((t - reference) / reference).abs() / libm::pow(h * w_f, 4.0));
        }
        let ratio = reading.coriolis_constant / measured;
        assert!(
            (1.0 - 1e-6..=1.13).contains(&ratio),
            "point {point}: read {:e}, measured {measured:e}",
            reading.coriolis_constant
        );
        let t_ratio = reading.time_s / reference;
        assert!(
            (0.94..=1.06).contains(&t_ratio),
            "point {point}: T {t_ratio}"
        );
        checked += 1;
    }
    assert!(checked >= 40, "{checked}");
}

#[test]
fn scenes_the_table_does_not_hold_have_no_reading() {
    let scene = Scene {
        omega_rad_s: 3.0,
        mu: 0.029,
        g_m_s2: 9.81,
        k2: K2,
        ri_m: 0.05,
        rim_radius_m: 0.1,
    };
    let speed = SpinUp {
        start_rad_s: 0.0,
        final_rad_s: 3.0,
        time_constant_s: 0.3,
    };
    assert!(read(&scene, &speed).is_some());
    let hollow = Scene { k2: 0.6, ..scene };
    let slowing = SpinUp {
        start_rad_s: 4.0,
        ..speed
    };
    let held = Scene { mu: 0.2, ..scene };
    let frictionless = Scene { mu: 0.0, ..scene };
    let forever = SpinUp {
        time_constant_s: 1e6,
        ..speed
    };
    for (s, p) in [
        (hollow, speed),
        (scene, slowing),
        (held, speed),
        (frictionless, speed),
        (scene, forever),
    ] {
        assert_eq!(read(&s, &p), None, "{s:?} {p:?}");
    }
}

/// Any finite number, extremes included.
fn any_finite() -> impl proptest::strategy::Strategy<Value = f64> {
    use proptest::prelude::*;
    prop_oneof![
        0.0f64..10.0,
        (-300.0f64..300.0).prop_map(|e| libm::pow(10.0, e)),
        Just(0.0),
        Just(f64::MIN_POSITIVE),
        Just(f64::MAX),
    ]
}

/// Mostly within the rig's range (so that many scenes lie inside the table), else any finite
/// number.
fn rig_or_any(low: f64, high: f64) -> impl proptest::strategy::Strategy<Value = f64> {
    use proptest::prelude::*;
    prop_oneof![3 => low..high, 1 => any_finite()]
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(2000))]
    /// Any finite scene and spin-up, however extreme: reading the table never panics, and what
    /// it reads, and the plan it gives, are finite and positive.
    #[test]
    fn any_finite_spin_up_reads_finite_values_or_none(
        mu in rig_or_any(0.001, 0.2), g in rig_or_any(1.0, 20.0), ri in rig_or_any(0.01, 0.1),
        rim in rig_or_any(0.09, 0.11), start in rig_or_any(0.0, 3.0), end in rig_or_any(1.0, 8.0),
        tau in rig_or_any(0.05, 5.0),
        tolerance in 1e-12f64..0.1,
    ) {
        let scene = Scene { omega_rad_s: end, mu, g_m_s2: g, k2: K2, ri_m: ri, rim_radius_m: rim };
        let speed = SpinUp { start_rad_s: start, final_rad_s: end, time_constant_s: tau };
        if let Some(r) = read(&scene, &speed) {
            for v in [r.coriolis_constant, r.flat_constant, r.effect_rel, r.time_s] {
                proptest::prop_assert!(v.is_finite() && v > 0.0, "{r:?}");
            }
            proptest::prop_assert!(r.release_s.is_finite() && r.release_s >= 0.0, "{r:?}");
        }
        let limits = Limits::for_scene(&scene, &speed);
        let cap = (1.5 / end.max(f64::MIN_POSITIVE)).min(tau);
        if let Some(c) = read(&scene, &speed).and_then(|r| choice(&r, &speed, tolerance, cap, limits)) {
            let Plan::Integrate(Method::Rk4 { step_s }) = c.plan else {
                proptest::prop_assert!(false, "{c:?}");
                unreachable!()
            };
            proptest::prop_assert!(step_s.is_finite() && step_s > 0.0 && step_s <= cap, "{c:?}");
            proptest::prop_assert!(c.rhs_evaluations >= 5 && c.predicted_cost.is_finite(), "{c:?}");
        }
    }
}

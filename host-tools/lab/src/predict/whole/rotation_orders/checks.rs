//! The rotation orders' two checks (the parent module's docs): the mirror behind the
//! first-order claim, and the closed-form second order against the disc.

use super::*;

/// The mirror behind the first-order claim, on two scenes of the cost grid's rotation rows:
/// each release at `(w1, w2)` is the mirrored release at `(-w1, -w2)`, so the mean over the
/// twelve azimuths is even in the speeds, while single releases move at first order.
#[test]
fn the_mean_over_releases_is_even_in_the_speeds() {
    for r in [
        (30.0, 1.8, 1.8, 0.2, 0.0375, 0.075),
        (50.0, 2.5, -1.875, 0.3, 0.0375, 0.075),
    ] {
        let s = scene(r);
        let plus = disc_times_s(&s).unwrap();
        let minus = disc_times_s(&scaled(&s, -1.0)).unwrap();
        let n = plus.len();
        for (i, p) in plus.iter().enumerate() {
            // Azimuth i * 30 deg mirrors to (12 - i) * 30 deg.
            let m = minus[(n - i) % n];
            assert!(
                (p - m).abs() <= 1e-8 * p,
                "{r:?} at {} deg: {p} vs {m}",
                30 * i
            );
        }
        assert!((mean(&plus) - mean(&minus)).abs() <= 1e-8 * mean(&plus));
        // The single releases do move at first order: their odd part is far from zero.
        let odd = (plus[3] - minus[3]).abs() / plus[3];
        assert!(odd > 1e-3, "{r:?}: {odd}");
    }
}

/// The closed-form second order (model-core `choose::incline_rotation`) against the disc at
/// small speeds, where the incline rolls: `(T(s w) - T_incline) / T_incline / s^2` at `s` = 1/4
/// and 1/8 (Richardson) equals the closed form's `mean T2 / mean T0` to 1e-3 on the cost grid's
/// rolling rows (30 deg, 1.8 rad/s, mu_s 0.2; 45 deg, 3.6 rad/s, mu_s 0.4), a low tilt with the
/// spin opposite, and a release near the axis.
#[test]
fn the_closed_form_second_order_is_the_discs() {
    for r in [
        (30.0, 1.8, 1.8, 0.2, 0.0375, 0.075),
        (45.0, 3.6, 3.6, 0.4, 0.0375, 0.075),
        (10.0, 1.0, -0.75, 0.4, 0.0375, 0.075),
        (60.0, 2.5, 2.5, 0.6, 0.02, 0.1),
    ] {
        let s = scene(r);
        assert_ne!(mode_of(&s), 1, "{r:?} slides");
        let (t0, closed) = model_core::choose::incline_rotation::mean_second_order(&s).unwrap();
        let d = |k: f64| (mean(&disc_times_s(&scaled(&s, k)).unwrap()) - t0) / t0 / (k * k);
        let measured = (4.0 * d(0.125) - d(0.25)) / 3.0;
        assert!(
            (closed - measured).abs() <= 1e-3 * measured.abs(),
            "{r:?}: closed {closed:e}, measured {measured:e}"
        );
    }
}

/// The sliding incline's closed-form second order (model-core `choose::incline_rotation`,
/// `Orders::sliding`) against the disc at small speeds, as the rolling one above: the cost
/// grid's sliding row (60 deg, 3.6 rad/s, mu_s 0.4), the held-out cost grid's three (50 deg,
/// mu_s 0.3: equal, opposite and slow speeds), and a steep tilt with a release near the axis.
#[test]
fn the_closed_form_sliding_second_order_is_the_discs() {
    for r in [
        (60.0, 3.6, 3.6, 0.4, 0.0375, 0.075),
        (50.0, 0.8, 0.8, 0.3, 0.0375, 0.075),
        (50.0, 2.5, -1.875, 0.3, 0.0375, 0.075),
        (50.0, 2.5, 2.5, 0.3, 0.0375, 0.075),
        (75.0, 1.0, -0.75, 0.6, 0.02, 0.1),
    ] {
        let s = scene(r);
        assert_eq!(mode_of(&s), 1, "{r:?} does not slide");
        let (t0, closed) = model_core::choose::incline_rotation::mean_second_order(&s).unwrap();
        let d = |k: f64| (mean(&disc_times_s(&scaled(&s, k)).unwrap()) - t0) / t0 / (k * k);
        let measured = (4.0 * d(0.125) - d(0.25)) / 3.0;
        println!("{r:?}: closed {closed:e}, measured {measured:e}");
        assert!(
            (closed - measured).abs() <= 1e-3 * measured.abs(),
            "{r:?}: closed {closed:e}, measured {measured:e}"
        );
    }
}

/// `may_stick` against the bowl model (a bare rim, rtol 1e-10): on sliding scenes of the grids,
/// those where some release rolls for part of its way are said to possibly stick, and those it
/// clears slide all the way in every release. The scenes: the cost grid's 60 deg, 3.6 rad/s,
/// mu_s 0.4 and the held-out one's 50 deg, 2.5 rad/s, mu_s 0.3 (both stick), 45 deg at 3.6
/// rad/s on a wide bowl (sticks), and four that slide all the way (the cleared, and one the
/// check flags without a stick: it is a bound, not an equivalence).
#[test]
fn a_sliding_granule_that_sticks_on_its_way_is_flagged() {
    use model_core::choose::whole::may_stick;
    use model_core::particle::bowl::{BowlOutcome, residence};
    for (r, sticks, flagged) in [
        ((60.0, 3.6, 3.6, 0.4, 0.0375, 0.075), true, true),
        ((50.0, 2.5, 2.5, 0.3, 0.0375, 0.075), true, true),
        ((45.0, 3.6, 3.6, 0.2, 0.075, 0.15), true, true),
        ((60.0, 2.0, 2.0, 0.4, 0.0375, 0.075), false, false),
        ((70.0, 3.0, 3.0, 0.4, 0.015, 0.1), false, false),
        ((50.0, 2.5, -1.875, 0.3, 0.0375, 0.075), false, false),
        ((45.0, 3.6, 3.6, 0.2, 0.0375, 0.075), false, true),
    ] {
        let s = scene(r);
        assert_eq!(mode_of(&s), 1, "{r:?} does not slide at rest");
        let limits = model_core::ode::system::SystemLimits {
            horizon_s: 5.0,
            max_steps: 2_000_000,
        };
        let rolled = model_core::particle::rolling::AZIMUTHS_DEG
            .iter()
            .any(|deg| {
                let rep = residence(
                    &s,
                    &BowlShape::bare_rim(),
                    deg.to_radians(),
                    RollingMethod::Dp54 { rtol: 1e-10 },
                    limits,
                )
                .unwrap();
                assert!(matches!(rep.outcome, BowlOutcome::Leaves { .. }), "{r:?}");
                rep.regime.roll_s > 0.0
            });
        assert_eq!(rolled, sticks, "{r:?}: rolled part of the way {rolled}");
        assert_eq!(may_stick(&s), flagged, "{r:?}");
    }
}

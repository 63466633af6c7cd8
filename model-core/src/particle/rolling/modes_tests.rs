//! The rolling-or-sliding granule against its limits with closed forms (docs/model.md §10),
//! its sliding equations against the rolling ones, and the independent rigid-body simulation's
//! findings quoted in issue 30.

use super::equations::forces;
use super::modes::{ModesOutcome, ModesReport, residence_roll_or_slide, run_from};
use super::slide::{from_rolling, slide_forces};
use super::*;

const FINE: RollingMethod<f64> = RollingMethod::Dp54 { rtol: 1e-12 };

fn time(r: &ModesReport<f64>) -> f64 {
    match r.outcome {
        ModesOutcome::Leaves {
            residence_time_s, ..
        } => residence_time_s,
        other => panic!("expected to leave: {other:?}"),
    }
}

fn still(th_deg: f64, mu_r: f64, mu_s: f64) -> RollingScene<f64> {
    RollingScene {
        precession_rad_s: 0.0,
        spin_rad_s: 0.0,
        rolling_resistance: mu_r,
        sliding_friction: mu_s,
        ri_m: 0.05,
        ..RollingScene::equal_speeds(0.0, th_deg.to_radians(), 0.15)
    }
}

/// Rolling is sliding without slip: in a rolling state, the sliding equations with the friction
/// rolling needs (`mu_s N` set to `|f_t|`, acting along `f_t`) give the rolling equations'
/// acceleration and spin rate, and the slip stays zero (`dv_c/dt = 0`). Scenes with tilt,
/// precession, spin, a rod and a granule radius; no rolling resistance (a torque the sliding
/// contact does not have).
#[test]
fn sliding_equations_reduce_to_rolling_ones_without_slip() {
    let mut checked = 0;
    for (w1, w2, th_deg, l, a) in [
        (1.3, 2.1, 60.0, 0.0, 0.003),
        (-0.7, 3.2, 30.0, 0.2, 0.01),
        (2.5, -1.1, 5.0, 0.05, 0.0),
        (0.0, 3.0, 45.0, 0.0, 0.02),
    ] {
        let base = RollingScene {
            precession_rad_s: w1,
            spin_rad_s: w2,
            rod_length_m: l,
            particle_radius_m: a,
            rolling_resistance: 0.0,
            ..RollingScene::equal_speeds(1.0, f64::to_radians(th_deg), 0.15)
        };
        for (t, y) in [
            (0.0, [0.03, -0.02, 0.1, 0.05, 0.01]),
            (0.37, [-0.1, 0.04, -0.3, 0.2, -0.05]),
            (1.9, [0.0, 0.12, 0.0, -0.4, 0.2]),
        ] {
            let roll = forces(&base, t, &y);
            let ft = roll.friction_xy_m_s2;
            let scene = RollingScene {
                sliding_friction: roll.friction_m_s2 / roll.normal_m_s2,
                ..base
            };
            let dir = [-ft[0] / roll.friction_m_s2, -ft[1] / roll.friction_m_s2];
            let slide = slide_forces(&scene, t, &from_rolling(&y), dir);
            let d = slide.derivative;
            let scale = 1.0 + roll.derivative.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (got, want) in [(d[2], roll.derivative[2]), (d[3], roll.derivative[3])] {
                assert!((got - want).abs() < 1e-12 * scale, "{got} vs {want}");
            }
            assert!((d[6] - roll.derivative[4]).abs() < 1e-12 * scale);
            // dv_c/dt = (dux - dsy, duy + dsx) = 0.
            assert!((d[2] - d[5]).abs() < 1e-12 * scale, "{d:?}");
            assert!((d[3] + d[4]).abs() < 1e-12 * scale, "{d:?}");
            assert!((slide.normal_m_s2 - roll.normal_m_s2).abs() < 1e-12 * scale);
            let (need, _) = super::slide::needed_friction_m_s2(&scene, t, &from_rolling(&y));
            assert!((need[0] - ft[0]).abs() + (need[1] - ft[1]).abs() < 1e-12 * scale);
            checked += 1;
        }
    }
    assert_eq!(checked, 12);
}

/// A fixed incline where rolling needs more than `mu_s`: `(1 - k2) tan th > mu_s` (60 deg,
/// 0.4: 0.495). The granule slides the whole way down with `a = g (sin th - mu_s cos th)`
/// along the straight path of length `s(beta)` to the rim: `T = sqrt(2 s / a)`, to 1e-9.
#[test]
fn sliding_down_an_incline_matches_its_closed_form() {
    for (th_deg, mu_s, k2) in [
        (60.0, 0.4, 5.0 / 7.0),
        (30.0, 0.1, 5.0 / 7.0),
        (45.0, 0.2, 0.6),
    ] {
        let s = RollingScene {
            k2,
            ..still(th_deg, 0.029, mu_s)
        };
        let th = f64::to_radians(th_deg);
        assert!((1.0 - k2) * th.tan() > mu_s);
        let accel = 9.81 * (th.sin() - mu_s * th.cos());
        for beta_deg in [0.0, 75.0, 180.0, 290.0] {
            let beta = f64::to_radians(beta_deg);
            let path =
                -s.ri_m * beta.cos() + (0.15f64.powi(2) - (s.ri_m * beta.sin()).powi(2)).sqrt();
            let closed = (2.0 * path / accel).sqrt();
            let r = residence_roll_or_slide(&s, beta, FINE).unwrap();
            let t = time(&r);
            assert!(
                ((t - closed) / closed).abs() < 1e-9,
                "{th_deg} {beta_deg}: {t} vs {closed}"
            );
            assert_eq!(r.tally.regime.roll_s, 0.0, "slides from release to rim");
            // RK4 is exact on constant acceleration, and the cubic Hermite locates the rim on
            // the parabola: the same T to rounding.
            let rk4 =
                residence_roll_or_slide(&s, beta, RollingMethod::Rk4 { step_s: 1e-3 }).unwrap();
            assert!(
                ((time(&rk4) - closed) / closed).abs() < 1e-9,
                "rk4: {rk4:?}"
            );
            assert!((r.tally.regime.slide_s - t).abs() < 1e-12);
            assert_eq!(r.tally.switches, 0);
        }
    }
}

/// Where the contact gives enough friction the granule rolls down the incline at
/// `k2 g (sin th - mu_r cos th)` (`5/7 g sin th` for a solid sphere without resistance, `3/5`
/// for a hollow one), the rolling model's closed form, to 1e-9.
#[test]
fn rolling_down_an_incline_matches_its_closed_form() {
    for (th_deg, mu_r, k2) in [
        (60.0, 0.0, 5.0 / 7.0),
        (30.0, 0.029, 5.0 / 7.0),
        (45.0, 0.0, 0.6),
    ] {
        let s = RollingScene {
            k2,
            ..still(th_deg, mu_r, 1.0)
        };
        for beta_deg in [0.0, 120.0, 200.0] {
            let beta = f64::to_radians(beta_deg);
            let closed = incline_residence_s(&s, beta).unwrap();
            if mu_r == 0.0 {
                let path =
                    -s.ri_m * beta.cos() + (0.15f64.powi(2) - (s.ri_m * beta.sin()).powi(2)).sqrt();
                let th = f64::to_radians(th_deg);
                let by_hand = (2.0 * path / (k2 * 9.81 * th.sin())).sqrt();
                assert!((closed - by_hand).abs() < 1e-12 * by_hand);
            }
            let r = residence_roll_or_slide(&s, beta, FINE).unwrap();
            let t = time(&r);
            assert!(((t - closed) / closed).abs() < 1e-9, "{t} vs {closed}");
            assert_eq!(r.tally.regime.slide_s, 0.0);
        }
    }
}

/// The horizontal turntable. Rolling (enough friction): the inertial circle at `(1 - k2) Omega`
/// of [`disc_residence_s`]. Frictionless (`mu_s = 0`): the granule keeps the velocity
/// `Omega ri` it had at release and runs straight in the inertial frame,
/// `T = sqrt(R^2 - ri^2) / (Omega ri)`. Both to 1e-9, at both spin directions.
#[test]
fn turntable_limits_match_their_closed_forms() {
    for omega in [0.8, -2.7, 6.0] {
        let base = RollingScene {
            precession_rad_s: 0.0,
            spin_rad_s: omega,
            axes_angle_rad: 0.0,
            rolling_resistance: 0.0,
            ri_m: 0.05,
            rim_radius_m: 0.1,
            ..RollingScene::equal_speeds(1.0, 0.0, 0.1)
        };
        let rolls = RollingScene {
            sliding_friction: 10.0,
            ..base
        };
        let r = residence_roll_or_slide(&rolls, 0.3, FINE).unwrap();
        let closed = disc_residence_s(omega, 5.0 / 7.0, 0.05, 0.1).unwrap();
        assert!(((time(&r) - closed) / closed).abs() < 1e-9, "{omega}");
        assert_eq!(r.tally.regime.slide_s, 0.0);
        let slides = RollingScene {
            sliding_friction: 0.0,
            ..base
        };
        let r = residence_roll_or_slide(&slides, 1.1, FINE).unwrap();
        let closed = (0.1f64.powi(2) - 0.05f64.powi(2)).sqrt() / (omega.abs() * 0.05);
        assert!(
            ((time(&r) - closed) / closed).abs() < 1e-9,
            "{omega}: {r:?}"
        );
        assert_eq!(r.tally.regime.roll_s, 0.0);
    }
}

/// A granule thrown sliding at `u0` without spin on a still, level bottom: friction slows the
/// centre at `mu_s g` and spins the sphere up until the slip is gone at
/// `t* = (1 - k2) u0 / (mu_s g)`; then it rolls on at `k2 u0` (5/7 of `u0`) to the rim. The
/// slide -> roll event is located, not stepped over: its time to 1e-9, and `T` too.
#[test]
fn a_thrown_granule_rolls_after_its_slip_is_gone() {
    for (u0, mu_s, k2) in [(0.5, 0.3, 5.0 / 7.0), (1.2, 0.05, 0.6)] {
        let s = RollingScene {
            k2,
            ri_m: 0.0,
            rim_radius_m: 2.0,
            ..still(0.0, 0.0, mu_s)
        };
        let g = 9.81;
        let t_star = (1.0 - k2) * u0 / (mu_s * g);
        let x_star = u0 * t_star - 0.5 * mu_s * g * t_star * t_star;
        assert!(x_star < 2.0);
        let closed = t_star + (2.0 - x_star) / (k2 * u0);
        let y0 = [0.0, 0.0, u0, 0.0, 0.0, 0.0, 0.0];
        let limits = SystemLimits {
            horizon_s: 60.0,
            max_steps: 100_000,
        };
        let r = run_from(&s, 0.0, y0, FINE, limits, None).unwrap();
        assert!(
            ((r.tally.regime.slide_s - t_star) / t_star).abs() < 1e-9,
            "{r:?}"
        );
        assert!(((time(&r) - closed) / closed).abs() < 1e-9, "{r:?}");
        let ModesOutcome::Leaves { exit_speed_m_s, .. } = r.outcome else {
            unreachable!()
        };
        assert!((exit_speed_m_s - k2 * u0).abs() < 1e-9, "{exit_speed_m_s}");
        assert_eq!(r.tally.switches, 1);
    }
}

fn mean_over_azimuths(s: &RollingScene<f64>) -> (f64, f64) {
    let (mut sum, mut slide) = (0.0, 0.0);
    for deg in AZIMUTHS_DEG {
        let r = residence_roll_or_slide(s, deg.to_radians(), RollingMethod::Dp54 { rtol: 1e-9 })
            .unwrap();
        sum += time(&r);
        slide += r.tally.regime.slide_s;
    }
    (sum / 12.0, slide / sum)
}

/// Issue 30's independent rigid-body simulation (MuJoCo) at the rig's 60 deg tilt: with sliding
/// friction 0.35 to 0.45 the granule slides from release to exit (98-99 % of the time there),
/// leaves 4.1 to 4.4 % sooner than the rolling model says, and T moves 3.8 % between 0.35 and
/// 0.45. Here (75 mm bowl at 0.9 rad/s; 150 mm at 3.6 rad/s): slides 100 % and 98 % of the
/// time, 3.6 % and 3.4 % sooner at 0.4, T moves 3.8 % and 3.4 %.
#[test]
fn the_rig_slides_as_the_rigid_body_simulation_says() {
    for (omega, rim) in [(0.9, 0.075), (3.6, 0.15)] {
        let at = |mu_s: f64| RollingScene {
            rolling_resistance: 0.0,
            sliding_friction: mu_s,
            ..RollingScene::equal_speeds(omega, 60f64.to_radians(), rim)
        };
        let rolling = residence_over_azimuths(&at(0.4), FINE)
            .unwrap()
            .mean_s
            .unwrap();
        let (low, low_share) = mean_over_azimuths(&at(0.35));
        let (mid, mid_share) = mean_over_azimuths(&at(0.4));
        let (high, _) = mean_over_azimuths(&at(0.45));
        assert!(
            low_share > 0.97 && mid_share > 0.97,
            "{low_share} {mid_share}"
        );
        let sooner = 1.0 - mid / rolling;
        assert!(sooner > 0.03 && sooner < 0.045, "{omega}: {sooner}");
        let spread = (high - low) / low;
        assert!(spread > 0.033 && spread < 0.040, "{omega}: {spread}");
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]
    /// Any finite input: an error or an outcome, never a panic, and every time in it finite and
    /// within the horizon (a short one and a step cap keep the cases quick).
    #[test]
    fn any_finite_scene_gives_an_answer_or_an_error(
        w1 in -8.0f64..8.0, w2 in -8.0f64..8.0, th in -0.1f64..1.6, mu_r in -0.01f64..1.0,
        mu_s in -0.01f64..1.5, k2 in 0.0f64..1.01, a in -0.001f64..0.05, l in -0.01f64..1.0,
        ri in -0.01f64..0.3, extra in -0.01f64..0.3, beta in -10.0f64..10.0, rk4 in proptest::bool::ANY,
    ) {
        let s = RollingScene {
            precession_rad_s: w1, spin_rad_s: w2, axes_angle_rad: th, rolling_resistance: mu_r,
            sliding_friction: mu_s, g_m_s2: 9.81, k2, particle_radius_m: a, rod_length_m: l,
            ri_m: ri, rim_radius_m: ri + extra,
        };
        let method = if rk4 {
            RollingMethod::Rk4 { step_s: 1e-3 }
        } else {
            RollingMethod::Dp54 { rtol: 1e-6 }
        };
        let limits = SystemLimits { horizon_s: 0.5, max_steps: 20_000 };
        if let Ok(r) = super::modes::roll_or_slide_within(&s, beta, method, limits) {
            let ok = |v: f64| v.is_finite() && (0.0..=0.5 + 1e-9).contains(&v);
            proptest::prop_assert!(ok(r.tally.regime.roll_s) && ok(r.tally.regime.slide_s), "{r:?}");
            match r.outcome {
                ModesOutcome::Leaves { residence_time_s, exit_speed_m_s } => {
                    proptest::prop_assert!(ok(residence_time_s) && exit_speed_m_s.is_finite());
                }
                ModesOutcome::LiftsOff { time_s } => proptest::prop_assert!(ok(time_s)),
                _ => {}
            }
        }
    }
}

/// A slide from rest just past the stick threshold (45 deg, 3.6 rad/s, mu_s 0.2, the release at
/// 180 deg: at rtol 1e-10 its slip grows at about 0.12 m/s^2 against a friction of 1.57 m/s^2) used to cost
/// 2 709 steps at rtol 1e-6, 23 110 at 1e-7 and over 200 000 at 1e-8 against 493 at 1e-10:
/// the loose steps left the slip's direction off and its stiff relaxation held them at ~1e-5 s
/// (docs/model.md §12). With the slip held to its own tolerance each looser run is cheaper
/// than the tighter one, and within its tolerance of the run at 1e-12.
#[test]
fn a_loose_tolerance_is_not_dearer_on_a_slide_from_rest() {
    let s = RollingScene {
        sliding_friction: 0.2,
        ri_m: 0.0375,
        ..RollingScene::with_speeds(3.6, 3.6, 45f64.to_radians(), 0.075)
    };
    let beta = 180f64.to_radians();
    let limits = SystemLimits {
        horizon_s: 10.0,
        max_steps: 200_000,
    };
    let reference = time(&residence_roll_or_slide(&s, beta, FINE).expect("reference"));
    let mut last_steps = u32::MAX;
    for rtol in [1e-10, 1e-9, 1e-8, 1e-7, 1e-6] {
        let r = super::modes::roll_or_slide_within(&s, beta, RollingMethod::Dp54 { rtol }, limits)
            .expect("leaves");
        assert!(
            (time(&r) - reference).abs() <= 100.0 * rtol * reference,
            "rtol {rtol}: T {} against {reference}",
            time(&r)
        );
        assert!(
            r.tally.steps < last_steps,
            "rtol {rtol}: {} steps, the tighter run took {last_steps}",
            r.tally.steps
        );
        last_steps = r.tally.steps;
    }
    assert!(last_steps < 400, "{last_steps} steps at 1e-6");
}

/// A roll that gives way at the stick threshold (30 deg, 3.6 rad/s, mu_s 0.2 on a bare rim,
/// the releases at 90 and 270 deg: rolling needs `mu_s N` at 0.238 s, and the slip then grows
/// as the square of the time since): while the slip was small the friction followed its
/// direction, a stiff relaxation at `mu_s N / |slip|` that held DP5(4) at its stability limit,
/// steps of about the slip over `mu_s g`, for 2 400 to 3 900 steps at every rtol from 1e-6 to
/// 1e-10, and more at 1e-6 (3 957 and 3 808) than at 1e-7 (2 734 and 2 396): the chooser's
/// first rung cost 2.9 ms where 1e-7 cost 2.0 (docs/model.md §12). With the friction against
/// the slip's free acceleration while the slip is below the run's absolute tolerance
/// (`slide::friction_direction`), the looser run was the cheaper (7 982 right-hand sides at
/// 1e-6, 16 409 at 1e-7, 23 498 at 1e-9 at 90 deg); with it up to 1e-4 of the scene's speed
/// at every tolerance (`modes::SLAVED`) 818, 902 and 1 094, each within 100 times its
/// tolerance of the run at 1e-12.
#[test]
fn a_roll_giving_way_at_the_stick_threshold_is_cheaper_at_a_looser_tolerance() {
    let s = RollingScene {
        sliding_friction: 0.2,
        ..RollingScene::with_speeds(3.6, 3.6, 30f64.to_radians(), 0.075)
    };
    let limits = SystemLimits {
        horizon_s: 10.0,
        max_steps: 200_000,
    };
    for deg in [90.0, 270.0] {
        let beta = f64::to_radians(deg);
        let reference = time(&residence_roll_or_slide(&s, beta, FINE).expect("reference"));
        let run = |rtol: f64| {
            let r = modes::roll_or_slide_within(&s, beta, RollingMethod::Dp54 { rtol }, limits)
                .expect("leaves");
            assert!(
                (time(&r) - reference).abs() <= 100.0 * rtol * reference,
                "{deg} deg at {rtol:e}: T {} against {reference}",
                time(&r)
            );
            assert_eq!(
                r.tally.switches, 1,
                "{deg} deg at {rtol:e}: rolls, then slides"
            );
            r.tally.evaluations
        };
        let (loose, tight, tighter) = (run(1e-6), run(1e-7), run(1e-9));
        assert!(
            loose <= tight && tight <= tighter && tighter < 1_500,
            "{deg} deg: {loose} evaluations at 1e-6, {tight} at 1e-7, {tighter} at 1e-9"
        );
    }
}

/// The friction's direction in a slide (`slide::friction_direction`): against the slip's free
/// acceleration `A` while the slip is at most the slaved threshold, goes along `A` and the
/// friction cannot hold it; against the slip itself once it is above, or where the friction
/// can hold it (the slip then shrinks, and its end is found as before); the last direction
/// where the slip has turned against it.
#[test]
fn a_small_growing_slip_takes_the_friction_against_its_free_acceleration() {
    use super::slide::friction_direction;
    let k2 = 5.0 / 7.0;
    // `A` along x, 7 m/s^2: the friction can hold up to `mu_s N / (1 - k2)`.
    let free = [7.0, 0.0];
    let slip = [1e-6, 2e-7];
    let unit = |v: [f64; 2]| {
        let n = v[0].hypot(v[1]);
        [v[0] / n, v[1] / n]
    };
    let close = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) < 1e-15;
    let last = unit(slip);
    // Grows (`(1 - k2) |A|` = 2 > 1.9): within the threshold, against `A`.
    assert_eq!(
        friction_direction(k2, slip, free, 1.9, last, 1e-5),
        [1.0, 0.0]
    );
    // Above the threshold, or with none: against the slip.
    assert!(close(
        friction_direction(k2, slip, free, 1.9, last, 1e-7),
        unit(slip)
    ));
    assert!(close(
        friction_direction(k2, slip, free, 1.9, last, 0.0),
        unit(slip)
    ));
    // The friction can hold it: against the slip, within the threshold too.
    assert!(close(
        friction_direction(k2, slip, free, 2.1, last, 1e-5),
        unit(slip)
    ));
    // A slip against `A` is not slaved to it.
    let back = [-1e-6, 2e-7];
    assert!(close(
        friction_direction(k2, back, free, 1.9, unit(back), 1e-5),
        unit(back)
    ));
    // Turned against the last direction: the last.
    assert_eq!(
        friction_direction(k2, slip, free, 1.9, [-1.0, 0.0], 0.0),
        [-1.0, 0.0]
    );
}

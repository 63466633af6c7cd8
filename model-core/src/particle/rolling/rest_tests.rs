//! The held segment (`rest`): the rest located, and held to the closed forms of a still
//! incline.

use super::modes::{ModesOutcome, residence_roll_or_slide, run_from};
use super::rest::hold;
use super::slide::from_rolling;
use super::*;

/// The scene a QA round found the rest stepped over in: 5 deg tilt, w1 = w2 = 3.2979 rad/s, a
/// 75 mm bowl, released at 22.86 mm; its 150 deg release stops at about 0.16 s and is held
/// there for about 86 ms before it rolls on.
pub(super) fn stopping() -> RollingScene<f64> {
    RollingScene {
        precession_rad_s: 3.2979,
        spin_rad_s: 3.2979,
        axes_angle_rad: 5f64.to_radians(),
        rolling_resistance: 0.029,
        sliding_friction: 0.2,
        g_m_s2: 9.81,
        k2: 5.0 / 7.0,
        particle_radius_m: 0.003,
        rod_length_m: 0.0,
        ri_m: 0.02286,
        rim_radius_m: 0.075,
    }
}

/// Before, both models stepped over the rest (the equations switch at 1e-7 m/s): the rolling
/// model's T at rtol 1e-9 was off by 100x the tolerance and the roll-or-slide run's by 46x, and
/// their cost rose 70-fold from 1e-9 to 1e-12 (194 053 evaluations); the hold did not show in
/// the regime. Now the rest and the restart are events: within 20x the tolerance (a release
/// that never rests is within 1-3x, this one within 1-2x since its restart is its own stretch,
/// `rest::start_speed_m_s`; 13-16x before), at fewer evaluations at 1e-9 than at 1e-12.
#[test]
fn a_granule_that_comes_to_rest_is_held_as_its_own_segment() {
    let s = stopping();
    let beta = 150f64.to_radians();
    let rolling = |rtol| {
        let r = residence(&s, beta, RollingMethod::Dp54 { rtol }).unwrap();
        (left(r.outcome), r.evaluations)
    };
    let modes = |rtol| {
        let r = residence_roll_or_slide(&s, beta, RollingMethod::Dp54 { rtol }).unwrap();
        (left_modes(r.outcome), r.tally.evaluations, r.tally.regime)
    };
    let ((loose, loose_cost), (tight, tight_cost)) = (rolling(1e-9), rolling(1e-12));
    assert!((loose / tight - 1.0).abs() < 20.0 * 1e-9, "{loose} {tight}");
    assert!(loose_cost < tight_cost, "{loose_cost} {tight_cost}");
    let ((loose, loose_cost, _), (tight, tight_cost, regime)) = (modes(1e-9), modes(1e-12));
    assert!((loose / tight - 1.0).abs() < 20.0 * 1e-9, "{loose} {tight}");
    assert!(loose_cost < tight_cost, "{loose_cost} {tight_cost}");
    assert!((tight - loose).abs() < 1e-7);
    // Held about 86 ms, and the regime says so.
    assert!((0.085..0.088).contains(&regime.held_s), "{regime:?}");
    assert!(
        (regime.roll_s + regime.held_s - tight).abs() < 1e-12,
        "{regime:?}"
    );
}

/// T of a release that leaves.
fn left(o: RollingOutcome<f64>) -> f64 {
    match o {
        RollingOutcome::Leaves {
            residence_time_s, ..
        } => residence_time_s,
        _ => panic!("{o:?}"),
    }
}

/// T of a release that leaves, rolling or sliding.
fn left_modes(o: ModesOutcome<f64>) -> f64 {
    match o {
        ModesOutcome::Leaves {
            residence_time_s, ..
        } => residence_time_s,
        _ => panic!("{o:?}"),
    }
}

/// A still incline at `tilt_deg` (neither motor turns), mu_r 0.029, mu_s 0.5 (it rolls).
fn incline(tilt_deg: f64) -> RollingScene<f64> {
    RollingScene {
        precession_rad_s: 0.0,
        spin_rad_s: 0.0,
        axes_angle_rad: tilt_deg.to_radians(),
        sliding_friction: 0.5,
        ..stopping()
    }
}

/// The incline's angle of rolling resistance, `atan(mu_r)`, deg (1.661 deg at 0.029).
fn resistance_angle_deg() -> f64 {
    0.029f64.atan().to_degrees()
}

const TIGHT: RollingMethod<f64> = RollingMethod::Dp54 { rtol: 1e-11 };

/// Below the angle of resistance a granule rolled uphill (`+e1`, the downhill direction is
/// `-e1`) at 0.1 m/s stops where its closed form says, `u0^2 / (2 a)` with
/// `a = k2 g (sin th + mu_r cos th)`, after `u0 / a`, and stays there to the horizon; the held
/// segment alone keeps it put.
#[test]
fn below_the_angle_of_resistance_it_stops_and_stays() {
    let s = incline(resistance_angle_deg() - 0.5);
    let th = s.axes_angle_rad;
    let a = s.k2 * s.g_m_s2 * (th.sin() + s.rolling_resistance * th.cos());
    let (x0, u0) = (-0.03, 0.1);
    let y0 = from_rolling(&[x0, 0.0, u0, 0.0, 0.0]);
    let limits = default_limits();
    let r = run_from(&s, 0.0, y0, TIGHT, limits, None).unwrap();
    assert_eq!(
        r.outcome,
        ModesOutcome::Inside {
            horizon_s: limits.horizon_s
        }
    );
    let stop = u0 / a;
    assert!((r.tally.regime.roll_s - stop).abs() < 1e-10, "{r:?}");
    assert!((r.tally.regime.held_s - (limits.horizon_s - stop)).abs() < 1e-9);
    let x = x0 + u0 * u0 / (2.0 * a);
    assert!(
        (r.end_state[0] - x).abs() < 1e-11,
        "{:?} vs {x}",
        r.end_state
    );
    assert_eq!(&r.end_state[1..4], &[0.0; 3]);
    // Held alone: nothing ends it.
    let rest = [x, 0.0, 0.0, 0.0, 0.0];
    assert_eq!(hold(&s, 0.0, &rest, 60.0, |_| -1.0).t, None);
}

/// Just above the angle of resistance a granule released at rest starts at once, along the
/// incline at `a = k2 g (sin th - mu_r cos th)`, and reaches the rim `R - ri` away after
/// `sqrt(2 (R - ri) / a)`; one rolled uphill stops (the rest event) and, not held, rolls back
/// down from rest at that acceleration.
#[test]
fn just_above_it_starts_from_rest_at_the_incline_s_acceleration() {
    let s = incline(resistance_angle_deg() + 0.05);
    let th = s.axes_angle_rad;
    let down = s.k2 * s.g_m_s2 * (th.sin() - s.rolling_resistance * th.cos());
    let up = s.k2 * s.g_m_s2 * (th.sin() + s.rolling_resistance * th.cos());
    let t = (2.0 * (s.rim_radius_m - s.ri_m) / down).sqrt();
    let r = residence(&s, 0.0, TIGHT).unwrap();
    let residence_time_s = left(r.outcome);
    assert!(
        (residence_time_s / t - 1.0).abs() < 1e-9,
        "{residence_time_s} vs {t}"
    );
    let RollingOutcome::Leaves { exit_speed_m_s, .. } = r.outcome else {
        unreachable!()
    };
    assert!((exit_speed_m_s / (down * t) - 1.0).abs() < 1e-9);
    let m = residence_roll_or_slide(&s, 0.0, TIGHT).unwrap();
    assert_eq!(m.tally.regime.held_s, 0.0);
    assert!((left_modes(m.outcome) / t - 1.0).abs() < 1e-9);
    // Uphill from -0.03 m at 0.1 m/s: stops after u0 / up, u0^2 / (2 up) further up, and rolls
    // back down to the rim at -R.
    let (x0, u0) = (-0.03, 0.1);
    let r = run_from(
        &s,
        0.0,
        from_rolling(&[x0, 0.0, u0, 0.0, 0.0]),
        TIGHT,
        default_limits(),
        None,
    )
    .unwrap();
    let top = x0 + u0 * u0 / (2.0 * up);
    let t = u0 / up + (2.0 * (top + s.rim_radius_m) / down).sqrt();
    let residence_time_s = left_modes(r.outcome);
    assert!(
        (residence_time_s / t - 1.0).abs() < 1e-9,
        "{residence_time_s} vs {t}"
    );
    assert_eq!(r.tally.regime.held_s, 0.0);
}

/// A bowl tilted 2 deg that only spins (3 rad/s) turns gravity in its frame: a granule released
/// at rest at 30 mm, 180 deg (uphill of the axis at the start), is held while
/// `|D| = |g sin th (-cos psi, sin psi) + w2^2 (ri, 0)|` is within `mu_r g cos th`, and starts
/// where they meet, `cos psi = (g^2 sin^2 th + w2^4 ri^2 - mu_r^2 g^2 cos^2 th) /
/// (2 g sin th w2^2 ri)`, `t = psi / w2` (0.313 s). Before, such a scene counted as still and
/// the release as held for ever.
#[test]
fn a_spinning_tilted_bowl_lets_a_held_granule_go_when_gravity_turns() {
    let s = RollingScene {
        precession_rad_s: 0.0,
        spin_rad_s: 3.0,
        axes_angle_rad: 2f64.to_radians(),
        ri_m: 0.03,
        sliding_friction: 0.4,
        ..stopping()
    };
    let (g, th, w2, ri) = (s.g_m_s2, s.axes_angle_rad, s.spin_rad_s, s.ri_m);
    let (grav, cent, res) = (
        g * th.sin(),
        w2 * w2 * ri,
        s.rolling_resistance * g * th.cos(),
    );
    let start = ((grav * grav + cent * cent - res * res) / (2.0 * grav * cent)).acos() / w2;
    let beta = 180f64.to_radians();
    let r = residence(&s, beta, TIGHT).unwrap();
    left(r.outcome);
    assert!((r.held_s - start).abs() < 1e-10, "{} vs {start}", r.held_s);
    let m = residence_roll_or_slide(&s, beta, TIGHT).unwrap();
    left_modes(m.outcome);
    assert!((m.tally.regime.held_s - start).abs() < 1e-10);
}

/// A bowl tilted 3.92 deg at 0.971 and 3.206 rad/s, released at 34.9 mm, 150 deg: the granule
/// stops at 0.054 s, is held 0.246 s and restarts from the edge of holding. Before, the start
/// from rest ran at the scene's tolerance: the speed hovered at the rest threshold and fired a
/// rest event of its own, and T at rtol 1e-8 was 3.3e-5 s off (3 300x; `bowl predict --model
/// rolling --tol 1e-8`), at 1e-7 4e-5 s. Now the restart is within 10x the tolerance from 1e-6
/// to 1e-10, in both models.
#[test]
fn a_restart_from_a_hold_is_as_accurate_as_asked() {
    let s = RollingScene {
        precession_rad_s: 0.971,
        spin_rad_s: 3.206,
        axes_angle_rad: 3.92f64.to_radians(),
        sliding_friction: 0.5,
        ri_m: 0.0349,
        ..stopping()
    };
    let beta = 150f64.to_radians();
    let rolling = |rtol| {
        left(
            residence(&s, beta, RollingMethod::Dp54 { rtol })
                .unwrap()
                .outcome,
        )
    };
    let modes = |rtol| {
        let r = residence_roll_or_slide(&s, beta, RollingMethod::Dp54 { rtol }).unwrap();
        assert!((0.24..0.25).contains(&r.tally.regime.held_s), "{r:?}");
        left_modes(r.outcome)
    };
    let (reference, reference_modes) = (rolling(1e-12), modes(1e-12));
    assert!((reference - reference_modes).abs() < 1e-12);
    for rtol in [1e-6, 1e-7, 1e-8, 1e-9, 1e-10] {
        let (t, tm) = (rolling(rtol), modes(rtol));
        assert!(
            (t / reference - 1.0).abs() < 10.0 * rtol,
            "{rtol}: {t} vs {reference}"
        );
        assert!(
            (tm / reference - 1.0).abs() < 10.0 * rtol,
            "{rtol}: {tm} vs {reference}"
        );
    }
}

/// The scene of a release that rolls to rest on the bottom (2 deg tilt, 0.3 and 3 rad/s, a 75
/// mm bowl, ri 30 mm; release 90 deg).
fn slowing_to_rest() -> RollingScene<f64> {
    RollingScene {
        ri_m: 0.03,
        ..RollingScene::with_speeds(0.3, 3.0, 2f64.to_radians(), 0.075)
    }
}

/// `held(rtol)`, the time held at a tolerance, is about 0.369 s at 1e-12 and within 10x rtol of
/// that at every rtol 1e-6 to 1e-10.
fn held_as_long(held: impl Fn(f64) -> f64) {
    let exact = held(1e-12);
    assert!((exact - 0.369).abs() < 1e-3, "{exact}");
    for rtol in [1e-6, 3e-7, 1e-7, 1e-8, 1e-9, 1e-10] {
        let off = (held(rtol) - exact).abs();
        assert!(off < 10.0 * rtol, "rtol {rtol:e}: held {off:e} s off");
    }
}

/// A release that rolls to rest on the bottom on its way to the wall ([`slowing_to_rest`], a
/// 45 deg wall 15 mm high with a 5 mm fillet; docs/model.md §10), to 1 s, before it reaches the
/// wall: its time held is within 10x rtol of the run at 1e-12 at every rtol 1e-6 to 1e-10.
/// Before, at 1e-6 it was 4.7e-4 s off (470x): the rest was located in a step that
/// spanned it with the velocity 9e-5 m/s off, not held, and the resistance took that long to
/// stop it (`rest::slow_speed_m_s`).
#[test]
fn a_rest_on_the_bottom_is_held_as_long_at_a_loose_tolerance() {
    use crate::particle::bowl::{BowlShape, residence};
    let sc = slowing_to_rest();
    let shape = BowlShape {
        wall_angle_rad: 45f64.to_radians(),
        wall_height_m: 0.015,
        fillet_radius_m: 0.005,
        restitution: 0.5,
    };
    let limits = SystemLimits {
        horizon_s: 1.0,
        max_steps: MAX_STEPS,
    };
    held_as_long(|rtol| {
        let method = RollingMethod::Dp54 { rtol };
        let r = residence(&sc, &shape, 90f64.to_radians(), method, limits).unwrap();
        r.regime.held_s
    });
}

/// The same release in the rolling model (`bowl predict --model rolling`, no wall: the rim at
/// 75 mm), to 5 s: its time held is within 10x rtol of the run at 1e-12 at every rtol 1e-6 to
/// 1e-10, as the bowl model's. Before, its roll did not go on to the rest as a stretch of its
/// own (`rest::slow_speed_m_s`) and at 1e-6 it was held 4.9e-4 s too little (490x); now
/// 6.2e-6 s, and within 4x rtol at 3e-7 to 1e-10.
#[test]
fn a_rest_in_the_rolling_model_is_held_as_long_at_a_loose_tolerance() {
    let sc = slowing_to_rest();
    let limits = SystemLimits {
        horizon_s: 5.0,
        max_steps: MAX_STEPS,
    };
    held_as_long(|rtol| {
        let method = RollingMethod::Dp54 { rtol };
        residence_within(&sc, 90f64.to_radians(), method, limits)
            .unwrap()
            .held_s
    });
}

/// The chart's near-stick scene (`bowl chart rolling-work-precision`: 30 deg, 2 rad/s combined,
/// mu_r 0.55 against `tan 30 = 0.577`): the drive barely beats the resistance at the release.
/// Before, the roll from rest ran at the scene's tolerance on the velocity (`rtol` of its speed
/// scale, about the speed itself at first): at rtol 1e-6 the 150 deg release hovered at
/// 5e-6 m/s for 1.1 s (T 2.18340 s against 1.54798, 313 827 steps) and at 1e-4 and 1e-7 it hit
/// the step cap. Now the release from rest is a restart stretch, then a stretch up to the slow
/// speed (`rest_loop`): within 10x rtol from 1e-4 to 1e-7, cheaper than at 1e-12.
#[test]
fn a_release_that_barely_starts_is_its_own_stretch() {
    let s = RollingScene {
        rolling_resistance: 0.55,
        ..RollingScene::equal_speeds(2.0, 30f64.to_radians(), 0.075)
    };
    let beta = 150f64.to_radians();
    let run = |rtol| residence(&s, beta, RollingMethod::Dp54 { rtol }).unwrap();
    let tight = run(1e-12);
    let exact = left(tight.outcome);
    assert!((exact - 1.54798).abs() < 1e-5, "{exact}");
    for rtol in [1e-6, 1e-4, 1e-5, 1e-7] {
        let r = run(rtol);
        let t = left(r.outcome);
        assert!(
            (t / exact - 1.0).abs() < 10.0 * rtol,
            "rtol {rtol}: {t} {exact}"
        );
        assert!(r.evaluations < tight.evaluations, "rtol {rtol}: {r:?}");
    }
}

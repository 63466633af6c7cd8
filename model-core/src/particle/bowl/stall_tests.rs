//! The bowl's runs that once stalled or cost too much: the stall watch, a loose tolerance on
//! the wall, and a granule at the seam or starting a fresh slide (docs/model.md §12).

use super::tests::{FINE, shape};
use super::*;

/// The cost grids' bowl (75 mm, its default release radius) at `tilt` deg, both speeds `w`
/// rad/s, and `mu_s`.
fn rig(tilt: f64, w: f64, mu_s: f64) -> RollingScene<f64> {
    RollingScene {
        sliding_friction: mu_s,
        ..RollingScene::with_speeds(w, w, tilt.to_radians(), 0.075)
    }
}

/// The stall watch (`residence_or_stall`, docs/model.md §12) breaks after
/// [`STALL_STEPS`] accepted steps in a row that each advance the time by less than
/// [`crate::particle::rolling::modes::STALL_STEP`] of the scene's time scale, and a real step
/// starts its count again. Where nothing stalls the watched run is the unwatched one, to the
/// bit: every release of the 60 deg wall at 45 deg tilt, 1.8 rad/s, mu_s 0.2 at 1e-6, 1e-7 and
/// 1e-10 (at 1e-6 its release at 30 deg stalled before the wall's slip had its own error
/// control: 30 steps to 0.2449 s, then none got past it), of a 10 deg bowl whose granule
/// changes mode over a hundred times in its wall's corner, and of a scene that slides.
#[test]
fn the_stall_watch_breaks_on_steps_that_do_not_advance_the_time() {
    use crate::particle::rolling::AZIMUTHS_DEG;
    use crate::particle::rolling::modes::{STALL_STEP, StallWatch};
    let (length, speed) = (0.075, 0.27);
    let tiny = 0.5 * STALL_STEP * length / speed;
    let dp54 = RollingMethod::Dp54 { rtol: 1e-9 };
    let watch = StallWatch::new(Some(STALL_STEPS), (length, speed), 1.0, dp54);
    let mut t = 1.0;
    for _ in 0..3 {
        for _ in 1..STALL_STEPS {
            t += tiny;
            assert!(watch.step(t).is_continue(), "{t}");
        }
        // A real step: the count starts again.
        t += 1e-4;
        assert!(watch.step(t).is_continue());
    }
    for _ in 1..STALL_STEPS {
        t += tiny;
        assert!(watch.step(t).is_continue());
    }
    assert!(watch.step(t + tiny).is_break());
    assert!(
        StallWatch::new(None, (length, speed), 1.0, dp54)
            .step(1.0)
            .is_continue()
    );
    let wall = shape(60.0, 0.02, 0.0);
    let capped = |max_steps| SystemLimits {
        horizon_s: 10.0,
        max_steps,
    };
    for (s, rtols) in [
        (rig(45.0, 1.8, 0.2), &[1e-6, 1e-7, 1e-10][..]),
        (rig(10.0, 1.8, 0.4), &[1e-6, 1e-7]),
        (rig(60.0, 3.6, 0.2), &[1e-6, 1e-10]),
    ] {
        for &rtol in rtols {
            for deg in AZIMUTHS_DEG {
                let m = RollingMethod::Dp54 { rtol };
                let b = deg.to_radians();
                let plain = residence(&s, &wall, b, m, capped(200_000));
                let watched = residence_or_stall(&s, &wall, b, m, capped(200_000));
                assert!(plain.is_ok(), "{deg} deg at {rtol:e}: {plain:?}");
                assert_eq!(watched, plain, "{deg} deg at {rtol:e}");
            }
        }
    }
}

/// The wall's slide holds its slip to its own tolerance, as the bottom's (docs/model.md §12):
/// before, a slide that starts from no slip at the stick threshold on the wall left the slip's
/// direction tens of degrees off at a loose tolerance, the slip turned against the friction
/// within a step or two and the slide ended as a stick, thousands of times, until a restart
/// ended where it began and the run stalled. On a 60 deg wall 20 mm high (75 mm bottom) every
/// release now answers at every tolerance, the leaving ones within `100 rtol` of the run at
/// 1e-11, and no looser run costs more than 1.25 times the next tighter one nor more than the
/// run at 1e-10: the releases that stalled at 1e-6 (45 deg tilt, 1.8 rad/s, mu_s 0.2 at 30 deg;
/// 3.6 rad/s, mu_s 0.6 at 30 and 60 deg) and the granule held in the corner at 10 deg,
/// 3.6 rad/s, mu_s 0.2 (its twelve releases 1 025 058 steps at 1e-6 with five failing, 275 782
/// at 1e-7 with one failing, 231 434 at 1e-10; now 89 778, 120 135 and 224 912).
#[test]
fn a_loose_tolerance_is_not_dearer_on_the_wall() {
    use crate::particle::rolling::AZIMUTHS_DEG;
    let rig = |tilt: f64, w: f64, mu_s: f64| RollingScene {
        sliding_friction: mu_s,
        ri_m: 0.0375,
        ..RollingScene::with_speeds(w, w, tilt.to_radians(), 0.075)
    };
    let wall = shape(60.0, 0.02, 0.0);
    let lim = SystemLimits {
        horizon_s: 10.0,
        max_steps: 200_000,
    };
    let rtols = [1e-10, 1e-9, 1e-8, 1e-7, 1e-6];
    for (s, deg) in [
        (rig(45.0, 1.8, 0.2), 30.0),
        (rig(45.0, 3.6, 0.6), 30.0),
        (rig(45.0, 3.6, 0.6), 60.0),
    ] {
        let b = f64::to_radians(deg);
        let leaves = |r: Result<BowlReport<f64>, BowlError>| match r {
            Ok(BowlReport {
                outcome:
                    BowlOutcome::Leaves {
                        residence_time_s, ..
                    },
                steps,
                ..
            }) => (residence_time_s, steps),
            other => panic!("{deg} deg: {other:?}"),
        };
        let (reference, _) = leaves(residence(&s, &wall, b, FINE, lim));
        let mut tighter = (u32::MAX, u32::MAX);
        for rtol in rtols {
            let (t, steps) = leaves(residence(&s, &wall, b, RollingMethod::Dp54 { rtol }, lim));
            assert!(
                (t - reference).abs() <= 100.0 * rtol * reference,
                "{deg} deg at {rtol:e}: T {t} against {reference}"
            );
            let (last, at_1e10) = tighter;
            assert!(
                f64::from(steps) <= 1.25 * f64::from(last) && steps <= at_1e10,
                "{deg} deg at {rtol:e}: {steps} steps, the tighter run {last}, 1e-10 {at_1e10}"
            );
            tighter = (steps, if at_1e10 == u32::MAX { steps } else { at_1e10 });
        }
    }
    // Held in the corner: every release at every tolerance stays inside (as at 1e-10), and the
    // twelve cost less the looser the tolerance.
    let s = rig(10.0, 3.6, 0.2);
    let mut last = u32::MAX;
    for rtol in [1e-10, 1e-7, 1e-6] {
        let mut total = 0;
        for deg in AZIMUTHS_DEG {
            let r = residence(
                &s,
                &wall,
                deg.to_radians(),
                RollingMethod::Dp54 { rtol },
                lim,
            );
            let r = r.unwrap_or_else(|e| panic!("{deg} deg at {rtol:e}: {e:?}"));
            assert!(
                matches!(r.outcome, BowlOutcome::Inside { .. }),
                "{deg} deg at {rtol:e}: {:?}",
                r.outcome
            );
            total += r.steps;
        }
        assert!(
            total < last,
            "{rtol:e}: {total} steps, the tighter run {last}"
        );
        last = total;
    }
    assert!(last < 100_000, "{last} steps at 1e-6");
}

/// Two segments that ended at their own start (docs/model.md §12, "The wall's slide at its stick
/// threshold"): a granule coming off a 5 mm fillet onto the bottom moving inwards was handed
/// over exactly at the seam, where both sides' events were already at zero, and went bottom ->
/// wall -> bottom at one instant (20 deg, 0.8 rad/s, mu_s 0.3, a 70 deg wall 15 mm high, release
/// at 0 deg, rtol 1e-6: 2 000 000 steps at 0.3175 s); a wall slide restarted from exactly no
/// slip ended at its first rounding (with the handover fixed and this not: 30 deg, 0.5 rad/s,
/// mu_s 0.2, the 60 deg wall, release at 330 deg, rtol 1e-8: 199 456 restarts at 0.743 s). Both now answer in a few thousand steps,
/// held by the wall as at rtol 1e-10.
#[test]
fn a_granule_at_the_seam_or_a_fresh_slide_does_not_stall() {
    let lim = SystemLimits {
        horizon_s: 10.0,
        max_steps: 50_000,
    };
    for (s, sh, deg, rtol) in [
        (rig(20.0, 0.8, 0.3), shape(70.0, 0.015, 0.005), 0.0, 1e-6),
        (rig(30.0, 0.5, 0.2), shape(60.0, 0.02, 0.0), 330.0, 1e-8),
    ] {
        let b = f64::to_radians(deg);
        for rtol in [rtol, 1e-10] {
            let m = RollingMethod::Dp54 { rtol };
            let r = residence(&s, &sh, b, m, lim);
            assert!(
                matches!(r, Ok(r) if matches!(r.outcome, BowlOutcome::Inside { .. })),
                "{deg} deg at {rtol:e}: {r:?}"
            );
        }
    }
}

/// A slide whose slip grows from below the run's absolute tolerance (`rolling::slide::
/// friction_direction`), on the bottom and on the wall: a granule the 60 deg wall holds (30 deg,
/// 1.8 rad/s, mu_s 0.2, release at 30 deg) took 242 439 evaluations at rtol 1e-6 against
/// 11 167 at 1e-7, its slides on the bottom creeping at DP5(4)'s stability limit while the
/// friction followed a slip of 1e-7 m/s; one at 45 deg, 3.6 rad/s (release at 30 deg) 153 866
/// against 191 430, its slides on the wall doing the same (docs/model.md §12). Each is held
/// by the wall at both tolerances, as at 1e-10, and the looser run is the cheaper.
#[test]
fn a_small_growing_slip_is_cheaper_at_a_looser_tolerance_with_the_wall() {
    let wall = shape(60.0, 0.02, 0.0);
    let lim = SystemLimits {
        horizon_s: 10.0,
        max_steps: 200_000,
    };
    // The bound on each: now 0.79 and 0.42 of the tighter run's evaluations.
    for (s, bound) in [(rig(30.0, 1.8, 0.2), 0.9), (rig(45.0, 3.6, 0.2), 0.6)] {
        let b = f64::to_radians(30.0);
        let evaluations = |rtol: f64| {
            let r = residence(&s, &wall, b, RollingMethod::Dp54 { rtol }, lim);
            match r {
                Ok(r) if matches!(r.outcome, BowlOutcome::Inside { .. }) => r.evaluations,
                other => panic!("{s:?} at {rtol:e}: {other:?}"),
            }
        };
        evaluations(1e-10);
        let (loose, tight) = (evaluations(1e-6), evaluations(1e-7));
        assert!(
            f64::from(loose) < bound * f64::from(tight),
            "{:.0} deg: {loose} evaluations at 1e-6, {tight} at 1e-7",
            s.axes_angle_rad.to_degrees()
        );
    }
}

/// A roll that gives way where rolling needs barely more than `mu_s N` (1.00004 times it at the
/// release: 51.3 deg tilt, 1.886 and -1.334 rad/s, mu_r 0.029, mu_s 0.362, the 60 deg wall 20 mm
/// high, release at 180 deg): the slip at rest grew 28 deg off its free acceleration, shrank back
/// into rest wherever it left it, and DP5(4) stalled at 0.35 ms at rtol 1e-12 and 1e-13 ("the
/// steps stopped advancing the time at a roll/slide switch"). Both answer since a growing slip
/// the friction cannot hold takes the friction against its free acceleration up to 1e-4 of the
/// scene's speed at every tolerance (`slide::friction_direction`), within 1e-8 of the run at
/// 1e-11 (an 8.1 ms slide, then a roll to the corner and a flight over the lip).
#[test]
fn a_slide_from_a_roll_barely_past_the_threshold_answers_at_a_tight_tolerance() {
    let s = RollingScene {
        precession_rad_s: 1.885933756828308,
        spin_rad_s: -1.3343454897403717,
        sliding_friction: 0.36206411306729797,
        ri_m: 0.0375,
        ..RollingScene::with_speeds(1.0, 1.0, 51.32191002368927f64.to_radians(), 0.075)
    };
    let wall = shape(60.0, 0.02, 0.0);
    let lim = SystemLimits {
        horizon_s: 10.0,
        max_steps: 200_000,
    };
    let b = f64::to_radians(180.0);
    let leaves =
        |rtol: f64| match residence_or_stall(&s, &wall, b, RollingMethod::Dp54 { rtol }, lim) {
            Ok(BowlReport {
                outcome:
                    BowlOutcome::Leaves {
                        residence_time_s, ..
                    },
                ..
            }) => residence_time_s,
            other => panic!("at {rtol:e}: {other:?}"),
        };
    let reference = leaves(1e-11);
    for rtol in [1e-12, 1e-13] {
        let t = leaves(rtol);
        assert!(
            (t - reference).abs() <= 1e-8 * reference,
            "at {rtol:e}: T {t} against {reference}"
        );
    }
}

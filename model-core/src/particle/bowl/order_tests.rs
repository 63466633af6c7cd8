//! RK4 at its order on the bowl (docs/model.md §10, work-precision): the two scenes of
//! `bowl chart bowl-work-precision`, their twelve releases against DP5(4) at rtol 1e-13. Three
//! things took RK4 off its order there: a step across the fillet's end (the normal force's
//! jump), a roll's no-slip drift deciding the contact after an event, and fixed steps up to a
//! zero of a slide's slip (a release from rest, a stick).

use super::wall::{Meridian, Piece};
use super::*;

fn limits() -> SystemLimits<f64> {
    SystemLimits {
        horizon_s: 3.0,
        max_steps: 2_000_000,
    }
}

/// The chart's two scenes: the rig's (60 deg tilt, 1.8 rad/s, a 60 deg wall 20 mm high with a
/// sharp corner) and the lift-off scene (rod offset 0.3 m, 4.4 and 2 rad/s, a 5 mm fillet).
fn scenes() -> [(RollingScene<f64>, BowlShape<f64>); 2] {
    let rig = RollingScene {
        rolling_resistance: 0.029,
        sliding_friction: 0.4,
        ..RollingScene::equal_speeds(1.8, 60f64.to_radians(), 0.075)
    };
    let wall = |fillet_radius_m| BowlShape {
        wall_angle_rad: 60f64.to_radians(),
        wall_height_m: 0.02,
        fillet_radius_m,
        restitution: 0.5,
    };
    let lift = RollingScene {
        precession_rad_s: 4.4,
        spin_rad_s: 2.0,
        rod_length_m: 0.3,
        ..rig
    };
    [(rig, wall(0.0)), (lift, wall(0.005))]
}

/// T and the count of changes of one release.
fn run(scene: usize, beta_deg: f64, method: RollingMethod<f64>) -> (f64, u32) {
    let (sc, shape) = scenes()[scene];
    let r = residence(&sc, &shape, beta_deg.to_radians(), method, limits()).unwrap();
    let BowlOutcome::Leaves {
        residence_time_s, ..
    } = r.outcome
    else {
        panic!(
            "the release at {beta_deg} deg does not leave: {:?}",
            r.outcome
        );
    };
    (residence_time_s, r.switches)
}

/// The chart's twelve releases, 30 deg apart.
const AZIMUTHS_DEG: [f64; 12] = [
    0.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0, 210.0, 240.0, 270.0, 300.0, 330.0,
];

/// RK4 on a scene at `h`, `h/2`, `h/4`: every release counts the reference's changes (DP5(4)
/// at rtol 1e-13), halving the step divides the error in the mean T over the twelve releases
/// (as the chart has it) by about 16, and the error at `h/4` is below `finest`.
fn assert_rk4_at_its_order(scene: usize, h: f64, finest: f64) {
    let mut sums = [0.0; 4];
    for beta in AZIMUTHS_DEG {
        let (t, changes) = run(scene, beta, RollingMethod::Dp54 { rtol: 1e-13 });
        sums[0] += t;
        for k in 0..3 {
            let step_s = h / f64::from(1u32 << k);
            let (t, n) = run(scene, beta, RollingMethod::Rk4 { step_s });
            sums[k + 1] += t;
            assert_eq!(n, changes, "changes at {beta} deg, h = {step_s} s");
        }
    }
    let errors: [f64; 3] = core::array::from_fn(|k| (sums[k + 1] - sums[0]).abs() / 12.0);
    for k in 0..2 {
        let ratio = errors[k] / errors[k + 1];
        assert!(
            (10.0..=30.0).contains(&ratio),
            "errors {errors:?}: halving h divided the error by {ratio:.1}, not ~16"
        );
    }
    assert!(errors[2] < finest, "{errors:?}");
}

/// The lift-off scene: six of its releases (120 to 270 deg) slide onto the fillet, stick there,
/// roll across the fillet's end onto the cone and lift off at the lip's edge. Before, RK4
/// counted a change more than the reference at every step on those six (a slide of
/// microseconds after the fillet's end, begun by the roll's drift) and its error in the mean T
/// went 3.1e-5, 5.7e-5, 4.5e-6 of T at h = 0.5, 0.25, 0.125 ms (the chart's), not 16x down per
/// halving.
#[test]
fn rk4_keeps_its_order_through_the_lift_off_scenes_wall() {
    assert_rk4_at_its_order(1, 5e-4, 1e-10);
}

/// The rig's scene: every release slides from rest to the corner and flies out (some bounce
/// once). Before, RK4's error in the mean T fell 8x per halving of h (its first steps, the
/// slip's direction taken from a slip of the step's size, were off by `h^3`): 4.8e-7, 6.3e-8,
/// 8.1e-9 s at h = 2, 1, 0.5 ms.
#[test]
fn rk4_keeps_its_order_from_a_release_at_rest() {
    assert_rk4_at_its_order(0, 2e-3, 1e-11);
}

/// The lift-off scene at the chart's finest steps, h = 31, 16 and 8 us, run as `bowl predict`
/// runs it (the stall watch on): no release is given up, every release counts the reference's
/// changes, and the error in the mean T falls 8x per halving or is below 1e-12 s (the
/// reference's own). Before, a slide ended as settled after 8 accepted steps with its slip at
/// rest, and RK4's steps graded towards the stick on the fillet were so short that 8 of them
/// came before it: the error went 9.7e-13, 4.8e-11, 1.3e-10 s; and at 16 and 8 us the stall
/// watch took the graded steps from the release at rest (below 1e-9 of the scene's time scale
/// for more than 16 steps) for a stall and gave up on five releases (120 to 240 deg).
#[test]
fn rk4_at_its_finest_steps_ends_no_slide_early_and_gives_up_on_nothing() {
    let (sc, shape) = scenes()[1];
    let mut sums = [0.0; 4];
    for beta in AZIMUTHS_DEG {
        let (t, changes) = run(1, beta, RollingMethod::Dp54 { rtol: 1e-13 });
        sums[0] += t;
        for k in 0..3 {
            let step_s = 3.125e-5 / f64::from(1u32 << k);
            let m = RollingMethod::Rk4 { step_s };
            let r = residence_or_stall(&sc, &shape, beta.to_radians(), m, limits())
                .unwrap_or_else(|e| panic!("given up at {beta} deg, h = {step_s} s: {e:?}"));
            let BowlOutcome::Leaves {
                residence_time_s, ..
            } = r.outcome
            else {
                panic!("{beta} deg, h = {step_s} s: {:?}", r.outcome);
            };
            sums[k + 1] += residence_time_s;
            assert_eq!(r.switches, changes, "changes at {beta} deg, h = {step_s} s");
        }
    }
    let errors: [f64; 3] = core::array::from_fn(|k| (sums[k + 1] - sums[0]).abs() / 12.0);
    for k in 0..2 {
        assert!(
            errors[k + 1] <= (errors[k] / 8.0).max(1e-12),
            "errors {errors:?} s at 31, 16, 8 us"
        );
    }
}

/// A segment's meridian follows its own piece past its ends: on the fillet's piece the arc
/// goes on beyond the fillet's end (the same curvature, so a step that crosses the end sees no
/// jump), while the whole meridian turns into the cone there; at the end itself both agree.
#[test]
fn a_piece_of_the_meridian_goes_on_past_its_end() {
    let (sc, shape) = scenes()[1];
    let m: Meridian<f64> = shape.meridian(&sc).unwrap();
    let end = m.arc_length();
    let fillet = m.on_piece(0.5 * end);
    assert_eq!(fillet.piece, Piece::Fillet);
    let past = end + 1e-4;
    let curvature = 1.0 / m.arc_radius_m;
    let bend = fillet.at(past).bend;
    assert!(((bend[0] * bend[0] + bend[1] * bend[1]).sqrt() - curvature).abs() < 1e-9 * curvature);
    assert_eq!(m.at(past).bend, [0.0, 0.0]);
    assert_eq!(m.on_piece(past).piece, Piece::Cone);
    for (a, b) in fillet.at(end).pos.iter().zip(m.at(end).pos) {
        assert!((a - b).abs() < 1e-15);
    }
    // Over the lip's edge: the pivot; back below it, the cone again.
    assert_eq!(m.piece_at(m.top_s + 1e-6), Piece::Pivot);
    assert_eq!(m.piece_at(m.top_s - 1e-6), Piece::Cone);
}

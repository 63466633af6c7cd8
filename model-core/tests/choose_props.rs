//! The whole-model chooser (`choose::whole::choose_level`) on any finite input, f64 and f32:
//! no panic, and every number it reports is a number or says plainly that it has none. The
//! chooser runs before anything is integrated, on whatever a user typed (`bowl predict` checks
//! the flags first, but the library is public): a scene it cannot judge must still come back
//! as a choice, never a NaN presented as an answer.

use model_core::Real;
use model_core::choose::whole::{LEVELS, Level, WholeChoice, choose_level};
use model_core::particle::bowl::BowlShape;
use model_core::particle::rolling::RollingScene;
use proptest::prelude::*;

/// Finite values across the ranges a user could type, the silly ones included (zero,
/// negative, huge).
fn any_finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1e6f64..1e6,
        -10.0f64..10.0,
        -1.0f64..1.0,
        Just(0.0),
        Just(-0.0),
        Just(1e-300),
        Just(f64::MAX),
        Just(f64::MIN),
    ]
}

fn scene<T: Copy>(v: &[T; 11]) -> RollingScene<T> {
    RollingScene {
        precession_rad_s: v[0],
        spin_rad_s: v[1],
        axes_angle_rad: v[2],
        rolling_resistance: v[3],
        sliding_friction: v[4],
        g_m_s2: v[5],
        k2: v[6],
        particle_radius_m: v[7],
        rod_length_m: v[8],
        ri_m: v[9],
        rim_radius_m: v[10],
    }
}

fn shape<T: Copy>(w: &[T; 4]) -> BowlShape<T> {
    BowlShape {
        wall_angle_rad: w[0],
        wall_height_m: w[1],
        fillet_radius_m: w[2],
        restitution: w[3],
    }
}

/// [`check`] of the chooser's answer at `scene` and `shape`.
fn choose_and_check<T: Real + Into<f64> + core::fmt::Debug>(
    scene: &RollingScene<T>,
    shape: &BowlShape<T>,
    tolerance: T,
    each_release: bool,
) -> Result<WholeChoice<T>, TestCaseError> {
    let c = choose_level(scene, shape, tolerance, each_release);
    check(
        shape.validate(scene).is_ok(),
        c.level,
        c.cheaper_fail.map(|f| f.is_some()),
        c.rotation_estimate,
        c.friction_needed,
        c.incline_mean_s,
        c.second_order.map(|s| (s.c2, s.bound, s.corrected_bound)),
    )?;
    Ok(c)
}

/// What must hold of any choice: the level is one of [`LEVELS`]; the levels below it each say
/// why not and none at or above it does; an incline mean, where given, is a finite time, and
/// positive where the scene is valid (`valid`: [`BowlShape::validate`] accepts it; callers
/// validate first, and on a bowl of zero size the incline's 0 s is that bowl's answer); the
/// estimate is a number (infinite when it was not computed, never NaN); a second order, where
/// given, is finite.
fn check<T: Copy + PartialOrd + core::fmt::Debug + Into<f64>>(
    valid: bool,
    level: Level,
    cheaper_fail_set: [bool; 4],
    rotation_estimate: T,
    friction_needed: T,
    incline_mean_s: Option<T>,
    second_order: Option<(T, T, T)>,
) -> Result<(), TestCaseError> {
    let at = LEVELS.iter().position(|&l| l == level);
    prop_assert!(at.is_some(), "{level:?} not a level");
    let at = at.unwrap();
    for (i, set) in cheaper_fail_set.iter().enumerate() {
        prop_assert_eq!(
            *set,
            i < at,
            "level {:?}: reason at {} is {}",
            level,
            i,
            set
        );
    }
    prop_assert!(!rotation_estimate.into().is_nan(), "estimate NaN");
    prop_assert!(!friction_needed.into().is_nan(), "friction needed NaN");
    if let Some(t) = incline_mean_s {
        let t: f64 = t.into();
        prop_assert!(t.is_finite() && t >= 0.0, "incline mean {t}");
        prop_assert!(!valid || t > 0.0, "incline mean {t} on a valid scene");
    }
    if let Some((c2, bound, corrected)) = second_order {
        prop_assert!(
            c2.into().is_finite() && bound.into().is_finite() && corrected.into().is_finite(),
            "{c2:?} {bound:?} {corrected:?}"
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]
    #[test]
    fn the_chooser_answers_every_finite_scene(
        v in proptest::array::uniform11(any_finite()),
        wall in proptest::array::uniform4(any_finite()),
        tolerance in any_finite(),
        each_release in any::<bool>(),
    ) {
        choose_and_check(&scene(&v), &shape(&wall), tolerance, each_release)?;
        // The same scene in f32 (values beyond f32's range become infinite there, which is
        // not finite input: those are left to the f64 run).
        let v32 = v.map(|x| x as f32);
        let w32 = wall.map(|x| x as f32);
        if v32.iter().chain(&w32).all(|x| x.is_finite()) && (tolerance as f32).is_finite() {
            choose_and_check(&scene(&v32), &shape(&w32), tolerance as f32, each_release)?;
        }
    }

    /// Near the rig's own scenes (the ranges `bowl predict` accepts): the same, and the
    /// incline, where it is chosen, gives its mean.
    #[test]
    fn the_chooser_answers_every_rig_scene(
        w1 in -4.0f64..4.0,
        w2 in -4.0f64..4.0,
        tilt_deg in 0.0f64..89.0,
        mu_r in 0.0f64..0.2,
        mu_s in 0.0f64..1.0,
        rod in 0.0f64..0.5,
        ri_share in 0.0f64..1.0,
        rim in 0.01f64..0.3,
        wall_deg in 10.0f64..90.0,
        wall_h in 0.0f64..0.05,
        tolerance in 1e-6f64..0.2,
        each_release in any::<bool>(),
    ) {
        let s = RollingScene {
            precession_rad_s: w1,
            spin_rad_s: w2,
            axes_angle_rad: tilt_deg.to_radians(),
            rolling_resistance: mu_r,
            sliding_friction: mu_s,
            g_m_s2: 9.81,
            k2: 5.0 / 7.0,
            particle_radius_m: 0.003,
            rod_length_m: rod,
            ri_m: ri_share * rim,
            rim_radius_m: rim,
        };
        let shape = BowlShape {
            wall_angle_rad: wall_deg.to_radians(),
            wall_height_m: wall_h,
            fillet_radius_m: 0.0,
            restitution: 0.5,
        };
        prop_assume!(shape.validate(&s).is_ok());
        let c = choose_and_check(&s, &shape, tolerance, each_release)?;
        if c.level == Level::Incline {
            prop_assert!(c.incline_mean_s.is_some(), "the incline chosen without its mean");
        }
    }
}

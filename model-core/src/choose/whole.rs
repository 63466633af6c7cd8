//! The chooser over the whole hierarchy of the tilted, precessing bowl (issue 30, part 3;
//! docs/model.md §12): the least model that meets the tolerance at the scene, and why each
//! cheaper one does not. Cheapest first:
//!
//! 1. [`Level::Incline`]: the fixed incline, closed form per release: rolling down it at
//!    `k2 g (sin th - mu_r cos th)`, or sliding at `g (sin th - mu_s cos th)` where rolling
//!    would need more friction than the contact gives (`(1 - k2) tan th > mu_s`), the bowl's
//!    rotation left out. Nanoseconds.
//! 2. [`Level::Rolling`]: the rolling model of §9, integrated per release.
//! 3. [`Level::RollingOrSliding`]: the flat disc rolling or sliding (§10 on the bottom alone),
//!    integrated with its mode switches.
//! 4. [`Level::Bowl`]: the real bowl with its fillet, wall and lip (§10).
//!
//! (The paper's 1-D forms are not members here: on a tilted bowl they leave out the tilt's
//! gravity, which is what moves the granule at the rig's tilts; `Model::Flat`/`Coriolis` stay
//! the chooser's answer for the level bowl of the paper, [`super::choose_constant`].)
//!
//! Every check is made before anything is integrated, at closed-form cost, so a choice never
//! costs much more than the model it picks:
//! - **the wall** (any level below the bowl): a wall of height `H > 0` decides where and
//!   whether the granule leaves (its lip at `R + H cot alpha`, beyond the bottom's `R`; a
//!   vertical one holds it unless it climbs);
//! - **sliding** (the rolling levels): rolling down the incline needs `(1 - k2) tan th` of the
//!   normal force (plus what the rotation adds at release, computed there for every release
//!   azimuth); above `mu_s` the granule slides;
//! - **the rotation** (the incline): the bowl's rotation changes `T` by about
//!   `K (|Omega|^2 + 2 w1^2) T_incline^2 ri / (R - ri)` ([`rotation_estimate`]); `K` is measured
//!   per mode over a grid of scenes and checked on another (docs/model.md §12), and the incline is
//!   taken when that estimate is within the tolerance. Where it is not (and the incline is not
//!   near the stick threshold at rest), the rotation's second order along the incline's path,
//!   rolling or sliding ([`second_order_bound`], from the incline's own times), bounds its error
//!   by `|c2| + K4 F^2`, and takes it when that is within. Single releases differ far more than
//!   their mean (the rotation turns each path), so the incline is only offered for the mean.
//!
//! A granule that rolls at release may still start to slide later; the rolling level says so
//! in its own validity (the maximum friction ratio), and the caller then runs the next level.

use crate::Real;
use crate::particle::bowl::BowlShape;
use crate::particle::rolling::RollingScene;

use super::incline::{Tilt, mean_from_sum, needed_at, sum_of};
pub use super::incline::{
    friction_needed_at_release, friction_needed_at_rim, incline_friction_needed, incline_mean_s,
    incline_release_s, incline_times_s,
};
pub use super::rotation_bound::{
    CORRECTED_K4, CORRECTED_K4_NEAR_RIM, CORRECTED_K4_SLIDING, InclineMode, NEAR_SLIDING,
    ROTATION_K, ROTATION_K_NEAR_SLIDING, ROTATION_K_ROD, ROTATION_K_SLIDING, SECOND_ORDER_K4,
    SECOND_ORDER_K4_NEAR_RIM, SECOND_ORDER_K4_SLIDING, SecondOrder, incline_mode, may_stick,
    rod_form, rotation_constant, rotation_estimate, rotation_form, second_order_bound,
};
use super::rotation_bound::{Prepared, estimate_of, form_in, likely_refused, mode_in};

/// A level of the hierarchy, cheapest first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// The fixed incline, rolling or sliding (closed form per release).
    Incline,
    /// The rolling model (§9), integrated.
    Rolling,
    /// The flat disc, rolling or sliding (§10 on the bottom), integrated.
    RollingOrSliding,
    /// The bowl with its wall and lip (§10).
    Bowl,
}

/// Every level, cheapest first.
pub const LEVELS: [Level; 4] = [
    Level::Incline,
    Level::Rolling,
    Level::RollingOrSliding,
    Level::Bowl,
];

impl Level {
    /// Short name for text and JSON.
    pub const fn name(self) -> &'static str {
        match self {
            Level::Incline => "incline",
            Level::Rolling => "rolling",
            Level::RollingOrSliding => "rolling-or-sliding",
            Level::Bowl => "bowl",
        }
    }
}

/// Why a cheaper level does not hold at the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Fails<T> {
    /// The wall matters: the granule leaves over a lip at `lip_m`, not at the bottom's rim
    /// `rim_m` (equal for a vertical wall, which the granule must climb).
    Wall {
        /// The lip's radius, m.
        lip_m: T,
        /// The bottom's radius, m.
        rim_m: T,
        /// The wall's height, m.
        height_m: T,
    },
    /// The granule slides: rolling needs `needed` of the normal force (worst release), the
    /// contact gives `mu_s`.
    Slides {
        /// The friction rolling needs, as a fraction of the normal force.
        needed: T,
        /// The sliding coefficient.
        mu_s: T,
    },
    /// The bowl's rotation changes `T` by about `estimate` (relative), more than the
    /// tolerance.
    Rotation {
        /// The estimated relative change of `T`.
        estimate: T,
    },
    /// Single releases are wanted, and the incline does not follow a release's turning path.
    EachRelease,
    /// The incline gives no time (the tilt does not move the granule down it).
    NoDrive,
}

/// The chooser's decision: the level, and for each cheaper level why it does not hold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WholeChoice<T> {
    /// The least level that meets the tolerance.
    pub level: Level,
    /// For each level below it (in [`LEVELS`] order), why not; `None` at and above `level`.
    pub cheaper_fail: [Option<Fails<T>>; 4],
    /// The incline's estimated relative error from the rotation (a priori, [`rotation_estimate`]).
    pub rotation_estimate: T,
    /// Where that estimate is above the tolerance and the incline rolls: the rotation's second
    /// order and the bound it gives ([`second_order_bound`]); the incline is taken when that
    /// bound is within the tolerance.
    pub second_order: Option<SecondOrder<T>>,
    /// The friction rolling needs at release (worst azimuth), as a fraction of `N`.
    pub friction_needed: T,
    /// The incline's mean `T` over [`AZIMUTHS_DEG`](crate::particle::rolling::AZIMUTHS_DEG), s, corrected by the rotation's second
    /// order where the chooser took it so ([`SecondOrder::corrected`]); computed for the
    /// choice: when the incline is chosen, this is its answer, at no further cost.
    pub incline_mean_s: Option<T>,
}

/// Picks the least level within `tolerance` (relative, on the mean `T`; `each_release`: every
/// release) at `scene` in a bowl of `shape`.
pub fn choose_level<T: Real>(
    scene: &RollingScene<T>,
    shape: &BowlShape<T>,
    tolerance: T,
    each_release: bool,
) -> WholeChoice<T> {
    let mut fails = [None; 4];
    let tilt = Tilt::of(scene);
    let needed = needed_at(scene, tilt, scene.ri_m);
    let mut rotation_estimate = T::from_f64(f64::INFINITY);
    let mut second_order = None;
    // The rotation estimate is calibrated where it is at most 10 % (docs/model.md §12); a
    // tolerance above that would reach beyond it.
    let tolerance = tolerance.min(T::from_f64(0.1));
    // The wall: every level below the bowl ends at R on a flat bottom.
    if shape.wall_height_m > T::ZERO {
        let a = shape.wall_angle_rad;
        let lip = scene.rim_radius_m + shape.wall_height_m * a.cos() / a.sin();
        let wall = Fails::Wall {
            lip_m: lip,
            rim_m: scene.rim_radius_m,
            height_m: shape.wall_height_m,
        };
        fails = [Some(wall); 4];
        fails[3] = None;
        return WholeChoice {
            level: Level::Bowl,
            cheaper_fail: fails,
            rotation_estimate,
            second_order,
            friction_needed: needed,
            incline_mean_s: None,
        };
    }
    let slides = needed > scene.sliding_friction;
    let mode = mode_in(scene, tilt);
    // The second order's scene part (its orders along the path), needed only where the
    // a-priori estimate refuses the incline: built before the incline's pass where a guess says
    // it will, so the processor works on it while the pass waits on its square roots (built
    // after the pass, it was the longest chain of work left; docs/model.md §12).
    let early = !each_release && likely_refused(scene, tilt, mode, tolerance);
    let prepared = if early {
        Prepared::new(scene, tilt, mode)
    } else {
        None
    };
    // The incline: its own friction check is inside it; the rotation decides.
    let times = incline_times_s(scene);
    let sum = times.as_ref().map(sum_of);
    let incline = sum.map(mean_from_sum);
    fails[0] = match (&times, sum, incline) {
        (Some(_), _, _) if each_release => Some(Fails::EachRelease),
        (Some(times), Some(sum), Some(t)) => {
            // The rotation's form, once for the estimate and the second order's bound.
            let f = form_in(scene, tilt, t);
            rotation_estimate = estimate_of(scene, f, t, mode);
            if rotation_estimate > tolerance {
                // The a-priori estimate refuses it: the rotation's second order along the
                // incline's path may still bound it within (docs/model.md §12, "The four
                // rotation rows"); only here (the rows the estimate takes pay only the guess
                // above). The plain incline where its bound holds; else its mean corrected by
                // `c2` where the remainder's bound does. Prepared early where the guess said
                // so (`None` there: no second order), else now.
                second_order = match prepared {
                    Some(p) => p.bound((times, sum), f),
                    None if early => None,
                    None => Prepared::new(scene, tilt, mode).and_then(|p| p.bound((times, sum), f)),
                };
                match &mut second_order {
                    Some(b) if b.bound <= tolerance => None,
                    Some(b) if b.corrected_bound <= tolerance => {
                        b.corrected = true;
                        None
                    }
                    _ => Some(Fails::Rotation {
                        estimate: rotation_estimate,
                    }),
                }
            } else {
                None
            }
        }
        _ => Some(Fails::NoDrive),
    };
    if fails[0].is_none() {
        let corrected = second_order.filter(|b| b.corrected);
        return WholeChoice {
            level: Level::Incline,
            cheaper_fail: fails,
            rotation_estimate,
            second_order,
            friction_needed: needed,
            incline_mean_s: match (incline, corrected) {
                (Some(t), Some(b)) => Some(t * (T::ONE + b.c2)),
                (t, _) => t,
            },
        };
    }
    if slides {
        fails[1] = Some(Fails::Slides {
            needed,
            mu_s: scene.sliding_friction,
        });
        return WholeChoice {
            level: Level::RollingOrSliding,
            cheaper_fail: fails,
            rotation_estimate,
            second_order,
            friction_needed: needed,
            incline_mean_s: incline,
        };
    }
    WholeChoice {
        level: Level::Rolling,
        cheaper_fail: fails,
        rotation_estimate,
        second_order,
        friction_needed: needed,
        incline_mean_s: incline,
    }
}

#[cfg(test)]
#[path = "whole_tests.rs"]
mod tests;

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
//!   taken when that estimate is within the tolerance. Where it is not and the incline rolls,
//!   the rotation's second order along the incline's path ([`second_order_bound`], from the
//!   incline's own times) bounds its error by `|c2| + K4 F^2`, and takes it when that is within.
//!   Single releases differ far more than
//!   their mean (the rotation turns each path), so the incline is only offered for the mean.
//!
//! A granule that rolls at release may still start to slide later; the rolling level says so
//! in its own validity (the maximum friction ratio), and the caller then runs the next level.

use crate::Real;
use crate::particle::bowl::BowlShape;
use crate::particle::rolling::{AZIMUTHS_DEG, RollingScene, incline_residence_s};

use super::incline_rotation::tilted_second_order;

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
    /// The incline's mean `T` over [`AZIMUTHS_DEG`], s (computed for the choice: when the
    /// incline is chosen, this is its answer, at no further cost).
    pub incline_mean_s: Option<T>,
}

/// The rotation's effect on the incline's mean `T`: at most
/// `K (|Omega|^2 + 2 w1^2) T_incline^2 ri / (R - ri)` (relative, [`rotation_estimate`]), where
/// `|Omega|` is the bowl's combined speed and `w1` the precession, which turns the downhill
/// direction under the granule while the bowl's spin carries it round (at a low tilt with
/// opposite speeds `|Omega|` is small but the precession is not: 7 % at 5 deg, w1 3.6, w2 -2.7
/// rad/s); `ri / (R - ri)` is the release's offset against its path (the rotation moves a
/// granule released near the rim most: 40-fold from `ri/R` 0.2 to 0.7 at one `(Omega T)^2`).
/// `K` by the incline's mode: this one where it rolls and keeps rolling to the rim (rolling
/// needs at most 0.95 `mu_s` there, [`friction_needed_at_rim`]); 0.0108 (rounded up) is the
/// largest ratio of the incline's error (against the rolling-or-sliding disc) to the form over
/// those scenes of the fitting grid (294 scenes: tilt 5-75 deg, 0.25-3.6 rad/s, equal, unequal
/// and opposite speeds, mu_s 0.2-0.6, `ri/R` 0.2-0.7). On the held-out grid (119 other scenes:
/// tilt 15-70 deg, 0.8-3 rad/s, spin -1.3 w1, mu_s 0.25-0.5, `ri/R` 0.15-0.8) no error exceeds
/// 0.9 of its estimate (docs/model.md §12, `cargo test --release -p lab
/// whole::rotation_fit::rotation_fit_data -- --ignored --nocapture`). Fitted where the estimate
/// is at most 10 %; the tolerance is capped there.
pub const ROTATION_K: f64 = 0.011;

/// [`ROTATION_K`] where the incline slides (0.0137 on the fitting grid, rounded up).
pub const ROTATION_K_SLIDING: f64 = 0.014;

/// [`ROTATION_K`] where the incline rolls but the rotation brings the granule near or past the
/// stick threshold before the rim (rolling needs more than 0.95 `mu_s` there): it may slide for
/// part of its path, which the rolling incline leaves out (0.0272 on the fitting grid, rounded
/// up; the largest ratios of all are these scenes).
pub const ROTATION_K_NEAR_SLIDING: f64 = 0.028;

/// How near the stick threshold a rolling incline's granule may come at the rim (rolling needs
/// this fraction of `mu_s N` there) and still count as rolling all the way for
/// [`ROTATION_K`].
pub const NEAR_SLIDING: f64 = 0.95;

/// What the bowl's centre circling the precession axis at the rod offset `L` adds to the
/// incline's error, per unit of [`rod_form`]: 0.6646 (rounded up) is the largest ratio of the
/// error beyond [`ROTATION_K`]'s part to the form over a fitting grid (135 scenes: `L` 0.05,
/// 0.15, 0.3 m; tilt 10-75 deg; w 0.5-3.6 rad/s; three bowls); on a held-out grid (36 scenes:
/// `L` 0.1, 0.25 m; tilt 20, 50, 70 deg; w 0.8, 2.5 rad/s, equal and opposite; three other
/// bowls) no error exceeds 0.67 of the estimate (docs/model.md §12, `cargo test --release -p
/// lab whole::rotation_fit::rod_offset -- --ignored --nocapture`). Left out, the incline was
/// taken where it was 6 % off at a 5 % tolerance (60 deg, 1.8 rad/s, `L` 0.3 m).
pub const ROTATION_K_ROD: f64 = 0.67;

/// The rod offset's part of [`rotation_estimate`] without its constant:
/// `w1^2 L T^2 ri / (R - ri)^2` (the centre's acceleration `w1^2 L` against the incline's
/// drive `2 (R - ri) / T^2`, and the offset of the release as in [`rotation_form`]).
pub fn rod_form<T: Real>(scene: &RollingScene<T>, incline_mean_s: T) -> T {
    let w1 = scene.precession_rad_s;
    let path = scene.rim_radius_m - scene.ri_m;
    // Also catches a NaN path.
    if path.is_nan() || path <= T::ZERO {
        return T::from_f64(f64::INFINITY);
    }
    w1 * w1 * scene.rod_length_m * incline_mean_s * incline_mean_s * scene.ri_m.abs()
        / (path * path)
}

/// The incline's estimated relative error in the mean `T` from the bowl's rotation (see
/// [`ROTATION_K`]) and its centre's circling at the rod offset ([`ROTATION_K_ROD`]); infinite
/// when the release is not inside the rim.
pub fn rotation_estimate<T: Real>(scene: &RollingScene<T>, incline_mean_s: T) -> T {
    let tilt = Tilt::of(scene);
    estimate_in(scene, tilt, incline_mean_s, mode_in(scene, tilt))
}

/// The constant of [`rotation_estimate`] for the incline's mode at the scene.
pub fn rotation_constant<T: Real>(scene: &RollingScene<T>) -> T {
    mode_constant(incline_mode(scene))
}

/// [`rotation_estimate`] with the incline's mode already known.
fn estimate_in<T: Real>(
    scene: &RollingScene<T>,
    tilt: Tilt<T>,
    incline_mean_s: T,
    mode: InclineMode,
) -> T {
    let estimate = mode_constant::<T>(mode) * form_in(scene, tilt, incline_mean_s)
        + T::from_f64(ROTATION_K_ROD) * rod_form(scene, incline_mean_s);
    // A speed whose square overflows times a release at the centre (`inf * 0`) bounds nothing:
    // infinite, so the incline is not taken and no NaN is reported.
    if estimate.is_nan() {
        T::from_f64(f64::INFINITY)
    } else {
        estimate
    }
}

fn mode_constant<T: Real>(mode: InclineMode) -> T {
    T::from_f64(match mode {
        InclineMode::Slides => ROTATION_K_SLIDING,
        InclineMode::NearAtRim | InclineMode::NearAtRest => ROTATION_K_NEAR_SLIDING,
        InclineMode::Rolls => ROTATION_K,
    })
}

/// The incline's mode at the scene, as the rotation's bounds have it (docs/model.md §12).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InclineMode {
    /// It rolls, and keeps rolling to the rim (rolling needs at most [`NEAR_SLIDING`] of
    /// `mu_s` there, [`friction_needed_at_rim`]).
    Rolls,
    /// It slides (`(1 - k2) tan th > mu_s`).
    Slides,
    /// It rolls, and only the rotation brings it near or past the stick threshold at the rim.
    NearAtRim,
    /// It rolls, but is near the stick threshold already at rest (`(1 - k2) tan th` above
    /// [`NEAR_SLIDING`] of `mu_s`): any rotation makes it slide part of the way, and `T` is
    /// not smooth in the speeds.
    NearAtRest,
}

/// The incline's mode at the scene ([`InclineMode`]).
pub fn incline_mode<T: Real>(scene: &RollingScene<T>) -> InclineMode {
    mode_in(scene, Tilt::of(scene))
}

fn mode_in<T: Real>(scene: &RollingScene<T>, tilt: Tilt<T>) -> InclineMode {
    let mu_s = scene.sliding_friction;
    let near = T::from_f64(NEAR_SLIDING) * mu_s;
    let at_rest = (T::ONE - scene.k2) * tilt.sin / tilt.cos;
    if at_rest > mu_s {
        InclineMode::Slides
    } else if needed_at(scene, tilt, scene.rim_radius_m) > near {
        if at_rest > near {
            InclineMode::NearAtRest
        } else {
            InclineMode::NearAtRim
        }
    } else {
        InclineMode::Rolls
    }
}

/// `K4` of the second-order bound ([`second_order_bound`]) where the incline rolls to the rim:
/// the least that covers `err - |c2|` per unit of `F^2` ([`rotation_form`] squared) over those
/// scenes of the fitting grid (the rotation estimate's 294 scenes; `c2` the closed form's,
/// [`mean_second_order_from`](super::incline_rotation::mean_second_order_from); the error
/// against the rolling-or-sliding disc): 6.93e-4, rounded up (docs/model.md §12, `lab`
/// `whole::rotation_orders::rotation_orders`, which fits it, asserts this covers it and that
/// no fitting or held-out scene is taken beyond a tolerance).
pub const SECOND_ORDER_K4: f64 = 0.0007;

/// [`SECOND_ORDER_K4`] where only the rotation brings the granule near the stick threshold at
/// the rim ([`InclineMode::NearAtRim`]): 3.14e-3 on the fitting grid, rounded up.
pub const SECOND_ORDER_K4_NEAR_RIM: f64 = 0.0032;

/// The rotation's second order along the rolling incline's path, and the bound it gives the
/// plain incline's error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SecondOrder<T> {
    /// `c2`: the rotation's second-order change of the incline's mean `T` (relative,
    /// [`mean_second_order_from`](super::incline_rotation::mean_second_order_from); the first order is zero in the mean).
    pub c2: T,
    /// The bound on the plain incline's error: `|c2| + K4 F^2`.
    pub bound: T,
}

/// The bound [`SecondOrder`] on the plain incline's relative error in the mean `T`, where the
/// incline rolls ([`InclineMode::Rolls`] or [`InclineMode::NearAtRim`]) and the bowl turns on
/// its own axis (no rod offset); `None` elsewhere (a sliding incline's slip has its own
/// dynamics, not written; near the threshold at rest `T` is not smooth in the speeds).
/// `times` are the incline's at [`AZIMUTHS_DEG`] ([`incline_times_s`]).
pub fn second_order_bound<T: Real>(
    scene: &RollingScene<T>,
    times: &[T; 12],
    incline_mean_s: T,
    mode: InclineMode,
) -> Option<SecondOrder<T>> {
    bound_in(scene, Tilt::of(scene), times, incline_mean_s, mode)
}

fn bound_in<T: Real>(
    scene: &RollingScene<T>,
    tilt: Tilt<T>,
    times: &[T; 12],
    incline_mean_s: T,
    mode: InclineMode,
) -> Option<SecondOrder<T>> {
    let k4 = match mode {
        InclineMode::Rolls => SECOND_ORDER_K4,
        InclineMode::NearAtRim => SECOND_ORDER_K4_NEAR_RIM,
        InclineMode::Slides | InclineMode::NearAtRest => return None,
    };
    if scene.rod_length_m != T::ZERO {
        return None;
    }
    let (_, c2) = tilted_second_order(scene, tilt.sin, tilt.cos, times)?;
    let f = form_in(scene, tilt, incline_mean_s);
    let bound = c2.abs() + T::from_f64(k4) * f * f;
    bound.is_finite().then_some(SecondOrder { c2, bound })
}

/// [`rotation_estimate`] without its constant: `(|Omega|^2 + 2 w1^2) T^2 ri / (R - ri)`.
pub fn rotation_form<T: Real>(scene: &RollingScene<T>, incline_mean_s: T) -> T {
    form_in(scene, Tilt::of(scene), incline_mean_s)
}

fn form_in<T: Real>(scene: &RollingScene<T>, tilt: Tilt<T>, incline_mean_s: T) -> T {
    let w = tilt.combined_speed(scene);
    let w1 = scene.precession_rad_s;
    let path = scene.rim_radius_m - scene.ri_m;
    // Also catches a NaN path.
    if path.is_nan() || path <= T::ZERO {
        return T::from_f64(f64::INFINITY);
    }
    let offset = scene.ri_m.abs() / path;
    (w * w + T::TWO * w1 * w1) * incline_mean_s * incline_mean_s * offset
}

/// The incline's mean residence time over the release azimuths (rolling or sliding as its
/// friction allows), s; `None` when it does not move the granule.
pub fn incline_mean_s<T: Real>(scene: &RollingScene<T>) -> Option<T> {
    incline_times_s(scene).map(|t| mean_of(&t))
}

/// The incline's residence time at each of [`AZIMUTHS_DEG`] ([`incline_release_s`]), s; `None`
/// when it does not move the granule.
pub fn incline_times_s<T: Real>(scene: &RollingScene<T>) -> Option<[T; 12]> {
    let mut times = [T::ZERO; 12];
    for (t, deg) in times.iter_mut().zip(AZIMUTHS_DEG) {
        *t = incline_release_s(scene, T::from_f64(deg.to_radians()))?;
    }
    Some(times)
}

fn mean_of<T: Real>(times: &[T; 12]) -> T {
    let mut sum = T::ZERO;
    for &t in times {
        sum += t;
    }
    sum / T::from_f64(AZIMUTHS_DEG.len() as f64)
}

/// The friction rolling down the incline needs, as a fraction of the normal force:
/// `(1 - k2) tan th` (resistance aside, as the slide test of §10).
pub fn incline_friction_needed<T: Real>(scene: &RollingScene<T>) -> T {
    let tilt = Tilt::of(scene);
    (T::ONE - scene.k2) * tilt.sin / tilt.cos
}

/// One release down the incline: rolling, or sliding where rolling needs more than `mu_s`.
pub fn incline_release_s<T: Real>(scene: &RollingScene<T>, beta_rad: T) -> Option<T> {
    if incline_friction_needed(scene) > scene.sliding_friction {
        // Sliding: the drive g (sin th - mu_s cos th) is the rolling form's with k2 = 1 and
        // the sliding coefficient in place of the resistance (the path is the same).
        let sliding = RollingScene {
            k2: T::ONE,
            rolling_resistance: scene.sliding_friction,
            ..*scene
        };
        incline_residence_s(&sliding, beta_rad)
    } else {
        incline_residence_s(scene, beta_rad)
    }
}

/// The friction rolling needs at release, worst over the azimuths, as a fraction of the normal
/// force: the incline's `(1 - k2) tan th` plus what the rotation adds at rest in the bowl
/// (the centrifugal push `omega^2 ri` is taken by the contact like gravity's in-plane part,
/// `(1 - k2)` of it).
pub fn friction_needed_at_release<T: Real>(scene: &RollingScene<T>) -> T {
    needed_at(scene, Tilt::of(scene), scene.ri_m)
}

/// The tilt's sine and cosine, computed once per choice (every check needs them; `libm`'s
/// calls, repeated in each, were a tenth of the incline's own cost).
#[derive(Clone, Copy)]
struct Tilt<T> {
    sin: T,
    cos: T,
}

impl<T: Real> Tilt<T> {
    fn of(scene: &RollingScene<T>) -> Self {
        let th = scene.axes_angle_rad;
        Tilt {
            sin: th.sin(),
            cos: th.cos(),
        }
    }

    /// [`RollingScene::combined_speed_rad_s`].
    fn combined_speed(self, scene: &RollingScene<T>) -> T {
        let (w1, w2) = (scene.precession_rad_s, scene.spin_rad_s);
        (w1 * w1 + w2 * w2 + T::TWO * w1 * w2 * self.cos)
            .max(T::ZERO)
            .sqrt()
    }
}

/// [`friction_needed_at_release`] for a release at `radius_m`.
fn needed_at<T: Real>(scene: &RollingScene<T>, tilt: Tilt<T>, radius_m: T) -> T {
    let w = tilt.combined_speed(scene);
    let g = scene.g_m_s2;
    let in_plane = g * tilt.sin + w * w * radius_m;
    let normal = g * tilt.cos;
    if normal <= T::ZERO {
        return T::from_f64(f64::INFINITY);
    }
    let needed = (T::ONE - scene.k2) * in_plane / normal;
    // A speed whose square overflows at a release at the centre (`inf * 0`): the need is not
    // known, so rolling is not assumed.
    if needed.is_nan() {
        T::from_f64(f64::INFINITY)
    } else {
        needed
    }
}

/// The friction rolling needs at the bottom's rim, as [`friction_needed_at_release`] with the
/// centrifugal push `omega^2 R` of the rim: a granule that rolls at release (`mu_s` above the
/// friction needed there) but not at the rim switches from rolling to sliding on its way out,
/// where the slide/roll switch near the stick threshold can chatter (docs/model.md §12).
pub fn friction_needed_at_rim<T: Real>(scene: &RollingScene<T>) -> T {
    let at_rim = RollingScene {
        ri_m: scene.rim_radius_m,
        ..*scene
    };
    friction_needed_at_release(&at_rim)
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
    // The incline: its own friction check is inside it; the rotation decides.
    let times = incline_times_s(scene);
    let incline = times.as_ref().map(mean_of);
    fails[0] = match (incline, times) {
        (Some(_), _) if each_release => Some(Fails::EachRelease),
        (Some(t), Some(times)) => {
            let mode = mode_in(scene, tilt);
            rotation_estimate = estimate_in(scene, tilt, t, mode);
            if rotation_estimate > tolerance {
                // The a-priori estimate refuses it: the rotation's second order along the
                // incline's path may still bound it within (docs/model.md §12, "The four
                // rotation rows"); only here, so the rows taken by the estimate pay nothing.
                second_order = bound_in(scene, tilt, &times, t, mode);
                match second_order {
                    Some(b) if b.bound <= tolerance => None,
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
        return WholeChoice {
            level: Level::Incline,
            cheaper_fail: fails,
            rotation_estimate,
            second_order,
            friction_needed: needed,
            incline_mean_s: incline,
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

//! The incline's error from the bowl's rotation (docs/model.md §12): its mode as the bounds
//! have it ([`InclineMode`]), the a-priori estimate ([`rotation_estimate`], `K` per mode
//! fitted on a grid of scenes), and where that is above the tolerance, the rotation's second
//! order along the incline's path ([`second_order_bound`]): the bound on the plain incline's
//! error and on the incline corrected by it. The chooser ([`super::whole::choose_level`])
//! takes the incline where one of them is within the tolerance.

use crate::Real;
use crate::particle::rolling::RollingScene;

use super::incline::{Tilt, needed_at, needed_in};
use super::incline_rotation::{Orders, checked_sum};

/// The rotation's effect on the incline's mean `T`: at most
/// `K (|Omega|^2 + 2 w1^2) T_incline^2 ri / (R - ri)` (relative, [`rotation_estimate`]), where
/// `|Omega|` is the bowl's combined speed and `w1` the precession, which turns the downhill
/// direction under the granule while the bowl's spin carries it round (at a low tilt with
/// opposite speeds `|Omega|` is small but the precession is not: 7 % at 5 deg, w1 3.6, w2 -2.7
/// rad/s); `ri / (R - ri)` is the release's offset against its path (the rotation moves a
/// granule released near the rim most: 40-fold from `ri/R` 0.2 to 0.7 at one `(Omega T)^2`).
/// `K` by the incline's mode: this one where it rolls and keeps rolling to the rim (rolling
/// needs at most 0.95 `mu_s` there,
/// [`friction_needed_at_rim`](super::incline::friction_needed_at_rim)); 0.0108 (rounded up) is
/// the largest ratio of the incline's error (against the rolling-or-sliding disc) to the form over
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
/// [`ROTATION_K`]; and for a sliding one, the least friction rolling would need at the rim may
/// come down to `mu_s` over this and still count as sliding all the way ([`may_stick`]).
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
    estimate_of(
        scene,
        form_in(scene, tilt, incline_mean_s),
        incline_mean_s,
        mode,
    )
}

/// [`rotation_estimate`] from the rotation's form `f` ([`rotation_form`]) and the incline's
/// mode (the chooser computes `f` once for the estimate and the second order's bound).
pub(crate) fn estimate_of<T: Real>(
    scene: &RollingScene<T>,
    f: T,
    incline_mean_s: T,
    mode: InclineMode,
) -> T {
    // Without a rod offset its term is zero (or, where the path or a speed gives no number,
    // the form's infinity or NaN too): not computed, a division off the chooser's path.
    let rod = if scene.rod_length_m == T::ZERO {
        T::ZERO
    } else {
        T::from_f64(ROTATION_K_ROD) * rod_form(scene, incline_mean_s)
    };
    let estimate = mode_constant::<T>(mode) * f + rod;
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
    /// `mu_s` there, [`friction_needed_at_rim`](super::incline::friction_needed_at_rim)).
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

pub(crate) fn mode_in<T: Real>(scene: &RollingScene<T>, tilt: Tilt<T>) -> InclineMode {
    let mu_s = scene.sliding_friction;
    let near = T::from_f64(NEAR_SLIDING) * mu_s;
    let at_rest = needed_in(scene, tilt.sin, tilt.cos);
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

/// [`SECOND_ORDER_K4`] where the incline slides ([`InclineMode::Slides`], with the sliding
/// incline's own second order, whose `c2` is the disc's to 2.4e-4 on the 138 sliding scenes of
/// the grids): 2.05e-3 on the fitting grid, rounded up.
pub const SECOND_ORDER_K4_SLIDING: f64 = 0.0021;

/// `K4` of the corrected incline's bound `K4 F^2` (its mean `T (1 + c2)`, [`SecondOrder`]) where
/// the incline rolls to the rim: the least that covers the corrected incline's error per unit
/// of `F^2` over those scenes of the fitting grid (`c2` the closed form's, the error against
/// the rolling-or-sliding disc): 1.97e-3, rounded up (docs/model.md §12, `lab`
/// `whole::rotation_orders`, which fits it and asserts this covers it).
pub const CORRECTED_K4: f64 = 0.002;

/// [`CORRECTED_K4`] where the incline slides: 2.01e-3 on the fitting grid, rounded up.
pub const CORRECTED_K4_SLIDING: f64 = 0.0021;

/// [`CORRECTED_K4`] where only the rotation brings the granule near the stick threshold at the
/// rim: 7.31e-3 on the fitting grid, rounded up.
pub const CORRECTED_K4_NEAR_RIM: f64 = 0.0074;

/// The rotation's second order along the incline's path (rolling or sliding), and the bounds it
/// gives the incline's error, plain and corrected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SecondOrder<T> {
    /// `c2`: the rotation's second-order change of the incline's mean `T` (relative,
    /// [`mean_second_order_from`](super::incline_rotation::mean_second_order_from); the first
    /// order is zero in the mean).
    pub c2: T,
    /// The bound on the plain incline's error: `|c2| + K4 F^2`.
    pub bound: T,
    /// The bound on the corrected incline's error (its mean `T (1 + c2)`): `K4c F^2`, the
    /// remainder beyond the second order ([`CORRECTED_K4`]).
    pub corrected_bound: T,
    /// The chooser took the incline with its mean corrected (`T (1 + c2)`): the plain
    /// incline's bound is above the tolerance, the corrected one's within.
    pub corrected: bool,
}

/// The bound [`SecondOrder`] on the plain incline's relative error in the mean `T`, where the
/// incline rolls ([`InclineMode::Rolls`] or [`InclineMode::NearAtRim`]) or slides
/// ([`InclineMode::Slides`]) and the bowl turns on its own axis (no rod offset); `None`
/// elsewhere (near the threshold at rest `T` is not smooth in the speeds).
/// `times` are the incline's at [`AZIMUTHS_DEG`](crate::particle::rolling::AZIMUTHS_DEG) ([`incline_times_s`](super::incline::incline_times_s)).
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
    let sum = checked_sum(times)?;
    let f = form_in(scene, tilt, incline_mean_s);
    bound_of(scene, tilt, (times, sum), f, mode)
}

/// [`second_order_bound`] from the incline's times (finite and positive, as the incline gives
/// them) and their sum, and the rotation's form `f` ([`rotation_form`]): what the chooser
/// already holds, not computed again.
pub(crate) fn bound_of<T: Real>(
    scene: &RollingScene<T>,
    tilt: Tilt<T>,
    times_and_sum: (&[T; 12], T),
    f: T,
    mode: InclineMode,
) -> Option<SecondOrder<T>> {
    Prepared::new(scene, tilt, mode)?.bound(times_and_sum, f)
}

/// A guess, before the incline is computed, at whether the a-priori estimate will refuse it
/// (so the chooser prepares the second order early only where it will likely be needed): the
/// estimate at `T^2 = 2 R / A`, `A` the incline's drive in its mode, as products (no
/// division). Only the chooser's speed depends on it, never a choice or a number.
pub(crate) fn likely_refused<T: Real>(
    scene: &RollingScene<T>,
    tilt: Tilt<T>,
    mode: InclineMode,
    tolerance: T,
) -> bool {
    let g = scene.g_m_s2;
    let drive = if mode == InclineMode::Slides {
        g * (tilt.sin - scene.sliding_friction * tilt.cos)
    } else {
        scene.k2 * g * (tilt.sin - scene.rolling_resistance * tilt.cos)
    };
    let (ri, rim, w1) = (scene.ri_m.abs(), scene.rim_radius_m, scene.precession_rad_s);
    let path = rim - ri;
    let rotation = mode_constant::<T>(mode) * (tilt.combined_speed_sq(scene) + T::TWO * w1 * w1);
    let rod = T::from_f64(ROTATION_K_ROD) * w1 * w1 * scene.rod_length_m;
    T::TWO * rim * ri * (rotation * path + rod) > tolerance * drive * path * path
}

/// The scene's part of [`second_order_bound`]: its constants `K4` by the mode, and the orders
/// along the incline's path, which need neither the incline's times nor its mean (the chooser
/// builds it before its incline pass, so the two overlap in the processor).
pub(crate) struct Prepared<T> {
    orders: Orders<T>,
    k4: f64,
    k4c: f64,
}

impl<T: Real> Prepared<T> {
    /// `None` where the incline has no second order bound: near the stick threshold at rest,
    /// a sliding granule that may stick, a rod offset, or no orders at all.
    pub(crate) fn new(scene: &RollingScene<T>, tilt: Tilt<T>, mode: InclineMode) -> Option<Self> {
        let (k4, k4c) = match mode {
            InclineMode::Rolls => (SECOND_ORDER_K4, CORRECTED_K4),
            InclineMode::NearAtRim => (SECOND_ORDER_K4_NEAR_RIM, CORRECTED_K4_NEAR_RIM),
            // A sliding granule the rotation may bring to stick rolls for part of its path:
            // `T` is not smooth in the speeds there either.
            InclineMode::Slides if may_stick_in(scene, tilt) => return None,
            InclineMode::Slides => (SECOND_ORDER_K4_SLIDING, CORRECTED_K4_SLIDING),
            InclineMode::NearAtRest => return None,
        };
        if scene.rod_length_m != T::ZERO {
            return None;
        }
        let orders = Orders::of_mode(scene, tilt, mode == InclineMode::Slides)?;
        Some(Prepared { orders, k4, k4c })
    }

    /// The bounds from the incline's times and their sum, and the rotation's form `f`.
    pub(crate) fn bound(&self, (times, sum): (&[T; 12], T), f: T) -> Option<SecondOrder<T>> {
        let c2 = self.orders.relative(times, sum)?;
        let bound = c2.abs() + T::from_f64(self.k4) * f * f;
        let corrected_bound = T::from_f64(self.k4c) * f * f;
        (bound.is_finite() && corrected_bound.is_finite()).then_some(SecondOrder {
            c2,
            bound,
            corrected_bound,
            corrected: false,
        })
    }
}

/// Whether a granule the incline slides may come to stick on its way out: the least friction
/// rolling would need at the bottom's rim, the centrifugal push `omega^2 R` against gravity's
/// in-plane part, `(1 - k2) (g sin th - omega^2 R) / (g cos th)`, is below `mu_s /`
/// [`NEAR_SLIDING`]. Where it is, the granule may roll for part of its path and the sliding
/// incline's second order does not hold (docs/model.md §12, "The sliding incline's second
/// order"): on the 129 sliding scenes of the grids every one whose releases rolled for part of
/// the way has it below `mu_s` (0.06-0.96 of it), none above.
pub fn may_stick<T: Real>(scene: &RollingScene<T>) -> bool {
    may_stick_in(scene, Tilt::of(scene))
}

fn may_stick_in<T: Real>(scene: &RollingScene<T>, tilt: Tilt<T>) -> bool {
    // `needed_at` at `-R` puts the centrifugal push against gravity (an overflowing speed
    // gives minus infinity: may stick).
    needed_at(scene, tilt, -scene.rim_radius_m) * T::from_f64(NEAR_SLIDING) < scene.sliding_friction
}

/// [`rotation_estimate`] without its constant: `(|Omega|^2 + 2 w1^2) T^2 ri / (R - ri)`.
pub fn rotation_form<T: Real>(scene: &RollingScene<T>, incline_mean_s: T) -> T {
    form_in(scene, Tilt::of(scene), incline_mean_s)
}

pub(crate) fn form_in<T: Real>(scene: &RollingScene<T>, tilt: Tilt<T>, incline_mean_s: T) -> T {
    let w_sq = tilt.combined_speed_sq(scene);
    let w1 = scene.precession_rad_s;
    let path = scene.rim_radius_m - scene.ri_m;
    // Also catches a NaN path.
    if path.is_nan() || path <= T::ZERO {
        return T::from_f64(f64::INFINITY);
    }
    let offset = scene.ri_m.abs() / path;
    (w_sq + T::TWO * w1 * w1) * incline_mean_s * incline_mean_s * offset
}

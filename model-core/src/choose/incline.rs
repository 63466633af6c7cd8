//! The fixed incline (the chooser's cheapest level, [`Level::Incline`](super::whole::Level)):
//! the granule goes straight down the tilted bottom from its release, rolling at
//! `k2 g (sin th - mu_r cos th)` or, where rolling would need more friction than the contact
//! gives, sliding at `g (sin th - mu_s cos th)` (docs/model.md §12); the bowl's rotation left
//! out. Closed form per release ([`incline_residence_s`], the path's length against the
//! constant drive); the friction rolling needs on it, at release and at the rim.

use crate::Real;
use crate::particle::rolling::{AZIMUTHS_DEG, RollingScene, incline_residence_s};

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

pub(crate) fn mean_of<T: Real>(times: &[T; 12]) -> T {
    mean_from_sum(sum_of(times))
}

/// The mean over [`AZIMUTHS_DEG`] of times whose sum is `sum`.
pub(crate) fn mean_from_sum<T: Real>(sum: T) -> T {
    sum / T::from_f64(AZIMUTHS_DEG.len() as f64)
}

pub(crate) fn sum_of<T: Real>(times: &[T; 12]) -> T {
    let mut sum = T::ZERO;
    for &t in times {
        sum += t;
    }
    sum
}

/// The friction rolling down the incline needs, as a fraction of the normal force:
/// `(1 - k2) tan th` (resistance aside, as the slide test of §10).
pub fn incline_friction_needed<T: Real>(scene: &RollingScene<T>) -> T {
    let th = scene.axes_angle_rad;
    needed_in(scene, th.sin(), th.cos())
}

/// [`incline_friction_needed`] with the tilt's sine `s` and cosine `c` already computed.
pub(crate) fn needed_in<T: Real>(scene: &RollingScene<T>, s: T, c: T) -> T {
    (T::ONE - scene.k2) * s / c
}

/// Whether the incline slides (rolling needs more than `mu_s`, [`incline_friction_needed`]).
pub(crate) fn slides_in<T: Real>(scene: &RollingScene<T>, s: T, c: T) -> bool {
    needed_in(scene, s, c) > scene.sliding_friction
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
pub(crate) struct Tilt<T> {
    pub(crate) sin: T,
    pub(crate) cos: T,
}

impl<T: Real> Tilt<T> {
    pub(crate) fn of(scene: &RollingScene<T>) -> Self {
        let th = scene.axes_angle_rad;
        Tilt {
            sin: th.sin(),
            cos: th.cos(),
        }
    }

    /// [`RollingScene::combined_speed_rad_s`] squared (every check needs only the square: no
    /// square root).
    pub(crate) fn combined_speed_sq(self, scene: &RollingScene<T>) -> T {
        let (w1, w2) = (scene.precession_rad_s, scene.spin_rad_s);
        (w1 * w1 + w2 * w2 + T::TWO * w1 * w2 * self.cos).max(T::ZERO)
    }
}

/// [`friction_needed_at_release`] for a release at `radius_m`.
pub(crate) fn needed_at<T: Real>(scene: &RollingScene<T>, tilt: Tilt<T>, radius_m: T) -> T {
    let w_sq = tilt.combined_speed_sq(scene);
    let g = scene.g_m_s2;
    let in_plane = g * tilt.sin + w_sq * radius_m;
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

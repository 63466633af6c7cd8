//! The equations of motion of a sphere *sliding* on the flat bottom of the tilted, precessing
//! bowl, in the bowl's frame (docs/model.md §10). The paper (Eq. 1, 3 to 5) has the granule roll
//! and lets the measured sliding coefficient 0.4 act as a rolling resistance; at the rig's 60 deg
//! tilt rolling needs more friction than 0.4 of the normal force, so the contact slips: Coulomb
//! friction `mu_s N` acts against the slip velocity of the contact point and its torque drives
//! the spin, which is then a free state (three components) instead of following the rolling
//! constraint.
//!
//! Frame, `Omega`, `alpha`, `gB`, `A_O`, `p`, `C`, `E` and `N` as in [`super::equations`]. State
//! `[x, y, ux, uy, sx, sy, sz]`: the contact point, the centre's velocity relative to the bowl,
//! and `s = a w` with `w` the sphere's angular velocity relative to the bowl (m/s, so that the
//! granule's radius `a` drops out as it does when rolling).
//!
//! ```text
//! v_c   = u - s x n = (ux - sy, uy + sx)                 slip of the contact point on the bowl
//! f/m   = -mu_s (N/m) v_c/|v_c|                           Coulomb, against the slip
//! du/dt = (gB - A_O - E - C - 2 Omega x u)_xy + f/m       Newton in the rotating frame
//! ds/dt = -(k2/(1 - k2)) n x f/m - a alpha - Omega x s    Euler: I dw_abs/dt = -a n x f,
//!                                                          dw_abs/dt = dw/dt + alpha + Omega x w
//! ```
//!
//! `m a^2 / I = k2 / (1 - k2)` turns the torque into the spin's rate. Rolling is the special
//! case `v_c = 0` with `f` the friction [`super::equations::forces`] says rolling needs; a test
//! holds the two sets of equations to each other there. A change of the friction by `df`
//! changes `dv_c/dt` by `df / (m (1 - k2))` in every direction, so a granule whose rolling
//! needs more than `mu_s N` slips against that needed friction, and a slip that reaches zero
//! stays rolling exactly when rolling then needs no more than `mu_s N` (`super::modes`).

use super::RollingScene;
use super::equations::{AT_REST_M_S, at_contact, cross};
use crate::Real;

/// The sliding state: `[x, y, ux, uy, sx, sy, sz]`, m and m/s.
pub type SlideState<T> = [T; 7];

/// Everything the sliding equations give at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlideForces<T> {
    /// The state's time derivative.
    pub derivative: SlideState<T>,
    /// Normal force per unit mass, m/s^2 (the granule lifts off where it is <= 0).
    pub normal_m_s2: T,
    /// The contact point's slip velocity relative to the bowl, m/s.
    pub slip_m_s: [T; 2],
}

/// The slip velocity of a sliding state, m/s.
pub fn slip_m_s<T: Real>(y: &SlideState<T>) -> [T; 2] {
    [y[2] - y[5], y[3] + y[4]]
}

/// The right-hand side of the sliding granule at `(t, y)`. `slip_dir` is the unit direction the
/// slip had at the last accepted step (or, at the start of a slide, the direction it starts
/// in): the friction acts against it wherever the slip is below [`AT_REST_M_S`] or has turned
/// against it, so the right-hand side stays continuous through the step in which the slip
/// reaches zero, and the integrator's interpolant locates that instant (`super::modes`).
pub fn slide_forces<T: Real>(
    s: &RollingScene<T>,
    t: T,
    y: &SlideState<T>,
    slip_dir: [T; 2],
) -> SlideForces<T> {
    slide_forces_slaved(s, t, y, slip_dir, T::ZERO)
}

/// [`slide_forces`] whose friction, while the slip is at most `slaved_m_s` and grows (the
/// friction cannot hold it), opposes the slip's free acceleration `A` rather than the slip
/// itself ([`friction_direction`]); `slaved_m_s` at most [`AT_REST_M_S`] is [`slide_forces`].
pub(crate) fn slide_forces_slaved<T: Real>(
    s: &RollingScene<T>,
    t: T,
    y: &SlideState<T>,
    slip_dir: [T; 2],
    slaved_m_s: T,
) -> SlideForces<T> {
    let [x, yy, ux, uy, sx, sy, sz] = *y;
    // The same normal force as rolling (docs/model.md §9): it does not depend on the spin.
    let (f, c, e, normal) = at_contact(s, t, [x, yy], [ux, uy]);
    let o = f.omega;
    let a = s.particle_radius_m;
    let slip = slip_m_s(y);
    let fric = s.sliding_friction * normal.max(T::ZERO);
    let ou = cross(&o, &[ux, uy, T::ZERO]);
    let os = cross(&o, &[sx, sy, sz]);
    // Without friction.
    let free_u = [
        f.gravity[0] - f.carrier[0] - e[0] - c[0] - T::TWO * ou[0],
        f.gravity[1] - f.carrier[1] - e[1] - c[1] - T::TWO * ou[1],
    ];
    let free_s = [-a * f.alpha[0] - os[0], -a * f.alpha[1] - os[1]];
    let dir = friction_direction(
        s.k2,
        slip,
        [free_u[0] - free_s[1], free_u[1] + free_s[0]],
        fric,
        slip_dir,
        slaved_m_s,
    );
    let fm = [-fric * dir[0], -fric * dir[1]];
    let dux = free_u[0] + fm[0];
    let duy = free_u[1] + fm[1];
    // ds/dt = -(k2/(1-k2)) n x f/m - a alpha - Omega x s, with n x f = (-fy, fx, 0).
    let ratio = s.k2 / (T::ONE - s.k2);
    let dsx = ratio * fm[1] - a * f.alpha[0] - os[0];
    let dsy = -ratio * fm[0] - a * f.alpha[1] - os[1];
    let dsz = -a * f.alpha[2] - os[2];
    SlideForces {
        derivative: [ux, uy, dux, duy, dsx, dsy, dsz],
        normal_m_s2: normal,
        slip_m_s: slip,
    }
}

/// The direction the friction opposes in a slide with the slip `slip` (`free`: the slip's
/// acceleration `A` without friction; `fric` = `mu_s N`; `last`: the slide's direction at its
/// last accepted step):
///
/// * a slip at rest (at most [`AT_REST_M_S`]): [`at_rest_direction`];
/// * a slip at most `slaved_m_s` that the friction cannot hold (`(1 - k2) |A| > mu_s N`) and
///   that goes along `A`: `A`'s direction. Such a slip turns to `A` within `|slip| / |A|`
///   seconds, so it is `A`'s direction but for a lag of `|slip|` times `A`'s turning rate over
///   `|A|`; opposing the slip itself there makes the slide stiff as `mu_s N / |slip|` (the
///   slip's direction relaxes at that rate), and DP5(4) then creeps at its stability limit,
///   steps of about `|slip| / (mu_s g)`, a step count that grows as the inverse of the time
///   since the slide began and was erratic in the tolerance (a roll giving way at the stick
///   threshold, 30 deg, 3.6 rad/s, mu_s 0.2: 2 400-3 900 steps for one release at every rtol
///   from 1e-6 to 1e-10, more at 1e-6 than at 1e-7; docs/model.md §12). The run passes
///   `slaved_m_s` = its absolute tolerance on the velocities: a slip below it is one the
///   integrator does not resolve, and the friction's direction moves the velocities by no more
///   than that slip;
/// * otherwise the slip's own direction, or `last` where the slip has turned against it.
pub(crate) fn friction_direction<T: Real, const N: usize>(
    k2: T,
    slip: [T; N],
    free: [T; N],
    fric: T,
    last: [T; N],
    slaved_m_s: T,
) -> [T; N] {
    let dot = |a: &[T; N], b: &[T; N]| a.iter().zip(b).fold(T::ZERO, |acc, (x, y)| acc + *x * *y);
    let speed = dot(&slip, &slip).sqrt();
    if speed <= T::from_f64(AT_REST_M_S) {
        return at_rest_direction(k2, free, fric, last);
    }
    if speed <= slaved_m_s && dot(&slip, &free) > T::ZERO {
        let a = dot(&free, &free).sqrt();
        if (T::ONE - k2) * a > fric {
            return core::array::from_fn(|i| free[i] / a);
        }
    }
    if dot(&slip, &last) > T::ZERO {
        core::array::from_fn(|i| slip[i] / speed)
    } else {
        last
    }
}

/// How near `A`'s direction must be to the slide's last one (the cosine of the angle between
/// them) for [`at_rest_direction`] to keep the last: about 0.003 deg.
pub(crate) const AT_REST_ALONG: f64 = 0.999_999_999;

/// The direction a slip at rest (below [`AT_REST_M_S`]) takes for the friction: where the
/// friction cannot hold it (`(1 - k2) |A| > mu_s N`, `A` the slip's acceleration without
/// friction, `fric` = `mu_s N`) the slip grows along `A`, and the friction opposes that, turning
/// with `A`; else the slide's last direction `last` (the slip then turns against it and the
/// slide ends). Held to the last direction where `A` had turned away from it, a slip at the
/// stick threshold grew across it, out of rest, and the friction swung to oppose it, back in:
/// the slip hovered at the rest threshold, in and out at every step of 1e-9 to 1e-11 s, the
/// right-hand side switching between the two directions, for the 4 ms its real growth
/// (rolling's need 1.5e-5 above `mu_s N`) would take, past the step cap (a sharp 54 deg corner
/// at 10 deg tilt, -0.54 and -0.43 rad/s, mu_s 0.052, docs/model.md §10). Where `A` is still
/// along `last` (within [`AT_REST_ALONG`]) the last direction is kept: a slide from rest grows
/// its slip along it, and switching the friction to `A`'s direction each time the slip dips
/// into rest only made DP5(4) reject steps (the cost grid's sticking releases at 60 deg,
/// 3.6 rad/s, mu_s 0.4 took 32 000 evaluations at rtol 1e-6 for 21 500; docs/model.md §12).
pub(crate) fn at_rest_direction<T: Real, const N: usize>(
    k2: T,
    free: [T; N],
    fric: T,
    last: [T; N],
) -> [T; N] {
    let a = free.iter().fold(T::ZERO, |acc, v| acc + *v * *v).sqrt();
    let along = free
        .iter()
        .zip(&last)
        .fold(T::ZERO, |acc, (f, l)| acc + *f * *l);
    let last_size = last.iter().fold(T::ZERO, |acc, v| acc + *v * *v).sqrt();
    if along > T::from_f64(AT_REST_ALONG) * a * last_size {
        last
    } else if (T::ONE - k2) * a > fric && a > T::ZERO {
        core::array::from_fn(|i| free[i] / a)
    } else {
        last
    }
}

/// A rolling state `[x, y, ux, uy, sig]` as a sliding one: rolling means no slip, so
/// `s x n = u`, i.e. `sx = -uy`, `sy = ux`, and the spin about the axis is `sig`.
pub fn from_rolling<T: Real>(y: &[T; 5]) -> SlideState<T> {
    [y[0], y[1], y[2], y[3], -y[3], y[2], y[4]]
}

/// A sliding state whose slip has reached zero as a rolling one.
pub fn to_rolling<T: Real>(y: &SlideState<T>) -> [T; 5] {
    [y[0], y[1], y[2], y[3], y[6]]
}

/// The friction per unit mass a granule without slip at `(t, y)` needs to keep from slipping,
/// m/s^2, and the normal force per unit mass: `-(1 - k2) A` with `A` the slip's acceleration
/// when no friction acts (`dv_c/dt = A + f / (m (1 - k2))`). Without rolling resistance this
/// is the rolling model's `f_t`; with it, it leaves out the resistance, which the sliding
/// contact does not have, so that a slide starts exactly where these equations make the slip
/// grow, along `A`.
pub fn needed_friction_m_s2<T: Real>(s: &RollingScene<T>, t: T, y: &SlideState<T>) -> ([T; 2], T) {
    let free = RollingScene {
        sliding_friction: T::ZERO,
        ..*s
    };
    let f = slide_forces(&free, t, y, [T::ZERO, T::ZERO]);
    let d = f.derivative;
    let scale = -(T::ONE - s.k2);
    (
        [scale * (d[2] - d[5]), scale * (d[3] + d[4])],
        f.normal_m_s2,
    )
}

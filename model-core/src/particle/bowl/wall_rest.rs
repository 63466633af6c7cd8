//! A rolling granule that comes to rest on the fillet or the wall and is held there by the
//! rolling resistance (docs/model.md §10), as on the bottom ([`crate::particle::rolling::rest`],
//! whose pieces this uses): the rest is an event of the roll (its velocity turned against its
//! direction at the last accepted step, `super::wall::wall_forces_slaved`), the hold a segment
//! of its own, ended where the first of these reaches zero:
//!
//! * the drive exceeds what the resistance holds, `|D| - mu_r N/m` (`k2 D` the acceleration
//!   along the surface at rest without resistance, [`super::wall::WallForces::drive_m_s2`]):
//!   the roll restarts from rest, a stretch of its own
//!   ([`crate::particle::rolling::rest::start_speed_m_s`]);
//! * the friction rolling needs (without resistance, the wall's roll/slide test,
//!   `super::wall_run`) reaches `mu_s N`: it slides. Not the friction that holds it at rest
//!   (`-b_t`, `1 / (1 - k2)` times larger on an incline): where `mu_s < mu_r` that one exceeds
//!   `mu_s N` while rolling's does not, the hold ended in a slide that the roll/slide test ended
//!   at once, the roll came to rest again at the same instant, without end (55 releases of the
//!   corner sweep at the stick threshold given up);
//! * the normal force reaches zero: it flies.
//!
//! Held, the centre and its tangential spin stay put; the contact gives exactly the force that
//! keeps it there. The spin about the normal is not held by anything (the model has no drilling
//! friction), so the spin in space about it is kept: relative to the bowl it follows the bowl's
//! turn, `s . n = (s . n)_0 - a (Omega(t) - Omega(t0)) . n`, which the drive feels through
//! `Omega x s`.

use super::wall::{Contact, Meridian, WallState, to_space, wall_forces};
use crate::Real;
use crate::particle::rolling::RollingScene;
use crate::particle::rolling::equations::{dot, frame};
use crate::particle::rolling::modes::fired;
use crate::particle::rolling::rest::{hold_while, start_speed_m_s};

/// Why a hold on the wall ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Let {
    /// The drive exceeds the resistance: it rolls on from rest.
    Rolls,
    /// The friction that holds it reached `mu_s N`: it slides.
    Slides,
    /// The normal force reached zero: it flies.
    LiftsOff,
}

/// How a hold on the wall ended: when, in what state and why (`None`: held at the horizon),
/// and the right-hand sides it evaluated.
pub(super) struct WallHold<T> {
    pub(super) end: Option<(T, WallState<T>, Let)>,
    pub(super) evaluations: u32,
}

/// The surface's unit normal (towards the centre) at a wall state.
fn normal<T: Real>(m: &Meridian<T>, y: &WallState<T>) -> [T; 3] {
    let en = (y[1] * y[1] + y[2] * y[2]).sqrt().max(T::EPSILON);
    let [rp, zp] = m.at(y[0]).tangent;
    [-zp * y[1] / en, -zp * y[2] / en, rp]
}

/// `y` at rest: no velocity, and of the spin only its part about the normal (no slip).
fn at_rest<T: Real>(m: &Meridian<T>, y: &WallState<T>) -> WallState<T> {
    let n = normal(m, y);
    let along = y[5] * n[0] + y[6] * n[1] + y[7] * n[2];
    [
        y[0],
        y[1],
        y[2],
        T::ZERO,
        T::ZERO,
        along * n[0],
        along * n[1],
        along * n[2],
    ]
}

/// The wall state at `t` as the granule at rest, if it is at rest (its speed within
/// [`start_speed_m_s`], as on the bottom) and the rolling resistance holds it there.
pub(super) fn held_at<T: Real>(
    sc: &RollingScene<T>,
    m: &Meridian<T>,
    t: T,
    y: &WallState<T>,
) -> Option<WallState<T>> {
    let u = to_space(m, y)[1];
    let rest = at_rest(m, y);
    (dot(&u, &u).sqrt() <= start_speed_m_s(sc) && margins(sc, m, t, &rest, T::ONE)[0] <= T::ZERO)
        .then_some(rest)
}

/// At a state at rest: `|D| - mu_r N/m`, `|f| - mu_s N/m` of the friction `f` rolling needs
/// (the module's note), and `-N/m`, each over `reference` (m/s^2).
fn margins<T: Real>(
    sc: &RollingScene<T>,
    m: &Meridian<T>,
    t: T,
    rest: &WallState<T>,
    reference: T,
) -> [T; 3] {
    let f = wall_forces(sc, m, t, rest, Contact::Roll);
    let n = f.normal_m_s2.max(T::ZERO);
    let (d, need) = (f.drive_m_s2, f.needed_m_s2);
    [
        (dot(&d, &d).sqrt() / sc.k2 - sc.rolling_resistance * n) / reference,
        (dot(&need, &need).sqrt() - sc.sliding_friction * n) / reference,
        -f.normal_m_s2 / reference,
    ]
}

/// The granule held at `rest` from `t0`: the state at `t`, its spin about the normal following
/// the bowl's turn (the module's note).
fn held_state<T: Real>(
    sc: &RollingScene<T>,
    m: &Meridian<T>,
    (t0, rest): (T, &WallState<T>),
    t: T,
) -> WallState<T> {
    let n = normal(m, rest);
    let (o0, o) = (frame(sc, t0).omega, frame(sc, t).omega);
    let turn: [T; 3] = core::array::from_fn(|i| o[i] - o0[i]);
    let along =
        rest[5] * n[0] + rest[6] * n[1] + rest[7] * n[2] - sc.particle_radius_m * dot(&turn, &n);
    let mut y = *rest;
    for i in 0..3 {
        y[5 + i] = along * n[i];
    }
    y
}

/// The granule held at `rest` (from [`held_at`]) from `t0` until the first of the module's
/// three ends, located to rounding between the samples of
/// [`crate::particle::rolling::rest::hold_while`], or the horizon; `reference` makes the
/// margins dimensionless (m/s^2).
pub(super) fn hold<T: Real>(
    sc: &RollingScene<T>,
    m: &Meridian<T>,
    t0: T,
    rest: &WallState<T>,
    horizon_s: T,
    reference: T,
) -> WallHold<T> {
    let at = |t: T| margins(sc, m, t, &held_state(sc, m, (t0, rest), t), reference);
    let held = hold_while(sc, t0, horizon_s, |t| {
        let e = at(t);
        e[0].max(e[1]).max(e[2])
    });
    let end = held.t.map(|te| {
        let why = match fired(&at(te)) {
            0 => Let::Rolls,
            1 => Let::Slides,
            _ => Let::LiftsOff,
        };
        (te, held_state(sc, m, (t0, rest), te), why)
    });
    WallHold {
        end,
        evaluations: held.evaluations.saturating_add(u32::from(end.is_some())),
    }
}

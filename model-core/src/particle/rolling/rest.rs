//! A rolling granule that comes to rest and is held there by the rolling resistance
//! (docs/model.md §9): its own segment of a run, between two located events, so that no step
//! straddles the switch of the equations at rest (issue 30).
//!
//! * roll -> held where the velocity relative to the bowl turns against its direction at the
//!   last accepted step ([`rest_event`]; the resistance holds that direction once the velocity
//!   is at rest or reversed, [`super::equations::forces_along`], so the crossing is smooth and
//!   located on the step's interpolant) and the resistance can hold the granule there
//!   (`|D| <= mu_r N/m`): the velocity is then zero exactly;
//! * held -> roll where `|D| - mu_r N/m` ([`rest_margin_m_s2`]) reaches zero from below: the
//!   roll restarts from rest along `D/|D|`. While held nothing of the state moves (the position
//!   is fixed in the bowl and the spin's rate `-(Ox ux + Oy uy)` is zero); only the forces
//!   change with time, so the segment is sampled in time ([`HOLD_STEPS`]) and the crossing
//!   located between two samples.

use core::cell::Cell;

use super::RollingScene;
use super::equations::{AT_REST_M_S, State, dot, rest_margin_m_s2};
use crate::Real;
use crate::ode::event::locate;

/// Samples of a held segment per unit of the scene's time scale `1 / max(|Omega|, 1 rad/s)`:
/// the forces on a granule at rest change with the bowl's turn, by about a radian per time
/// scale, so the margin is sampled every 1/16 rad of it.
pub const HOLD_STEPS: f64 = 16.0;

/// The roll -> held event of a roll whose velocity `u` had the direction `last` at the last
/// accepted step: `-(u . last)`, zero where the velocity stops or turns across `last` (and
/// linear in `u`: its slope along a step is that of the step's velocity change).
/// (On the wall, `bowl::wall_run`, the same of the centre's velocity in space.)
pub(crate) fn turned<T: Real, const N: usize>(u: [T; N], last: [T; N]) -> T {
    -dot(&u, &last)
}

/// After an accepted step of a roll whose velocity is `u`: the direction `last` follows the
/// velocity while it still goes along it (the velocity at rest or reversed is the event).
pub(crate) fn follow_velocity<T: Real, const N: usize>(u: [T; N], last: &Cell<[T; N]>) {
    let speed = dot(&u, &u).sqrt();
    if speed > T::from_f64(AT_REST_M_S) && dot(&u, &last.get()) > T::ZERO {
        last.set(u.map(|c| c / speed));
    }
}

/// The speed, in units of the scene's (its radius times `max(|Omega|, 1 rad/s)`), below which
/// a roll's velocity at its rest event is a rest: at a located rest only the integration's
/// error is left of it (at most `rtol` of that scale), while a velocity that turned by more
/// than a right angle within one step keeps its size.
pub const REST_SPEED: f64 = 1e-4;

/// The speed, m/s ([`REST_SPEED`] of the scene's), up to which a roll that restarts from a hold
/// is a stretch of its own, its velocity held to `rtol` of this speed instead of the scene's.
/// It restarts where `|D| - mu_r N/m` crosses zero, so its speed grows only as the square of
/// the time since, and a velocity error `du` shifts the whole run by `du / (du/dt)`: large
/// while `du/dt` is still near zero. There the resistance's direction `u/|u|` is stiff (its
/// rate `k2 mu_r (N/m) / |u|`); at the scene's tolerance (`rtol` of its speed, far above the
/// speed itself) the steps ran at that stiffness's limit, the direction wobbled by tens of
/// degrees, the drive along the velocity fell short of the resistance and the speed hovered at
/// [`AT_REST_M_S`] for 0.3 ms, then fired a rest event of its own: a release held on the way
/// was 3.3e-5 s off at rtol 1e-8 (3.92 deg tilt, 0.971 and 3.206 rad/s, 150 deg; `rest_tests`).
/// Above this speed the wobble at the scene's tolerance is below `rtol / REST_SPEED` rad.
pub(crate) fn start_speed_m_s<T: Real>(scene: &RollingScene<T>) -> T {
    T::from_f64(REST_SPEED) * scene.rim_radius_m * scene.combined_speed_rad_s().max(T::ONE)
}

/// The speed, m/s ([`SLOW`] times [`start_speed_m_s`]), half of which a roll on the bottom
/// that has been above it slows to on its way to a rest: from there it goes on as a stretch of
/// its own, its velocity held to `rtol` of this speed (`rest_loop`), as a restart from a hold
/// does. Near its rest the resistance's direction `u/|u|` turns fast and the step that
/// reaches the rest at the scene's tolerance spans it: at rtol 1e-6 the velocity at the located
/// rest (where it turned across its direction at the last step) was 9e-5 m/s off, not held,
/// and the resistance took 4.7e-4 s more to stop it; the time held was that far off the run at
/// 1e-12 (470x rtol; 2 deg tilt, 0.3 and 3 rad/s, a 45 deg wall 15 mm high with a 5 mm fillet,
/// release 90 deg, issue 30). Now 5.9e-6 s, and within 4x rtol at 3e-7 to 1e-10.
pub(crate) fn slow_speed_m_s<T: Real>(scene: &RollingScene<T>) -> T {
    T::from_f64(SLOW) * start_speed_m_s(scene)
}

/// See [`slow_speed_m_s`]: 16 left the rtol 1e-6 run 7.7e-5 s off (the rest located in the
/// step before the speed fell to 8 times the start speed), 64 and 256 alike 6e-6 and 4e-6.
pub const SLOW: f64 = 64.0;

/// A roll's watch for slowing to its rest ([`slow_speed_m_s`]), in the roll's own units of
/// speed, shared by both runs that roll (`rest_loop`): a roll at the scene's tolerances (not a
/// stretch) is armed once its speed is above the slow speed (at its start or after an
/// accepted step), and from then its event `slow/2 - |u|` ends it where it slows to half that.
pub(crate) struct Slowing<T> {
    slow: T,
    /// A stretch of its own already (`start`): it does not end so.
    watched: bool,
    armed: Cell<bool>,
}

impl<T: Real> Slowing<T> {
    /// For a roll that starts with velocity `u`; `slow`: [`slow_speed_m_s`] in the roll's
    /// units; `start`: the roll's stretch speed, if it is one.
    pub(crate) fn new(slow: T, start: Option<T>, u: [T; 2]) -> Self {
        let watched = start.is_none();
        let armed = Cell::new(watched && dot(&u, &u).sqrt() > slow);
        Self {
            slow,
            watched,
            armed,
        }
    }

    /// After an accepted step to velocity `u`.
    pub(crate) fn follow(&self, u: [T; 2]) {
        if self.watched && dot(&u, &u).sqrt() > self.slow {
            self.armed.set(true);
        }
    }

    /// The event at velocity `u`, once armed: `slow/2 - |u|`, zero where the roll slowed to
    /// half the slow speed.
    pub(crate) fn event(&self, u: [T; 2]) -> Option<T> {
        self.armed
            .get()
            .then(|| self.slow / T::TWO - dot(&u, &u).sqrt())
    }
}

/// A rolling state at `t` as the granule at rest, if it is at rest ([`REST_SPEED`]) and the
/// rolling resistance holds it there.
pub(crate) fn held_at<T: Real>(scene: &RollingScene<T>, t: T, y: &State<T>) -> Option<State<T>> {
    let speed = (y[2] * y[2] + y[3] * y[3]).sqrt();
    let rest = [y[0], y[1], T::ZERO, T::ZERO, y[4]];
    (speed <= start_speed_m_s(scene) && rest_margin_m_s2(scene, t, &rest) <= T::ZERO)
        .then_some(rest)
}

/// How a held segment ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct HoldEnd<T> {
    /// When it ended, s (`None`: still held at the horizon).
    pub(crate) t: Option<T>,
    /// Right-hand sides (forces) it evaluated.
    pub(crate) evaluations: u32,
}

/// The granule held at rest in `y` from `t0` until the first of `|D| - mu_r N/m` and the
/// caller's `other` event (dimensionless, negative while held; `super::modes`: rolling's need
/// of friction reaching `mu_s N`) reaches zero, located to rounding between samples
/// [`HOLD_STEPS`] apart, or the horizon.
pub(crate) fn hold<T: Real>(
    scene: &RollingScene<T>,
    t0: T,
    y: &State<T>,
    horizon_s: T,
    other: impl Fn(T) -> T,
) -> HoldEnd<T> {
    let reference = scene.g_m_s2 + T::ONE;
    hold_while(scene, t0, horizon_s, |t: T| {
        (rest_margin_m_s2(scene, t, y) / reference).max(other(t))
    })
}

/// A hold from `t0` until `event` (dimensionless, negative while the granule is held: on the
/// bottom [`hold`]'s, on the wall `bowl::wall_rest`'s) reaches zero, located to rounding
/// between samples [`HOLD_STEPS`] apart, or the horizon. In a bowl whose frame does not turn
/// (no spin: the frame turns with the precession about the vertical, which gravity is along;
/// or [`RollingScene::stationary`]) nothing of the forces changes, and one evaluation decides
/// the whole hold: sampled, a granule parked to a 20 s horizon cost 320 evaluations for
/// nothing.
pub(crate) fn hold_while<T: Real>(
    scene: &RollingScene<T>,
    t0: T,
    horizon_s: T,
    event: impl Fn(T) -> T,
) -> HoldEnd<T> {
    if (scene.spin_rad_s == T::ZERO || scene.stationary()) && event(t0) < T::ZERO {
        return HoldEnd {
            t: None,
            evaluations: 1,
        };
    }
    let h = T::ONE / (T::from_f64(HOLD_STEPS) * scene.combined_speed_rad_s().max(T::ONE));
    let mut evaluations = 0u32;
    let mut t = t0;
    while t < horizon_s {
        let t1 = (t + h).min(horizon_s);
        evaluations = evaluations.saturating_add(1);
        if event(t1) >= T::ZERO {
            let span = t1 - t;
            let count = Cell::new(0u32);
            let g = |th: T| {
                count.set(count.get() + 1);
                let e = T::EPSILON.sqrt();
                let slope =
                    (event(t + (th + e) * span) - event(t + (th - e) * span)) / (T::TWO * e);
                (event(t + th * span), slope)
            };
            let theta = locate(g, T::ZERO);
            evaluations = evaluations.saturating_add(count.get().saturating_mul(3));
            // The end where the margin has reached zero: never before it, so the roll that
            // follows starts where the drive can move the granule.
            let mut te = t + theta * span;
            for _ in 0..8 {
                if event(te) >= T::ZERO {
                    break;
                }
                te = (te + T::from_f64(4.0) * T::EPSILON * te.abs().max(span)).min(t1);
            }
            return HoldEnd {
                t: Some(te),
                evaluations,
            };
        }
        t = t1;
    }
    HoldEnd {
        t: None,
        evaluations,
    }
}

//! A slide's slip, shared by the bottom's run and the wall's (`bowl::wall_run`): where the slip
//! counts as ended ([`stuck_m_s`]), how the friction's direction follows it ([`follow_slip`]),
//! and the tolerance its error is held to ([`slip_error`]): near zero the slide's right-hand
//! side is stiff, and the components' own tolerances say nothing of the slip's direction.

use core::cell::Cell;
use core::ops::ControlFlow;

use crate::Real;
use crate::particle::rolling::equations::{AT_REST_M_S, dot};

/// The slip below which a slide has ended, in units of the scene's speed: a few roundings of
/// it, so that the end is located as exactly as the slip's zero itself (a slip that falls
/// linearly at `mu_s g / (1 - k2)` reaches this 1e-16 s before its zero).
pub(super) const STUCK: f64 = 64.0;

pub(crate) fn stuck_m_s<T: Real>(speed_ref: T) -> T {
    T::from_f64(STUCK) * T::EPSILON * speed_ref
}

/// After an accepted step of a slide with the slip `s` (`stuck`: [`stuck_m_s`]): arms the
/// slip-end event once the slip has been above twice `stuck`, and turns the friction's
/// direction `dir` to the slip's for the next step while it still goes along `dir` (the
/// friction opposes it).
pub(crate) fn follow_slip<T: Real, const N: usize>(
    s: &[T; N],
    dir: &Cell<[T; N]>,
    armed: &Cell<bool>,
    stuck: T,
) {
    let d = dir.get();
    let speed = dot(s, s).sqrt();
    if speed > T::TWO * stuck {
        armed.set(true);
    }
    if speed > T::from_f64(AT_REST_M_S) && dot(s, &d) > T::ZERO {
        dir.set(core::array::from_fn(|i| s[i] / speed));
    }
}

/// Why a segment's check after an accepted step stopped it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Stop {
    /// The steps no longer advance the time ([`super::StallWatch`]).
    Stalled,
    /// A slide's slip has come down to rest and stays there ([`Settle`]): the slide has ended.
    Settled,
    /// A roll restarted from a hold has reached its start speed
    /// (`crate::particle::rolling::rest::start_speed_m_s`): it goes on as any roll.
    Started,
    /// A slip leaving the slaved band lags its free acceleration's direction so far that the
    /// friction against it would shrink it back ([`lags_its_growth`]): the slide goes on from
    /// the slip turned to that direction.
    Realign,
}

/// Whether a slip `s` leaving the slaved band (above `band`, up to twice it; `run_from`'s
/// [`super::SLAVED`]) of a slide whose rolling needs more than `mu_s N` has fallen so far
/// behind the direction of its free acceleration `A` that the friction against it (`mu_s N /
/// (1 - k2)` along it) exceeds `A`'s part along it, so that it would shrink back into the band:
/// in the band the friction opposes `A` and the slip grows along `A` as `A` was, at the rate
/// by which rolling's need exceeds `mu_s N`, near the stick threshold so slowly that `A` turns
/// by more than `sqrt(2 (1 - mu_s N / ((1 - k2) |A|)))` rad before the slip leaves the band.
/// The real slip turns to `A` within `|s| / (|A| sin phi)`; so does this one, at once. `need`,
/// asked only for a slip leaving the band: `A` and `mu_s N` (m/s^2). The slip turned to `A`,
/// keeping its size, where it lags.
pub(crate) fn lags_its_growth<T: Real, const N: usize>(
    k2: T,
    s: &[T; N],
    band: T,
    need: impl FnOnce() -> ([T; N], T),
) -> Option<[T; N]> {
    let speed = dot(s, s).sqrt();
    if speed <= band || speed > T::TWO * band {
        return None;
    }
    let (free, fric) = need();
    let a = dot(&free, &free).sqrt();
    let one = T::ONE - k2;
    (one * a > fric && one * dot(&free, s) < fric * speed)
        .then(|| core::array::from_fn(|i| free[i] / a * speed))
}

/// How long a slide's slip must stay at rest ([`SETTLED_M_S`]) where rolling needs no more
/// than `mu_s N` to end the slide as settled ([`Settle`]): this many times the time the whole
/// friction takes to sweep the slip across that band, `SETTLED_M_S (1 - k2) / (mu_s N)` (the
/// slip answers a friction `f` at `f / (m (1 - k2))`). A slip falling straight to its zero
/// crosses the band in at most `K / (K - |A|)` such times (`K` the friction's deceleration of
/// it, `A` its acceleration without friction), so it reaches its zero, the slip-end event,
/// before it counts as settled unless `|A|` is within 1/8 of `K`; a slip that hovers in the
/// band stays there. Counted in accepted steps instead (8 of them), the rule depended on the
/// step: RK4's steps graded towards a stick (`graded_step`) are so short there that at
/// h = 16 and 8 us eight of them fell within the band before the stick, and the slide ended
/// early by a step-dependent amount (its relative error in the mean T on the lift-off scene of
/// the bowl's work-precision chart rose from 6.5e-12 at 31 us to 3.3e-10 and 8.8e-10, docs/model.md
/// §10).
pub(crate) const SETTLE_SWEEPS: f64 = 8.0;

/// The slip at and below which a slide's slip is at rest for [`Settle`], m/s: twice
/// [`AT_REST_M_S`], where the friction's direction stops following the slip.
pub(crate) const SETTLED_M_S: f64 = 2.0 * AT_REST_M_S;

/// Watches a slide for a slip at rest that stays there while the friction could hold it.
/// Below [`AT_REST_M_S`] the friction keeps its last direction instead of following the slip;
/// where the contact's free acceleration has a part across that direction (a granule in the
/// wall's corner, rolling's need near `mu_s N`) the slip then neither reverses along it (the
/// slip-end event) nor falls to the stuck threshold: it hovers at the rest threshold, in and
/// out of it at every step, the steps shrinking to 1e-11 s at the switch of the right-hand
/// side, until the step cap (a 77 deg sharp corner at 19 deg tilt, 1.6 and -0.73 rad/s,
/// mu_s 0.10: 690 000 steps in 0.03 s, docs/model.md §10). A slip at rest that the friction
/// can hold is no slip: once it has stayed at rest for [`SETTLE_SWEEPS`] of the friction's
/// sweeps of the band (a time, not a count of steps: the answer must not depend on the step)
/// the slide ends there and the granule rolls. A slide whose slip passes through zero ends at
/// its reversal within a step, and a slide from no slip that rolling's need keeps above
/// `mu_s N` grows its slip: neither changes.
pub(crate) struct Settle<T> {
    above: Cell<bool>,
    /// The end of the first accepted step of the current stay at rest.
    since: Cell<Option<T>>,
    /// `1 - k2`: the slip answers a friction `f` at `f / (m (1 - k2))`.
    one_minus_k2: T,
}

impl<T: Real> Settle<T> {
    /// A watch for a granule of `k2` (`m rp^2 / (I + m rp^2)`).
    pub(crate) fn new(k2: T) -> Self {
        Self {
            above: Cell::new(false),
            since: Cell::new(None),
            one_minus_k2: T::ONE - k2,
        }
    }

    /// Whether the slip has been above [`SETTLED_M_S`] in this slide.
    pub(crate) fn left_rest(&self) -> bool {
        self.above.get()
    }

    /// After an accepted step to `t` of a slide whose slip is `s`; `holds`, asked only while
    /// the slip is at rest: `mu_s N` (m/s^2) where the friction can hold rolling there, `None`
    /// where rolling needs more. Breaks once the slip has settled.
    pub(crate) fn step<const N: usize>(
        &self,
        t: T,
        s: &[T; N],
        holds: impl FnOnce() -> Option<T>,
    ) -> ControlFlow<Stop> {
        let speed = dot(s, s).sqrt();
        if speed > T::from_f64(SETTLED_M_S) {
            self.above.set(true);
            self.since.set(None);
            return ControlFlow::Continue(());
        }
        let Some(friction) = holds() else {
            self.since.set(None);
            return ControlFlow::Continue(());
        };
        let since = self.since.get().unwrap_or(t);
        self.since.set(Some(since));
        // The friction's deceleration of the slip; with none (`mu_s N` = 0) nothing settles.
        let sweep = T::from_f64(SETTLED_M_S) * self.one_minus_k2 / friction;
        if friction > T::ZERO && t - since >= T::from_f64(SETTLE_SWEEPS) * sweep {
            ControlFlow::Break(Stop::Settled)
        } else {
            ControlFlow::Continue(())
        }
    }
}

/// How many fresh slides in a row (from no slip) that end at once, their slip never out of
/// rest, make a chatter ([`Chatter`]).
pub(crate) const CHATTER_ENDS: u32 = 8;

/// A segment of more than this many accepted steps is no chatter ([`Chatter`]).
const CHATTER_STEPS: u32 = 2;

/// Watches a run's changes of mode for a chatter at the stick threshold: rolling's need at
/// `mu_s N` to rounding, a slide from no slip whose slip, held to the friction's direction at
/// the switch while it is at rest, turns against that direction (the needed friction turning
/// away from it, or dipping under `mu_s N`) within a step and ends, then rolling that needs
/// `mu_s N` again a step later: a change of mode at every step, on the bottom (a 75 deg wall's
/// corner at 6 deg tilt, -0.61 and -2.9 rad/s, mu_s 0.065: 100 000 changes in 0.02 ms) and
/// on the fillet (a slide restarted from no slip every 1e-13 s until the stall watch). There
/// rolling and sliding give the same friction, `mu_s N`, to the threshold's width; once
/// [`CHATTER_ENDS`] such slides end in a row, each in at most [`CHATTER_STEPS`] steps, a fresh
/// slide ends only where its slip has turned against the friction by [`AT_REST_M_S`] (the
/// friction can hold it: it rolls) or left rest (then its friction follows it as any slide's):
/// the mode the friction can hold, not one decided anew at every step. A run without such a
/// chatter keeps the stuck threshold, and its answer, to the bit.
pub(crate) struct Chatter {
    ends: u32,
}

impl Chatter {
    pub(crate) fn new() -> Self {
        Self { ends: 0 }
    }

    /// How far a fresh slide's slip must turn against its friction for it to end, m/s.
    pub(crate) fn fresh_end_m_s<T: Real>(&self, speed_ref: T) -> T {
        if self.ends >= CHATTER_ENDS {
            T::from_f64(AT_REST_M_S)
        } else {
            stuck_m_s(speed_ref)
        }
    }

    /// After a segment of `steps` accepted steps; `fresh_end`: a slide that ended at its slip's
    /// end without its slip leaving rest.
    pub(crate) fn after(&mut self, steps: u32, fresh_end: bool) {
        if fresh_end {
            self.ends = self.ends.saturating_add(1);
        } else if steps > CHATTER_STEPS {
            self.ends = 0;
        }
    }
}

/// The slip of a state (m/s): on the bottom linear in it (`Linear`: the slip of a step's error
/// estimate is the slip's error), on the wall not (`OfState`: its velocity and the spin's part
/// `s x n` depend on where on the meridian it is; the slip's error is then the difference of the
/// slips of the step's two solutions, the 5th- and the embedded 4th-order one).
#[derive(Clone, Copy)]
pub(crate) enum SlipOf<'a, T, const N: usize> {
    /// Linear in the state.
    Linear(fn(&[T; N]) -> [T; 2]),
    /// Any function of the state.
    OfState(&'a dyn Fn(&[T; N]) -> [T; 3]),
}

/// The slip's error in a step of a slide in which it grows, against [`SLIP_RTOL`] times `rtol`
/// of the slip itself (`e`: the step's error estimate, `y` and `y1` its start and end). The
/// friction acts against the slip's direction, which turns at `|A_perp| / |v_c|` (the free
/// slip's acceleration across it over the slip): the slide's right-hand side is stiff while the
/// slip is small. The components' own tolerances (`rtol` of the scene's speed) say nothing of
/// that direction while the slip is below them, and a loose step can leave it off by tens of
/// degrees, the stiff relaxation then holding the step at its stability limit and the slip at
/// about that step's friction impulse, neither growing: a slide from rest at 45 deg, 3.6 rad/s,
/// mu_s 0.2 (release at 180 deg) took 2 709 steps at rtol 1e-6, 23 110 at 1e-7, more than
/// 200 000 at 1e-8, and 493 at 1e-10. On the wall the same direction error turns the slip
/// against the friction within a step or two, which ends the slide as a stick: a granule at the
/// stick threshold in the wall's corner then changed mode every few microseconds and failed
/// (docs/model.md §12).
pub(super) fn slip_error<T: Real, const N: usize>(
    slip: SlipOf<'_, T, N>,
    rtol: T,
    (e, y, y1): (&[T; N], &[T; N], &[T; N]),
) -> T {
    let norm = |v: [T; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let (before, after, error) = match slip {
        SlipOf::Linear(f) => {
            let flat = |v: [T; 2]| [v[0], v[1], T::ZERO];
            (flat(f(y)), flat(f(y1)), flat(f(e)))
        }
        SlipOf::OfState(f) => {
            let end = f(y1);
            let lower: [T; N] = core::array::from_fn(|i| y1[i] - e[i]);
            let other = f(&lower);
            (f(y), end, core::array::from_fn(|i| end[i] - other[i]))
        }
    };
    let (before, after) = (norm(before), norm(after));
    if after <= before {
        // A shrinking slip is left to the components' tolerances: held to its own, the steps
        // would shrink with it while its direction turns on the way to sticking, where the
        // slip-end event (its reversal within a step) finds the stick at any step.
        return T::ZERO;
    }
    norm(error) / (T::from_f64(SLIP_RTOL) * rtol * after + T::from_f64(SLIP_ATOL_M_S))
}

/// The slip's relative tolerance as a multiple of the run's `rtol`: its direction to 1e-4 rad at
/// rtol 1e-6 (1 and 10 gave the same fix at up to twice the steps elsewhere, docs/model.md §12).
pub(crate) const SLIP_RTOL: f64 = 100.0;

/// A slip error below this is always accepted, m/s: below [`AT_REST_M_S`], where the friction's
/// direction stops following the slip, and far above the rounding of the slip's components
/// (about 1e-16 of the scene's speed), so a slip at rest asks for no step it cannot take.
pub(crate) const SLIP_ATOL_M_S: f64 = 1e-9;

/// The part of the scene's time scale (its length over its speed) next to a zero of a slide's
/// slip over which RK4 grades its steps ([`graded_step`]): 1/32 made RK4's error in T fall 16x
/// per halving of `h` from 2 ms down to the reference's own error on both scenes of the bowl's
/// work-precision chart, at 20-37 % more evaluations than the plain step at the same `h`
/// (1/128 did it at 10 %, but irregularly; 1/8 at 50-70 %; docs/model.md §10).
pub(crate) const GRADED_SPAN: f64 = 1.0 / 32.0;

/// The slip's speed (m/s) and its rate of change `d|slip|/dt` (m/s^2) at a state `y` whose time
/// derivative is `dy`: on the bottom the slip of `dy` is the slip's derivative; on the wall a
/// central difference along `dy` over `dt` (s).
fn slip_speed_rate<T: Real, const N: usize>(
    slip: SlipOf<'_, T, N>,
    y: &[T; N],
    dy: &[T; N],
    dt: T,
) -> (T, T) {
    let (s, ds) = match slip {
        SlipOf::Linear(f) => {
            let (s, ds) = (f(y), f(dy));
            ([s[0], s[1], T::ZERO], [ds[0], ds[1], T::ZERO])
        }
        SlipOf::OfState(f) => {
            let along = |sign: T| -> [T; N] { core::array::from_fn(|i| y[i] + sign * dt * dy[i]) };
            let (plus, minus) = (f(&along(T::ONE)), f(&along(-T::ONE)));
            (
                f(y),
                core::array::from_fn(|i| (plus[i] - minus[i]) / (T::TWO * dt)),
            )
        }
    };
    let speed = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    let rate = if speed > T::ZERO {
        (s[0] * ds[0] + s[1] * ds[1] + s[2] * ds[2]) / speed
    } else {
        T::ZERO
    };
    (speed, rate)
}

/// RK4's step in a slide from a state `y` (slope `dy`): `h`, graded down near a zero of the
/// slip. Where the slip starts from zero (a release from rest, a roll giving way) or falls to
/// it (the stick), the friction's direction, the slip's over its size, turns fast: at the stick
/// as `tau^p` in the time `tau` left (`p = |A| / (mu_s N' - |A|)` with `A` the slip's
/// acceleration without friction, about 0.2 on a fillet of the lift-off scene), so the solution
/// has no second derivative there, and near either zero a stage whose slip is of the step's
/// order sees that direction wrong by O(1). A fixed step across it lost RK4's order: 3rd order
/// from a release from rest (the rig's scene), about 1st at a stick (the lift-off scene: the
/// wall's slide ended 6e-5 s late at h = 0.125 ms). The step here is `h (tau / span)^(3/4)`
/// within `span` of the zero (`tau` = the slip over its rate of change, the time from or to
/// the zero), the graded mesh of weakly singular problems: each step's error then stays within
/// RK4's `h^4` for any exponent `p >= 0`, for about `4 span / h` steps more per zero. Never
/// below [`graded_floor`].
pub(crate) fn graded_step<T: Real, const N: usize>(
    slip: SlipOf<'_, T, N>,
    h: T,
    span: T,
    y: &[T; N],
    dy: &[T; N],
) -> T {
    let (speed, rate) = slip_speed_rate(slip, y, dy, T::EPSILON.sqrt() * h);
    let tau = if speed == T::ZERO {
        T::ZERO
    } else {
        speed / rate.abs()
    };
    // Far from a zero, or no rate to tell.
    if tau.is_nan() || tau >= span {
        return h;
    }
    (h * ((tau / span).ln() * T::from_f64(0.75)).exp()).max(graded_floor(h))
}

/// The shortest step RK4 grades down to at `h` ([`graded_step`]): `sqrt(eps) h`.
pub(crate) fn graded_floor<T: Real>(h: T) -> T {
    h * T::EPSILON.sqrt()
}

//! The one loop of a rolling run through its rests (docs/model.md §9), for both runs that
//! roll: the rolling model's ([`super::integrate`]) and the roll mode of the roll-or-slide run
//! ([`super::modes`]). Each has its own roll (its state's units, its tolerances, its events)
//! and its own ends; the order of the pieces between them is here, so that a change to it
//! (issue 30's located rest, the restart stretch) cannot reach one run and miss the other:
//!
//! * a roll until its first event; at a located rest ([`rest::turned`]) the granule is taken
//!   at rest if the resistance holds it there ([`rest::held_at`]), and rolls on otherwise;
//! * a granule at rest that the resistance holds: a held segment ([`rest::hold`]) until the
//!   drive exceeds the resistance (the roll that follows does not hold again at once);
//! * from a hold's end or a release from rest: a restart stretch up to
//!   [`rest::start_speed_m_s`] (the roll mode's `Stop::Started`), a stretch on up to
//!   [`rest::slow_speed_m_s`], then the roll at the scene's own tolerances;
//! * a roll that slows on its way to a rest ([`Rolled::Slowed`], [`rest::Slowing`]): a stretch
//!   of its own up to [`rest::slow_speed_m_s`], which ends at the rest or back at that speed.

use core::ops::ControlFlow;

use super::equations::State;
use super::rest;
use super::{RollingError, RollingScene};
use crate::Real;

/// How one roll of a [`RollPieces`] ended.
pub(crate) enum Rolled<T, E> {
    /// The velocity came to rest (the rest event) at `t`, in `y` (m, m/s).
    Rest(T, State<T>),
    /// A restart stretch reached its start speed at `t`, in `y` (m, m/s): the roll goes on
    /// at the scene's tolerances.
    Started(T, State<T>),
    /// A roll slowed to half the slow speed ([`rest::slow_speed_m_s`]) at `t`, in `y` (m,
    /// m/s): it goes on to its rest as a stretch of its own up to that speed, as a restart
    /// does.
    Slowed(T, State<T>),
    /// Anything else (the rim, lift-off, a change of mode, the horizon): the loop's end.
    Ended(E),
}

/// What [`RollPieces::next`] gives: the state to go on rolling from, or the loop's end.
pub(crate) type AfterPiece<T, E> = Result<ControlFlow<E, State<T>>, RollingError>;
/// What [`RollPieces::hold`] gives: the time the drive restarts the granule, or the loop's end.
pub(crate) type AfterHold<T, E> = Result<ControlFlow<E, T>, RollingError>;
/// What [`RollPieces::roll`] gives.
pub(crate) type AfterRoll<T, E> = Result<Rolled<T, E>, RollingError>;

/// One run's own pieces for [`roll_with_rests`]. `End`: how the loop ends (the run's outcome,
/// or where the caller takes over); an error ends the run.
pub(crate) trait RollPieces<T: Real> {
    type End;

    /// Before every piece but the first, the granule at `t` in `y` (m, m/s): the state to go
    /// on rolling from, or the loop's end there (the caller's step budget, another mode).
    fn next(&mut self, t: T, y: &State<T>) -> AfterPiece<T, Self::End>;

    /// The granule held at rest in `rest` from `t` ([`rest::hold`]): the time the drive
    /// restarts it, or the loop's end (the horizon, lift-off, the caller's other event).
    fn hold(&mut self, t: T, rest: &State<T>) -> AfterHold<T, Self::End>;

    /// A roll from `t` in `y` (m, m/s) until its first event. `start`: a restart from a hold,
    /// a stretch of its own up to this speed (m/s, [`rest::start_speed_m_s`]) that ends in
    /// [`Rolled::Started`].
    fn roll(&mut self, t: T, y: &State<T>, start: Option<T>) -> AfterRoll<T, Self::End>;
}

/// Rolls from `t0` in `y0` (m, m/s), holds at each rest the resistance holds and restarts from
/// it, until one of `pieces` ends the loop.
pub(crate) fn roll_with_rests<T: Real, P: RollPieces<T>>(
    scene: &RollingScene<T>,
    pieces: &mut P,
    (t0, y0): (T, State<T>),
) -> Result<P::End, RollingError> {
    let (mut t, mut y) = (t0, y0);
    // The hold just ended where the drive began to exceed the resistance: the roll that
    // follows starts from rest without holding again, and restarts from the edge of holding.
    let mut from_hold = false;
    // The roll slowed on its way to a rest: the rest of the way a stretch of its own.
    let mut slowed = false;
    let slow = rest::slow_speed_m_s(scene);
    loop {
        let after_hold = core::mem::take(&mut from_hold);
        let still = y[2] == T::ZERO && y[3] == T::ZERO;
        // A granule at rest that the resistance does not hold (a release from rest) starts
        // as a hold's end does, a restart stretch of its own: as a roll at the scene's tolerance
        // it hovered at 5e-6 m/s for 1.1 s (see `rest_tests`).
        let restarts = after_hold || still;
        // Taken every time round, so that a slowing never carries past the piece it was for.
        let slowing = core::mem::take(&mut slowed);
        if !after_hold
            && still
            && let Some(at_rest) = rest::held_at(scene, t, &y)
        {
            match pieces.hold(t, &at_rest)? {
                ControlFlow::Continue(te) => (t, y, from_hold) = (te, at_rest, true),
                ControlFlow::Break(end) => return Ok(end),
            }
        } else {
            let start = if restarts {
                Some(rest::start_speed_m_s(scene))
            } else if slowing {
                Some(slow)
            } else {
                None
            };
            (t, y) = match pieces.roll(t, &y, start)? {
                // Held there with no velocity at all, or rolling on.
                Rolled::Rest(te, ye) => (te, rest::held_at(scene, te, &ye).unwrap_or(ye)),
                // From the start speed on to the slow speed, a stretch again: at a loose
                // `rtol` the scene's tolerance on the velocity is as large as the start speed.
                Rolled::Started(te, ye) => {
                    slowed = restarts && ye[2] * ye[2] + ye[3] * ye[3] < slow * slow;
                    (te, ye)
                }
                Rolled::Slowed(te, ye) => {
                    slowed = true;
                    (te, ye)
                }
                Rolled::Ended(end) => return Ok(end),
            };
        }
        y = match pieces.next(t, &y)? {
            ControlFlow::Continue(y) => y,
            ControlFlow::Break(end) => return Ok(end),
        };
    }
}

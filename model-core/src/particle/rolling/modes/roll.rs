//! The roll mode of the run on the bottom (`super::run_from`): its pieces of the rolling loop
//! through rests (`rest_loop::roll_with_rests`), a roll between events and a hold at rest, each
//! judged by this run's own events (a change to sliding among them) and tallied in its report.

use core::cell::Cell;
use core::ops::ControlFlow;

use super::report::{Mode, ModesReport};
use super::segments::{fired, max4, segment};
use super::slip::{Chatter, Stop};
use super::stall::StallWatch;
use super::{MAX_SWITCHES, Next, next_mode};
use crate::Real;
use crate::particle::rolling::equations::{State, forces_along, start_direction};
use crate::particle::rolling::rest;
use crate::particle::rolling::rest_loop::{AfterHold, AfterPiece, AfterRoll, RollPieces, Rolled};
use crate::particle::rolling::slide::{SlideState, from_rolling, needed_friction_m_s2};
use crate::particle::rolling::{RollingMethod, RollingScene, SystemLimits};

/// Where the roll mode's loop through its rests ended.
pub(super) enum RollEnd<T> {
    /// At the horizon, rolling or held: the report as it stands.
    Report,
    /// The rim (0), rolling's need of friction reaching `mu_s N` (1) or lift-off (2): at `t`,
    /// in the state, with its velocity (m/s), as the run's other modes end.
    Event((T, SlideState<T>, T, T), usize),
    /// A rest, a hold or a restart ended at `t` in the state, and the granule is no longer in
    /// the roll mode there (it slides or lifts off): the run judges it anew.
    Judge(T, SlideState<T>),
}

/// The run's state the roll mode reads and adds to.
pub(super) struct RollRun<'a, T> {
    pub(super) scene: &'a RollingScene<T>,
    pub(super) method: RollingMethod<T>,
    pub(super) limits: SystemLimits<T>,
    /// The scene's `refs` and `scales` ([`super::scene_scales`]).
    pub(super) scales: ((T, T), (T, T)),
    pub(super) watch: &'a StallWatch<T>,
    pub(super) chatter: &'a mut Chatter,
    pub(super) report: &'a mut ModesReport<T>,
    /// The mode of the segment before.
    pub(super) previous: &'a mut Option<Mode>,
}

impl<T: Real> RollPieces<T> for RollRun<'_, T> {
    type End = RollEnd<T>;

    fn next(&mut self, t: T, y: &State<T>) -> AfterPiece<T, RollEnd<T>> {
        self.report.tally.remaining(self.limits, MAX_SWITCHES)?;
        // At a rest, a hold's end or a restart under way the slide event has not fired. Another
        // mode goes back to the run, which judges the same state again (`next_mode` reads
        // nothing else): the slide or lift-off it finds is this one.
        let y = from_rolling(y);
        Ok(match next_mode(self.scene, t, &y, false) {
            Next::Roll(yr) => ControlFlow::Continue(yr),
            _ => ControlFlow::Break(RollEnd::Judge(t, y)),
        })
    }

    fn hold(&mut self, t: T, at_rest: &State<T>) -> AfterHold<T, RollEnd<T>> {
        let (scene, reference, horizon_s) = (self.scene, self.scales.0.0, self.limits.horizon_s);
        let tally = &mut self.report.tally;
        // Held at rest (`rest`) while the rolling resistance and static friction hold it.
        tally.enter(self.previous, Mode::Held);
        let held = rest::hold(scene, t, at_rest, horizon_s, |t| {
            slide_margin(scene, t, at_rest) / reference
        });
        tally.evaluations = tally.evaluations.saturating_add(held.evaluations);
        let Some(te) = held.t else {
            tally.spend(Mode::Held, horizon_s - t);
            self.report.end_state = from_rolling(at_rest);
            return Ok(ControlFlow::Break(RollEnd::Report));
        };
        tally.spend(Mode::Held, te - t);
        Ok(ControlFlow::Continue(te))
    }

    fn roll(&mut self, t: T, y: &State<T>, start: Option<T>) -> AfterRoll<T, RollEnd<T>> {
        let (scene, watch) = (self.scene, self.watch);
        let (refs, scales) = self.scales;
        let remaining = self.report.tally.remaining(self.limits, MAX_SWITCHES)?;
        let tally = &mut self.report.tally;
        let steps_before = tally.steps;
        tally.enter(self.previous, Mode::Roll);
        let last = Cell::new(start_direction(scene, t, y));
        // A roll at the scene's tolerances, once above the slow speed (after an accepted step),
        // ends where it slows to half of it and goes on to its rest as a stretch of its own
        // (`rest::slow_speed_m_s`).
        let speed_ref = refs.1;
        let slowing = rest::Slowing::new(rest::slow_speed_m_s(scene), start, [y[2], y[3]]);
        let slows = |y: &[T; 5]| slowing.event([y[2], y[3]]).map(|s| s / speed_ref);
        // A restart from a hold, or a roll slowing to its rest: up to `start`, a stretch of its
        // own with the velocity held to `rtol` of that speed and the position to `rtol` of the
        // distance the scene's speed covers in the time that speed takes over the scene's length
        // (so that its first trial step is the scene's, 1e-3 of that time: from the speed alone
        // it was 1e-3 of the bowl's radius over 1e-4 of the scene's speed, 0.75 s, and a slowing
        // stretch taken in one such step came to rest 1.2e-6 s early at every rtol 1e-7..1e-9).
        let Some((te, ye, started)) = segment(
            tally,
            Mode::Roll,
            |t, y: &[T; 5]| forces_along(scene, t, y, last.get()).derivative,
            (t, *y),
            self.method,
            start.map_or(scales, |speed| (scales.0 * speed / scales.1, speed)),
            |t, y: &[T; 5]| {
                let e = max4(roll_events(scene, t, y, last.get(), refs));
                slows(y).map_or(e, |s| e.max(s))
            },
            |t, y: &[T; 5]| {
                rest::follow_velocity([y[2], y[3]], &last);
                slowing.follow([y[2], y[3]]);
                watch.check(t)?;
                match start {
                    Some(s) if y[2] * y[2] + y[3] * y[3] >= s * s => {
                        ControlFlow::Break(Stop::Started)
                    }
                    _ => ControlFlow::Continue(()),
                }
            },
            None,
            remaining,
        )?
        else {
            return Ok(Rolled::Ended(RollEnd::Report));
        };
        if started {
            return Ok(Rolled::Started(te, ye));
        }
        let events = roll_events(scene, te, &ye, last.get(), refs);
        let which = fired(&events);
        self.chatter
            .after(self.report.tally.steps - steps_before, false);
        if slows(&ye).is_some_and(|s| s > events[which]) {
            return Ok(Rolled::Slowed(te, ye));
        }
        if which == 3 {
            return Ok(Rolled::Rest(te, ye));
        }
        Ok(Rolled::Ended(RollEnd::Event(
            (te, from_rolling(&ye), ye[2], ye[3]),
            which,
        )))
    }
}

/// The rolling state's rim, roll -> slide, lift-off and rest events (the rest: the velocity
/// turned against `last`, its direction at the last accepted step, [`rest::turned`]), each
/// made dimensionless and negative inside: the run stops where the first of them reaches zero.
fn roll_events<T: Real>(
    scene: &RollingScene<T>,
    t: T,
    y: &[T; 5],
    last: [T; 2],
    refs: (T, T),
) -> [T; 4] {
    let (reference, speed_ref) = refs;
    let (ft, normal) = needed_friction_m_s2(scene, t, &from_rolling(y));
    let rim = scene.rim_radius_m;
    [
        (y[0] * y[0] + y[1] * y[1]) / (rim * rim) - T::ONE,
        ((ft[0] * ft[0] + ft[1] * ft[1]).sqrt() - scene.sliding_friction * normal) / reference,
        -normal / reference,
        rest::turned([y[2], y[3]], last) / speed_ref,
    ]
}

/// How far the friction rolling needs at `(t, y)` exceeds what the contact gives,
/// `|f_t| - mu_s N`, m/s^2.
fn slide_margin<T: Real>(scene: &RollingScene<T>, t: T, y: &[T; 5]) -> T {
    let (ft, normal) = needed_friction_m_s2(scene, t, &from_rolling(y));
    (ft[0] * ft[0] + ft[1] * ft[1]).sqrt() - scene.sliding_friction * normal
}

//! The numerical releases ([`super`]'s first member): one release integrated to the rim by the
//! project's integrators ([`crate::ode::system`]), and the sweep over the release azimuths.

use core::ops::ControlFlow;

use core::cell::Cell;

use super::equations::{State, forces, forces_along, start_direction};
use super::modes::MAX_SWITCHES;
use super::rest;
use super::rest_loop::{self, AfterHold, AfterPiece, AfterRoll, RollPieces, Rolled};
use super::{
    RollingError, RollingMethod, RollingOutcome, RollingReport, RollingScene, default_limits,
    release,
};
use crate::Real;
use crate::ode::system::{self, Ended, SystemError, SystemLimits};

/// The rim in the state scaled by `1/R`: `|(x, y)|^2 - 1` and its derivative along `dy`.
fn rim_event<T: Real>(y: &State<T>, dy: &State<T>) -> (T, T) {
    (
        y[0] * y[0] + y[1] * y[1] - T::ONE,
        T::TWO * (y[0] * dy[0] + y[1] * dy[1]),
    )
}

/// One release at azimuth `beta_rad` (as `release` places it). Gives up after
/// [`HORIZON_S`](super::HORIZON_S) and [`MAX_STEPS`](super::MAX_STEPS).
pub fn residence<T: Real>(
    scene: &RollingScene<T>,
    beta_rad: T,
    method: RollingMethod<T>,
) -> Result<RollingReport<T>, RollingError> {
    residence_within(scene, beta_rad, method, default_limits())
}

/// [`residence`] within the caller's horizon and step cap (a fit that only needs to know that
/// a granule takes far longer than measured stops early; near the stick threshold a granule
/// that slows to rest and restarts can take many steps).
pub fn residence_within<T: Real>(
    scene: &RollingScene<T>,
    beta_rad: T,
    method: RollingMethod<T>,
    limits: SystemLimits<T>,
) -> Result<RollingReport<T>, RollingError> {
    let y0 = release(scene, beta_rad)?;
    let start = forces(scene, T::ZERO, &y0);
    if start.held && scene.stationary() {
        return Ok(RollingReport {
            outcome: RollingOutcome::Held,
            evaluations: 1,
            steps: 0,
            held_s: T::ZERO,
        });
    }
    let mut plain = PlainRoll {
        scene,
        method,
        limits,
        pieces: 1,
        evaluations: 1,
        steps: 0,
        held_s: T::ZERO,
        max_ratio: T::ZERO,
        first_slip: None,
    };
    // Rolls and holds at rest in turn (`rest`), each ended by a located event.
    rest_loop::roll_with_rests(scene, &mut plain, (T::ZERO, y0))
}

/// The rolling model's pieces of [`rest_loop::roll_with_rests`], and what they have cost and
/// seen so far.
struct PlainRoll<'a, T> {
    scene: &'a RollingScene<T>,
    method: RollingMethod<T>,
    limits: SystemLimits<T>,
    /// Pieces (rolls and holds) begun: at most [`MAX_SWITCHES`].
    pieces: u32,
    evaluations: u32,
    steps: u32,
    held_s: T,
    /// The largest friction ratio `|f_t| / N` rolling needed so far.
    max_ratio: T,
    /// When rolling first needed more friction than there is, s.
    first_slip: Option<T>,
}

impl<T: Real> PlainRoll<'_, T> {
    fn report(&self, outcome: RollingOutcome<T>, held_s: T) -> RollingReport<T> {
        RollingReport {
            outcome,
            evaluations: self.evaluations,
            steps: self.steps,
            held_s,
        }
    }
}

impl<T: Real> RollPieces<T> for PlainRoll<'_, T> {
    type End = RollingReport<T>;

    fn next(&mut self, _: T, y: &State<T>) -> AfterPiece<T, Self::End> {
        // A granule that rests and restarts at every step is reported as a step limit, not
        // followed forever.
        self.pieces += 1;
        if self.pieces > MAX_SWITCHES {
            return Err(RollingError::Integration(SystemError::StepLimit));
        }
        Ok(ControlFlow::Continue(*y))
    }

    fn hold(&mut self, t: T, rest: &State<T>) -> AfterHold<T, Self::End> {
        let (scene, horizon_s) = (self.scene, self.limits.horizon_s);
        let held = rest::hold(scene, t, rest, horizon_s, |_| -T::ONE);
        self.evaluations = self.evaluations.saturating_add(held.evaluations);
        let outcome = match held.t {
            None => RollingOutcome::NotLeftBy { horizon_s },
            Some(t1) if forces(scene, t1, rest).normal_m_s2 <= T::ZERO => {
                RollingOutcome::LiftsOff { time_s: t1 }
            }
            Some(t1) => {
                self.held_s += t1 - t;
                return Ok(ControlFlow::Continue(t1));
            }
        };
        let held_s = self.held_s + held.t.unwrap_or(horizon_s) - t;
        Ok(ControlFlow::Break(self.report(outcome, held_s)))
    }

    fn roll(&mut self, t: T, y: &State<T>, start: Option<T>) -> AfterRoll<T, Self::End> {
        let (scene, limits) = (self.scene, self.limits);
        let rim = scene.rim_radius_m;
        let remaining = SystemLimits {
            max_steps: limits.max_steps.saturating_sub(self.steps),
            ..limits
        };
        if remaining.max_steps == 0 {
            return Err(RollingError::Integration(SystemError::StepLimit));
        }
        let (max_ratio, first_slip) = (&mut self.max_ratio, &mut self.first_slip);
        let mut watch = |t: T, y: &State<T>| -> ControlFlow<T> {
            let f = forces(scene, t, y);
            if f.normal_m_s2 <= T::ZERO {
                return ControlFlow::Break(t);
            }
            let ratio = f.friction_m_s2 / f.normal_m_s2;
            *max_ratio = max_ratio.max(ratio);
            if first_slip.is_none() && ratio > scene.sliding_friction {
                *first_slip = Some(t);
            }
            ControlFlow::Continue(())
        };
        let (run, last, slowed) = roll(scene, (t, *y), self.method, start, remaining, &mut watch)?;
        self.evaluations = self.evaluations.saturating_add(run.evaluations);
        self.steps = self.steps.saturating_add(run.steps);
        let outcome = match run.ended {
            Ended::Event { t: te, y: ye } if slowed => {
                return Ok(Rolled::Slowed(te, ye.map(|v| v * rim)));
            }
            // The first of the two events: the one nearer zero (each is located to rounding).
            Ended::Event { t: te, y: ye }
                if rim_event(&ye, &[T::ZERO; 5]).0
                    >= rest::turned([ye[2], ye[3]], last) / speed_scale(scene) =>
            {
                RollingOutcome::Leaves {
                    residence_time_s: te,
                    exit_speed_m_s: (ye[2] * ye[2] + ye[3] * ye[3]).sqrt() * rim,
                    max_friction_ratio: self.max_ratio,
                    first_slip_s: self.first_slip,
                }
            }
            // The velocity came to rest (or turned by more than a right angle in a step).
            Ended::Event { t: te, y: ye } => return Ok(Rolled::Rest(te, ye.map(|v| v * rim))),
            Ended::Stopped {
                t: te,
                y: ye,
                why: None,
            } => return Ok(Rolled::Started(te, ye.map(|v| v * rim))),
            Ended::Stopped { why: Some(t), .. } => RollingOutcome::LiftsOff { time_s: t },
            Ended::Horizon { .. } => RollingOutcome::NotLeftBy {
                horizon_s: limits.horizon_s,
            },
        };
        Ok(Rolled::Ended(self.report(outcome, self.held_s)))
    }
}

/// The speed scale of a roll's state in units of the rim's radius, 1/s.
fn speed_scale<T: Real>(scene: &RollingScene<T>) -> T {
    scene.combined_speed_rad_s().max(T::ONE)
}

/// A roll's run; a stop by its check carries the lift-off's time, or `None` where a restart
/// from a hold got under way.
type Roll<T> = system::Run<T, 5, Option<T>>;

/// One roll from `(t0, y0)` (m, m/s) to the rim, a rest (the velocity turned against its last
/// direction, [`rest::turned`]), the watch's stop (lift-off, `Some` of its time) or the
/// horizon; the event's state in units of the rim's radius, and the velocity's direction at the
/// last accepted step (the rest event's), and whether it ended slowing to its rest
/// ([`rest::Slowing`]). `start`: a restart from a hold or a roll slowing to its rest, stopped
/// (`None`) once its speed reaches this (m/s), its velocity held to `rtol` of it
/// ([`rest::start_speed_m_s`], [`rest::slow_speed_m_s`]).
fn roll<T: Real>(
    scene: &RollingScene<T>,
    (t0, y0): (T, State<T>),
    method: RollingMethod<T>,
    start: Option<T>,
    limits: SystemLimits<T>,
    watch: &mut impl FnMut(T, &State<T>) -> ControlFlow<T>,
) -> Result<(Roll<T>, [T; 2], bool), RollingError> {
    let rim = scene.rim_radius_m;
    let last = Cell::new(start_direction(scene, t0, &y0));
    // Lengths in units of R: the rim is then the fixed |(x, y)| = 1.
    let scale = T::ONE / rim;
    let scaled = |y: &State<T>| -> State<T> { y.map(|v| v * scale) };
    let speed_scale = speed_scale(scene);
    let rhs = |t: T, y: &State<T>| -> State<T> {
        scaled(&forces_along(scene, t, &y.map(|v| v * rim), last.get()).derivative)
    };
    // The start speed in the scaled state.
    let start = start.map(|s| s * scale);
    // A roll at the scene's tolerances ends where it slows to its rest and goes on as a
    // stretch of its own, as the bowl model's (`rest::slow_speed_m_s`).
    let slowing = rest::Slowing::new(
        rest::slow_speed_m_s(scene) * scale,
        start,
        [y0[2], y0[3]].map(|v| v * scale),
    );
    let check = |t: T, y: &State<T>| {
        rest::follow_velocity([y[2], y[3]], &last);
        slowing.follow([y[2], y[3]]);
        if let ControlFlow::Break(t) = watch(t, &y.map(|v| v * rim)) {
            return ControlFlow::Break(Some(t));
        }
        match start {
            Some(s) if y[2] * y[2] + y[3] * y[3] >= s * s => ControlFlow::Break(None),
            _ => ControlFlow::Continue(()),
        }
    };
    // The first of the rim and the rest, each with its own slope.
    let event = |_: T, y: &State<T>, _: T, dy: &State<T>| {
        let at_rim = rim_event(y, dy);
        let at_rest = (
            rest::turned([y[2], y[3]], last.get()) / speed_scale,
            rest::turned([dy[2], dy[3]], last.get()) / speed_scale,
        );
        let first = if at_rim.0 >= at_rest.0 {
            at_rim
        } else {
            at_rest
        };
        // Slowing: `slow/2 - |u|`, its slope `-(u . du) / |u|`.
        let speed = (y[2] * y[2] + y[3] * y[3]).sqrt();
        let slope = if speed > T::ZERO {
            -(y[2] * dy[2] + y[3] * dy[3]) / speed / speed_scale
        } else {
            T::ZERO
        };
        match slowing.event([y[2], y[3]]) {
            Some(s) if s / speed_scale > first.0 => (s / speed_scale, slope),
            _ => first,
        }
    };
    match method {
        RollingMethod::Dp54 { rtol } => {
            let speed = start.unwrap_or(speed_scale);
            let atol = [rtol, rtol, rtol * speed, rtol * speed, rtol * speed];
            let h0 = T::from_f64(1e-3) / speed_scale;
            system::dp54_with(
                rhs,
                t0,
                scaled(&y0),
                (rtol, atol),
                h0,
                &event,
                check,
                |_, _, _| T::ZERO,
                limits,
            )
        }
        RollingMethod::Rk4 { step_s } => {
            system::rk4_with(rhs, t0, scaled(&y0), step_s, &event, check, limits)
        }
    }
    .map(|run| {
        // Where the roll ended by slowing to its rest (that event the nearest zero).
        let slowed = match &run.ended {
            Ended::Event { y, .. } => slowing.event([y[2], y[3]]).is_some_and(|s| {
                s / speed_scale
                    > rim_event(y, &[T::ZERO; 5])
                        .0
                        .max(rest::turned([y[2], y[3]], last.get()) / speed_scale)
            }),
            _ => false,
        };
        (run, last.get(), slowed)
    })
    .map_err(RollingError::Integration)
}

/// Residence times over the release azimuths `beta = 0, 30, ..., 330` degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AzimuthSummary<T> {
    /// Mean over the releases that leave, s (`None` if none does).
    pub mean_s: Option<T>,
    /// Shortest, s.
    pub min_s: Option<T>,
    /// Longest, s.
    pub max_s: Option<T>,
    /// How many of the 12 releases leave.
    pub left: u32,
    /// How many of those slid on the way (rolling needed more friction than there is).
    pub slid: u32,
    /// How many lifted off the bottom (the normal force reached zero): the model ends there.
    pub lifted: u32,
    /// The largest friction ratio `|f_t| / N` rolling needed over the releases that left.
    pub max_friction_ratio: T,
    /// Right-hand-side evaluations of all 12.
    pub evaluations: u32,
}

/// The release azimuths of [`residence_over_azimuths`], degrees.
pub const AZIMUTHS_DEG: [f64; 12] = [
    0.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0, 210.0, 240.0, 270.0, 300.0, 330.0,
];

/// [`residence`] at every azimuth of [`AZIMUTHS_DEG`].
pub fn residence_over_azimuths<T: Real>(
    scene: &RollingScene<T>,
    method: RollingMethod<T>,
) -> Result<AzimuthSummary<T>, RollingError> {
    over_azimuths_within(scene, method, default_limits())
}

/// [`residence_over_azimuths`] within the caller's horizon and step cap per release.
pub fn over_azimuths_within<T: Real>(
    scene: &RollingScene<T>,
    method: RollingMethod<T>,
    limits: SystemLimits<T>,
) -> Result<AzimuthSummary<T>, RollingError> {
    let mut tally = AzimuthTally::new();
    for deg in AZIMUTHS_DEG {
        let beta = T::from_f64(deg.to_radians());
        tally.add(&residence_within(scene, beta, method, limits)?);
    }
    Ok(tally.summary())
}

/// The summary of releases taken one report at a time: [`over_azimuths_within`]'s over the
/// twelve azimuths, and the PC's over any list of them (one summary, whichever releases).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AzimuthTally<T> {
    sum: T,
    min_s: Option<T>,
    max_s: Option<T>,
    left: u32,
    slid: u32,
    lifted: u32,
    max_ratio: T,
    evaluations: u32,
}

impl<T: Real> Default for AzimuthTally<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Real> AzimuthTally<T> {
    /// No releases yet.
    pub fn new() -> Self {
        Self {
            sum: T::ZERO,
            min_s: None,
            max_s: None,
            left: 0,
            slid: 0,
            lifted: 0,
            max_ratio: T::ZERO,
            evaluations: 0,
        }
    }

    /// One more release.
    pub fn add(&mut self, report: &RollingReport<T>) {
        self.evaluations = self.evaluations.saturating_add(report.evaluations);
        self.lifted += u32::from(matches!(report.outcome, RollingOutcome::LiftsOff { .. }));
        if let RollingOutcome::Leaves {
            residence_time_s: t,
            first_slip_s,
            max_friction_ratio,
            ..
        } = report.outcome
        {
            self.max_ratio = self.max_ratio.max(max_friction_ratio);
            self.sum += t;
            self.left += 1;
            self.slid += u32::from(first_slip_s.is_some());
            self.min_s = Some(self.min_s.map_or(t, |m| m.min(t)));
            self.max_s = Some(self.max_s.map_or(t, |m| m.max(t)));
        }
    }

    /// The summary of the releases added.
    pub fn summary(&self) -> AzimuthSummary<T> {
        AzimuthSummary {
            mean_s: (self.left > 0).then(|| self.sum / T::from_f64(f64::from(self.left))),
            min_s: self.min_s,
            max_s: self.max_s,
            left: self.left,
            slid: self.slid,
            lifted: self.lifted,
            max_friction_ratio: self.max_ratio,
            evaluations: self.evaluations,
        }
    }
}

//! The granule that rolls or slides on the flat bottom of the tilted, precessing bowl
//! (docs/model.md §10): it rolls ([`super::equations`], rolling resistance as there) while the
//! friction rolling needs stays within `mu_s N`, and slides ([`super::slide`], Coulomb friction
//! `mu_s N` against the slip, the spin driven by its torque) otherwise. Each change of mode is an
//! event of the project's integrators ([`crate::ode::system`]), located on the step's
//! interpolant like the rim, and the run restarts from there in the other mode, so no step
//! straddles a kink of the right-hand side:
//!
//! * roll -> slide where `|f_t| - mu_s N` reaches zero from below; the slip then starts
//!   against `f_t` (a friction short of `f_t` by `df` gives `dv_c/dt = -df / (m (1 - k2))`);
//! * slide -> roll where the slip reaches zero (its component along its last direction turns
//!   negative), if rolling then needs no more than `mu_s N`; otherwise the granule keeps sliding
//!   against the friction rolling would need;
//! * the rim (the centre's contact point at radius `R`) and lift-off (`N` reaching zero) in
//!   either mode.
//!
//! The run of modes on the bottom is here; the roll mode's pieces of the rolling model's loop
//! through rests (`rest_loop`) are `roll.rs`; what it gives and costs is `report.rs`, the parts the
//! wall's run (`bowl::wall_run`) shares with it are `segments.rs` (one segment between events)
//! and `slip.rs` (a slide's slip: its direction, its end, its error), and the watch that gives up
//! on a stalled run is `stall.rs`.

mod report;
mod roll;
mod segments;
mod slip;
mod stall;

use core::cell::Cell;
use core::ops::ControlFlow;

pub use report::{Mode, ModesOutcome, ModesReport, Regime, Tally};
pub(crate) use segments::{fired, max3, scene_scales, segment};
pub(crate) use slip::{Chatter, Settle, SlipOf, Stop, follow_slip, lags_its_growth, stuck_m_s};
pub use stall::STALL_STEP;
pub(crate) use stall::StallWatch;

use roll::{RollEnd, RollRun};

use super::equations::{AT_REST_M_S, forces};
use super::rest_loop::roll_with_rests;
use super::slide::{
    SlideState, from_rolling, needed_friction_m_s2, slide_forces, slide_forces_slaved, slip_m_s,
    to_rolling,
};
use super::{RollingError, RollingMethod, RollingScene, SystemLimits, default_limits, release};
use crate::Real;
use crate::ode::system::SystemError;

/// The slip, in units of the scene's speed, up to which a slide on the bottom whose rolling
/// needs more than `mu_s N` and whose slip grows has its friction against the slip's free
/// acceleration `A` rather than the slip (`slide::friction_direction`'s slaved slip), at every
/// DP5(4) tolerance. The real slip turns to `A` within `|s| / (|A| sin phi)` and lags it by
/// `|s|` times `A`'s turning rate over `|A|`: below this, 1e-4 rad for `A` turning at the
/// scene's rate. Held to the slip's own direction from the rest threshold (1e-7 m/s) up, a
/// slip at the stick threshold (rolling's need 1e-5 of it above `mu_s N`) grew along `A` so
/// slowly that `A` turned further than that excess allows before the slip was out of rest, and
/// the friction against it then shrank it back: it hovered at 1e-7 m/s in steps of 5e-8 s
/// until the step cap (47.4 deg tilt, 1.16 and -1.88 rad/s, mu_s 0.314 at the threshold
/// 0.311, a 45 deg wall 5 mm high, release 206.5 deg: 2 million steps in 0.09 s, issue 30).
pub const SLAVED: f64 = 1e-4;

/// The most changes of mode one release may take: a granule at the stick-slip threshold can
/// switch at every step; beyond this it is reported as a step limit, not followed forever.
pub const MAX_SWITCHES: u32 = 100_000;

/// One release at azimuth `beta_rad` (as [`super::residence`]: at rest in the bowl at `ri`,
/// `(x, y) = ri (-cos beta, -sin beta)`), rolling or sliding, within [`super::HORIZON_S`] and
/// [`super::MAX_STEPS`].
pub fn residence_roll_or_slide<T: Real>(
    scene: &RollingScene<T>,
    beta_rad: T,
    method: RollingMethod<T>,
) -> Result<ModesReport<T>, RollingError> {
    roll_or_slide_within(scene, beta_rad, method, default_limits())
}

/// [`residence_roll_or_slide`] within the caller's horizon and step cap.
pub fn roll_or_slide_within<T: Real>(
    scene: &RollingScene<T>,
    beta_rad: T,
    method: RollingMethod<T>,
    limits: SystemLimits<T>,
) -> Result<ModesReport<T>, RollingError> {
    roll_or_slide_watching(scene, beta_rad, method, limits, None)
}

/// [`roll_or_slide_within`] that gives up ([`SystemError::Stalled`]) once the run stalls
/// (`stall_steps`: see [`StallWatch`]; `None`: never).
pub(crate) fn roll_or_slide_watching<T: Real>(
    scene: &RollingScene<T>,
    beta_rad: T,
    method: RollingMethod<T>,
    limits: SystemLimits<T>,
    stall_steps: Option<u32>,
) -> Result<ModesReport<T>, RollingError> {
    let y0 = release(scene, beta_rad)?;
    let start = forces(scene, T::ZERO, &y0);
    let (ft, normal) = needed_friction_m_s2(scene, T::ZERO, &from_rolling(&y0));
    let fits = (ft[0] * ft[0] + ft[1] * ft[1]).sqrt() <= scene.sliding_friction * normal;
    if start.held && fits && scene.stationary() {
        return Ok(ModesReport {
            outcome: ModesOutcome::Held,
            tally: Tally {
                evaluations: 1,
                ..Tally::new()
            },
            end_state: from_rolling(&y0),
        });
    }
    run_from(
        scene,
        T::ZERO,
        from_rolling(&y0),
        method,
        limits,
        stall_steps,
    )
}

/// Which mode a state at `t` is in, and for a slide the direction its slip takes.
enum Next<T> {
    Roll([T; 5]),
    Slide(SlideState<T>, [T; 2]),
    LiftsOff,
}

/// `must_slide`: the roll -> slide event just fired, located where rolling needs `mu_s N` to
/// the location's accuracy; judging again there could find it a hair below and roll on from
/// the same instant, one step at a time.
fn next_mode<T: Real>(
    scene: &RollingScene<T>,
    t: T,
    y: &SlideState<T>,
    must_slide: bool,
) -> Next<T> {
    let slip = slip_m_s(y);
    let speed = (slip[0] * slip[0] + slip[1] * slip[1]).sqrt();
    if speed > T::from_f64(AT_REST_M_S) {
        return Next::Slide(*y, [slip[0] / speed, slip[1] / speed]);
    }
    let rolling = to_rolling(y);
    let no_slip = from_rolling(&rolling);
    let (ft, normal) = needed_friction_m_s2(scene, t, &no_slip);
    if normal <= T::ZERO {
        return Next::LiftsOff;
    }
    let need = (ft[0] * ft[0] + ft[1] * ft[1]).sqrt();
    let fits = need <= scene.sliding_friction * normal;
    if (fits && !must_slide) || need <= T::ZERO {
        return Next::Roll(rolling);
    }
    // Rolling needs more than the contact gives: the slip starts against that friction.
    Next::Slide(no_slip, [-ft[0] / need, -ft[1] / need])
}

/// The sliding state's rim, slip-end and lift-off events (as the roll mode's,
/// `roll::roll_events`). The slip ends where it turns against its last direction (it passes
/// through zero in a step) or, once it has been above twice [`slip::STUCK`] roundings
/// (`armed`), where it falls below that: a slip that shrinks while its direction turns (the
/// needed friction near `mu_s N`) makes the equations stiff as it vanishes (the direction turns
/// at a rate `|f| / |v_c|`), so the steps shrink with it and it would never be reached by steps
/// alone.
fn slide_events<T: Real>(
    scene: &RollingScene<T>,
    t: T,
    y: &SlideState<T>,
    dir: [T; 2],
    (armed, fresh_end): (bool, T),
    refs: (T, T),
) -> [T; 3] {
    let (reference, speed_ref) = refs;
    let f = slide_forces(scene, t, y, dir);
    let rim = scene.rim_radius_m;
    let slip = f.slip_m_s;
    let reversed = -(slip[0] * dir[0] + slip[1] * dir[1]);
    let stuck = if armed {
        let speed = (slip[0] * slip[0] + slip[1] * slip[1]).sqrt();
        reversed.max(stuck_m_s(speed_ref) - speed)
    } else {
        // Not yet armed (a slide from no slip): its end where the slip has turned against the
        // friction by more than the stuck threshold, as on the wall (`bowl::wall_run`), not at
        // its first rounding. Where rolling's need grazed `mu_s N` and fell back, the slide
        // from no slip reversed at once and ended where it began, rolling found the need at
        // `mu_s N` to rounding and slid again at the same instant, without end (a 54 deg wall
        // with a 3.9 mm fillet at 10 deg tilt, -2.2 and 0.33 rad/s, mu_s 0.055: a stall at
        // 1.3127 s, docs/model.md §10). In a chatter further ([`Chatter`]).
        reversed - fresh_end
    };
    [
        (y[0] * y[0] + y[1] * y[1]) / (rim * rim) - T::ONE,
        stuck / speed_ref,
        -f.normal_m_s2 / reference,
    ]
}

/// The run from a state at `t0` in the sliding form (a rolling state has no slip), whatever
/// its mode; the modes and their events as the module says; a stalled segment gives up
/// (`stall_steps`: see [`StallWatch`]).
pub(crate) fn run_from<T: Real>(
    scene: &RollingScene<T>,
    t0: T,
    y0: SlideState<T>,
    method: RollingMethod<T>,
    limits: SystemLimits<T>,
    stall_steps: Option<u32>,
) -> Result<ModesReport<T>, RollingError> {
    let (refs, scales) = scene_scales(scene);
    // A growing slip below the velocities' absolute tolerance, or below [`SLAVED`] of the
    // scene's speed: the friction opposes its free acceleration (`slide::friction_direction`;
    // RK4 has no tolerance, and keeps the slip's), and where it leaves that band lagging the
    // acceleration's direction it is turned to it ([`lags_its_growth`]).
    let slaved = match method {
        RollingMethod::Dp54 { rtol } => Some((rtol * scales.1).max(T::from_f64(SLAVED) * scales.1)),
        RollingMethod::Rk4 { .. } => None,
    };
    let mut report = ModesReport {
        outcome: ModesOutcome::Inside {
            horizon_s: limits.horizon_s,
        },
        tally: Tally::new(),
        end_state: y0,
    };
    let (mut t, mut y) = (t0, y0);
    let mut previous: Option<Mode> = None;
    let mut must_slide = false;
    // One watch over the whole run: a stall can be one segment's steps or a run of segments
    // that each end where they start.
    let watch = StallWatch::new(stall_steps, scales, t0, method);
    let mut chatter = Chatter::new();
    loop {
        let remaining = report.tally.remaining(limits, MAX_SWITCHES)?;
        let steps_before = report.tally.steps;
        let (ended, which) = match next_mode(scene, t, &y, must_slide) {
            Next::LiftsOff => {
                report.outcome = ModesOutcome::LiftsOff { time_s: t };
                report.end_state = y;
                return Ok(report);
            }
            Next::Roll(yr) => {
                let mut run = RollRun {
                    scene,
                    method,
                    limits,
                    scales: (refs, scales),
                    watch: &watch,
                    chatter: &mut chatter,
                    report: &mut report,
                    previous: &mut previous,
                };
                match roll_with_rests(scene, &mut run, (t, yr))? {
                    RollEnd::Report => return Ok(report),
                    RollEnd::Judge(te, ye) => {
                        (t, y, must_slide) = (te, ye, false);
                        continue;
                    }
                    RollEnd::Event(ended, which) => (ended, which),
                }
            }
            Next::Slide(ys, dir0) => {
                report.tally.enter(&mut previous, Mode::Slide);
                let dir = Cell::new(dir0);
                let slip0 = slip_m_s(&ys);
                let stuck = stuck_m_s(refs.1);
                let fresh_end = chatter.fresh_end_m_s(refs.1);
                let armed = Cell::new(
                    slip0[0] * slip0[0] + slip0[1] * slip0[1] > T::from_f64(4.0) * stuck * stuck,
                );
                let settle = Settle::new(scene.k2);
                let realign = Cell::new(None);
                let Some((te, ye, settled)) = segment(
                    &mut report.tally,
                    Mode::Slide,
                    |t, y: &SlideState<T>| {
                        slide_forces_slaved(scene, t, y, dir.get(), slaved.unwrap_or(T::ZERO))
                            .derivative
                    },
                    (t, ys),
                    method,
                    scales,
                    |t, y: &SlideState<T>| {
                        max3(slide_events(
                            scene,
                            t,
                            y,
                            dir.get(),
                            (armed.get(), fresh_end),
                            refs,
                        ))
                    },
                    |t, y: &SlideState<T>| {
                        let s = slip_m_s(y);
                        follow_slip(&s, &dir, &armed, stuck);
                        watch.check(t)?;
                        let turned = slaved.and_then(|band| {
                            lags_its_growth(scene.k2, &s, band, || {
                                let (ft, normal) =
                                    needed_friction_m_s2(scene, t, &from_rolling(&to_rolling(y)));
                                let one = T::ONE - scene.k2;
                                (
                                    [-ft[0] / one, -ft[1] / one],
                                    scene.sliding_friction * normal,
                                )
                            })
                        });
                        if turned.is_some() {
                            realign.set(turned);
                            return ControlFlow::Break(Stop::Realign);
                        }
                        settle.step(t, &s, || {
                            let (ft, normal) =
                                needed_friction_m_s2(scene, t, &from_rolling(&to_rolling(y)));
                            let limit = scene.sliding_friction * normal;
                            (ft[0] * ft[0] + ft[1] * ft[1] <= limit * limit).then_some(limit)
                        })
                    },
                    Some(SlipOf::Linear(slip_m_s::<T>)),
                    remaining,
                )?
                else {
                    return Ok(report);
                };
                if let (true, Some(turned)) = (settled, realign.get()) {
                    // The slip turned to its growth's direction: its spin set so that the
                    // contact slips by `turned`, the translation kept (`slip_m_s`).
                    let mut ye = ye;
                    ye[5] = ye[2] - turned[0];
                    ye[4] = turned[1] - ye[3];
                    (t, y, must_slide) = (te, ye, false);
                    if watch.step(te).is_break() {
                        return Err(RollingError::Integration(SystemError::Stalled));
                    }
                    continue;
                }
                let events =
                    slide_events(scene, te, &ye, dir.get(), (armed.get(), fresh_end), refs);
                // A settled slide ends as at its slip's end.
                let which = if settled { 1 } else { fired(&events) };
                chatter.after(
                    report.tally.steps - steps_before,
                    which == 1 && !settle.left_rest(),
                );
                let mut ye = ye;
                if which == 1 {
                    // The slip is zero here to the location's accuracy: make it
                    // exactly so (rolling), keeping the translation.
                    ye[4] = -ye[3];
                    ye[5] = ye[2];
                }
                ((te, ye, ye[2], ye[3]), which)
            }
        };
        let (te, ye, ux, uy) = ended;
        if watch.step(te).is_break() {
            return Err(RollingError::Integration(SystemError::Stalled));
        }
        if which != 1 {
            report.end_state = ye;
        }
        match which {
            0 => {
                report.outcome = ModesOutcome::Leaves {
                    residence_time_s: te - t0,
                    exit_speed_m_s: (ux * ux + uy * uy).sqrt(),
                };
                return Ok(report);
            }
            2 => {
                report.outcome = ModesOutcome::LiftsOff { time_s: te };
                return Ok(report);
            }
            _ => {
                must_slide = previous == Some(Mode::Roll);
                t = te;
                y = ye;
            }
        }
    }
}

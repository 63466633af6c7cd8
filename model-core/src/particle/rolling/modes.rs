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

use core::cell::Cell;
use core::ops::ControlFlow;

use super::equations::{AT_REST_M_S, forces};
use super::slide::{
    SlideState, from_rolling, needed_friction_m_s2, slide_forces, slip_m_s, to_rolling,
};
use super::{RollingError, RollingMethod, RollingScene, SystemLimits, default_limits, release};
use crate::Real;
use crate::ode::system::{self, Ended, SystemError};

/// How the granule moves on the bottom.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Mode {
    /// Rolling without slip.
    Roll,
    /// Sliding: the contact point slips.
    Slide,
}

/// The time a release spent in each mode, s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Regime<T> {
    /// Rolling, s.
    pub roll_s: T,
    /// Sliding, s.
    pub slide_s: T,
}

impl<T: Real> Regime<T> {
    /// Each mode's share of the time (0 and 0 for a release that never moved).
    pub fn shares(&self) -> (T, T) {
        let total = self.roll_s + self.slide_s;
        if total > T::ZERO {
            (self.roll_s / total, self.slide_s / total)
        } else {
            (T::ZERO, T::ZERO)
        }
    }
}

/// What happens to one granule that may roll or slide, on the bottom alone or in a bowl with a
/// wall (`bowl::BowlOutcome` is this one).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ModesOutcome<T> {
    /// It reaches the rim (in a bowl with a wall: its centre passes the lip's radius).
    Leaves {
        /// Residence time `T`, s.
        residence_time_s: T,
        /// Speed of its centre relative to the bowl there, m/s.
        exit_speed_m_s: T,
    },
    /// Released at rest, held there (rolling resistance within what it can give, static
    /// friction within `mu_s N`), and the forces never change.
    Held,
    /// The normal force reached zero at this time, s: it leaves the surface (flight is not
    /// modelled).
    LiftsOff {
        /// s.
        time_s: T,
    },
    /// Still in the bowl at the horizon (in a bowl with a wall: held by the wall, or slower), s.
    Inside {
        /// s.
        horizon_s: T,
    },
}

/// The time a run of segments spent in each mode, its changes of mode, and what it cost (on the
/// bottom here, on the wall in `bowl::wall_run`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tally<T> {
    /// Time in each mode, s.
    pub regime: Regime<T>,
    /// Changes of mode.
    pub switches: u32,
    /// Right-hand-side evaluations.
    pub evaluations: u32,
    /// Accepted steps.
    pub steps: u32,
}

impl<T: Real> Tally<T> {
    /// Nothing spent yet.
    pub(crate) fn new() -> Self {
        Self {
            regime: Regime {
                roll_s: T::ZERO,
                slide_s: T::ZERO,
            },
            switches: 0,
            evaluations: 0,
            steps: 0,
        }
    }

    /// The limits left for the next segment: the caller's horizon and the steps not yet taken;
    /// a step limit once the steps or `max_switches` changes of mode are spent.
    pub(crate) fn remaining(
        &self,
        limits: SystemLimits<T>,
        max_switches: u32,
    ) -> Result<SystemLimits<T>, RollingError> {
        let remaining = SystemLimits {
            horizon_s: limits.horizon_s,
            max_steps: limits.max_steps.saturating_sub(self.steps),
        };
        if remaining.max_steps == 0 || self.switches > max_switches {
            return Err(RollingError::Integration(SystemError::StepLimit));
        }
        Ok(remaining)
    }

    /// Counts a change of mode when `mode` is not the `previous` segment's, and remembers it.
    pub(crate) fn enter(&mut self, previous: &mut Option<Mode>, mode: Mode) {
        if previous.is_some_and(|p| p != mode) {
            self.switches += 1;
        }
        *previous = Some(mode);
    }

    /// Adds `dt` to the time in `mode`.
    fn spend(&mut self, mode: Mode, dt: T) {
        match mode {
            Mode::Roll => self.regime.roll_s += dt,
            Mode::Slide => self.regime.slide_s += dt,
        }
    }
}

/// One release's outcome, the time it spent in each mode, and what it cost.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModesReport<T> {
    /// The outcome.
    pub outcome: ModesOutcome<T>,
    /// Time in each mode up to the outcome, changes of mode, cost.
    pub tally: Tally<T>,
    /// The state where it left or lifted off, in the sliding form (the start state otherwise):
    /// where a bowl's wall takes over from the bottom.
    pub end_state: SlideState<T>,
}

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

/// A step that advances the time by less than this fraction of the scene's time scale (its
/// length over its speed, `1 / max(|Omega|, 1 rad/s)`: 0.1-1 s) makes no progress. A real
/// step, even one cut short to locate an event, is far longer at rtol 1e-6 to 1e-10; a run
/// stalled at a slide/roll switch takes steps of ~1e-16 s (docs/model.md §12).
pub const STALL_STEP: f64 = 1e-9;

/// Watches a segment's accepted steps for a stall: `steps` in a row, each shorter than
/// [`STALL_STEP`] of the time scale (`None`: never).
pub(crate) struct StallWatch<T> {
    steps: Option<u32>,
    dt: T,
    last_t: Cell<T>,
    run: Cell<u32>,
}

impl<T: Real> StallWatch<T> {
    /// A watch from `t0` at the scene's `scales` (length, speed).
    pub(crate) fn new(steps: Option<u32>, scales: (T, T), t0: T) -> Self {
        Self {
            steps,
            dt: T::from_f64(STALL_STEP) * scales.0 / scales.1,
            last_t: Cell::new(t0),
            run: Cell::new(0),
        }
    }

    /// After an accepted step to `t`: break once the run of tiny steps is long enough.
    pub(crate) fn step(&self, t: T) -> ControlFlow<()> {
        let Some(n) = self.steps else {
            return ControlFlow::Continue(());
        };
        let tiny = (t - self.last_t.get()).abs() < self.dt;
        self.last_t.set(t);
        let run = if tiny { self.run.get() + 1 } else { 0 };
        self.run.set(run);
        if run >= n {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
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

/// The rolling state's roll -> slide, rim and lift-off events, each made dimensionless and
/// negative inside: the run stops where the first of them reaches zero.
fn roll_events<T: Real>(scene: &RollingScene<T>, t: T, y: &[T; 5], reference: T) -> [T; 3] {
    let (ft, normal) = needed_friction_m_s2(scene, t, &from_rolling(y));
    let rim = scene.rim_radius_m;
    [
        (y[0] * y[0] + y[1] * y[1]) / (rim * rim) - T::ONE,
        ((ft[0] * ft[0] + ft[1] * ft[1]).sqrt() - scene.sliding_friction * normal) / reference,
        -normal / reference,
    ]
}

/// The slip below which a slide has ended, in units of the scene's speed: a few roundings of
/// it, so that the end is located as exactly as the slip's zero itself (a slip that falls
/// linearly at `mu_s g / (1 - k2)` reaches this 1e-16 s before its zero).
const STUCK: f64 = 64.0;

/// The sliding state's rim, slip-end and lift-off events (as [`roll_events`]). The slip ends
/// where it turns against its last direction (it passes through zero in a step) or, once it
/// has been above twice [`STUCK`] roundings (`armed`), where it falls below that: a slip
/// that shrinks while its direction turns (the needed friction near `mu_s N`) makes the
/// equations stiff as it vanishes (the direction turns at a rate `|f| / |v_c|`), so the steps
/// shrink with it and it would never be reached by steps alone.
fn slide_events<T: Real>(
    scene: &RollingScene<T>,
    t: T,
    y: &SlideState<T>,
    dir: [T; 2],
    armed: bool,
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
        reversed
    };
    [
        (y[0] * y[0] + y[1] * y[1]) / (rim * rim) - T::ONE,
        stuck / speed_ref,
        -f.normal_m_s2 / reference,
    ]
}

pub(crate) fn stuck_m_s<T: Real>(speed_ref: T) -> T {
    T::from_f64(STUCK) * T::EPSILON * speed_ref
}

pub(crate) fn max3<T: Real>(v: [T; 3]) -> T {
    v[0].max(v[1]).max(v[2])
}

/// The event of the three that fired: the one closest to zero from below (the others are
/// still negative where the first reaches zero).
pub(crate) fn fired<T: Real>(v: &[T]) -> usize {
    let mut best = 0;
    for i in 1..v.len() {
        if v[i] > v[best] {
            best = i;
        }
    }
    best
}

/// Scales of a scene: `refs`, the acceleration and speed that make the events dimensionless,
/// and `scales`, the length and speed of the integrator's tolerances (see [`segment`]).
pub(crate) fn scene_scales<T: Real>(scene: &RollingScene<T>) -> ((T, T), (T, T)) {
    let rim = scene.rim_radius_m;
    let spin = scene.combined_speed_rad_s();
    let w1l = scene.precession_rad_s * scene.precession_rad_s * scene.rod_length_m;
    // Scales that make the events dimensionless: accelerations and speeds of the scene.
    let reference = scene.g_m_s2 + spin * spin * rim + w1l + T::ONE;
    let refs = (reference, (reference * rim).sqrt());
    (refs, (rim, rim * spin.max(T::ONE)))
}

fn dot<T: Real, const N: usize>(a: &[T; N], b: &[T; N]) -> T {
    a.iter().zip(b).fold(T::ZERO, |acc, (x, y)| acc + *x * *y)
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
fn slip_error<T: Real, const N: usize>(
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

/// Integrates one segment in `mode` from `(t0, y0)` with the method, stopping at the first
/// event, and adds its cost and its time to `tally`: the event's time and state, or `None` at
/// the horizon. `slip`: a slide's slip, held to [`slip_error`]'s tolerance besides the
/// components' (`None` where the contact does not slip).
#[allow(clippy::too_many_arguments)]
pub(crate) fn segment<T: Real, const N: usize>(
    tally: &mut Tally<T>,
    mode: Mode,
    rhs: impl FnMut(T, &[T; N]) -> [T; N],
    (t0, y0): (T, [T; N]),
    method: RollingMethod<T>,
    scales: (T, T),
    event: impl Fn(T, &[T; N]) -> T,
    check: impl FnMut(T, &[T; N]) -> ControlFlow<()>,
    slip: Option<SlipOf<'_, T, N>>,
    limits: SystemLimits<T>,
) -> Result<Option<(T, [T; N])>, RollingError> {
    let (length, speed) = scales;
    let event = system::timed(event);
    let run = match method {
        RollingMethod::Dp54 { rtol } => {
            // Lengths, velocities and spins at their own scales (as the rolling model's runs).
            let atol: [T; N] =
                core::array::from_fn(|i| if i < 2 { rtol * length } else { rtol * speed });
            let h0 = T::from_f64(1e-3) * length / speed;
            let slip_error = |e: &[T; N], y: &[T; N], y1: &[T; N]| {
                slip.map_or(T::ZERO, |slip| slip_error(slip, rtol, (e, y, y1)))
            };
            system::dp54_with(
                rhs,
                t0,
                y0,
                (rtol, atol),
                h0,
                &event,
                check,
                slip_error,
                limits,
            )
        }
        RollingMethod::Rk4 { step_s } => {
            system::rk4_with(rhs, t0, y0, step_s, &event, check, limits)
        }
    }
    .map_err(RollingError::Integration)?;
    tally.evaluations = tally.evaluations.saturating_add(run.evaluations);
    tally.steps = tally.steps.saturating_add(run.steps);
    match run.ended {
        Ended::Event { t, y } => {
            tally.spend(mode, t - t0);
            Ok(Some((t, y)))
        }
        Ended::Horizon { .. } => {
            tally.spend(mode, limits.horizon_s - t0);
            Ok(None)
        }
        // The check gave up on the run (a stall: [`StallWatch`]).
        Ended::Stopped { .. } => Err(RollingError::Integration(SystemError::Stalled)),
    }
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
    let reference = refs.0;
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
    let watch = StallWatch::new(stall_steps, scales, t0);
    loop {
        let remaining = report.tally.remaining(limits, MAX_SWITCHES)?;
        let (ended, which) = match next_mode(scene, t, &y, must_slide) {
            Next::LiftsOff => {
                report.outcome = ModesOutcome::LiftsOff { time_s: t };
                report.end_state = y;
                return Ok(report);
            }
            Next::Roll(yr) => {
                report.tally.enter(&mut previous, Mode::Roll);
                let Some((te, ye)) = segment(
                    &mut report.tally,
                    Mode::Roll,
                    |t, y: &[T; 5]| forces(scene, t, y).derivative,
                    (t, yr),
                    method,
                    scales,
                    |t, y: &[T; 5]| max3(roll_events(scene, t, y, reference)),
                    |t, _| watch.step(t),
                    None,
                    remaining,
                )?
                else {
                    return Ok(report);
                };
                let which = fired(&roll_events(scene, te, &ye, reference));
                ((te, from_rolling(&ye), ye[2], ye[3]), which)
            }
            Next::Slide(ys, dir0) => {
                report.tally.enter(&mut previous, Mode::Slide);
                let dir = Cell::new(dir0);
                let slip0 = slip_m_s(&ys);
                let stuck = stuck_m_s(refs.1);
                let armed = Cell::new(
                    slip0[0] * slip0[0] + slip0[1] * slip0[1] > T::from_f64(4.0) * stuck * stuck,
                );
                let Some((te, ye)) = segment(
                    &mut report.tally,
                    Mode::Slide,
                    |t, y: &SlideState<T>| slide_forces(scene, t, y, dir.get()).derivative,
                    (t, ys),
                    method,
                    scales,
                    |t, y: &SlideState<T>| {
                        max3(slide_events(scene, t, y, dir.get(), armed.get(), refs))
                    },
                    |t, y: &SlideState<T>| {
                        follow_slip(&slip_m_s(y), &dir, &armed, stuck);
                        watch.step(t)
                    },
                    Some(SlipOf::Linear(slip_m_s::<T>)),
                    remaining,
                )?
                else {
                    return Ok(report);
                };
                let events = slide_events(scene, te, &ye, dir.get(), armed.get(), refs);
                let mut ye = ye;
                if fired(&events) == 1 {
                    // The slip is zero here to the location's accuracy: make it
                    // exactly so (rolling), keeping the translation.
                    ye[4] = -ye[3];
                    ye[5] = ye[2];
                }
                ((te, ye, ye[2], ye[3]), fired(&events))
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

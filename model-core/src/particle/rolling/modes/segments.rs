//! One segment of a run between changes of mode, shared by the bottom's run and the wall's
//! (`bowl::wall_run`): integrated by the project's integrators ([`crate::ode::system`]) until
//! its first event, with the scene's scales for the tolerances and the events, and which of the
//! events fired.

use core::ops::ControlFlow;

use super::report::{Mode, Tally};
use super::slip::{GRADED_SPAN, SlipOf, Stop, graded_step, slip_error};
use crate::Real;
use crate::ode::system::{self, Ended, SystemError};
use crate::particle::rolling::{RollingError, RollingMethod, RollingScene, SystemLimits};

pub(crate) fn max3<T: Real>(v: [T; 3]) -> T {
    v[0].max(v[1]).max(v[2])
}

pub(crate) fn max4<T: Real>(v: [T; 4]) -> T {
    max3([v[0], v[1], v[2]]).max(v[3])
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

/// Integrates one segment in `mode` from `(t0, y0)` with the method, stopping at the first
/// event, and adds its cost and its time to `tally`: the event's time and state, or `None` at
/// the horizon; the flag says the check stopped it there with the slide settled
/// ([`super::slip::Settle`]: the slip at rest, as where the slip-end event fires) or a roll
/// restarted from a hold under way ([`Stop::Started`]). `slip`: a
/// slide's slip, held to [`slip_error`]'s tolerance besides the
/// components' by DP5(4), and near which RK4 grades its steps ([`graded_step`]) (`None` where
/// the contact does not slip).
#[allow(clippy::too_many_arguments)]
pub(crate) fn segment<T: Real, const N: usize>(
    tally: &mut Tally<T>,
    mode: Mode,
    rhs: impl FnMut(T, &[T; N]) -> [T; N],
    (t0, y0): (T, [T; N]),
    method: RollingMethod<T>,
    scales: (T, T),
    event: impl Fn(T, &[T; N]) -> T,
    check: impl FnMut(T, &[T; N]) -> ControlFlow<Stop>,
    slip: Option<SlipOf<'_, T, N>>,
    limits: SystemLimits<T>,
) -> Result<Option<(T, [T; N], bool)>, RollingError> {
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
            // A slide's steps graded near its slip's zeros ([`graded_step`]).
            let span = T::from_f64(GRADED_SPAN) * length / speed;
            let graded = |_: T, y: &[T; N], dy: &[T; N]| {
                slip.map_or(step_s, |slip| graded_step(slip, step_s, span, y, dy))
            };
            system::rk4_graded(rhs, t0, y0, step_s, graded, &event, check, limits)
        }
    }
    .map_err(RollingError::Integration)?;
    tally.evaluations = tally.evaluations.saturating_add(run.evaluations);
    tally.steps = tally.steps.saturating_add(run.steps);
    match run.ended {
        Ended::Event { t, y } => {
            tally.spend(mode, t - t0);
            Ok(Some((t, y, false)))
        }
        Ended::Stopped {
            t,
            y,
            why: Stop::Settled | Stop::Started | Stop::Realign,
        } => {
            tally.spend(mode, t - t0);
            Ok(Some((t, y, true)))
        }
        Ended::Horizon { .. } => {
            tally.spend(mode, limits.horizon_s - t0);
            Ok(None)
        }
        // The check gave up on the run (a stall: [`super::StallWatch`]).
        Ended::Stopped {
            why: Stop::Stalled, ..
        } => Err(RollingError::Integration(SystemError::Stalled)),
    }
}

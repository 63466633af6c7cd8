//! The watch that gives up on a run that makes no progress: a run stuck at a slide/roll switch
//! takes steps of ~1e-16 s forever, and is better reported as stalled
//! (`SystemError::Stalled`) than followed to its step limit (docs/model.md §12).

use core::cell::Cell;
use core::ops::ControlFlow;

use super::slip::{Stop, graded_floor};
use crate::Real;
use crate::particle::rolling::RollingMethod;

/// A step that advances the time by less than this fraction of the scene's time scale (its
/// length over its speed, `1 / max(|Omega|, 1 rad/s)`: 0.1-1 s) makes no progress. A real
/// step, even one cut short to locate an event, is far longer at rtol 1e-6 to 1e-10; a run
/// stalled at a slide/roll switch takes steps of ~1e-16 s (docs/model.md §12).
pub const STALL_STEP: f64 = 1e-9;

/// Watches a segment's accepted steps for a stall: `steps` in a row, each shorter than
/// [`STALL_STEP`] of the time scale (`None`: never), and for RK4 shorter than half its graded
/// floor too ([`graded_floor`]).
pub(crate) struct StallWatch<T> {
    steps: Option<u32>,
    dt: T,
    last_t: Cell<T>,
    run: Cell<u32>,
}

impl<T: Real> StallWatch<T> {
    /// A watch from `t0` at the scene's `scales` (length, speed) over a run by `method`. RK4
    /// takes steps down to [`graded_floor`] of its own accord, near a zero of a slide's slip
    /// ([`super::slip::graded_step`]), and they grow away from it: progress, however short.
    /// At h = 16 us its first steps from a release at rest were below [`STALL_STEP`] of the
    /// scene's time scale for more than 16 steps, and `bowl predict --method rk4` gave up on
    /// five releases of the lift-off scene of the bowl's work-precision chart (docs/model.md
    /// §10); only shorter steps, which events at a segment's start make, are no progress.
    pub(crate) fn new(steps: Option<u32>, scales: (T, T), t0: T, method: RollingMethod<T>) -> Self {
        let dt = T::from_f64(STALL_STEP) * scales.0 / scales.1;
        let dt = match method {
            RollingMethod::Rk4 { step_s } => dt.min(T::HALF * graded_floor(step_s)),
            RollingMethod::Dp54 { .. } => dt,
        };
        Self {
            steps,
            dt,
            last_t: Cell::new(t0),
            run: Cell::new(0),
        }
    }

    /// After an accepted step to `t`: break once the run of tiny steps is long enough.
    pub(crate) fn step(&self, t: T) -> ControlFlow<()> {
        if self.tiny_run(t) {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }

    /// [`Self::step`] as a segment's check.
    pub(crate) fn check(&self, t: T) -> ControlFlow<Stop> {
        if self.tiny_run(t) {
            ControlFlow::Break(Stop::Stalled)
        } else {
            ControlFlow::Continue(())
        }
    }

    fn tiny_run(&self, t: T) -> bool {
        let Some(n) = self.steps else {
            return false;
        };
        let tiny = (t - self.last_t.get()).abs() < self.dt;
        self.last_t.set(t);
        let run = if tiny { self.run.get() + 1 } else { 0 };
        self.run.set(run);
        run >= n
    }
}

//! The watch that gives up on a run that makes no progress: a run stuck at a slide/roll switch
//! takes steps of ~1e-16 s forever, and is better reported as stalled
//! (`SystemError::Stalled`) than followed to its step limit (docs/model.md §12).

use core::cell::Cell;
use core::ops::ControlFlow;

use super::slip::Stop;
use crate::Real;

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

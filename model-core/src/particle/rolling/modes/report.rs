//! What a run of modes gives: how the granule moves ([`Mode`]), the time it spent in each
//! ([`Regime`]), how the release ended ([`ModesOutcome`]) and what the run cost ([`Tally`]),
//! together a [`ModesReport`]. The bottom's run and the wall's (`bowl::wall_run`) fill the same
//! tally, so a release that crosses between them is counted as one.

use crate::Real;
use crate::ode::system::SystemError;
use crate::particle::rolling::slide::SlideState;
use crate::particle::rolling::{RollingError, SystemLimits};

/// How the granule moves on the bottom.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Mode {
    /// Rolling without slip.
    Roll,
    /// Sliding: the contact point slips.
    Slide,
    /// At rest, held there by the rolling resistance (and static friction).
    Held,
}

/// The time a release spent in each mode, s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Regime<T> {
    /// Rolling, s.
    pub roll_s: T,
    /// Sliding, s.
    pub slide_s: T,
    /// Held at rest on the bottom by the rolling resistance, s.
    pub held_s: T,
}

impl<T: Real> Regime<T> {
    /// Each mode's share of the time, rolling, sliding and held (0s for a release that never
    /// moved).
    pub fn shares(&self) -> (T, T, T) {
        let total = self.roll_s + self.slide_s + self.held_s;
        if total > T::ZERO {
            (
                self.roll_s / total,
                self.slide_s / total,
                self.held_s / total,
            )
        } else {
            (T::ZERO, T::ZERO, T::ZERO)
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
    /// The mode entered last (`None`: none yet): at the horizon, whether the granule is held.
    pub last: Option<Mode>,
}

impl<T: Real> Tally<T> {
    /// Nothing spent yet.
    pub(crate) fn new() -> Self {
        Self {
            regime: Regime {
                roll_s: T::ZERO,
                slide_s: T::ZERO,
                held_s: T::ZERO,
            },
            switches: 0,
            evaluations: 0,
            steps: 0,
            last: None,
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
        self.last = Some(mode);
    }

    /// Adds `dt` to the time in `mode`.
    pub(crate) fn spend(&mut self, mode: Mode, dt: T) {
        match mode {
            Mode::Roll => self.regime.roll_s += dt,
            Mode::Slide => self.regime.slide_s += dt,
            Mode::Held => self.regime.held_s += dt,
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

//! What one release in the bowl gives ([`BowlReport`]) and, for one still inside at the
//! horizon, where it is held at rest ([`HeldAt`]).

use super::BowlOutcome;
use crate::Real;
use crate::particle::rolling::modes::{Regime, Tally};

/// Where a granule still inside at the horizon is held at rest: the words of `bowl predict`
/// ("held by the wall", "held on the fillet", "held at rest on the bottom") and its JSON's
/// `held_at`. Before, only a vertical wall's sharp corner was reported held; a granule the
/// rolling resistance held on the fillet or the bottom was "still inside", as if it moved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum HeldAt {
    /// On the flat bottom (the rolling resistance and static friction hold it).
    Bottom,
    /// On the fillet between the bottom and the wall.
    Fillet,
    /// On the wall's cone, or in its sharp corner (vertical or flared).
    Wall,
}

/// One release in the bowl.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BowlReport<T> {
    /// The outcome.
    pub outcome: BowlOutcome<T>,
    /// Time rolling and sliding (bottom and wall), s.
    pub regime: Regime<T>,
    /// Time on the fillet and the wall, s.
    pub on_wall_s: T,
    /// Time held at rest in a vertical wall's sharp corner, up to the horizon, s.
    pub held_s: T,
    /// Where a release still inside at the horizon is held at rest there (`None`: it is still
    /// moving, or it has left).
    pub held_at: Option<HeldAt>,
    /// Time in flight, s.
    pub flight_s: T,
    /// Whether it left in flight (its centre passed the lip while flying, e.g. off the lip's
    /// edge) rather than in contact (rolling or sliding over the lip or a bare rim).
    pub left_in_flight: bool,
    /// Landings (impacts after a flight).
    pub landings: u32,
    /// Changes of contact (roll/slide) and of surface (bottom/wall).
    pub switches: u32,
    /// Right-hand sides.
    pub evaluations: u32,
    /// Accepted steps.
    pub steps: u32,
}

impl<T: Real> BowlReport<T> {
    /// A release still inside at `horizon_s` that has spent no time yet.
    pub(super) fn new(horizon_s: T) -> Self {
        Self {
            outcome: BowlOutcome::Inside { horizon_s },
            regime: Regime {
                roll_s: T::ZERO,
                slide_s: T::ZERO,
                held_s: T::ZERO,
            },
            on_wall_s: T::ZERO,
            held_s: T::ZERO,
            held_at: None,
            flight_s: T::ZERO,
            left_in_flight: false,
            landings: 0,
            switches: 0,
            evaluations: 0,
            steps: 0,
        }
    }

    /// Adds a stay's time in each mode, changes and cost.
    pub(super) fn add(&mut self, stay: &Tally<T>) {
        self.regime.roll_s += stay.regime.roll_s;
        self.regime.slide_s += stay.regime.slide_s;
        self.regime.held_s += stay.regime.held_s;
        self.switches = self.switches.saturating_add(stay.switches);
        self.evaluations = self.evaluations.saturating_add(stay.evaluations);
        self.steps = self.steps.saturating_add(stay.steps);
    }
}

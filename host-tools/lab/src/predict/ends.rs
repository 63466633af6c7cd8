//! How a prediction ends, with a leaving granule's numbers in one named value: the one place
//! [`Outcome::Leaves`] is taken apart (the JSON, the text and the batch's CSV each format
//! [`Leaves`]) and put together (an integrator's answer, [`Leaves::into`]).

use model_core::particle::Outcome;

/// The numbers of a granule that leaves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Leaves {
    /// Residence time `T`, s.
    pub residence_time_s: f64,
    /// Radial velocity at the rim, m/s.
    pub exit_radial_velocity_m_s: f64,
    /// Total exit speed, m/s.
    pub exit_total_velocity_m_s: f64,
    /// Relative condition number of `T` (the problem's, whatever the method).
    pub condition_number: f64,
    /// More than half of `T`'s digits may be lost.
    pub ill_conditioned: bool,
}

/// [`Outcome`] with [`Leaves`] for its leaving case.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Ends {
    /// The granule reaches the rim.
    Leaves(Leaves),
    /// It starts at (or beyond) the rim: `T = 0`.
    AtRim {
        /// `omega R`, m/s.
        exit_total_velocity_m_s: f64,
    },
    /// Friction holds it.
    Never {
        /// `a = mu g / omega^2`, m.
        equilibrium_radius_m: f64,
        /// Within rounding of the threshold.
        near_threshold: bool,
    },
}

impl From<Outcome<f64>> for Ends {
    fn from(o: Outcome<f64>) -> Self {
        match o {
            Outcome::Leaves {
                residence_time_s,
                exit_radial_velocity_m_s,
                exit_total_velocity_m_s,
                condition_number,
                ill_conditioned,
            } => Ends::Leaves(Leaves {
                residence_time_s,
                exit_radial_velocity_m_s,
                exit_total_velocity_m_s,
                condition_number,
                ill_conditioned,
            }),
            Outcome::AlreadyAtRim {
                exit_total_velocity_m_s,
            } => Ends::AtRim {
                exit_total_velocity_m_s,
            },
            Outcome::NeverLeaves {
                equilibrium_radius_m,
                near_threshold,
            } => Ends::Never {
                equilibrium_radius_m,
                near_threshold,
            },
        }
    }
}

impl From<Leaves> for Outcome<f64> {
    fn from(l: Leaves) -> Self {
        Outcome::Leaves {
            residence_time_s: l.residence_time_s,
            exit_radial_velocity_m_s: l.exit_radial_velocity_m_s,
            exit_total_velocity_m_s: l.exit_total_velocity_m_s,
            condition_number: l.condition_number,
            ill_conditioned: l.ill_conditioned,
        }
    }
}

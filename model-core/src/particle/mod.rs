//! A sphere rolling outward in the spinning bowl: paper Eq. 5 to 12, corrected as in
//! docs/model.md.
//!
//! The particle starts at rest at radius `ri_m` on a bowl turning at `omega_rad_s`; the
//! centrifugal term pushes it out, an *effective rolling resistance* `mu` (times `g`) holds it
//! back, and in the [`Model::Coriolis`] model the Coriolis force, pressing the rolling sphere
//! against the bowl, adds a friction `2 mu omega r'`. It leaves at the rim radius
//! `rim_radius_m` after the residence time `T`.
//!
//! * [`residence`]: `T` and the exit velocities, as an explicit [`Outcome`] (leaves / already at
//!   the rim / never leaves) with a condition number, never NaN.
//! * [`residence_time_s`]: `T` alone (telemetry, RTIME); [`residence_times_s`]: the same for a
//!   batch of scenes, at a higher host throughput (`bowl predict --batch --throughput`).
//! * [`position_m`], [`radial_velocity_m_s`]: `r(t)` and `r'(t)` (paper Eq. 6, 7, 10, 11).
//! * [`omega_for_residence_time`]: the inverse, the bowl speed that gives a target `T`.
//!
//! # The resistance coefficient
//! The paper uses a *sliding* friction coefficient 0.4 in a *rolling* model; with it the
//! equilibrium radius `a = mu g / omega^2` exceeds every bowl and nothing ever leaves. We name the
//! coefficient for what the model needs, an effective rolling resistance, and default it to the
//! paper's own "correction factor" 0.029 (docs/model.md §5, "The parameter problem"); 0.4 stays
//! reachable and then gives [`Outcome::NeverLeaves`].
//!
//! The pieces: `scene.rs` (the scene and its checks), `residence_time.rs` (`T` and the exit, one
//! scene or a batch), `trajectory.rs` (`r(t)`, `r'(t)`); the models' own solvers are `flat.rs`
//! and `coriolis.rs` (with `flat_batch.rs`, `coriolis_batch.rs` and `batch.rs` for batches),
//! `inverse.rs` the inverse.

mod batch;
pub mod bowl;
mod coriolis;
mod coriolis_batch;
mod flat;
mod flat_batch;
mod inverse;
pub mod named_scenes;
mod phi;
pub(crate) mod radial;
mod residence_time;
pub mod rolling;
mod scene;
mod shape;
pub mod speed_table;
mod trajectory;

pub use inverse::{InverseError, omega_for_residence_time};
pub use radial::{OdeError, integrate, integrate_constant};
pub(crate) use residence_time::{Before, Exit, before_model, condition, finite_time};
pub use residence_time::{Outcome, residence, residence_time_s, residence_times_s};
pub use scene::{Input, Scene, SceneError, magnitude_limits};
pub(crate) use shape::{Shape, ShapeAt};
pub use trajectory::{position_m, radial_velocity_m_s};

use phi::phi_expm1;

/// Which equation of motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Model {
    /// Paper Eq. 5: `r'' = k2 (r omega^2 - mu g)`; solution Eq. 6, 7 (correct in the paper).
    Flat,
    /// Paper Eq. 9: `r'' = k2 (r omega^2 - mu g - 2 mu omega r')`; solution Eq. 10, 11 with the
    /// corrected coefficients `A = (1 + k mu/s)/2`, `B = (1 - k mu/s)/2` (the paper prints 0.5
    /// and 0.45, which break `r(0) = ri`).
    Coriolis,
}

#[cfg(test)]
mod precision_tests;
#[cfg(test)]
pub(crate) mod tests;

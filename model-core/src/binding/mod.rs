//! The one binding of the controller ([`crate::control`]) and the particle model
//! ([`crate::particle`]) to the serial protocol's device interface
//! ([`crate::wire::device::Backend`]). No heap, no hardware: the Black Pill firmware, the
//! emulated board under QEMU and the host's virtual rig all run this code; each supplies only
//! what is its own (the motors and sensors or a simulated plant, and an [`Injector`] for INJECT).
//!
//! - [`configure`]: wire parameters (the table in [`crate::wire::params`]) to the controller's
//!   configuration and the particle scene, and when each may change;
//! - [`record`]: the layout of the record persisted in flash (parameters and motor models);
//! - [`backend`]: [`ControllerBackend`], the controller and the scene behind the protocol.
//!
//! It depends on [`crate::wire`], [`crate::control`] and [`crate::particle`], never on the
//! simulator: commissioning on a simulated plant is `crate::sim::assembly`, and a simulated
//! granule's bowl in wire parameters `crate::sim::granule::ParticleParams::describe_bowl`.
//!
//! The parameters in force are kept in wire units (what SET sent is what PARAMS reports,
//! exactly), and the controller's configuration is derived from them. A value the scene check
//! or the controller's validation refuses is rejected with `RANGE` (or `STATE` when the
//! controller is busy) and changes nothing.

pub mod backend;
pub mod configure;
pub mod record;

pub use backend::ControllerBackend;
pub use configure::{
    OVERSPEED_PER_MAX, ParamRole, TABLE_PARAMS, config_from_params, default_params,
    scene_from_params, table_from_params, table_to_params,
};
pub use record::{
    PERSISTED_COUNT, Persisted, Record, default_persisted, persisted, split_persisted,
};

use crate::wire::{GateEvent, Injection, Reason};

/// Motor axes: precession (0) and spin (1).
pub const AXES: usize = 2;

/// Where fault injections and granule releases go: the simulated world of an emulated board or
/// a virtual rig; on real hardware injections go nowhere.
pub trait Injector {
    /// Applies `what` or says why not.
    fn inject(&mut self, what: Injection) -> Result<(), Reason>;
    /// Drops one granule (RELEASE): a simulated granule, or the real rig's release solenoid.
    /// A rig without one refuses.
    fn release(&mut self) -> Result<(), Reason> {
        Err(Reason::Unsupported)
    }
    /// The oldest gate event (release trigger, exit light gate) not yet sent.
    fn gate_event(&mut self) -> Option<GateEvent> {
        None
    }
}

/// Real hardware: nothing can be injected.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoInjection;

impl Injector for NoInjection {
    fn inject(&mut self, _what: Injection) -> Result<(), Reason> {
        Err(Reason::Unsupported)
    }
}

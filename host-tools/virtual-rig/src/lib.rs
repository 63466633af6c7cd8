//! The virtual rig: the rig without hardware, in layers, one name each.
//!
//! - `model_core::sim::Plant`: the simulated motors, shafts and sensors (model-core; every
//!   simulated rig runs it).
//! - [`World`] (`world.rs`): what surrounds the plant at a real rig: injected faults and the
//!   granules RELEASE drops, timed by the two gates.
//! - [`SimulatedBackend`] (`backend.rs`): plant + controller, the controller bound to the
//!   protocol's parameters as the firmware binds it (`model_core::binding`), with its world: the
//!   protocol's backend. (`model_core::sim::ClosedLoop` is the bare plant + controller the
//!   reports drive without the protocol.)
//! - [`VirtualRig`] (`rig.rs`): plant + controller + the protocol device, advanced one
//!   millisecond at a time: bytes in, bytes out.
//! - `serve.rs`: the virtual rig on a pseudo-terminal (real time or faster) or into a capture
//!   file, with optional line noise.
//!
//! `controller_words.rs`: the controller's refusals and states in words.

pub mod backend;
pub mod controller_words;
pub mod rig;
pub mod serve;
pub mod world;

pub use backend::SimulatedBackend;
pub use rig::VirtualRig;
pub use world::World;

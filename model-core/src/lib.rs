//! Pure logic of the bowl granulation rig: `no_std`, no heap, no panics on any finite input.
//!
//! The physics follows the paper "The Coriolis Effect on Spherical Particles Inside the Bowl"
//! with the corrections of `docs/model.md`; every formula cites the paper's equation.
//! SI units throughout; names carry the unit (`omega_rad_s`, `radius_m`).
//!
//! The same code runs on the host (f64 for analysis, f32 to reproduce the target) and on the
//! STM32F411's Cortex-M4F (f32).
#![no_std]
#![forbid(unsafe_op_in_unsafe_fn)]
#![warn(missing_docs)]

pub mod binding;
pub mod bowl;
pub mod choose;
pub mod control;
pub mod ode;
pub mod particle;
pub mod real;
pub mod sim;
pub mod wire;

pub use real::Real;

//! Test cases and benchmarks that run unchanged on the host and on the emulated Cortex-M4F.
//!
//! `no_std` and allocation-free, so the QEMU image (`tests/qemu`) can link them. On the host,
//! `tests/host.rs` runs every case under `cargo test`; under QEMU, `qemu-tests` runs the same list,
//! reports over semihosting, and measures the instructions each benchmark executes per call.
//!
//! A case compares the code under test with an independent reference (a different formula, an
//! identity, or values written down from an independent derivation) and returns a [`Failure`]
//! that says what differed.
#![no_std]

pub mod bowl;
pub mod check;
pub mod control;
pub mod cost;
pub mod ode;
pub mod particle;
pub mod wire;

pub use check::{Bench, Case, Failure};

/// Every case, grouped by the module it tests.
pub static CASE_GROUPS: &[&[Case]] = &[
    bowl::CASES,
    particle::CASES,
    ode::CASES,
    control::CASES,
    wire::CASES,
];

/// Every benchmark, grouped likewise.
pub static BENCH_GROUPS: &[&[Bench]] = &[
    bowl::BENCHES,
    particle::BENCHES,
    ode::BENCHES,
    cost::BENCHES,
    control::BENCHES,
    wire::BENCHES,
    cost::ODE_BENCHES,
];

/// All cases in one iterator.
pub fn all_cases() -> impl Iterator<Item = &'static Case> {
    CASE_GROUPS.iter().flat_map(|g| g.iter())
}

/// All benchmarks in one iterator.
pub fn all_benches() -> impl Iterator<Item = &'static Bench> {
    BENCH_GROUPS.iter().flat_map(|g| g.iter())
}

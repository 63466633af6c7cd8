//! The application logic, free of any HAL: the same code runs on the Black Pill and on the
//! emulated board. A board supplies the [`hal`] traits; [`tasks`] are the async loops that
//! the board's executor runs.
//!
//! - [`hal`]: the traits a board implements (motor output, capture clock, watchdog, flash
//!   region); the byte stream is `embedded_io_async`.
//! - [`binding`]: the controller + particle model behind the wire protocol (`TaskCore`).
//! - [`edges`]: the queue from the pulse-capture interrupt/task to the control tick.
//! - [`gates`]: a real board's release trigger and exit light gate, debounced, as gate events.
//! - [`params`]: parameters persisted in flash (version + CRC-32, append-only records).
//! - [`persist`]: the loop that saves changed parameters and reports lost capture edges.
//! - [`reset`]: reset cause and a reset counter that survives resets in uninitialised RAM.
//! - [`led`]: the status LED's pattern for each state (idle, driving, fault, link lost).
//! - [`motors`]: the pair of motor outputs and the all-off path used by faults and panics.
//! - [`tasks`]: capture, control tick, link (telemetry + commands), supervisor.

pub mod binding;
pub mod edges;
pub mod gates;
pub mod hal;
pub mod led;
pub mod motors;
pub mod params;
pub mod persist;
pub mod reset;
pub mod slot;
pub mod tasks;

#[cfg(test)]
mod test_flash;

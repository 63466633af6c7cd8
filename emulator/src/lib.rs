//! The PC side of an emulated board, in one place: building the firmware's emulator images
//! ([`image`]), starting the emulator ([`qemu`]: one launcher, named timing profiles), and the
//! harness around a running board ([`board`]: its link on a socket, [`splitter`]: that link
//! shared between the telemetry decoder and `bowl` commands, [`plant_log`]: the simulated
//! plant's own record). The demo (`bowl demo`), the firmware's end-to-end tests
//! (`firmware/tests/`) and the benchmark runner (`tests/qemu-run`, through the `bowl-emulator`
//! command) all start emulators through this crate.
//!
//! One module per emulator: [`qemu`] runs the `qemu-*` images on QEMU's netduinoplus2;
//! [`blackpill`] runs the exact Black Pill image on an emulated STM32F411.

pub mod blackpill;
pub mod board;
pub mod image;
pub mod plant_log;
pub mod process;
pub mod qemu;
pub mod splitter;
pub mod workspace;

/// The emulators the project runs its images on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Emulator {
    /// QEMU netduinoplus2 (an STM32F405: the F411's Cortex-M4F and memory map, more of both),
    /// running the firmware's `qemu-*` images ([`qemu`]).
    Qemu,
    /// The exact Black Pill image on an emulated STM32F411 (qiling, [`blackpill`]).
    Blackpill,
}

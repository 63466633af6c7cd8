//! Bowl rig controller firmware: the application logic, HAL-free, and one board layer per feature.
//!
//! - [`app`]: the tasks (pulse capture, control tick, telemetry, commands, supervisor) written
//!   against small traits (a motor output, an edge source, a byte stream, a watchdog, a
//!   parameter store), so the same code runs on the STM32F411 and on the emulated board.
//! - `blackpill` (feature `blackpill`): the STM32F411CE Black Pill's peripherals via embassy-stm32.
//! - `qemu` (feature `qemu`): QEMU netduinoplus2: SysTick time driver, WFI executor, raw USART.
//!
//! The PC side of the emulated board (building its images, QEMU, sharing its link) is the
//! `bowl-emulator` crate (`emulator/`).
#![cfg_attr(not(test), no_std)]
#![warn(missing_docs)]

pub mod app;

#[cfg(feature = "blackpill")]
pub mod blackpill;
#[cfg(feature = "qemu")]
pub mod qemu;

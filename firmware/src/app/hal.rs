//! The traits a board implements. Small on purpose: each is one peripheral's job.
//! (Edge timestamps arrive through [`super::edges::EdgeQueue`], filled by the board; the byte
//! stream is `embedded_io_async::{Read, Write}`.)

/// One motor's PWM output with its direction input on the H-bridge.
pub trait MotorOutput {
    /// Drives the motor at `duty` in -1..=1: the magnitude sets the PWM compare value, the sign
    /// the direction pin. Values outside the range, and NaN, are treated as 0 (off).
    fn set_duty(&mut self, duty: f32);
    /// PWM compare to 0 at once: the bridge input goes low (coast on a PWM/DIR bridge).
    fn off(&mut self);
    /// A fault: the output stage itself is disabled (on the STM32 the timer's main output
    /// enable), not only the compare value, so no later compare write can drive the bridge
    /// until a non-zero duty is set again after the fault is cleared.
    fn disable(&mut self) {
        self.off();
    }
}

/// The power stage around the bridges: the hardware stop (on the STM32 TIM1's break input,
/// which switches the PWM off without the CPU), the motor supply switch (a relay or high-side
/// switch whose enable is off without power: fail-safe) and the bridges' current sense.
pub trait PowerStage {
    /// The latest sample of each motor's current, A, signed in the motor's forward direction,
    /// taken in step with the PWM; None where the board measures none.
    fn currents_a(&mut self) -> [Option<f32>; 2];
    /// Whether the hardware stop has tripped since the last call, or its line is still active.
    /// The PWM is already off when this says so; the caller latches the fault.
    fn stop_tripped(&mut self) -> bool;
    /// Closes (`true`) or opens the motor supply switch.
    fn set_supply(&mut self, on: bool);
}

/// A board without a hardware stop, a supply switch or current sense (the QEMU board, the
/// host): never trips, measures nothing.
pub struct NoPowerStage;

impl PowerStage for NoPowerStage {
    fn currents_a(&mut self) -> [Option<f32>; 2] {
        [None; 2]
    }
    fn stop_tripped(&mut self) -> bool {
        false
    }
    fn set_supply(&mut self, _on: bool) {}
}

/// The free-running timer the edge timestamps come from.
pub trait CaptureClock {
    /// The timer's current value (same units and wrap as the edge timestamps).
    fn now_ticks(&self) -> u32;
}

/// The independent watchdog: resets the MCU unless fed in time.
pub trait Watchdog {
    /// Restarts the watchdog's countdown.
    fn feed(&mut self);
}

/// A flash region reserved for parameter records: `SECTORS` sectors of `SECTOR_SIZE` bytes,
/// each erased on its own.
pub trait FlashRegion {
    /// Bytes per erasable sector (a multiple of 4).
    const SECTOR_SIZE: u32;
    /// Sectors in the region (at least 2, so one always holds the last record while the other
    /// is erased).
    const SECTORS: u32;
    /// Reads `buf.len()` bytes at `offset`.
    fn read(&mut self, offset: u32, buf: &mut [u8]) -> Result<(), FlashError>;
    /// Programs `data` (a multiple of 4 bytes, into erased words) at `offset` (4-aligned).
    fn write(&mut self, offset: u32, data: &[u8]) -> Result<(), FlashError>;
    /// Erases sector `sector` (0-based; all its bytes 0xFF). Slow: the caller keeps the motors
    /// off.
    fn erase(&mut self, sector: u32) -> Result<(), FlashError>;
}

/// A flash operation that failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "blackpill", derive(defmt::Format))]
pub enum FlashError {
    /// Offset or length outside the region, or not 4-aligned.
    OutOfBounds,
    /// The flash controller reported an error (programming, erase or protection).
    Hardware,
}

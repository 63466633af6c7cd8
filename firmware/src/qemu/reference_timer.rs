//! QEMU's model of TIM2 (`stm32f2xx_timer`) as an independent clock: its counter is computed by
//! QEMU from the virtual clock in nanoseconds, not from SysTick, so the platform test can check
//! the embassy time driver against it.
//!
//! Measured on QEMU 10.0: the model counts at 1 GHz / (PSC + 1) of virtual time (2e6 executed
//! instructions at `-icount shift=0` read 41 692 counts with PSC = 47, i.e. 1e9/48 Hz), not at the
//! 48 MHz its `clock-frequency` property suggests. Only the counter is used, never its interrupt.

const TIM2_BASE: usize = 0x4000_0000;
const CR1: *mut u32 = TIM2_BASE as *mut u32;
const PSC: *mut u32 = (TIM2_BASE + 0x28) as *mut u32;
const ARR: *mut u32 = (TIM2_BASE + 0x2C) as *mut u32;
const CNT: *mut u32 = (TIM2_BASE + 0x24) as *mut u32;
const EGR: *mut u32 = (TIM2_BASE + 0x14) as *mut u32;

/// TIM2's effective input clock in QEMU 10's STM32F405 SoC (see the module docs).
pub const INPUT_HZ: u32 = 1_000_000_000;

/// Starts TIM2 free-running at 1 MHz (prescaler 1000), 32 bits wide.
pub fn start_1mhz() {
    // SAFETY: TIM2's registers on netduinoplus2; only the platform test uses TIM2.
    unsafe {
        PSC.write_volatile(INPUT_HZ / 1_000_000 - 1);
        ARR.write_volatile(u32::MAX);
        EGR.write_volatile(1); // update event: load the prescaler now
        CNT.write_volatile(0);
        CR1.write_volatile(1);
    }
}

/// Microseconds counted by TIM2 since `start_1mhz`, modulo 2^32.
pub fn now_us() -> u32 {
    // SAFETY: see `start_1mhz`.
    unsafe { CNT.read_volatile() }
}

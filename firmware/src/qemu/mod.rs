//! The emulated board: QEMU `netduinoplus2` (STM32F405, Cortex-M4F, the F411's memory map).
//!
//! No embassy-stm32 here (QEMU has no RCC model): a SysTick time driver, a WFI executor, the
//! emulated USART1 by raw registers, and semihosting for the console and the exit status.
//! Run it with `-icount shift=0,sleep=off` (see `firmware/qemu-rig-run`).

pub mod executor;
pub mod reference_timer;
pub mod time_driver;
pub mod usart;

use cortex_m_semihosting::debug;

/// Ends the QEMU run with a pass or fail exit status (semihosting `SYS_EXIT`).
pub fn exit(success: bool) -> ! {
    debug::exit(if success {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    loop {
        cortex_m::asm::wfi();
    }
}

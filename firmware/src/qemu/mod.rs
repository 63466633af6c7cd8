//! The emulated board: QEMU `netduinoplus2` (STM32F405, Cortex-M4F, the F411's memory map).
//!
//! No embassy-stm32 here (QEMU has no RCC model): a SysTick time driver, a WFI executor, the
//! emulated USART1 by raw registers, and semihosting for the console and the exit status.
//! Run it with `-icount shift=0,sleep=off` (see `firmware/qemu-rig-run`).

pub mod executor;
pub mod gates;
pub mod plant;
pub mod ram_flash;
pub mod reference_timer;
pub mod time_driver;
pub mod usart;
pub mod watchdog;

use cortex_m_semihosting::debug;

/// Interrupts without a handler of their own land here (cortex-m-rt's `DefaultHandler`, which
/// every device interrupt points to when no device crate provides a vector table).
#[cortex_m_rt::exception]
unsafe fn DefaultHandler(irqn: i16) {
    if irqn == usart::USART1_IRQ {
        usart::on_interrupt();
    } else {
        cortex_m_semihosting::hprintln!("unexpected interrupt {}", irqn);
        exit(false);
    }
}

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

/// What a test image's panic handler does: says where, and fails the run.
pub fn fail_on_panic(info: &core::panic::PanicInfo) -> ! {
    cortex_m_semihosting::hprintln!("PANIC: {}", info);
    exit(false)
}

/// What a test image's hard-fault handler does: says where, and fails the run.
pub fn fail_on_hard_fault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
    cortex_m_semihosting::hprintln!("HARD FAULT at pc {:#010x}", frame.pc());
    exit(false)
}

/// A test image's panic and hard-fault handlers: both say where and fail the run.
#[macro_export]
macro_rules! test_image_handlers {
    () => {
        #[panic_handler]
        fn panic(info: &core::panic::PanicInfo) -> ! {
            $crate::qemu::fail_on_panic(info)
        }

        #[cortex_m_rt::exception]
        unsafe fn HardFault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
            $crate::qemu::fail_on_hard_fault(frame)
        }
    };
}

//! embassy-time driver on SysTick for the emulated board.
//!
//! QEMU's netduinoplus2 has no RCC model, so embassy-stm32's TIM-based driver cannot run there.
//! SysTick, clocked from the core clock (QEMU fixes it at 168 MHz of virtual time), interrupts
//! every [`TICK_PERIOD_US`]; the interrupt counts periods and wakes expired timers. `now()` adds
//! the sub-period part read from the down-counter, so it has 1 us resolution; alarms fire at the
//! first tick interrupt at or after their deadline (at most `TICK_PERIOD_US` late).
//!
//! QEMU's SysTick loses about 1 ns of virtual time per reload (measured against its TIM2 model:
//! 10 ppm at a 100 us period, 1 ppm at this one), so embassy time here runs that much slow;
//! exact and repeatable all the same.
//!
//! The 1 ms period is a host-time choice: every interrupt that ends a WFI costs a round trip
//! through QEMU's main loop (tens of microseconds of host time), so 10 kHz ticks made the board
//! run at about half of real time, 1 kHz ticks several times faster than real time.
//!
//! Under `-icount shift=0,sleep=off` virtual time is a fixed function of the executed instructions
//! and of idle skips to the next timer deadline, so the whole board is exact and repeatable.

use core::cell::{Cell, RefCell};
use core::task::Waker;

use cortex_m::peripheral::{SCB, SYST, syst::SystClkSource};
use cortex_m_rt::exception;
use critical_section::Mutex;
use embassy_time_driver::Driver;
use embassy_time_queue_utils::Queue;

/// SysTick input clock of QEMU's STM32F405 SoC (its `sysclk`), in virtual time.
pub const CORE_CLOCK_HZ: u32 = 168_000_000;
/// Time between SysTick interrupts: the alarm resolution.
pub const TICK_PERIOD_US: u64 = 1_000;
const CYCLES_PER_US: u32 = CORE_CLOCK_HZ / 1_000_000;
const RELOAD: u32 = CYCLES_PER_US * TICK_PERIOD_US as u32 - 1;

struct SysTickDriver {
    /// Completed SysTick periods since `start`.
    periods: Mutex<Cell<u64>>,
    /// Earliest pending alarm, in embassy ticks (us); `u64::MAX` when none.
    next_alarm: Mutex<Cell<u64>>,
    queue: Mutex<RefCell<Queue>>,
}

embassy_time_driver::time_driver_impl!(static DRIVER: SysTickDriver = SysTickDriver {
    periods: Mutex::new(Cell::new(0)),
    next_alarm: Mutex::new(Cell::new(u64::MAX)),
    queue: Mutex::new(RefCell::new(Queue::new())),
});

/// Starts SysTick as the time base. Call once, before the executor runs.
pub fn start(mut syst: SYST) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(RELOAD);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
    // `syst` was taken by value, so nothing else can reconfigure SysTick: the driver owns it.
}

impl SysTickDriver {
    fn now_in(&self, cs: critical_section::CriticalSection<'_>) -> u64 {
        let mut periods = self.periods.borrow(cs).get();
        let mut current = SYST::get_current();
        // A wrap that the interrupt has not counted yet (we are inside a critical section):
        // count it here and re-read the counter, which is then certainly past the wrap.
        if SCB::is_pendst_pending() {
            periods += 1;
            current = SYST::get_current();
        }
        let elapsed_cycles = RELOAD - current.min(RELOAD);
        periods * TICK_PERIOD_US + u64::from(elapsed_cycles / CYCLES_PER_US)
    }

    fn on_tick(&self) -> u64 {
        critical_section::with(|cs| {
            let periods = self.periods.borrow(cs);
            periods.set(periods.get() + 1);
            let now = self.now_in(cs);
            if now >= self.next_alarm.borrow(cs).get() {
                let next = self.queue.borrow(cs).borrow_mut().next_expiration(now);
                self.next_alarm.borrow(cs).set(next);
            }
            now
        })
    }
}

impl Driver for SysTickDriver {
    fn now(&self) -> u64 {
        critical_section::with(|cs| self.now_in(cs))
    }

    fn schedule_wake(&self, at: u64, waker: &Waker) {
        critical_section::with(|cs| {
            let mut queue = self.queue.borrow(cs).borrow_mut();
            if queue.schedule_wake(at, waker) {
                // Wakes what is already due now and keeps the earliest remaining deadline.
                let next = queue.next_expiration(self.now_in(cs));
                self.next_alarm.borrow(cs).set(next);
            }
        });
    }
}

#[exception]
fn SysTick() {
    let now = DRIVER.on_tick();
    super::watchdog::check(now);
}

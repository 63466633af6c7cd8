//! An emulated independent watchdog (QEMU models no IWDG): the SysTick interrupt checks the
//! deadline; when it passes, the motors go off and the run ends with a failure status, as a
//! watchdog reset would end the session on the real board.

use core::cell::Cell;

use cortex_m_semihosting::hprintln;
use critical_section::Mutex;

use crate::app::hal::Watchdog;

/// Deadline in embassy ticks (us); `u64::MAX` = not armed.
static DEADLINE: Mutex<Cell<u64>> = Mutex::new(Cell::new(u64::MAX));

/// The emulated watchdog with its timeout.
pub struct SoftWatchdog {
    timeout_us: u64,
}

impl SoftWatchdog {
    /// Arms the watchdog: it fires `timeout_us` from now unless fed.
    pub fn start(timeout_us: u64) -> Self {
        let mut w = Self { timeout_us };
        w.feed();
        w
    }
}

impl Watchdog for SoftWatchdog {
    fn feed(&mut self) {
        let deadline = embassy_time::Instant::now().as_micros() + self.timeout_us;
        critical_section::with(|cs| DEADLINE.borrow(cs).set(deadline));
    }
}

/// Called from the SysTick interrupt with the current time.
pub(crate) fn check(now_us: u64) {
    let expired = critical_section::with(|cs| now_us > DEADLINE.borrow(cs).get());
    if expired {
        super::plant::emergency_off();
        hprintln!("watchdog: fired at {} us, motors off", now_us);
        super::exit(false);
    }
}

//! Why the MCU reset, from RCC_CSR's flags (read once at boot, then cleared).

/// The reset cause as the flags tell it (most specific first).
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum ResetFlag {
    /// The independent watchdog: the control tick stopped.
    IndependentWatchdog,
    /// The window watchdog (not used by this firmware).
    WindowWatchdog,
    /// A software reset (the panic handler resets this way).
    Software,
    /// Low-power management.
    LowPower,
    /// Power-on or brown-out.
    PowerOn,
    /// The NRST pin: reset button or debug probe.
    Pin,
    /// No flag set.
    Unknown,
}

/// Reads and clears the reset flags. Call once, first thing at boot.
pub fn take() -> ResetFlag {
    let rcc = embassy_stm32::pac::RCC;
    let csr = rcc.csr().read();
    let flag = if csr.wdgrstf() {
        ResetFlag::IndependentWatchdog
    } else if csr.wwdgrstf() {
        ResetFlag::WindowWatchdog
    } else if csr.sftrstf() {
        ResetFlag::Software
    } else if csr.lpwrrstf() {
        ResetFlag::LowPower
    } else if csr.porrstf() || csr.borrstf() {
        ResetFlag::PowerOn
    } else if csr.padrstf() {
        ResetFlag::Pin
    } else {
        ResetFlag::Unknown
    };
    rcc.csr().modify(|w| w.set_rmvf(true));
    flag
}

//! Why the MCU reset, from RCC_CSR's flags (read once at boot, then cleared), told apart from a
//! debug probe's reset by a mark the firmware leaves in RAM before it resets itself.
//!
//! A probe resets the core the way the panic handler does: SYSRESETREQ in the Cortex-M's AIRCR
//! (probe-rs after flashing, `probe-rs reset`), which sets SFTRSTF (and PINRSTF: RM0383, RCC_CSR
//! and "System reset": the internal reset drives the NRST pin too). So SFTRSTF alone cannot say
//! "panic". [`software_reset`] writes a mark to `.uninit` RAM (kept across a system reset, never
//! across power-on) before it resets; SFTRSTF without the mark is the probe.

use core::mem::MaybeUninit;

/// The reset cause as the flags tell it (most specific first).
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum ResetFlag {
    /// The independent watchdog: the control tick stopped.
    IndependentWatchdog,
    /// The window watchdog (not used by this firmware).
    WindowWatchdog,
    /// The firmware reset itself ([`software_reset`]): a panic, a hard fault or a failed startup
    /// (the log line before the reset says which).
    Software,
    /// A system reset the firmware did not ask for: a debug probe's reset (probe-rs after
    /// flashing, `probe-rs reset`), through SYSRESETREQ. Reported on the wire as `Pin` (the
    /// protocol's "NRST pin: reset button, debugger").
    Debugger,
    /// Low-power management.
    LowPower,
    /// Power-on or brown-out.
    PowerOn,
    /// The NRST pin: reset button, or a probe that resets through NRST.
    Pin,
    /// No flag set.
    Unknown,
}

/// Marks a reset the firmware asked for ("SWRS" and its inverse, so RAM garbage is never
/// taken for it).
const MARK: [u32; 2] = [0x5357_5253, !0x5357_5253];

#[unsafe(link_section = ".uninit.bowl_reset_mark")]
static mut SOFTWARE_MARK: MaybeUninit<[u32; 2]> = MaybeUninit::uninit();

fn mark_slot() -> *mut [u32; 2] {
    core::ptr::addr_of_mut!(SOFTWARE_MARK).cast::<[u32; 2]>()
}

/// Reads and clears the reset flags and the firmware's own reset mark. Call once, first thing
/// at boot.
pub fn take() -> ResetFlag {
    let rcc = embassy_stm32::pac::RCC;
    let csr = rcc.csr().read();
    // SAFETY: called once at boot before any task or interrupt runs; any bit pattern is a
    // valid [u32; 2] (after power-on it is garbage, which never equals MARK by more than luck
    // of 2^-64, and POR is tested before the mark matters anyway).
    let marked = unsafe {
        let marked = mark_slot().read_volatile() == MARK;
        mark_slot().write_volatile([0, 0]);
        marked
    };
    let flag = if csr.wdgrstf() {
        ResetFlag::IndependentWatchdog
    } else if csr.wwdgrstf() {
        ResetFlag::WindowWatchdog
    } else if csr.porrstf() || csr.borrstf() {
        // Power-on first: it may come with any other flag and RAM is garbage then.
        ResetFlag::PowerOn
    } else if csr.sftrstf() && marked {
        ResetFlag::Software
    } else if csr.sftrstf() {
        ResetFlag::Debugger
    } else if csr.lpwrrstf() {
        ResetFlag::LowPower
    } else if csr.padrstf() {
        ResetFlag::Pin
    } else {
        ResetFlag::Unknown
    };
    rcc.csr().modify(|w| w.set_rmvf(true));
    flag
}

/// Marks the reset as the firmware's own, then resets (SYSRESETREQ). The motors must already
/// be off: this only resets.
pub fn software_reset() -> ! {
    // SAFETY: a single volatile store of a plain array; whatever else was running is about to
    // be reset, so no reader can see it half written.
    unsafe { mark_slot().write_volatile(MARK) };
    cortex_m::peripheral::SCB::sys_reset()
}

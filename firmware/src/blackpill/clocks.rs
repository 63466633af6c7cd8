//! Clock tree: the Black Pill's 25 MHz crystal, PLL to 100 MHz (the F411's maximum); the
//! internal 16 MHz RC oscillator (HSI) through the same PLL output when the crystal does not
//! start.
//!
//! embassy-stm32 0.6's `init` waits for HSERDY without a timeout (`rcc/f247.rs`), so a missing
//! or dead crystal would hang there before the watchdog, the log or the LED ever start.
//! [`start_crystal`] gives the crystal a bounded time first, and [`config`] builds the tree
//! from whichever oscillator runs. Every later rate (TIM1's 20 kHz, TIM2's 1 MHz, USART2's
//! 115 200 baud) comes from the same 100 MHz, so the firmware is unchanged on the fallback;
//! only the HSI's tolerance is wider than the crystal's (see docs/bring-up.md).

use embassy_stm32::Config;
use embassy_stm32::rcc::{
    AHBPrescaler, APBPrescaler, Hse, HseMode, Pll, PllMul, PllPDiv, PllPreDiv, PllSource, Sysclk,
};
use embassy_stm32::time::Hertz;

/// Where SYSCLK comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum ClockSource {
    /// The 25 MHz crystal (HSE).
    Crystal,
    /// The internal RC oscillator (HSI, 16 MHz): the crystal did not start.
    InternalFallback,
}

/// The crystal's start-up allowance. The datasheet's typical HSE start-up time is a few ms;
/// ST's HAL allows 100 ms (`HSE_STARTUP_TIMEOUT`), and so does this.
const HSE_STARTUP_MS: u32 = 100;
/// The core's clock while this runs: HSI after every reset (RM0383, RCC_CFGR SW reset value).
const HSI_HZ: u32 = 16_000_000;

/// Switches the crystal oscillator on and waits at most [`HSE_STARTUP_MS`] for HSERDY. If it
/// never comes, the oscillator is switched off again and the internal clock is used. Call
/// before `embassy_stm32::init` (the core still runs on the HSI then).
pub fn start_crystal() -> ClockSource {
    let rcc = embassy_stm32::pac::RCC;
    rcc.cr().modify(|w| {
        // An oscillator circuit, not an external clock on OSC_IN.
        w.set_hsebyp(false);
        w.set_hseon(true);
    });
    for _ in 0..HSE_STARTUP_MS {
        if rcc.cr().read().hserdy() {
            return ClockSource::Crystal;
        }
        // About 1 ms on the HSI (at least: delay counts at most one cycle per iteration).
        cortex_m::asm::delay(HSI_HZ / 1_000);
    }
    if rcc.cr().read().hserdy() {
        return ClockSource::Crystal;
    }
    rcc.cr().modify(|w| w.set_hseon(false));
    ClockSource::InternalFallback
}

/// SYSCLK = 100 MHz either way; APB1 50 MHz (timers 100 MHz), APB2 100 MHz.
/// - Crystal: 25 MHz / 25 * 200 / 2.
/// - HSI: 16 MHz / 8 * 100 / 2: the PLL input at 2 MHz (RM0383, RCC_PLLCFGR PLLM: 1 to 2 MHz,
///   2 MHz recommended to limit jitter), VCO 200 MHz (100 to 432 MHz).
pub fn config(source: ClockSource) -> Config {
    let mut config = Config::default();
    let (pll_src, prediv, mul) = match source {
        ClockSource::Crystal => {
            config.rcc.hse = Some(Hse {
                freq: Hertz(25_000_000),
                mode: HseMode::Oscillator,
            });
            (PllSource::HSE, PllPreDiv::DIV25, PllMul::MUL200)
        }
        // `hse: None` makes embassy keep HSEON off: no wait on a crystal that is not there.
        ClockSource::InternalFallback => (PllSource::HSI, PllPreDiv::DIV8, PllMul::MUL100),
    };
    config.rcc.pll_src = pll_src;
    config.rcc.pll = Some(Pll {
        prediv,
        mul,
        divp: Some(PllPDiv::DIV2),
        divq: None,
        divr: None,
    });
    config.rcc.ahb_pre = AHBPrescaler::DIV1;
    config.rcc.apb1_pre = APBPrescaler::DIV2;
    config.rcc.apb2_pre = APBPrescaler::DIV1;
    config.rcc.sys = Sysclk::PLL1_P;
    config
}

//! The motor currents (docs/wiring.md, "Current sense and the hardware stop"): the current-sense
//! amplifiers' outputs on PB0 (ADC1_IN8, precession) and PB1 (ADC1_IN9, spin), converted by ADC1's
//! injected group at every PWM period's start (TIM1's update as TRGO), so each sample sits at the
//! same point of the PWM cycle whatever the duty: the valley of the current's ripple, below the
//! period's mean by `V d (1 - d) T / (2 L)` at most: 37.5 mA on the nominal 2 mH motor at 12 V and
//! 20 kHz, d = 0.5 (a duty-dependent bias inside the current trips' 50 mA band; a centre-aligned
//! PWM sampled at its peak would read the mean, at the cost of the timer's mode and the
//! emulator's up-counting timer model).
//!
//! The results stay in JDR1/JDR2 until the next conversion; the control tick reads the latest
//! (no DMA, no interrupt per sample) and the controller checks every one it gets (the current
//! trips, `model_core::control::supervisor`): a fault on the current is latched at the first
//! tick after it, within 1 ms. The stop that does not wait for the CPU is the comparator on the
//! break input ([`super::power_stage`]).

use embassy_stm32::Peri;
use embassy_stm32::pac::adc::vals::{Exten, SampleTime};
use embassy_stm32::pac::adccommon::vals::Adcpre;
use embassy_stm32::pac::gpio::vals::Moder;
use embassy_stm32::pac::timer::vals::Mms;
use embassy_stm32::peripherals::{PB0, PB1};

/// The amplifier's output at zero current, V (INA240 with REF1 = VS, REF2 = GND: mid-supply).
pub const ZERO_V: f32 = 1.65;
/// The amplifier's output per ampere, V/A (INA240A1, 20 V/V, on a 10 mOhm shunt).
pub const V_PER_A: f32 = 0.2;
/// The ADC's reference and full scale.
const VREF_V: f32 = 3.3;
const FULL_SCALE: f32 = 4095.0;
/// ADC1's channels of PB0 and PB1.
const CHANNELS: [u8; 2] = [8, 9];
/// JEXTSEL for TIM1_TRGO (RM0383, ADC external trigger for injected channels).
const JEXTSEL_TIM1_TRGO: u8 = 1;

/// ADC1 sampling both motor currents with the PWM.
pub struct AdcCurrents {
    _pins: (Peri<'static, PB0>, Peri<'static, PB1>),
}

/// Volts at the pin for an ADC count.
fn volts(counts: u16) -> f32 {
    f32::from(counts) * (VREF_V / FULL_SCALE)
}

/// Configures PB0/PB1 as analog inputs and ADC1's injected group on TIM1's update (after the PWM
/// timer is set up).
pub fn start(pb0: Peri<'static, PB0>, pb1: Peri<'static, PB1>) -> AdcCurrents {
    let pac = embassy_stm32::pac::RCC;
    pac.apb2enr().modify(|w| w.set_adc1en(true));
    let gpiob = embassy_stm32::pac::GPIOB;
    for ch in 0..2 {
        gpiob.moder().modify(|w| w.set_moder(ch, Moder::ANALOG));
    }
    // ADC clock: PCLK2 (100 MHz) / 4 = 25 MHz, within the F411's 36 MHz at 3.3 V.
    embassy_stm32::pac::ADC1_COMMON
        .ccr()
        .modify(|w| w.set_adcpre(Adcpre::DIV4));
    let adc = embassy_stm32::pac::ADC1;
    adc.smpr2().modify(|w| {
        // 15 cycles: the amplifier's 100 R / 1 nF output filter settles well within it.
        for ch in CHANNELS {
            w.set_smp(usize::from(ch), SampleTime::CYCLES15);
        }
    });
    // Two injected conversions: with JL = 1 the sequence is JSQ3, JSQ4 -> JDR1, JDR2.
    adc.jsqr().write(|w| {
        w.set_jl(1);
        w.set_jsq(2, CHANNELS[0]);
        w.set_jsq(3, CHANNELS[1]);
    });
    adc.cr1().write(|w| w.set_scan(true));
    adc.cr2().write(|w| {
        w.set_adon(true);
        w.set_jextsel(JEXTSEL_TIM1_TRGO);
        w.set_jexten(Exten::RISING_EDGE);
    });
    // TIM1 sends its update event as TRGO.
    embassy_stm32::pac::TIM1
        .cr2()
        .modify(|w| w.set_mms(Mms::UPDATE));
    AdcCurrents { _pins: (pb0, pb1) }
}

impl AdcCurrents {
    /// The latest sample of each motor's current, A, signed as the amplifier measures it
    /// (positive = the motor's forward direction).
    pub fn currents_a(&self) -> [f32; 2] {
        let adc = embassy_stm32::pac::ADC1;
        [0, 1].map(|k| (volts(adc.jdr(k).read().jdata()) - ZERO_V) / V_PER_A)
    }
}

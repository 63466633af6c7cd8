//! The two motor outputs: TIM1 PWM channels (PA8, PA9) at 20 kHz plus a direction GPIO each.
//!
//! A PWM/DIR H-bridge input pair: PWM low = outputs off. The bridge inputs have pull-downs
//! (docs/wiring.md), so the motors are also off while the MCU is in reset or unprogrammed.
//!
//! Off state: TIM1 keeps driving PA8/PA9 low when its main output is disabled (OSSI = 1,
//! OISx = 0, CCxP = 0), so after a fault the pins do not depend on the pull-downs.

use embassy_stm32::gpio::{Level, Output};
use embassy_stm32::pac::timer::vals::{Ossi, Ossr};
use embassy_stm32::peripherals::TIM1;
use embassy_stm32::timer::Channel;
use embassy_stm32::timer::simple_pwm::SimplePwmChannel;

use crate::app::hal::MotorOutput;

/// PWM frequency: above hearing, and slow enough for a bridge's switching losses.
pub const PWM_HZ: u32 = 20_000;

/// One motor: a TIM1 channel and its direction pin.
pub struct PwmMotor {
    channel: SimplePwmChannel<'static, TIM1>,
    /// The channel's index on TIM1 (0 = CH1).
    index: usize,
    direction: Output<'static>,
}

impl PwmMotor {
    /// Takes an enabled PWM channel (compare 0), its TIM1 channel (`Channel::Ch1` or `Ch2`)
    /// and a direction pin (low = forward).
    pub fn new(
        mut channel: SimplePwmChannel<'static, TIM1>,
        which: Channel,
        direction: Output<'static>,
    ) -> Self {
        channel.set_duty_cycle_fully_off();
        // Before the channel's output is enabled: from here on a fault (MOE = 0) drives it low.
        drive_off_state();
        channel.enable();
        Self {
            channel,
            index: which.index(),
            direction,
        }
    }

    /// Compare 0 now, not at the next update event: with compare preload on (embassy's PWM
    /// sets OCxPE) a compare write waits for the end of the period, so the old duty would
    /// still drive the bridge after the direction pin has changed.
    fn compare_zero_now(&mut self) {
        let tim1 = embassy_stm32::pac::TIM1;
        let (reg, slot) = (self.index / 2, self.index % 2);
        tim1.ccmr_output(reg).modify(|w| w.set_ocpe(slot, false));
        self.channel.set_duty_cycle_fully_off();
        tim1.ccmr_output(reg).modify(|w| w.set_ocpe(slot, true));
    }
}

impl MotorOutput for PwmMotor {
    fn set_duty(&mut self, duty: f32) {
        let duty = crate::app::motors::sanitize_duty(duty);
        if duty == 0.0 {
            self.off();
            return;
        }
        let reverse = duty < 0.0;
        let level = if reverse { Level::High } else { Level::Low };
        if self.direction.get_output_level() != level {
            // Never drive the new direction with the old duty: off at once, turn, then drive
            // (the new compare takes effect at the next update event).
            self.compare_zero_now();
            self.direction.set_level(level);
        }
        // After a fault the main output stays off until the controller drives again.
        let tim1 = embassy_stm32::pac::TIM1;
        if !tim1.bdtr().read().moe() {
            tim1.bdtr().modify(|w| w.set_moe(true));
        }
        let max = self.channel.max_duty_cycle();
        // |duty| <= 1, so the product fits; rounding to the nearest compare step.
        let compare = (libm::fabsf(duty) * max as f32 + 0.5) as u32;
        self.channel.set_duty_cycle(compare.min(max));
    }

    fn off(&mut self) {
        self.channel.set_duty_cycle_fully_off();
    }

    fn disable(&mut self) {
        // TIM1's main output enable serves both channels: a fault stops both motors, which
        // is what the supervisor asks for anyway.
        emergency_off();
    }
}

/// TIM1's off-state selection (RM0383, TIMx_BDTR, and the TIM1 table "Output control bits for
/// complementary OCx and OCxN channels with break feature"): with OSSI = 0 (the reset value,
/// and what embassy leaves) clearing MOE *releases* the pins: not driven by the timer, they
/// float and only the bridge's pull-downs hold them low. With OSSI = 1 and CCxE = 1 the timer
/// keeps the output enabled at its idle level OISx (0 here: TIM1_CR2 untouched), i.e. driven
/// low. OSSR = 1 does the same with MOE = 1 for a channel whose CCxE is cleared while its
/// complementary output is enabled; no CHxN pin is used today, it keeps a later complementary
/// wiring driven too. Idempotent; no lock, no driver state.
pub fn drive_off_state() {
    embassy_stm32::pac::TIM1.bdtr().modify(|w| {
        w.set_ossi(Ossi::IDLE_LEVEL);
        w.set_ossr(Ossr::IDLE_LEVEL);
    });
}

/// Both PWM outputs to zero and TIM1's main output off, by raw register writes: no lock, no
/// driver state, safe to call from the panic and fault handlers at any moment.
pub fn emergency_off() {
    let tim1 = embassy_stm32::pac::TIM1;
    // MOE off first, in the same write as OSSI = 1: the outputs go to their idle level (driven
    // low, OISx = 0) at once, not released to float, whatever ran (or did not run) before.
    tim1.bdtr().modify(|w| {
        w.set_ossi(Ossi::IDLE_LEVEL);
        w.set_ossr(Ossr::IDLE_LEVEL);
        w.set_moe(false);
    });
    tim1.ccr(0)
        .write_value(embassy_stm32::pac::timer::regs::Ccr1ch(0));
    tim1.ccr(1)
        .write_value(embassy_stm32::pac::timer::regs::Ccr1ch(0));
}

//! The stop that needs no CPU, and the motor supply switch (docs/wiring.md, "Current sense and
//! the hardware stop"):
//!
//! - **PA6 = TIM1_BKIN** (AF1, the F411CE's only break pin besides PB12, which is DIR1), active
//!   low, internal pull-up beside the board's 10 k: the window comparators on the current-sense
//!   outputs and the driver's fault output pull it low. With BKE = 1 the timer clears its main
//!   output enable (MOE) asynchronously, even with the CPU halted or its clock stopped, and with
//!   OSSI = 1 ([`super::motor_pwm::drive_off_state`]) both PWM pins are then *driven* low
//!   (RM0383, TIM1 "Using the break function"). While the line stays low MOE cannot be set
//!   again and the break flag BIF cannot be cleared, so a motor cannot be restarted into it.
//! - **PB14 = supply enable** (push-pull, high = the motor supply's relay or high-side switch
//!   closed). Off in reset, unprogrammed and without power (the switch's own pull-down), opened
//!   by the firmware on any fault the bridge may not stop (its hardware stop tripped) and in the
//!   panic and HardFault handlers ([`cut_supply_now`]).
//!
//! The control tick reads the break ([`PowerStage::stop_tripped`]) and latches the fault; the
//! hardware has switched the PWM off long before (within one timer clock).

use embassy_stm32::Peri;
use embassy_stm32::gpio::Output;
use embassy_stm32::pac::gpio::vals::{Moder, Pupdr};
use embassy_stm32::pac::timer::vals::Bkp;
use embassy_stm32::peripherals::PA6;

use super::current_sense::AdcCurrents;
use crate::app::hal::PowerStage;

/// The break pin's number on GPIOA, and its alternate function (TIM1_BKIN).
const BKIN_PIN: usize = 6;
const AF_TIM1: u8 = 1;
/// The supply enable's pin number on GPIOB.
const SUPPLY_PIN: usize = 14;

/// The break input (owned: nothing else may reconfigure PA6), the supply switch and the
/// motor currents.
pub struct BoardPowerStage {
    _bkin: Peri<'static, PA6>,
    supply: Output<'static>,
    currents: AdcCurrents,
}

/// Configures PA6 as TIM1_BKIN (active low, pull-up) and enables the break on TIM1, after the
/// PWM outputs exist (their off state must already be the driven one: OSSI = 1). `supply` is
/// PB14 set up low (open); [`PowerStage::set_supply`] closes it once the control task runs.
pub fn start(
    bkin: Peri<'static, PA6>,
    supply: Output<'static>,
    currents: AdcCurrents,
) -> BoardPowerStage {
    let gpioa = embassy_stm32::pac::GPIOA;
    // Pull-up and alternate function before the mode: the pin never reads low on the way.
    gpioa
        .pupdr()
        .modify(|w| w.set_pupdr(BKIN_PIN, Pupdr::PULL_UP));
    gpioa.afr(0).modify(|w| w.set_afr(BKIN_PIN, AF_TIM1));
    gpioa
        .moder()
        .modify(|w| w.set_moder(BKIN_PIN, Moder::ALTERNATE));
    super::motor_pwm::drive_off_state();
    embassy_stm32::pac::TIM1.bdtr().modify(|w| {
        w.set_bkp(0, Bkp::ACTIVE_LOW);
        w.set_bke(0, true);
        // No automatic re-enable: a tripped stop stays off until the controller drives again
        // after CLEAR (AOE = 0, the reset value, said here so nobody turns it on lightly).
        w.set_aoe(false);
    });
    BoardPowerStage {
        _bkin: bkin,
        supply,
        currents,
    }
}

impl PowerStage for BoardPowerStage {
    fn currents_a(&mut self) -> [Option<f32>; 2] {
        self.currents.currents_a().map(Some)
    }

    fn stop_tripped(&mut self) -> bool {
        let tim1 = embassy_stm32::pac::TIM1;
        let flagged = tim1.sr().read().bif(0);
        if flagged {
            // rc_w0: write 0 to BIF alone, 1 to every other flag (left as they are). Cannot
            // clear while the line is still low; the line is read below anyway.
            let mut keep = embassy_stm32::pac::timer::regs::SrAdv(0xFFFF_FFFF);
            keep.set_bif(0, false);
            tim1.sr().write_value(keep);
        }
        let line_low = embassy_stm32::pac::GPIOA.idr().read().idr(BKIN_PIN)
            == embassy_stm32::pac::gpio::vals::Idr::LOW;
        flagged || line_low
    }

    fn set_supply(&mut self, on: bool) {
        if on {
            self.supply.set_high();
        } else {
            self.supply.set_low();
        }
    }
}

/// Opens the motor supply switch by a raw register write (BSRR reset bit): no lock, no driver
/// state, safe from the panic and fault handlers.
pub fn cut_supply_now() {
    embassy_stm32::pac::GPIOB
        .bsrr()
        .write(|w| w.set_br(SUPPLY_PIN, true));
}

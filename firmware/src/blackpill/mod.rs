//! The STM32F411CE Black Pill board: embassy-stm32 peripherals behind the [`crate::app::hal`]
//! traits. Pin map (docs/wiring.md has the wiring):
//!
//! | Function                     | Pin  | Peripheral                                   |
//! |------------------------------|------|----------------------------------------------|
//! | Precession motor PWM         | PA8  | TIM1_CH1 (AF1), 20 kHz                       |
//! | Spin motor PWM               | PA9  | TIM1_CH2 (AF1), 20 kHz                       |
//! | Precession motor direction   | PB12 | GPIO out                                     |
//! | Spin motor direction         | PB13 | GPIO out                                     |
//! | Precession proximity sensor  | PA15 | TIM2_CH1 (AF1) input capture, 1 MHz, 32 bit  |
//! | Spin proximity sensor        | PB3  | TIM2_CH2 (AF1) input capture, same counter   |
//! | Exit light gate              | PB10 | TIM2_CH3 (AF1) input capture, same counter   |
//! | Release push button (KEY)    | PA0  | EXTI0 falling edge, reads the same counter   |
//! | Release solenoid driver      | PB5  | GPIO out, high = energised                   |
//! | Hardware stop (break input)  | PA6  | TIM1_BKIN (AF1), active low, pull-up         |
//! | Motor supply enable          | PB14 | GPIO out, high = supply switch closed        |
//! | Precession motor current     | PB0  | ADC1_IN8, injected group on TIM1's update    |
//! | Spin motor current           | PB1  | ADC1_IN9, same conversion sequence           |
//! | Host link TX                 | PA2  | USART2_TX, DMA1 stream 6                      |
//! | Host link RX                 | PA3  | USART2_RX, DMA1 stream 5 (circular)           |
//! | Status LED (active low)      | PC13 | GPIO out, a pattern per state (`app::led`)   |
//! | Debug probe                  | PA13/PA14 | SWDIO/SWCLK, defmt over RTT            |
//!
//! Timers: TIM1 PWM, TIM2 capture (both sensors on one 32-bit counter, so their timestamps and
//! the controller's `now` share one time base), TIM5 embassy's time driver. The IWDG resets the
//! MCU if the control tick stops; parameters live in flash
//! sectors 6 and 7 (0x0804_0000..0x0808_0000, 2 x 128 KiB; `memory.x` ends the image at 256 KiB).

pub mod capture;
pub mod clocks;
pub mod current_sense;
pub mod flash_region;
pub mod gates;
pub mod motor_pwm;
pub mod power_stage;
pub mod reset_cause;

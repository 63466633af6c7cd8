//! Bowl rig controller firmware (STM32F411CE Black Pill).
//!
//! Bring-up image: clocks, the on-board LED on PC13 as a heartbeat, defmt logs over RTT.
//! The control tasks arrive with the firmware issue; the logic they run lives in `model-core`.
#![no_std]
#![no_main]

use defmt::info;
use defmt_rtt as _;
use embassy_executor::Spawner;
use embassy_stm32::gpio::{Level, Output, Speed};
use embassy_time::Timer;
use model_core::bowl::{BowlGeometry, MotorSpeeds};

#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    let p = embassy_stm32::init(Default::default());
    // The Black Pill's blue LED is active low on PC13.
    let mut led = Output::new(p.PC13, Level::High, Speed::Low);
    let geometry = BowlGeometry::<f32>::default();
    let omega = geometry
        .combined_speed_rad_s(MotorSpeeds {
            precession_rad_s: 1.8,
            spin_rad_s: 1.8,
        })
        .unwrap_or(0.0);
    info!(
        "bowl rig firmware up; Eq. 2 self-check: 1.8 + 1.8 rad/s -> {} rad/s",
        omega
    );
    loop {
        led.set_low();
        Timer::after_millis(100).await;
        led.set_high();
        Timer::after_millis(900).await;
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    defmt::error!("panic: {}", defmt::Display2Format(info));
    cortex_m::peripheral::SCB::sys_reset()
}

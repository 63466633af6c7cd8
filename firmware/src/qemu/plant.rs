//! The simulated rig (`model_core::sim::Plant`) standing in for the motors and the proximity
//! sensors of the emulated board.
//!
//! The plant task advances the simulation by the embassy time that really passed (1 kHz),
//! with the duties the control task last applied, and pushes the sensor edges into the same
//! [`EdgeQueue`]s the STM32's capture interrupt fills. The simulation's capture clock (1 MHz,
//! 32 bit, like TIM2 on the Black Pill) is the board's [`CaptureClock`].
//!
//! Injected sensor faults act where a real one would: the plant keeps turning, its edges no
//! longer reach the firmware.

use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use embassy_time::{Duration, Instant, Ticker};
use model_core::sim::Plant;
use model_core::wire::{Injection, Reason};

use crate::app::binding::Injector;
use crate::app::edges::EdgeQueue;
use crate::app::hal::{CaptureClock, MotorOutput};
use crate::app::motors::sanitize_duty;
use crate::qemu::gates::{self, Granules};

/// The edge queues, `[precession, spin]`, filled by the plant task.
pub static EDGES: [EdgeQueue; 2] = [EdgeQueue::new(), EdgeQueue::new()];
/// Duties as the "bridge" sees them (f32 bits), written by [`SimMotor`].
static DUTIES: [AtomicU32; 2] = [AtomicU32::new(0), AtomicU32::new(0)];
/// The simulation's capture timer after its latest step.
static NOW_TICKS: AtomicU32 = AtomicU32::new(0);
/// Sensors whose edges no longer reach the firmware.
static SENSOR_DEAD: [AtomicBool; 2] = [AtomicBool::new(false), AtomicBool::new(false)];
/// Shafts blocked by INJECT STALL (the plant task blocks them in the simulation).
static BLOCKED: [AtomicBool; 2] = [AtomicBool::new(false), AtomicBool::new(false)];

/// Plant step: the control tick rate, so each tick sees the edges of one step.
pub const PLANT_PERIOD: Duration = Duration::from_millis(1);

/// One simulated motor output (the "PWM register").
pub struct SimMotor(pub usize);

impl MotorOutput for SimMotor {
    fn set_duty(&mut self, duty: f32) {
        DUTIES[self.0].store(sanitize_duty(duty).to_bits(), Ordering::Relaxed);
    }
    fn off(&mut self) {
        DUTIES[self.0].store(0, Ordering::Relaxed);
    }
}

/// Both outputs to zero: for the panic handler and the emulated watchdog.
pub fn emergency_off() {
    for d in &DUTIES {
        d.store(0, Ordering::Relaxed);
    }
}

/// The duties the plant is driven with now.
pub fn duties() -> [f32; 2] {
    [0, 1].map(|i| f32::from_bits(DUTIES[i].load(Ordering::Relaxed)))
}

/// The simulation's capture timer as the board's clock.
pub struct PlantClock;

impl CaptureClock for PlantClock {
    fn now_ticks(&self) -> u32 {
        NOW_TICKS.load(Ordering::Relaxed)
    }
}

/// Injections go to the plant: a lost sensor's edges stop reaching the firmware, a stalled
/// shaft is blocked inside the simulation from its next step on. RELEASE drops a simulated
/// granule ([`gates`]).
pub struct PlantInjector;

impl Injector for PlantInjector {
    fn inject(&mut self, what: Injection) -> Result<(), Reason> {
        match what {
            Injection::None => SENSOR_DEAD
                .iter()
                .chain(&BLOCKED)
                .for_each(|d| d.store(false, Ordering::Relaxed)),
            Injection::SensorLostPrecession => SENSOR_DEAD[0].store(true, Ordering::Relaxed),
            Injection::SensorLostSpin => SENSOR_DEAD[1].store(true, Ordering::Relaxed),
            Injection::StallPrecession => BLOCKED[0].store(true, Ordering::Relaxed),
            Injection::StallSpin => BLOCKED[1].store(true, Ordering::Relaxed),
        }
        Ok(())
    }

    fn release(&mut self) -> Result<(), Reason> {
        gates::release()
    }

    fn gate_event(&mut self) -> Option<model_core::wire::GateEvent> {
        gates::next_event()
    }
}

/// Runs the plant and its granules forever from their present state; `observe` sees the rig
/// after every step (for the truth log).
pub async fn run(mut rig: Plant, mut granules: Granules, mut observe: impl FnMut(&Plant)) -> ! {
    NOW_TICKS.store(rig.now_ticks(), Ordering::Relaxed);
    let mut ticker = Ticker::every(PLANT_PERIOD);
    let mut last = Instant::now();
    loop {
        ticker.next().await;
        let now = Instant::now();
        let dt_s = (now - last).as_micros() as f32 * 1e-6;
        last = now;
        for (axis, blocked) in BLOCKED.iter().enumerate() {
            let from_s = &mut rig.params_mut().axes[axis].faults.blocked_from_s;
            match (blocked.load(Ordering::Relaxed), from_s.is_finite()) {
                (true, false) => *from_s = 0.0,
                (false, true) => *from_s = f32::INFINITY,
                _ => {}
            }
        }
        // A granule moves during the step under the speeds the shafts have over it.
        granules.step(
            [rig.speed_rad_s(0), rig.speed_rad_s(1)],
            rig.now_ticks(),
            dt_s,
        );
        rig.advance(duties(), dt_s);
        for (axis, queue) in EDGES.iter().enumerate() {
            if !SENSOR_DEAD[axis].load(Ordering::Relaxed) {
                for &t in rig.edges(axis) {
                    queue.push(t);
                }
            }
        }
        NOW_TICKS.store(rig.now_ticks(), Ordering::Relaxed);
        observe(&rig);
    }
}

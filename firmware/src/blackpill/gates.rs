//! The release trigger, the release solenoid and the exit light gate (docs/wiring.md):
//!
//! - exit light gate on PB10, TIM2_CH3 input capture (rising edge: the beam broken), on the
//!   proximity sensors' counter, so its times and theirs share one microsecond clock
//!   ([`super::capture`] takes its edges in the TIM2 interrupt);
//! - release push button on PA0 (the Black Pill's KEY button, active low, internal pull-up),
//!   EXTI0 falling edge: the interrupt reads the same counter at once (TIM2's capture
//!   channels 4 and the others are not on free pins of the F411CE);
//! - release solenoid driver on PB5 (high energises it for [`SOLENOID_PULSE`]): RELEASE fires it
//!   and its release time is the counter when the pin went high.
//!
//! Both release sources and the exit gate feed [`EDGES`]; [`GateReader`] debounces them into
//! gate events.

use core::sync::atomic::{AtomicBool, Ordering};

use defmt::warn;
use embassy_stm32::Peri;
use embassy_stm32::exti::{ExtiInput, TriggerEdge};
use embassy_stm32::gpio::{Output, Pull};
use embassy_stm32::interrupt;
use embassy_stm32::interrupt::InterruptExt;
use embassy_stm32::mode::Blocking;
use embassy_stm32::peripherals::{EXTI0, PA0};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;
use embassy_time::{Duration, Timer};
use model_core::binding::Injector;
use model_core::wire::{GateEvent, Injection, Reason};

use crate::app::edges::EdgeQueue;
use crate::app::gates::GateReader;

/// How long RELEASE energises the solenoid: long enough for a small push solenoid's plunger
/// to travel (20..40 ms), short enough not to heat it.
pub const SOLENOID_PULSE: Duration = Duration::from_millis(40);

/// Raw gate timestamps `[release, exit]`, capture ticks (us).
pub static EDGES: [EdgeQueue; 2] = [EdgeQueue::new(), EdgeQueue::new()];

/// RELEASE asked for a pulse; the solenoid task fires it.
static FIRE: Signal<CriticalSectionRawMutex, ()> = Signal::new();
/// From RELEASE until the pulse has ended.
static SOLENOID_BUSY: AtomicBool = AtomicBool::new(false);

/// Keeps the release button's pin configured.
pub struct ReleaseButton {
    _input: ExtiInput<'static, Blocking>,
}

/// Configures PA0 and EXTI0 for the release button and enables its interrupt.
pub fn start_button(pa0: Peri<'static, PA0>, exti0: Peri<'static, EXTI0>) -> ReleaseButton {
    let input = ExtiInput::new_blocking(pa0, exti0, Pull::Up, TriggerEdge::Falling);
    interrupt::EXTI0.unpend();
    // SAFETY: the handler below only reads TIM2's counter, clears its EXTI line and pushes
    // to a queue that is interrupt-safe.
    unsafe { interrupt::EXTI0.enable() };
    ReleaseButton { _input: input }
}

#[interrupt]
fn EXTI0() {
    // The counter first: the time of the press, before anything else runs.
    let t = embassy_stm32::pac::TIM2.cnt().read();
    embassy_stm32::pac::EXTI
        .pr(0)
        .write_value(embassy_stm32::pac::exti::regs::Lines(1));
    EDGES[0].push(t);
}

/// Fires the solenoid on PB5 for each RELEASE; the pin is low (off) between pulses.
pub async fn run_solenoid(mut pin: Output<'static>) -> ! {
    pin.set_low();
    loop {
        FIRE.wait().await;
        // Pin and time together: no interrupt between them.
        critical_section::with(|_| {
            pin.set_high();
            EDGES[0].push(embassy_stm32::pac::TIM2.cnt().read());
        });
        Timer::after(SOLENOID_PULSE).await;
        pin.set_low();
        SOLENOID_BUSY.store(false, Ordering::Release);
    }
}

/// The board's side of the protocol's RELEASE and gate events; fault injection is refused
/// (real hardware).
pub struct BoardGates {
    reader: GateReader<'static>,
    lost_said: u32,
}

impl BoardGates {
    /// Gates whose events carry `boot`, this boot's reset counter.
    pub fn new(boot: u16) -> Self {
        Self {
            reader: GateReader::new(&EDGES, boot),
            lost_said: 0,
        }
    }
}

impl Injector for BoardGates {
    fn inject(&mut self, _what: Injection) -> Result<(), Reason> {
        Err(Reason::Unsupported)
    }

    fn release(&mut self) -> Result<(), Reason> {
        if SOLENOID_BUSY.swap(true, Ordering::AcqRel) {
            return Err(Reason::State);
        }
        FIRE.signal(());
        Ok(())
    }

    fn gate_event(&mut self) -> Option<GateEvent> {
        let event = self.reader.next_event();
        // The wire has no field for lost gate edges: say so in the log, never silently.
        let lost = self.reader.lost();
        if lost != self.lost_said {
            self.lost_said = lost;
            warn!("gates: edges lost so far: {}", lost);
        }
        event
    }
}

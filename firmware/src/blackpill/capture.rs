//! Pulse capture: both proximity sensors on TIM2 (32 bit, 1 MHz): CH1 on PA15 (precession),
//! CH2 on PB3 (spin), rising edges; and the exit light gate on CH3, PB10 ([`super::gates`]).
//! The TIM2 interrupt moves each latched timestamp into its [`EdgeQueue`]; an edge overwritten
//! before the interrupt read it (over-capture) is counted as lost, never silently dropped.

use embassy_stm32::Peri;
use embassy_stm32::gpio::Pull;
use embassy_stm32::interrupt;
use embassy_stm32::interrupt::InterruptExt;
use embassy_stm32::peripherals::{PA15, PB3, PB10, TIM2};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::input_capture::CapturePin;
use embassy_stm32::timer::low_level::{FilterValue, InputCaptureMode, InputTISelection, Timer};
use embassy_stm32::timer::{Ch1, Ch2, Ch3, Channel};

use crate::app::edges::EdgeQueue;
use crate::app::hal::CaptureClock;

/// Capture timer rate: 1 us resolution, 32-bit wrap after 71 minutes.
pub const CAPTURE_HZ: u32 = 1_000_000;

/// The edge queues, `[precession, spin]`, filled by the TIM2 interrupt.
pub static EDGES: [EdgeQueue; 2] = [EdgeQueue::new(), EdgeQueue::new()];

/// The running capture hardware (keeps the pins configured).
pub struct Capture {
    _timer: Timer<'static, TIM2>,
    _pins: (
        CapturePin<'static, TIM2, Ch1>,
        CapturePin<'static, TIM2, Ch2>,
        CapturePin<'static, TIM2, Ch3>,
    ),
}

/// The capture counter as the controller's clock.
#[derive(Clone, Copy)]
pub struct Tim2Clock;

impl CaptureClock for Tim2Clock {
    fn now_ticks(&self) -> u32 {
        embassy_stm32::pac::TIM2.cnt().read()
    }
}

/// Starts TIM2 at [`CAPTURE_HZ`] with the sensors' and the exit gate's channels capturing
/// rising edges.
pub fn start(
    tim: Peri<'static, TIM2>,
    pa15: Peri<'static, PA15>,
    pb3: Peri<'static, PB3>,
    pb10: Peri<'static, PB10>,
) -> Capture {
    // The sensor outputs are level-shifted push-pull or open collector with an external
    // pull-up (docs/wiring.md); no internal pull so a dead sensor reads as no edges.
    let pins = (
        CapturePin::new(pa15, Pull::None),
        CapturePin::new(pb3, Pull::None),
        // The light gate drives its output; the pull-down keeps an unplugged gate silent.
        CapturePin::new(pb10, Pull::Down),
    );
    let mut timer = Timer::new(tim);
    timer.set_tick_freq(Hertz(CAPTURE_HZ));
    timer.set_max_compare_value(u32::MAX);
    for ch in [Channel::Ch1, Channel::Ch2] {
        // Digital filter: 8 samples at fDTS/8 (about 0.6 us at 100 MHz) rejects ringing
        // on the cable without delaying real edges measurably.
        timer.set_input_capture_filter(ch, FilterValue::FDTS_DIV8_N8);
        timer.set_input_ti_selection(ch, InputTISelection::Normal);
        timer.set_input_capture_mode(ch, InputCaptureMode::Rising);
        timer.set_input_capture_prescaler(ch, 0);
        timer.enable_channel(ch, true);
        timer.enable_input_interrupt(ch, true);
    }
    // The light gate's edge is slower and noisier than a sensor's: 8 samples at fDTS/32
    // (about 2.6 us), still far below the time a granule takes to cross the beam.
    timer.set_input_capture_filter(Channel::Ch3, FilterValue::FDTS_DIV32_N8);
    timer.set_input_ti_selection(Channel::Ch3, InputTISelection::Normal);
    timer.set_input_capture_mode(Channel::Ch3, InputCaptureMode::Rising);
    timer.set_input_capture_prescaler(Channel::Ch3, 0);
    timer.enable_channel(Channel::Ch3, true);
    timer.enable_input_interrupt(Channel::Ch3, true);
    timer.generate_update_event();
    timer.start();
    interrupt::TIM2.unpend();
    // SAFETY: the handler below only touches TIM2's flags and the lock-free-to-callers queues.
    unsafe { interrupt::TIM2.enable() };
    Capture {
        _timer: timer,
        _pins: pins,
    }
}

#[interrupt]
fn TIM2() {
    let tim = embassy_stm32::pac::TIM2;
    let sr = tim.sr().read();
    let queues = [&EDGES[0], &EDGES[1], &super::gates::EDGES[1]];
    for (i, queue) in queues.into_iter().enumerate() {
        if sr.ccif(i) {
            // Reading CCRx clears CCxIF.
            let t = tim.ccr(i).read();
            queue.push(t);
            if sr.ccof(i) {
                // Another edge came and went before we read this one.
                queue.count_lost(1);
                // TIMx_SR's flags are rc_w0 (RM0383): writing 1 leaves a flag alone, writing 0
                // clears it. A read-modify-write would write 0 to every flag that rose since
                // the read above (another channel's capture flag, an edge lost with it), so
                // write ones everywhere but this one over-capture flag (as ST's HAL does).
                tim.sr().write(|w| {
                    w.0 = u32::MAX;
                    w.set_ccof(i, false);
                });
            }
        }
    }
}

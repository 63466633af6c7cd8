//! Bowl rig controller firmware for the STM32F411CE Black Pill.
//!
//! Boot: read the reset cause and count the reset, bring the outputs up *off*, load the
//! parameters from flash, then run the tasks: control tick (1 kHz), host link (commands,
//! answers, telemetry over USART2 with DMA), supervisor (watchdog, parameter persistence), the
//! status LED (a pattern per state: `firmware::app::led`), and the release solenoid. Pulse
//! capture and the exit light gate are the TIM2 interrupt, the release button EXTI0. Pin map:
//! `firmware::blackpill` and docs/wiring.md. A crystal that does not start leaves the board on
//! the HSI (`firmware::blackpill::clocks`), reported in the log, on the LED and in STATUS.
//! Flash and run: `cargo flash-rig` (probe-rs; defmt logs over RTT).
#![no_std]
#![no_main]

use core::cell::RefCell;

use cortex_m_rt::{ExceptionFrame, exception};
use defmt::{error, info, warn};
use defmt_rtt as _;
use embassy_executor::Spawner;
use embassy_stm32::flash::Flash;
use embassy_stm32::gpio::{Level, Output, Speed};
use embassy_stm32::peripherals::{DMA1_CH5, DMA1_CH6, USART2};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::Channel;
use embassy_stm32::timer::low_level::CountingMode;
use embassy_stm32::timer::simple_pwm::{PwmPin, SimplePwm};
use embassy_stm32::usart::{self, RingBufferedUartRx, Uart, UartTx};
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_stm32::{bind_interrupts, dma, gpio::OutputType};
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::ThreadModeRawMutex;
use embassy_time::{Duration, Ticker};
use firmware::app::binding::{
    ControllerBackend, DeviceCore, PERSISTED_COUNT, default_persisted, split_persisted,
};
use firmware::app::hal::Watchdog;
use firmware::app::led::{self, LedMode};
use firmware::app::motors::Motors;
use firmware::app::params::ParamLog;
use firmware::app::persist::{PERSIST_PERIOD, Persistence};
use firmware::app::reset;
use firmware::app::slot::Slot;
use firmware::app::tasks::{self, Heartbeat, SharedCore};
use firmware::blackpill::capture::{self, Tim2Clock};
use firmware::blackpill::clocks::{self, ClockSource};
use firmware::blackpill::current_sense;
use firmware::blackpill::flash_region::ParamSector;
use firmware::blackpill::gates::{self, BoardGates, ReleaseButton};
use firmware::blackpill::motor_pwm::{self, PWM_HZ, PwmMotor};
use firmware::blackpill::power_stage::{self, BoardPowerStage};
use firmware::blackpill::reset_cause::{self, ResetFlag};
use model_core::control::ControllerConfig;
use model_core::wire::{Hello, ResetCause, status_flags};

bind_interrupts!(struct Irqs {
    USART2 => usart::InterruptHandler<USART2>;
    DMA1_STREAM5 => dma::InterruptHandler<DMA1_CH5>;
    DMA1_STREAM6 => dma::InterruptHandler<DMA1_CH6>;
});

type Core = SharedCore<ThreadModeRawMutex, DeviceCore<BoardGates>>;

/// Watchdog timeout: 25 control periods of slack over the supervisor's 20 ms feeding period.
const WATCHDOG_TIMEOUT_US: u32 = 250_000;
/// A control tick's work ends before the next tick is due (the motors are the only thing the
/// executor serves at this rate); later, and the watchdog goes unfed for a period.
const CONTROL_DEADLINE: Duration = Duration::from_hz(tasks::CONTROL_HZ);

static CORE: Slot<Core> = Slot::new();
static HEARTBEAT: Heartbeat = Heartbeat::new();
static RX_RING: Slot<[u8; 256]> = Slot::new();
static PARAM_LOG: Slot<ParamLog<ParamSector>> = Slot::new();

struct Iwdg(IndependentWatchdog<'static, embassy_stm32::peripherals::IWDG>);

impl Watchdog for Iwdg {
    fn feed(&mut self) {
        self.0.pet();
    }
}

fn wire_cause(flag: ResetFlag) -> ResetCause {
    match flag {
        ResetFlag::IndependentWatchdog => ResetCause::IndependentWatchdog,
        ResetFlag::WindowWatchdog => ResetCause::WindowWatchdog,
        ResetFlag::Software => ResetCause::Software,
        // The protocol's Pin is "the NRST pin (reset button, debugger)".
        ResetFlag::Debugger => ResetCause::Pin,
        ResetFlag::LowPower => ResetCause::LowPower,
        ResetFlag::PowerOn => ResetCause::PowerOn,
        ResetFlag::Pin => ResetCause::Pin,
        ResetFlag::Unknown => ResetCause::Unknown,
    }
}

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    // Before anything else: the flags are cleared here, the counter lives in .uninit RAM.
    let flag = reset_cause::take();
    let resets = reset::count_this_boot();
    // The crystal gets a bounded start-up time; without it the board runs on the HSI instead
    // of hanging in embassy's HSE wait. Until `init` the PWM pins are inputs, as in reset:
    // the bridge's pull-downs hold the motors off (docs/wiring.md).
    let clock = clocks::start_crystal();
    let p = embassy_stm32::init(clocks::config(clock));

    // Outputs first, off: PWM compare 0, direction low.
    let pwm = SimplePwm::new(
        p.TIM1,
        Some(PwmPin::new(p.PA8, OutputType::PushPull)),
        Some(PwmPin::new(p.PA9, OutputType::PushPull)),
        None,
        None,
        Hertz(PWM_HZ),
        CountingMode::EdgeAlignedUp,
    );
    let ch = pwm.split();
    let mut motors = Motors::new([
        PwmMotor::new(
            ch.ch1,
            Channel::Ch1,
            Output::new(p.PB12, Level::Low, Speed::Low),
        ),
        PwmMotor::new(
            ch.ch2,
            Channel::Ch2,
            Output::new(p.PB13, Level::Low, Speed::Low),
        ),
    ]);
    motors.all_off();
    // The hardware stop on PA6, the motor supply switch on PB14 (open until the control task
    // runs) and the motor currents on PB0/PB1 (used once CUR_SENSE says the board has them).
    let currents = current_sense::start(p.PB0, p.PB1);
    let power = power_stage::start(p.PA6, Output::new(p.PB14, Level::Low, Speed::Low), currents);
    let solenoid = Output::new(p.PB5, Level::Low, Speed::Low);
    let capture = capture::start(p.TIM2, p.PA15, p.PB3, p.PB10);
    let button = gates::start_button(p.PA0, p.EXTI0);

    info!(
        "boot: reset cause {}, resets since power-on {}",
        flag, resets
    );
    if clock == ClockSource::InternalFallback {
        warn!(
            "clock: the 25 MHz crystal did not start; running on the internal 16 MHz oscillator (HSI), timing within the HSI's tolerance only"
        );
    }

    // Parameters: the newest valid record, or the defaults (and why).
    let log = PARAM_LOG
        .put(ParamLog::new(ParamSector::new(Flash::new_blocking(
            p.FLASH,
        ))))
        .unwrap_or_else(|| halt("parameter log slot"));
    // What STATUS tells the PC about this board (`flags`): the log alone reaches no one
    // once the probe is gone.
    let mut flags = 0;
    if clock == ClockSource::InternalFallback {
        flags |= status_flags::CLOCK_FALLBACK;
    }
    let stored = match log.load::<PERSISTED_COUNT>() {
        Ok(v) => {
            info!("params: loaded from flash");
            v
        }
        Err(e) => {
            warn!("params: {}, using defaults", e);
            flags |= status_flags::PARAMS_DEFAULTS;
            default_persisted()
        }
    };
    let hello = Hello {
        reset_cause: wire_cause(flag),
        reset_count: resets as u16,
    };
    let (mut rig, outcome) = ControllerBackend::new(
        ControllerConfig::nominal(),
        stored,
        hello,
        BoardGates::new(hello.reset_count),
    );
    if let Err(r) = outcome {
        warn!("params: stored values rejected ({}), using defaults", r);
        flags |= status_flags::PARAMS_DEFAULTS;
    }
    rig.update_status_flags(flags, 0);
    let core = CORE
        .put(Mutex::new(RefCell::new(DeviceCore::new(rig))))
        .unwrap_or_else(|| halt("core slot"));

    // Host link: USART2 115200 8N1, TX by DMA, RX into a circular DMA ring.
    let mut cfg = usart::Config::default();
    cfg.baudrate = model_core::wire::DEFAULT_BAUD;
    let uart = Uart::new(p.USART2, p.PA3, p.PA2, p.DMA1_CH6, p.DMA1_CH5, Irqs, cfg)
        .unwrap_or_else(|_| halt("USART2 config"));
    let (tx, rx) = uart.split();
    let ring = RX_RING
        .put([0; 256])
        .unwrap_or_else(|| halt("rx ring slot"));
    let rx = rx.into_ring_buffered(ring);

    let mut iwdg = IndependentWatchdog::new(p.IWDG, WATCHDOG_TIMEOUT_US);
    iwdg.unleash();

    let led = Output::new(p.PC13, Level::High, Speed::Low);
    spawn(spawner, control_task(core, motors, power, capture));
    spawn(spawner, link_task(core, rx, tx));
    spawn(spawner, supervisor_task(Iwdg(iwdg), core, log));
    spawn(spawner, led_task(led, core, clock));
    spawn(spawner, solenoid_task(solenoid, button));
    info!("running");
}

fn spawn<S>(
    spawner: Spawner,
    token: Result<embassy_executor::SpawnToken<S>, embassy_executor::SpawnError>,
) {
    match token {
        Ok(t) => spawner.spawn(t),
        Err(_) => halt("task pool"),
    }
}

/// A startup invariant failed: motors off, log, and reset (the next boot reports `Software`).
fn halt(what: &str) -> ! {
    motor_pwm::emergency_off();
    power_stage::cut_supply_now();
    error!("startup failed: {}", what);
    reset_cause::software_reset()
}

#[embassy_executor::task]
async fn control_task(
    core: &'static Core,
    mut motors: Motors<PwmMotor>,
    mut power: BoardPowerStage,
    _capture: capture::Capture,
) {
    tasks::control(
        core,
        &capture::EDGES,
        &Tim2Clock,
        &mut motors,
        &mut power,
        &HEARTBEAT,
        CONTROL_DEADLINE,
    )
    .await
}

#[embassy_executor::task]
async fn link_task(
    core: &'static Core,
    rx: RingBufferedUartRx<'static>,
    tx: UartTx<'static, embassy_stm32::mode::Async>,
) {
    tasks::link(core, rx, tx).await
}

/// Feeds the watchdog while the control tick runs, and persists changed parameters while the
/// motors are off.
#[embassy_executor::task]
async fn supervisor_task(
    watchdog: Iwdg,
    core: &'static Core,
    log: &'static mut ParamLog<ParamSector>,
) {
    let feed = tasks::supervisor(watchdog, &HEARTBEAT);
    let persist = async {
        let mut persistence = Persistence::new(log);
        let mut ticker = Ticker::every(PERSIST_PERIOD);
        loop {
            ticker.next().await;
            let report = persistence.step(core);
            // The wire has no field for capture losses: say so in the log, never silently.
            if let Some(lost) = report.edges_lost {
                warn!(
                    "capture: edges lost so far: precession {}, spin {}",
                    lost[0], lost[1]
                );
            }
            let save_failed = status_flags::PARAMS_SAVE_FAILED;
            match report.saved {
                Some(Ok(record)) => {
                    core.lock(|c| c.borrow_mut().backend.update_status_flags(0, save_failed));
                    let r = split_persisted(&record);
                    info!(
                        "params: saved; motor models {} / {}, identified {}",
                        r.models[0], r.models[1], r.identified
                    );
                }
                Some(Err(e)) => {
                    core.lock(|c| c.borrow_mut().backend.update_status_flags(save_failed, 0));
                    error!("params: save failed: {}", e);
                }
                None => {}
            }
        }
    };
    embassy_futures::join::join(feed, persist).await;
}

/// Fires the release solenoid for each RELEASE (and keeps the release button configured).
#[embassy_executor::task]
async fn solenoid_task(solenoid: Output<'static>, _button: ReleaseButton) {
    gates::run_solenoid(solenoid).await
}

/// The status LED (PC13, active low): the pattern of the controller's state, and the clock
/// warning when running on the HSI. It only reads the state: a stuck LED task changes nothing
/// else, and a stuck executor leaves the LED frozen (the watchdog resets the MCU then).
#[embassy_executor::task]
async fn led_task(mut led: Output<'static>, core: &'static Core, clock: ClockSource) {
    let fallback = clock == ClockSource::InternalFallback;
    let mut ticker = Ticker::every(Duration::from_millis(led::STEP_MS.into()));
    loop {
        ticker.next().await;
        let mode = core.lock(|c| {
            let c = c.borrow();
            let ctrl = c.backend.controller();
            LedMode::of(ctrl.state(), ctrl.fault())
        });
        let now_ms = embassy_time::Instant::now().as_millis() as u32;
        let on = led::lit(mode, fallback, now_ms);
        led.set_level(if on { Level::Low } else { Level::High });
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    // Motors first: raw register writes, no locks, nothing that could panic again.
    motor_pwm::emergency_off();
    power_stage::cut_supply_now();
    // Only the location: formatting the message would link core's float formatting (about
    // 18 KiB) for the float arguments of panic messages anywhere in the image.
    match info.location() {
        Some(l) => error!("panic at {}:{}", l.file(), l.line()),
        None => error!("panic"),
    }
    reset_cause::software_reset()
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    motor_pwm::emergency_off();
    power_stage::cut_supply_now();
    error!("hard fault at pc {=u32:#010x}", frame.pc());
    reset_cause::software_reset()
}

//! The rig on the emulated board: the firmware's application logic (the same tasks, the same
//! controller binding as the Black Pill image) on QEMU netduinoplus2, with the simulated plant
//! in place of motors and sensors and the real protocol on the emulated USART1.
//!
//! Run (USART1 on a pseudo-terminal for `bowl monitor` / `bowl send`):
//! `firmware/qemu-rig-run [--seconds S] [-- extra QEMU args]`.
//!
//! Semihosting console: `plant t_ms=.. w1=.. w2=.. d1=.. d2=..` twice a second (the simulation's
//! true speeds, rad/s, and the applied duties: an independent reference for tests), and the
//! end of the run. The run ends after the virtual seconds given by `-append seconds=S`
//! (default: never), or when the emulated watchdog fires (exit status 1).
#![no_std]
#![no_main]

use core::cell::RefCell;

use cortex_m_rt::{ExceptionFrame, entry, exception};
use cortex_m_semihosting::hprintln;
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::ThreadModeRawMutex;
use embassy_time::{Duration, Timer};
use firmware::app::binding::{
    ControllerBackend, DeviceCore, default_persisted, persisted, split_persisted,
};
use firmware::app::hal::NoPowerStage;
use firmware::app::motors::Motors;
use firmware::app::reset;
use firmware::app::slot::Slot;
use firmware::app::tasks::{self, Heartbeat, SharedCore};
use firmware::qemu::gates::{self, Granules};
use firmware::qemu::plant::{self, PlantClock, PlantInjector, SimMotor};
use firmware::qemu::watchdog::SoftWatchdog;
use firmware::qemu::{self, executor, time_driver, usart};
use model_core::control::ControllerConfig;
use model_core::sim::granule::ParticleParams;
use model_core::sim::{AssemblyError, Plant, PlantParams, commission_on_plant};
use model_core::wire::{Hello, ResetCause};

type Core = SharedCore<ThreadModeRawMutex, DeviceCore<PlantInjector>>;

static CORE: Slot<Core> = Slot::new();
static HEARTBEAT: Heartbeat = Heartbeat::new();

/// Same slack as the Black Pill's IWDG.
const WATCHDOG_TIMEOUT_US: u64 = 250_000;
/// How late a control tick's work may end: the plant task shares this executor (the Black
/// Pill's image has no plant), and a plant step can hold the CPU past the next tick.
const CONTROL_DEADLINE: Duration = Duration::from_millis(20);
/// Seed of the plant's tooth offsets and jitter.
const PLANT_SEED: u32 = 1;
/// Truth log period.
const TRUTH_EVERY_MS: u32 = 500;

#[embassy_executor::task]
async fn control_task(core: &'static Core) {
    let mut motors = Motors::new([SimMotor(0), SimMotor(1)]);
    tasks::control(
        core,
        &plant::EDGES,
        &PlantClock,
        &mut motors,
        // The QEMU board has no break input or supply switch.
        &mut NoPowerStage,
        &HEARTBEAT,
        CONTROL_DEADLINE,
    )
    .await
}

#[embassy_executor::task]
async fn link_task(core: &'static Core, rx: usart::UsartRx, tx: usart::UsartTx) {
    tasks::link(core, rx, tx).await
}

#[embassy_executor::task]
async fn supervisor_task() {
    tasks::supervisor(SoftWatchdog::start(WATCHDOG_TIMEOUT_US), &HEARTBEAT).await
}

#[embassy_executor::task]
async fn plant_task(rig: Plant, granules: Granules) {
    let mut next_log_ms = 0u32;
    // The truth log counts from power-on, as the device time does, not from the plant's
    // commissioning run before it.
    let boot_s = rig.time_s();
    plant::run(rig, granules, move |rig| {
        let t_ms = ((rig.time_s() - boot_s) * 1000.0) as u32;
        if t_ms >= next_log_ms {
            next_log_ms = t_ms + TRUTH_EVERY_MS;
            let d = plant::duties();
            hprintln!(
                "plant t_ms={} w1={} w2={} d1={} d2={}",
                t_ms,
                rig.speed_rad_s(0),
                rig.speed_rad_s(1),
                d[0],
                d[1]
            );
        }
    })
    .await
}

#[embassy_executor::task]
async fn end_task(seconds: u32) {
    Timer::after(Duration::from_secs(u64::from(seconds))).await;
    plant::emergency_off();
    hprintln!("qemu-rig: ran {} s of virtual time, exiting", seconds);
    qemu::exit(true)
}

/// `seconds=S` from QEMU's `-append`, via semihosting SYS_GET_CMDLINE.
fn run_seconds() -> Option<u32> {
    let mut buf = [0u8; 96];
    let mut block = [buf.as_mut_ptr() as usize, buf.len()];
    // SAFETY: SYS_GET_CMDLINE (0x15) writes at most block[1] bytes into buf and the length into
    // block[1]; both outlive the call, and the pointer is derived from a mutable borrow.
    let rc = unsafe { cortex_m_semihosting::syscall1(0x15, block.as_mut_ptr() as usize) };
    if rc != 0 {
        return None;
    }
    let line = buf.get(..block[1].min(buf.len()))?;
    let line = core::str::from_utf8(line).ok()?;
    line.split_whitespace()
        .find_map(|w| w.strip_prefix("seconds="))
        .and_then(|s| s.parse().ok())
}

#[entry]
fn main() -> ! {
    let resets = reset::count_this_boot();
    let core_p = cortex_m::Peripherals::take().unwrap_or_else(|| qemu::exit(false));
    let hello = Hello {
        reset_cause: ResetCause::Unknown,
        reset_count: resets as u16,
    };
    // The emulated board keeps no parameters across a power cycle: it boots with the defaults,
    // then is commissioned on its plant as a real rig is once after assembly (and as the host's
    // virtual rig is), so it runs on the models it identified, not on the datasheet's.
    // Its table describes the bowl its granules fall in (Granules: the default scene).
    let mut record = split_persisted(&default_persisted());
    ParticleParams::default().describe_bowl(&mut record.params);
    let (mut rig, _) = ControllerBackend::new(
        ControllerConfig::nominal(),
        persisted(&record),
        hello,
        PlantInjector,
    );
    let mut plant = Plant::new(PlantParams::nominal(), PLANT_SEED);
    match commission_on_plant(&mut rig, &mut plant) {
        Ok(()) => hprintln!("qemu-rig: commissioned on the plant"),
        Err(e) => hprintln!(
            "qemu-rig: commissioning on the plant failed ({}); running on the nominal models",
            match e {
                AssemblyError::Ended(_, Some(why)) => why.reason(),
                AssemblyError::Ended(_, None) => "it did not end idle",
                AssemblyError::Refused(_) => "COMMISSION was refused",
            }
        ),
    }
    gates::set_boot(resets as u16);
    let granules = Granules::new(PLANT_SEED, ControllerConfig::nominal().axes_angle_rad);
    // Device time starts now, after the commissioning run (which took CPU time, and plant
    // time: gate events are told where device time 0 is on the plant's clock).
    gates::set_time_origin(plant.now_ticks());
    time_driver::start(core_p.SYST);
    let (tx, rx) = usart::enable();
    let core = CORE
        .put(Mutex::new(RefCell::new(DeviceCore::new(rig))))
        .unwrap_or_else(|| qemu::exit(false));
    let seconds = run_seconds();
    hprintln!("qemu-rig: up, run for {:?} s of virtual time", seconds);
    executor::start(|spawner| {
        let ok = [
            plant_task(plant, granules)
                .map(|t| spawner.spawn(t))
                .is_ok(),
            control_task(core).map(|t| spawner.spawn(t)).is_ok(),
            link_task(core, rx, tx).map(|t| spawner.spawn(t)).is_ok(),
            supervisor_task().map(|t| spawner.spawn(t)).is_ok(),
            seconds.is_none_or(|s| end_task(s).map(|t| spawner.spawn(t)).is_ok()),
        ];
        if ok.contains(&false) {
            qemu::exit(false);
        }
    });
    qemu::exit(false)
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    plant::emergency_off();
    hprintln!("PANIC: {}", info);
    qemu::exit(false)
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    plant::emergency_off();
    hprintln!("HARD FAULT at pc {:#010x}", frame.pc());
    qemu::exit(false)
}

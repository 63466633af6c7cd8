//! The emulated board's release solenoid and gates: RELEASE drops a simulated granule (the
//! simulated rigs' one `model_core::sim::gates::Gates`, the project's default scene: Coriolis,
//! mu 0.029, start 0.05 m, rim 0.15 m), the plant task moves it under the plant's true bowl
//! speed one plant step at a time, and the release and exit gates report its times in device
//! time (microseconds since the device's clock started, as telemetry's milliseconds), taken on
//! the plant's capture clock, as the Black Pill's timer capture does.
//!
//! One granule at a time, so at most one release and one exit are ever pending: two slots, the
//! release always taken first.

use core::sync::atomic::{AtomicBool, AtomicU16, AtomicU32, Ordering};

use model_core::sim::gates::Gates;
use model_core::sim::granule::ParticleParams;
use model_core::wire::{GateEvent, GateKind, Reason};

/// Asked for by RELEASE, taken by the plant task at its next step.
static RELEASE_ASKED: AtomicBool = AtomicBool::new(false);
/// A granule is in the bowl.
static IN_FLIGHT: AtomicBool = AtomicBool::new(false);
/// The pending events' times, us, and whether each is pending.
static RELEASE_US: AtomicU32 = AtomicU32::new(0);
static RELEASE_PENDING: AtomicBool = AtomicBool::new(false);
static EXIT_US: AtomicU32 = AtomicU32::new(0);
static EXIT_PENDING: AtomicBool = AtomicBool::new(false);
/// The boot's reset counter (the `H` frame's), carried by every event.
static BOOT: AtomicU16 = AtomicU16::new(0);
/// The plant's capture clock at device time 0: the plant ran the commissioning before the
/// device's clock started, and events carry device time, as telemetry does.
static ORIGIN_US: AtomicU32 = AtomicU32::new(0);

/// Records the plant clock's value at device time 0.
pub fn set_time_origin(plant_us: u32) {
    ORIGIN_US.store(plant_us, Ordering::Relaxed);
}

/// Records the reset counter the events of this boot carry.
pub fn set_boot(reset_count: u16) {
    BOOT.store(reset_count, Ordering::Relaxed);
}

/// RELEASE: refused with `STATE` while a granule is in the bowl.
pub fn release() -> Result<(), Reason> {
    if IN_FLIGHT.load(Ordering::Acquire) || RELEASE_ASKED.load(Ordering::Acquire) {
        return Err(Reason::State);
    }
    RELEASE_ASKED.store(true, Ordering::Release);
    Ok(())
}

/// The oldest pending gate event.
pub fn next_event() -> Option<GateEvent> {
    let boot = BOOT.load(Ordering::Relaxed);
    let origin = ORIGIN_US.load(Ordering::Relaxed);
    let event = |kind, plant_us: u32| GateEvent {
        kind,
        time_us: plant_us.wrapping_sub(origin),
        boot,
    };
    if RELEASE_PENDING.swap(false, Ordering::AcqRel) {
        return Some(event(GateKind::Release, RELEASE_US.load(Ordering::Acquire)));
    }
    if EXIT_PENDING.swap(false, Ordering::AcqRel) {
        return Some(event(GateKind::Exit, EXIT_US.load(Ordering::Acquire)));
    }
    None
}

/// The granules of the plant task.
pub struct Granules(Gates);

impl Granules {
    /// Granules of the default scene, drawn with `seed`, in a bowl whose axes are `axes_rad`
    /// apart.
    pub fn new(seed: u32, axes_rad: f32) -> Self {
        Self(Gates::new(
            ParticleParams::default(),
            seed,
            f64::from(axes_rad),
        ))
    }

    /// One plant step of `dt_s` from capture time `now_us`, the shafts at `speeds_rad_s`.
    pub fn step(&mut self, speeds_rad_s: [f32; 2], now_us: u32, dt_s: f32) {
        if RELEASE_ASKED.swap(false, Ordering::AcqRel) {
            self.0.drop_granule(now_us);
            IN_FLIGHT.store(true, Ordering::Release);
            RELEASE_US.store(now_us, Ordering::Release);
            RELEASE_PENDING.store(true, Ordering::Release);
        }
        let speeds = speeds_rad_s.map(f64::from);
        if let Some(exit_us) = self.0.step(speeds, f64::from(dt_s)) {
            EXIT_US.store(exit_us, Ordering::Release);
            EXIT_PENDING.store(true, Ordering::Release);
            IN_FLIGHT.store(false, Ordering::Release);
        }
    }
}

//! The project's one simulated plant, [`model_core::sim::Plant`], behind a C ABI so the
//! emulated Black Pill harness (Python, tests/blackpill) drives the same plant as every other
//! simulated rig instead of a copy. The harness reads the PWM duty and direction pins from the
//! emulated timer and GPIO, calls [`plant_advance`], and feeds the returned edge timestamps to
//! the emulated capture timer.
//!
//! Why a C ABI and not a Rust harness on the unicorn engine: the peripheral models need
//! qiling's STM32F411 RCC/GPIO/EXTI models and its ELF loader, which are Python.
//!
//! The handle also carries the rig's granules (`model_core::sim::gates::Gates`, the same
//! granule-and-gates simulation as every simulated rig): the harness drops one when the
//! board's release solenoid fires ([`plant_release`]) and feeds the exit gate's time
//! ([`plant_exit`]) to the capture timer.
//!
//! Every function takes a pointer returned by [`plant_new`]; a null pointer or an axis other
//! than 0 or 1 is refused (a negative or zero result), never a crash.

use core::ffi::{CStr, c_char};
use model_core::control::ControllerConfig;
use model_core::sim::gates::Gates;
use model_core::sim::granule::ParticleParams;
use model_core::sim::{Plant, PlantParams};

/// A simulated rig: the plant and the granules in its bowl.
pub struct SimRig {
    plant: Plant,
    gates: Gates,
    /// The exit gate's capture time from the last [`plant_advance`], if a granule left in it.
    exit_us: Option<u32>,
}

impl SimRig {
    fn new(params: PlantParams, seed: u32, particle: ParticleParams) -> Self {
        Self {
            plant: Plant::new(params, seed),
            gates: Gates::new(
                particle,
                seed,
                f64::from(ControllerConfig::nominal().axes_angle_rad),
            ),
            exit_us: None,
        }
    }
}

/// The rig parameters the harness may set, flat and `repr(C)`. [`plant_params_nominal`] fills
/// it with the nominal rig; a rig file loader fills the same struct.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct RigParams {
    /// Supply voltage, V.
    pub supply_v: f32,
    /// cos of the angle between the axes (0 = no reaction torque).
    pub coupling: f32,
    /// Capture timer rate, Hz (timestamps returned by [`plant_edges`] count at this rate).
    pub timer_hz: u32,
    /// Per axis `[precession, spin]`: teeth per revolution.
    pub pulses_per_rev: [u16; 2],
    /// Per axis: tooth-spacing error, fraction of a pitch.
    pub tooth_error: [f32; 2],
    /// Per axis: edge jitter, s.
    pub jitter_s: [f32; 2],
    /// Per axis: once-per-revolution load ripple, N m.
    pub ripple_nm: [f32; 2],
}

/// What the harness needs of any plant, whatever the rig: a 32-bit capture clock at
/// `timer_hz`, and one physics step per call of [`plant_advance`] (the harness advances in a
/// quarter of a control period, the nominal rig's step length).
fn fit_to_harness(p: &mut PlantParams, timer_hz: u32) {
    p.timer_hz = timer_hz;
    p.timer_bits = 32;
    p.substeps = 1;
}

impl RigParams {
    fn to_plant(self) -> PlantParams {
        let mut p = PlantParams::nominal();
        p.supply_v = self.supply_v;
        p.coupling = self.coupling;
        fit_to_harness(&mut p, self.timer_hz);
        for (i, axis) in p.axes.iter_mut().enumerate() {
            axis.sensor.pulses_per_rev = self.pulses_per_rev[i].max(1);
            axis.sensor.tooth_error = self.tooth_error[i];
            axis.sensor.jitter_s = self.jitter_s[i];
            axis.ripple_nm = self.ripple_nm[i];
        }
        p
    }
}

/// Writes the nominal rig's parameters to `out`. Returns 0, or -1 for a null pointer.
///
/// # Safety
/// `out` is null or points to writable memory for one [`RigParams`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn plant_params_nominal(out: *mut RigParams) -> i32 {
    let n = PlantParams::nominal();
    let p = RigParams {
        supply_v: n.supply_v,
        coupling: n.coupling,
        timer_hz: n.timer_hz,
        pulses_per_rev: [
            n.axes[0].sensor.pulses_per_rev,
            n.axes[1].sensor.pulses_per_rev,
        ],
        tooth_error: [n.axes[0].sensor.tooth_error, n.axes[1].sensor.tooth_error],
        jitter_s: [n.axes[0].sensor.jitter_s, n.axes[1].sensor.jitter_s],
        ripple_nm: [n.axes[0].ripple_nm, n.axes[1].ripple_nm],
    };
    // SAFETY: the caller passes null or a valid pointer.
    match unsafe { out.as_mut() } {
        Some(o) => {
            *o = p;
            0
        }
        None => -1,
    }
}

/// A plant at rest at time 0, or null for a null `params`. Free it with [`plant_free`].
///
/// # Safety
/// `params` is null or points to a valid [`RigParams`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn plant_new(params: *const RigParams, seed: u32) -> *mut SimRig {
    // SAFETY: the caller passes null or a valid pointer.
    match unsafe { params.as_ref() } {
        Some(p) => Box::into_raw(Box::new(SimRig::new(
            p.to_plant(),
            seed,
            ParticleParams::default(),
        ))),
        None => core::ptr::null_mut(),
    }
}

/// A new plant for the rig described by the rig file at `path` (docs/rigs/nominal.toml lists
/// the keys), its capture clock at `timer_hz`; the file's own seed drives its tooth offsets and
/// jitter. On a bad file returns null and writes the reader's message (file, line, key, range),
/// NUL-terminated and cut to `message_cap` bytes, to `message`.
///
/// # Safety
/// `path` is null or a NUL-terminated string; `message` is null or writable for `message_cap`
/// bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn plant_new_from_rig_file(
    path: *const c_char,
    timer_hz: u32,
    message: *mut c_char,
    message_cap: u32,
) -> *mut SimRig {
    let report = |text: &str| {
        if message.is_null() || message_cap == 0 {
            return;
        }
        let n = text.len().min(message_cap as usize - 1);
        // SAFETY: the caller gives `message_cap` writable bytes; n + 1 <= message_cap.
        unsafe {
            core::ptr::copy_nonoverlapping(text.as_ptr().cast::<c_char>(), message, n);
            *message.add(n) = 0;
        }
    };
    if path.is_null() {
        report("no rig file path was given");
        return core::ptr::null_mut();
    }
    // SAFETY: the caller passes a NUL-terminated string.
    let path = unsafe { CStr::from_ptr(path) }
        .to_string_lossy()
        .into_owned();
    let rigs = match rig_file::load(std::path::Path::new(&path)) {
        Ok(rigs) => rigs,
        Err(e) => {
            report(&format!("{e:#}"));
            return core::ptr::null_mut();
        }
    };
    let [rig] = rigs.as_slice() else {
        report(&format!(
            "{path} holds {} rigs ([[plant]] tables); the emulated board runs one: give a file with one rig",
            rigs.len()
        ));
        return core::ptr::null_mut();
    };
    let mut params = rig.params;
    fit_to_harness(&mut params, timer_hz);
    let particle = rig.particle.unwrap_or_default();
    Box::into_raw(Box::new(SimRig::new(params, rig.seed, particle)))
}

/// Frees a plant from [`plant_new`] (null is ignored).
///
/// # Safety
/// `plant` is null or came from [`plant_new`] and is not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn plant_free(plant: *mut SimRig) {
    if !plant.is_null() {
        // SAFETY: the pointer came from `Box::into_raw` in `plant_new`.
        drop(unsafe { Box::from_raw(plant) });
    }
}

/// Advances by `dt_s` with the signed duties held (-1..=1; the sign is the direction).
/// Returns 0, or -1 for a null plant or a `dt_s` that is not finite and positive.
///
/// # Safety
/// `plant` is null or came from [`plant_new`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn plant_advance(
    plant: *mut SimRig,
    duty0: f32,
    duty1: f32,
    dt_s: f32,
) -> i32 {
    // SAFETY: the caller passes null or a live plant.
    let Some(p) = (unsafe { plant.as_mut() }) else {
        return -1;
    };
    if !(dt_s.is_finite() && dt_s > 0.0) {
        return -1;
    }
    p.plant.advance([duty0, duty1], dt_s);
    // The granule moves under the speeds the shafts reached in the step.
    let speeds = [0, 1].map(|axis| f64::from(p.plant.speed_rad_s(axis)));
    p.exit_us = p.gates.step(speeds, f64::from(dt_s));
    0
}

/// Drops a granule at the start radius at capture time `time_ticks` (when the board's release
/// solenoid fired); it moves from the next [`plant_advance`] on, and its exit gate time counts
/// from `time_ticks`. One still in the bowl is replaced. Returns 0, or -1 for a null plant.
///
/// # Safety
/// `plant` is null or came from [`plant_new`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn plant_release(plant: *mut SimRig, time_ticks: u32) -> i32 {
    // SAFETY: the caller passes null or a live plant.
    let Some(p) = (unsafe { plant.as_mut() }) else {
        return -1;
    };
    // A rig file's granules in the bowl model start from the shafts' true speeds now.
    let speeds = [0, 1].map(|axis| f64::from(p.plant.speed_rad_s(axis)));
    p.gates.drop_granule_at(time_ticks, speeds);
    0
}

/// Whether a granule reached the rim in the last [`plant_advance`]: 1 and its exit gate time
/// (capture ticks) in `out`, 0 if none did, -1 for a bad pointer.
///
/// # Safety
/// `plant` is null or came from [`plant_new`]; `out` is null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn plant_exit(plant: *const SimRig, out: *mut u32) -> i32 {
    // SAFETY: the caller passes null or valid pointers.
    let (Some(p), Some(out)) = (unsafe { plant.as_ref() }, unsafe { out.as_mut() }) else {
        return -1;
    };
    match p.exit_us {
        Some(t) => {
            *out = t;
            1
        }
        None => 0,
    }
}

/// Copies the edges of `axis` from the last [`plant_advance`] (timer ticks, oldest first) to
/// `out` (room for `cap`). Returns how many were copied, or -1 for a bad pointer or axis.
///
/// # Safety
/// `plant` is null or came from [`plant_new`]; `out` points to `cap` writable `u32`s.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn plant_edges(
    plant: *const SimRig,
    axis: u32,
    out: *mut u32,
    cap: u32,
) -> i32 {
    // SAFETY: the caller passes null or a live plant.
    let Some(p) = (unsafe { plant.as_ref() }) else {
        return -1;
    };
    if axis > 1 || out.is_null() {
        return -1;
    }
    let edges = p.plant.edges(axis as usize);
    let n = edges.len().min(cap as usize);
    // SAFETY: `out` has room for `cap >= n` values.
    unsafe { core::ptr::copy_nonoverlapping(edges.as_ptr(), out, n) };
    n as i32
}

/// True speed of `axis`, rad/s (NaN for a bad pointer or axis: the caller checks).
///
/// # Safety
/// `plant` is null or came from [`plant_new`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn plant_speed_rad_s(plant: *const SimRig, axis: u32) -> f32 {
    // SAFETY: the caller passes null or a live plant.
    match unsafe { plant.as_ref() } {
        Some(p) if axis <= 1 => p.plant.speed_rad_s(axis as usize),
        _ => f32::NAN,
    }
}

/// Armature current of `axis`, A, signed in the motor's positive direction (what an inline
/// shunt and amplifier measure; NaN for a bad pointer or axis: the caller checks).
///
/// # Safety
/// `plant` is null or came from [`plant_new`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn plant_current_a(plant: *const SimRig, axis: u32) -> f32 {
    // SAFETY: the caller passes null or a live plant.
    match unsafe { plant.as_ref() } {
        Some(p) if axis <= 1 => p.plant.current_a(axis as usize),
        _ => f32::NAN,
    }
}

/// The motor supply switch ahead of both bridges: `on` 0 opens it (no bridge drives, however
/// it failed), anything else closes it. Returns 0, or -1 for a null plant.
///
/// # Safety
/// `plant` is null or came from [`plant_new`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn plant_set_supply(plant: *mut SimRig, on: u32) -> i32 {
    // SAFETY: the caller passes null or a live plant.
    let Some(p) = (unsafe { plant.as_mut() }) else {
        return -1;
    };
    if on == 0 {
        p.plant.cut_supply();
    } else {
        p.plant.restore_supply();
    }
    0
}

/// Injects a fault into `axis` from plant time `from_s` on: `kind` 0 blocks the shaft (a stall),
/// 1 silences the sensor, 2 sticks the bridge on (any nonzero duty drives at full duty), 3 shorts
/// the bridge (drives at full duty even at zero duty: only the supply switch stops it). Returns
/// 0, or -1 for a null plant, an axis other than 0 or 1, or an unknown kind.
///
/// # Safety
/// `plant` is null or came from [`plant_new`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn plant_inject(
    plant: *mut SimRig,
    axis: u32,
    kind: u32,
    from_s: f32,
) -> i32 {
    // SAFETY: the caller passes null or a live plant.
    let Some(p) = (unsafe { plant.as_mut() }) else {
        return -1;
    };
    if axis > 1 {
        return -1;
    }
    let faults = &mut p.plant.params_mut().axes[axis as usize].faults;
    match kind {
        0 => faults.blocked_from_s = from_s,
        1 => faults.dead_sensor_from_s = from_s,
        2 => faults.bridge_stuck_from_s = from_s,
        3 => faults.bridge_shorted_from_s = from_s,
        _ => return -1,
    }
    0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nominal_plant_spins_up_and_emits_edges_through_the_c_abi() {
        let mut params = core::mem::MaybeUninit::<RigParams>::uninit();
        // SAFETY: a valid out pointer.
        assert_eq!(unsafe { plant_params_nominal(params.as_mut_ptr()) }, 0);
        // SAFETY: initialised just above.
        let params = unsafe { params.assume_init() };
        // SAFETY: valid pointers throughout; the plant is freed at the end.
        unsafe {
            let p = plant_new(&params, 1);
            assert!(!p.is_null());
            let mut edges = 0;
            let mut buf = [0u32; 64];
            for _ in 0..8000 {
                assert_eq!(plant_advance(p, 0.0, 0.8, 0.00025), 0);
                edges += plant_edges(p, 1, buf.as_mut_ptr(), 64);
            }
            let w = plant_speed_rad_s(p, 1);
            // Two seconds at 80 % of 12 V: the spin shaft runs and the sensor reports it.
            assert!(w > 1.0, "spin speed {w}");
            assert!(edges > 12, "edges {edges}");
            assert_eq!(plant_advance(p, 0.0, 0.0, f32::NAN), -1);
            assert_eq!(plant_edges(p, 2, buf.as_mut_ptr(), 64), -1);
            // A granule dropped into the spinning bowl leaves through the exit gate, after
            // the time it was dropped at; none is reported before it was dropped.
            let mut exit = 0u32;
            assert_eq!(plant_exit(p, &mut exit), 0);
            assert_eq!(plant_release(p, 2_000_000), 0);
            let mut steps = 0;
            while plant_exit(p, &mut exit) == 0 && steps < 40_000 {
                assert_eq!(plant_advance(p, 0.0, 0.8, 0.00025), 0);
                steps += 1;
            }
            assert_eq!(plant_exit(p, &mut exit), 1, "no exit in 10 s");
            let after_s = f64::from(exit - 2_000_000) * 1e-6;
            let moved_s = f64::from(steps) * 0.00025;
            assert!(
                after_s <= moved_s && after_s > moved_s - 0.00025,
                "exit {after_s} s after the drop, in step ending {moved_s} s"
            );
            assert_eq!(plant_exit(p, core::ptr::null_mut()), -1);
            plant_free(p);
            assert_eq!(plant_advance(core::ptr::null_mut(), 0.0, 0.0, 0.001), -1);
        }
    }

    fn spin_speed_after_a_tenth_of_a_second(p: *mut SimRig) -> f32 {
        let mut buf = [0u32; 64];
        // SAFETY: a live plant and a valid buffer.
        unsafe {
            for _ in 0..400 {
                assert_eq!(plant_advance(p, 0.0, 0.8, 0.00025), 0);
                plant_edges(p, 1, buf.as_mut_ptr(), 64);
            }
            plant_speed_rad_s(p, 1)
        }
    }

    #[test]
    fn a_rig_file_plant_is_the_rig_it_describes() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../docs/rigs/");
        let mut message = [0 as c_char; 256];
        let open = |name: &str, message: &mut [c_char; 256]| {
            let path = std::ffi::CString::new(format!("{dir}{name}")).unwrap();
            // SAFETY: valid strings and buffer.
            unsafe { plant_new_from_rig_file(path.as_ptr(), 1_000_000, message.as_mut_ptr(), 256) }
        };
        let nominal = open("nominal.toml", &mut message);
        let heavy = open("heavy-bowl.toml", &mut message);
        assert!(!nominal.is_null() && !heavy.is_null());
        // Three times the spin inertia: the heavy bowl gains speed at most a third as fast in the
        // first tenth of a second at the same duty (friction takes more of its torque too).
        let (w_nominal, w_heavy) = (
            spin_speed_after_a_tenth_of_a_second(nominal),
            spin_speed_after_a_tenth_of_a_second(heavy),
        );
        assert!(
            w_heavy < 0.8 * w_nominal,
            "heavy {w_heavy} vs nominal {w_nominal} rad/s"
        );
        // SAFETY: both came from plant_new_from_rig_file.
        unsafe {
            plant_free(nominal);
            plant_free(heavy);
        }
        let missing = open("no-such-rig.toml", &mut message);
        assert!(missing.is_null());
        // SAFETY: the function NUL-terminated the message.
        let text = unsafe { CStr::from_ptr(message.as_ptr()) }.to_string_lossy();
        assert!(
            text.contains("cannot read the rig file") && text.contains("no-such-rig.toml"),
            "{text}"
        );
    }
}

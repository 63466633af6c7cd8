//! `bowl sim faults --rig-file`: the fault matrix, each fault injected in turn on each axis of a
//! commissioned plant running at speed, detection time and peak speed on the plant's true speed.

use model_core::control::Fault;
use model_core::sim::ClosedLoop;
use model_core::wire::FaultCode;
use rig_client::words;
use rig_file::Rig;
use serde::Serialize;
use std::f64::consts::TAU;

use super::{LINK_TIMEOUT_S, commissioned, config_for, pour_material};

/// One injected fault's outcome (the worse of the two axes it was injected on, one at a time).
#[derive(Serialize, Debug, Clone)]
pub struct FaultOutcome {
    /// From injection to the latched fault, s; None = not detected.
    pub detected_s: Option<f64>,
    /// What the targets allow, s.
    pub bound_s: f64,
    /// Highest true speed of the faulted axis between injection and detection, rad/s.
    pub peak_speed_rad_s: f64,
    /// True speed of the faulted axis in the tick that saw its first edge after the injection,
    /// rad/s: no rule judging edges can stop the motor sooner, so a peak at this speed is the
    /// sensor's limit, not the controller's. None when no edge came before detection.
    pub first_edge_speed_rad_s: Option<f64>,
    /// Both duties were zero in the tick the fault latched.
    pub pwm_zero: bool,
    /// Still latched, duties zero, one second later.
    pub latched: bool,
    /// Highest true speed of the faulted axis from injection until no bridge drives it, rad/s:
    /// the detection, or for a shorted bridge (which drives on after the fault) the supply cut;
    /// one second after detection at most. (Coasting afterwards, a rod can still speed up as
    /// the spin's reaction hands it the bowl's momentum: no drive to stop.)
    pub peak_until_drive_off_rad_s: f64,
    /// The supervisor opened the supply cut (a current flowed after the bridge was told to stop).
    pub supply_cut: bool,
    /// What caught the fault: "edges", "current" or "watchdog" (the host link's); None = not
    /// detected. (A break input stops the bridge in hardware and is the firmware's to report.)
    pub detected_by: Option<&'static str>,
    /// The latched fault in words; None = not detected.
    pub fault: Option<String>,
}

/// The five faults.
#[derive(Serialize, Debug, Clone)]
pub struct FaultSet {
    /// Dead sensor.
    pub sensor_lost: FaultOutcome,
    /// Blocked shaft.
    pub stall: FaultOutcome,
    /// Bridge stuck on (full duty in the commanded direction; zero duty still coasts).
    pub overspeed: FaultOutcome,
    /// Bridge shorted (full duty whatever it is told, zero included: only the supply cut
    /// stops it).
    pub shorted_bridge: FaultOutcome,
    /// No command or heartbeat from the host.
    pub link_lost: FaultOutcome,
}

/// One plant of `bowl sim faults`.
#[derive(Serialize, Debug, Clone)]
pub struct PlantFaults {
    /// The plant's name.
    pub name: String,
    /// "ok" or "refused: <reason>".
    pub commissioning: String,
    /// A fault latched before any injection (a false fault).
    pub false_fault: bool,
    /// None when commissioning refused.
    pub faults: Option<FaultSet>,
}

#[derive(Clone, Copy, PartialEq)]
enum Injected {
    SensorLost,
    Stall,
    Overspeed,
    ShortedBridge,
    LinkLost,
}

/// Runs `rig` at `speed` and injects each fault in turn on each axis.
pub fn fault_plant(rig: &Rig, speed: f32) -> PlantFaults {
    let cl = match commissioned(rig, config_for(rig)) {
        Err(reason) => {
            return PlantFaults {
                name: rig.name.clone(),
                commissioning: format!("refused: {reason}"),
                false_fault: false,
                faults: None,
            };
        }
        Ok(cl) => cl,
    };
    // Settle at `speed` once, then copy the loop for every injection.
    let mut running = cl;
    let mut cfg = *running.ctrl.config();
    cfg.host_timeout_s = LINK_TIMEOUT_S;
    let mut false_fault = running.ctrl.set_parameters(cfg).is_err();
    pour_material(&mut running);
    false_fault |=
        running.ctrl.set_motor_speeds(speed, speed).is_err() || running.ctrl.start().is_err();
    let settle = (3.0 + 2.0 * std::f32::consts::TAU / speed).min(40.0);
    for _ in 0..(settle / running.dt_s()) as u32 {
        running.ctrl.host_heartbeat();
        running.tick();
        false_fault |= running.ctrl.fault().is_some();
    }
    let rate_bound = |axis: usize| {
        let n = rig.params.axes[axis].sensor.pulses_per_rev as f64;
        (3.0 * TAU / (n * speed as f64)).max(0.2)
    };
    let one = |what: Injected| {
        let mut worst: Option<FaultOutcome> = None;
        for axis in 0..2 {
            let bound = match what {
                Injected::LinkLost => LINK_TIMEOUT_S as f64 + 0.1,
                _ => rate_bound(axis),
            };
            let o = inject(running, what, axis, bound);
            let worse = match (&worst, o.detected_s) {
                (None, _) => true,
                (Some(w), None) => {
                    w.detected_s.is_some() || o.peak_speed_rad_s > w.peak_speed_rad_s
                }
                (Some(w), Some(d)) => w.detected_s.is_some_and(|wd| d > wd),
            };
            if worse {
                worst = Some(o);
            }
            if what == Injected::LinkLost {
                break;
            }
        }
        worst.expect("two axes ran")
    };
    PlantFaults {
        name: rig.name.clone(),
        commissioning: "ok".into(),
        false_fault,
        faults: Some(FaultSet {
            sensor_lost: one(Injected::SensorLost),
            stall: one(Injected::Stall),
            overspeed: one(Injected::Overspeed),
            shorted_bridge: one(Injected::ShortedBridge),
            link_lost: one(Injected::LinkLost),
        }),
    }
}

fn inject(mut cl: ClosedLoop, what: Injected, axis: usize, bound_s: f64) -> FaultOutcome {
    let t0 = cl.rig.time_s();
    {
        let f = &mut cl.rig.params_mut().axes[axis].faults;
        let now = t0 as f32;
        match what {
            Injected::SensorLost => f.dead_sensor_from_s = now,
            Injected::Stall => f.blocked_from_s = now,
            Injected::Overspeed => f.bridge_stuck_from_s = now,
            Injected::ShortedBridge => f.bridge_shorted_from_s = now,
            Injected::LinkLost => {}
        }
    }
    let heartbeat = what != Injected::LinkLost;
    let mut detected = None;
    let mut pwm_zero = false;
    let mut peak: f64 = 0.0;
    let mut first_edge_speed = None;
    let limit = (3.0 * bound_s + 2.0) as f32;
    let ticks = (limit / cl.dt_s()) as u32;
    for tick in 0..ticks {
        if heartbeat {
            cl.ctrl.host_heartbeat();
        }
        // The first tick's edges came before the injection.
        if tick > 0 && first_edge_speed.is_none() && !cl.rig.edges(axis).is_empty() {
            first_edge_speed = Some(cl.rig.speed_rad_s(axis).abs() as f64);
        }
        let duties = cl.tick();
        // Until detection: the loop ends there.
        peak = peak.max(cl.rig.speed_rad_s(axis).abs() as f64);
        if cl.ctrl.fault().is_some() {
            detected = Some(cl.rig.time_s() - t0);
            pwm_zero = duties == [0.0; 2];
            break;
        }
    }
    let mut latched = false;
    let mut peak_until_drive_off = peak;
    let fault: Option<Fault> = cl.ctrl.fault();
    if detected.is_some() {
        latched = true;
        let mut driven = what == Injected::ShortedBridge && !cl.rig.supply_is_cut();
        cl.run(1.0, |c| {
            latched &= c.ctrl.fault() == fault && c.duties() == [0.0; 2];
            if driven {
                peak_until_drive_off =
                    peak_until_drive_off.max(c.rig.speed_rad_s(axis).abs() as f64);
                driven = !c.rig.supply_is_cut();
            }
        });
    }
    FaultOutcome {
        detected_s: detected,
        bound_s,
        peak_speed_rad_s: peak,
        first_edge_speed_rad_s: first_edge_speed,
        pwm_zero,
        latched,
        peak_until_drive_off_rad_s: peak_until_drive_off,
        supply_cut: cl.rig.supply_is_cut(),
        detected_by: fault.map(|f| f.detected_by().word()),
        fault: fault.map(fault_words),
    }
}

/// A fault in the words the monitor and `bowl send status` use (by its telemetry code).
fn fault_words(f: Fault) -> String {
    FaultCode::from_code(f.code().into()).map_or_else(
        || format!("fault code {}", f.code()),
        |c| words::fault(c).to_string(),
    )
}

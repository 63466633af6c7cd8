//! `bowl sim faults --rig-file`: the fault matrix, each fault injected in turn on each axis of a
//! commissioned plant running at speed, detection time and peak speed on the plant's true speed.

use model_core::control::Fault;
use model_core::sim::ClosedLoop;
use model_core::wire::FaultCode;
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

/// One axis of a plant held at speed with a sensor that drops pulses (`--drop-pulses-pct`).
#[derive(Serialize, Debug, Clone)]
pub struct DroppedPulses {
    /// Pulses the sensor dropped from the start of the hold to its end (or the false fault).
    pub dropped: u32,
    /// Pulses the controller inferred missing meanwhile.
    pub inferred: u32,
    /// Mean true speed over the hold's last [`DROP_MEAN_S`] s, % from the target (None: it
    /// faulted first).
    pub true_speed_error_pct: Option<f64>,
    /// Mean measured speed over the same seconds, % from the mean true speed.
    pub reading_error_pct: Option<f64>,
}

/// Seconds the plant runs at speed with the sensor dropping pulses, after settling, before the
/// faults are injected: at 10 % dropped and 3 rad/s, two in a row came every 17 s.
pub const DROP_HOLD_S: f32 = 30.0;
/// The last seconds of the hold the speed errors are taken over.
pub const DROP_MEAN_S: f32 = 10.0;

/// One plant of `bowl sim faults`.
#[derive(Serialize, Debug, Clone)]
pub struct PlantFaults {
    /// The plant's name.
    pub name: String,
    /// "ok" or "refused: <reason>".
    pub commissioning: String,
    /// A fault latched before any injection (a false fault).
    pub false_fault: bool,
    /// The false fault in words (None: none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub false_fault_words: Option<String>,
    /// With `--drop-pulses-pct`: per axis, what the dropping sensor did over the hold.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dropped_pulses: Option<[DroppedPulses; 2]>,
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

/// Runs `rig` at `speed` and injects each fault in turn on each axis; with `drop_pct` > 0 each
/// sensor drops that share of its pulses at random from after commissioning on, and the plant
/// is held at speed [`DROP_HOLD_S`] s more before the injections.
pub fn fault_plant(rig: &Rig, speed: f32, drop_pct: f32) -> PlantFaults {
    let cl = match commissioned(rig, config_for(rig)) {
        Err(reason) => {
            return PlantFaults {
                name: rig.name.clone(),
                commissioning: format!("refused: {reason}"),
                false_fault: false,
                false_fault_words: None,
                dropped_pulses: None,
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
    for a in &mut running.rig.params_mut().axes {
        a.faults.missing_probability = drop_pct / 100.0;
    }
    let dropped_before = [running.rig.edges_dropped(0), running.rig.edges_dropped(1)];
    let inferred_before = running.ctrl.status().axes.map(|a| a.inferred_missing);
    false_fault |=
        running.ctrl.set_motor_speeds(speed, speed).is_err() || running.ctrl.start().is_err();
    let settle = (3.0 + 2.0 * std::f32::consts::TAU / speed).min(40.0);
    let hold = if drop_pct > 0.0 { DROP_HOLD_S } else { 0.0 };
    let ticks = ((settle + hold) / running.dt_s()) as u32;
    let mean_from = ((settle + hold - DROP_MEAN_S) / running.dt_s()) as u32;
    let mut sums = [[0.0f64; 2]; 2];
    let mut n = 0u32;
    for tick in 0..ticks {
        running.ctrl.host_heartbeat();
        running.tick();
        if running.ctrl.fault().is_some() {
            false_fault = true;
            break;
        }
        if tick >= mean_from {
            let st = running.ctrl.status();
            for (i, s) in sums.iter_mut().enumerate() {
                s[0] += running.rig.speed_rad_s(i) as f64;
                s[1] += st.axes[i].measured_rad_s as f64;
            }
            n += 1;
        }
    }
    let false_fault_words = running
        .ctrl
        .fault()
        .map(|f| FaultCode::from(Some(f)).words().to_string());
    let dropped_pulses = (drop_pct > 0.0).then(|| {
        let st = running.ctrl.status();
        [0, 1].map(|i| {
            let done = n > 0 && !false_fault;
            let true_mean = sums[i][0] / n.max(1) as f64;
            DroppedPulses {
                dropped: running.rig.edges_dropped(i) - dropped_before[i],
                inferred: st.axes[i].inferred_missing - inferred_before[i],
                true_speed_error_pct: done.then(|| 100.0 * (true_mean / speed as f64 - 1.0)),
                reading_error_pct: done
                    .then(|| 100.0 * (sums[i][1] / n.max(1) as f64 / true_mean - 1.0)),
            }
        })
    });
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
        false_fault_words,
        dropped_pulses,
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
            let dt = crate::number::from_f32(cl.dt_s());
            detected = Some(crate::number::tick_s(cl.rig.time_s() - t0, dt));
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
        fault: fault.map(|f| FaultCode::from(Some(f)).words().to_string()),
    }
}

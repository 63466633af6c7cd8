//! What the session showed, measured from the telemetry alone (what the PC receives): the step
//! responses of both motors, the fault reaction, and the residence-time predictions, checked
//! against the model computed independently on the host in f64.

use model_core::bowl::BowlGeometry;
use model_core::particle::{self, Model, Outcome, Scene};
use model_core::wire::{DeviceState, FaultCode, ParamId, ParamValues, Residence, Telemetry};
use serde::Serialize;

use super::script::{Mark, MarkKind, RESIDENCE_TARGET_MS};

/// The tolerances a step must meet to count as tracked.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Tolerances {
    /// Settling band around the setpoint, fraction of the setpoint.
    pub settle_band: f64,
    /// Settled within this long after the step, s.
    pub settle_within_s: f64,
    /// |steady mean - setpoint| at most this fraction of the setpoint.
    pub steady_error: f64,
    /// Fraction of the step window (its end) taken as steady.
    pub steady_fraction: f64,
    /// Motors counted as stopped below this speed, rad/s.
    pub stopped_rad_s: f64,
}

/// The tolerances used. The controller ramps at 4 rad/s^2 and its loop bandwidth is 8 rad/s,
/// capped at 0.5 x the pulse rate: with 12 pulses per revolution at 1.5 rad/s that cap is
/// 1.4 rad/s (time constant 0.7 s), so from rest a step needs 3 to 4 s to stay within 5 %;
/// at speed, about 1 s. The pulse-based measurement ripples by 1 to 3 % at the slowest step.
pub const TOLERANCES: Tolerances = Tolerances {
    settle_band: 0.05,
    settle_within_s: 5.0,
    steady_error: 0.02,
    steady_fraction: 0.3,
    stopped_rad_s: 0.05,
};

/// One motor's response to one step.
#[derive(Debug, Clone, Serialize)]
pub struct AxisStep {
    /// `precession` or `spin`.
    pub axis: &'static str,
    /// Measured speed when the step was commanded, rad/s.
    pub from_rad_s: f64,
    /// The setpoint, rad/s.
    pub set_rad_s: f64,
    /// 10 % to 90 % of the change, s (none if the change is too small, never completed, or
    /// not resolved: from rest the first speed reading comes only after a few pulses, already
    /// past 90 %).
    pub rise_time_s: Option<f64>,
    /// From the step to the first non-zero speed reading, s (steps from rest).
    pub first_reading_s: Option<f64>,
    /// From the step to staying inside the settling band, s (none if it never settled).
    pub settling_time_s: Option<f64>,
    /// Largest excursion past the setpoint, percent of the change.
    pub overshoot_pct: f64,
    /// Mean of the steady part, rad/s.
    pub steady_mean_rad_s: f64,
    /// |steady mean - setpoint|, percent of the setpoint.
    pub steady_error_pct: f64,
    /// Half the peak-to-peak of the steady part, percent of the setpoint.
    pub steady_ripple_pct: f64,
    /// Settled within the tolerance and the steady error within the tolerance.
    pub tracked: bool,
}

/// Predicted residence times as sent in telemetry, ms (mean over the steady part).
#[derive(Debug, Clone, Serialize)]
pub struct Predicted {
    /// Combined bowl speed measured (Eq. 2), rad/s.
    pub bowl_rad_s: f64,
    /// Flat model (paper Eq. 6/7), from telemetry, ms.
    pub flat_ms: Option<f64>,
    /// Coriolis model (paper Eq. 10/11, MODEL-NOTES coefficients), from telemetry, ms.
    pub coriolis_ms: Option<f64>,
    /// The same two computed on the host in f64 at the measured bowl speed, ms.
    pub host_flat_ms: Option<f64>,
    /// Coriolis, host, ms.
    pub host_coriolis_ms: Option<f64>,
}

/// One running step.
#[derive(Debug, Clone, Serialize)]
pub struct Step {
    /// The step's name.
    pub name: String,
    /// Device time of the step, s.
    pub at_s: f64,
    /// Length of its window, s.
    pub window_s: f64,
    /// The rig accepted the command.
    pub accepted: bool,
    /// Both motors.
    pub axes: Vec<AxisStep>,
    /// Residence times at the steady speed.
    pub predicted: Option<Predicted>,
}

/// The fault and the rig's reaction.
#[derive(Debug, Clone, Serialize)]
pub struct FaultReaction {
    /// Device time of the injection (last telemetry frame before the rig's answer), s.
    pub injected_at_s: f64,
    /// The fault the rig reported.
    pub fault: Option<String>,
    /// From the injection to the first frame reporting the fault, s.
    pub detection_s: Option<f64>,
    /// When the fault must be seen, s after the injection: the controller's sensor timeout
    /// `max(floor, 3 pulse periods)` at the spin setpoint counts from the *last* edge, which came
    /// up to one pulse period before the injection; plus one telemetry period either way for the
    /// bracketing of the injection and the detection by telemetry frames, and 5 ms for the
    /// board to act on the command (its link task and 1 kHz control tick).
    pub expected_detection_s: Option<[f64; 2]>,
    /// From the injection to the first frame with both duties zero in the Faulted state, s.
    pub motors_off_s: Option<f64>,
    /// Every frame from then until CLEAR shows both duties zero.
    pub stayed_off: bool,
    /// The healthy (precession) motor's measured speed before the fault and when cleared, rad/s.
    pub precession_before_rad_s: f64,
    /// At the clear.
    pub precession_at_clear_rad_s: f64,
    /// From the injection until the precession motor read below the stopped threshold, s.
    pub precession_stopped_s: Option<f64>,
    /// Both motors' drive went to zero and stayed there, and the healthy motor came to rest.
    pub stopped_both_motors: bool,
}

/// The residence-time step checked against the host's own inverse and Eq. 2 split.
#[derive(Debug, Clone, Serialize)]
pub struct ResidenceCheck {
    /// The target, ms (Coriolis model).
    pub target_ms: u32,
    /// The rig accepted it.
    pub accepted: bool,
    /// Bowl speed for the target from the host's inverse (f64), rad/s.
    pub host_bowl_rad_s: Option<f64>,
    /// Eq. 2 split of that speed at the rig's ratio and axes angle, rad/s.
    pub host_split_rad_s: Option<[f64; 2]>,
    /// The setpoints the rig chose, rad/s.
    pub rig_set_rad_s: [f64; 2],
    /// Host and rig agree within 5 mrad/s on both motors.
    pub split_agrees: bool,
    /// Flat-model residence time at the host's bowl speed, ms (the Coriolis one is the target).
    pub host_flat_at_target_ms: Option<f64>,
}

/// Everything the demo reports.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// Which rig ran.
    pub rig: String,
    /// Its description.
    pub rig_description: String,
    /// Why the emulated board was not used.
    pub qemu_note: Option<String>,
    /// Faster than real time.
    pub fast: bool,
    /// Device time covered, s.
    pub device_s: f64,
    /// Wall time, s.
    pub wall_s: f64,
    /// Decoder counters.
    pub frames: serde_json::Value,
    /// Telemetry rows logged.
    pub telemetry_rows: usize,
    /// The session ended early.
    pub aborted: Option<String>,
    /// The emulated board's console, last lines (empty on the host rig).
    pub board_console: Vec<String>,
    /// Bytes the host rig could not deliver (a stuck reader; 0 expected).
    pub host_bytes_dropped: u64,
    /// The rig's parameters at the start (PARAMS answer), by token.
    pub params: Option<serde_json::Map<String, serde_json::Value>>,
    /// Tolerances applied.
    pub tolerances: Tolerances,
    /// Running steps.
    pub steps: Vec<Step>,
    /// The fault.
    pub fault: Option<FaultReaction>,
    /// The residence-time step.
    pub residence: Option<ResidenceCheck>,
    /// The rig was back at rest (Idle, speeds below the threshold) at the end.
    pub ended_at_rest: bool,
    /// The session's points.
    pub marks: Vec<Mark>,
    /// Every command and its answer.
    pub commands: Vec<super::session::CommandRecord>,
    /// One line per check: all true means the demo showed what it should.
    pub checks: Checks,
}

/// The verdicts.
#[derive(Debug, Clone, Serialize)]
pub struct Checks {
    /// Every motor of every accepted running step tracked its setpoint.
    pub speeds_tracked: bool,
    /// The injected fault stopped both motors.
    pub fault_stopped_both_motors: bool,
    /// The residence-time setpoints match the host's inverse and split.
    pub residence_split_agrees: bool,
    /// No frame was corrupt or missing.
    pub link_clean: bool,
}

const AXES: [&str; 2] = ["precession", "spin"];

fn measured(t: &Telemetry, axis: usize) -> f64 {
    let m = if axis == 0 { t.precession } else { t.spin };
    f64::from(m.measured_mrad_s) / 1000.0
}

fn set(t: &Telemetry, axis: usize) -> f64 {
    let m = if axis == 0 { t.precession } else { t.spin };
    f64::from(m.set_mrad_s) / 1000.0
}

fn duty_bp(t: &Telemetry, axis: usize) -> i16 {
    if axis == 0 {
        t.precession.duty_bp
    } else {
        t.spin.duty_bp
    }
}

fn seconds(ms: u32) -> f64 {
    f64::from(ms) / 1000.0
}

/// Frames with `from_ms <= time < to_ms`.
fn window(tel: &[Telemetry], from_ms: u32, to_ms: u32) -> Vec<Telemetry> {
    tel.iter()
        .filter(|t| t.time_ms >= from_ms && t.time_ms < to_ms)
        .copied()
        .collect()
}

/// Step measures of one axis over the window that starts at the step.
fn axis_step(frames: &[Telemetry], at_ms: u32, axis: usize, tol: &Tolerances) -> Option<AxisStep> {
    let first = frames.first()?;
    let last = frames.last()?;
    let y0 = measured(first, axis);
    let y1 = set(last, axis);
    let change = y1 - y0;
    let rel = |t: &Telemetry| (measured(t, axis) - y0) / change;
    let since = |t: &Telemetry| seconds(t.time_ms.wrapping_sub(at_ms));
    let rise_time_s = if change.abs() >= 0.05 {
        let t10 = frames.iter().find(|t| rel(t) >= 0.1).map(since);
        let t90 = frames.iter().find(|t| rel(t) >= 0.9).map(since);
        // Both crossings in the same frame: the reading jumped, the rise is not resolved.
        t10.zip(t90).map(|(a, b)| b - a).filter(|&r| r > 0.0)
    } else {
        None
    };
    let first_reading_s = (y0 == 0.0)
        .then(|| frames.iter().find(|t| measured(t, axis) != 0.0).map(since))
        .flatten();
    let band = tol.settle_band * y1.abs().max(0.1);
    let outside = frames
        .iter()
        .rposition(|t| (measured(t, axis) - y1).abs() > band);
    let settling_time_s = match outside {
        None => Some(0.0),
        Some(i) if i + 1 < frames.len() => Some(since(&frames[i + 1])),
        Some(_) => None,
    };
    let overshoot_pct = if change.abs() >= 0.05 {
        frames
            .iter()
            .map(|t| (measured(t, axis) - y1) * change.signum() / change.abs() * 100.0)
            .fold(0.0, f64::max)
    } else {
        0.0
    };
    let steady_from = frames.len()
        - ((frames.len() as f64 * tol.steady_fraction).ceil() as usize).clamp(1, frames.len());
    let steady: Vec<f64> = frames[steady_from..]
        .iter()
        .map(|t| measured(t, axis))
        .collect();
    let mean = steady.iter().sum::<f64>() / steady.len() as f64;
    let (lo, hi) = steady
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    let scale = y1.abs().max(0.1);
    let steady_error_pct = (mean - y1).abs() / scale * 100.0;
    let tracked = settling_time_s.is_some_and(|s| s <= tol.settle_within_s)
        && steady_error_pct <= tol.steady_error * 100.0;
    Some(AxisStep {
        axis: AXES[axis],
        from_rad_s: y0,
        set_rad_s: y1,
        rise_time_s,
        first_reading_s,
        settling_time_s,
        overshoot_pct,
        steady_mean_rad_s: mean,
        steady_error_pct,
        steady_ripple_pct: 0.5 * (hi - lo) / scale * 100.0,
        tracked,
    })
}

/// The particle scene from the rig's parameters (g is not a parameter: 9.81).
pub fn scene_of(params: &ParamValues) -> Scene<f64> {
    let p = |id: ParamId| f64::from(params[id.index()]);
    Scene {
        omega_rad_s: 0.0,
        mu: p(ParamId::MuPpm) / 1e6,
        g_m_s2: 9.81,
        k2: p(ParamId::K2Ppm) / 1e6,
        ri_m: p(ParamId::StartUm) / 1e6,
        rim_radius_m: p(ParamId::RimUm) / 1e6,
    }
}

fn host_residence_ms(scene: &Scene<f64>, omega: f64, model: Model) -> Option<f64> {
    let s = Scene {
        omega_rad_s: omega,
        ..*scene
    };
    match particle::residence(&s, model) {
        Ok(Outcome::Leaves {
            residence_time_s, ..
        }) => Some(residence_time_s * 1000.0),
        _ => None,
    }
}

fn mean_residence(frames: &[Telemetry], pick: impl Fn(&Telemetry) -> Residence) -> Option<f64> {
    let v: Vec<f64> = frames
        .iter()
        .filter_map(|t| match pick(t) {
            Residence::Ms(ms) => Some(f64::from(ms)),
            _ => None,
        })
        .collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

fn predicted(
    frames: &[Telemetry],
    scene: Option<&Scene<f64>>,
    tol: &Tolerances,
) -> Option<Predicted> {
    if frames.is_empty() {
        return None;
    }
    let from = frames.len()
        - ((frames.len() as f64 * tol.steady_fraction).ceil() as usize).clamp(1, frames.len());
    let steady = frames.get(from..)?;
    let bowl =
        steady.iter().map(|t| f64::from(t.bowl_mrad_s)).sum::<f64>() / steady.len() as f64 / 1000.0;
    Some(Predicted {
        bowl_rad_s: bowl,
        flat_ms: mean_residence(steady, |t| t.residence_flat),
        coriolis_ms: mean_residence(steady, |t| t.residence_coriolis),
        host_flat_ms: scene.and_then(|s| host_residence_ms(s, bowl, Model::Flat)),
        host_coriolis_ms: scene.and_then(|s| host_residence_ms(s, bowl, Model::Coriolis)),
    })
}

fn fault_reaction(
    tel: &[Telemetry],
    inject: &Mark,
    clear_ms: u32,
    params: Option<&ParamValues>,
    tol: &Tolerances,
) -> FaultReaction {
    let after: Vec<Telemetry> = window(tel, inject.at_ms, clear_ms);
    let before = tel.iter().rev().find(|t| t.time_ms <= inject.at_ms);
    let detected = after.iter().find(|t| t.fault != FaultCode::None);
    let off = detected.and_then(|d| {
        after.iter().find(|t| {
            t.time_ms >= d.time_ms
                && t.state == DeviceState::Faulted
                && duty_bp(t, 0) == 0
                && duty_bp(t, 1) == 0
        })
    });
    let stayed_off = off.is_some_and(|o| {
        after
            .iter()
            .filter(|t| t.time_ms >= o.time_ms)
            .all(|t| duty_bp(t, 0) == 0 && duty_bp(t, 1) == 0)
    });
    let precession_stopped = off.and_then(|o| {
        after
            .iter()
            .find(|t| t.time_ms >= o.time_ms && measured(t, 0).abs() < tol.stopped_rad_s)
    });
    // The supervisor's timeout: max(floor, 3 expected pulse periods) at the spin speed.
    let expected = before.zip(params).map(|(b, p)| {
        let teeth = f64::from(p[ParamId::Teeth2.index()]);
        let w = set(b, 1).abs().max(1e-3);
        let period = std::f64::consts::TAU / (teeth * w);
        let floor =
            f64::from(model_core::control::ControllerConfig::nominal().sensor_timeout_floor_s);
        let timeout = (3.0 * period).max(floor);
        let frame = 1.0 / f64::from(p[ParamId::TelemetryHz.index()].max(1));
        [(timeout - period - frame).max(0.0), timeout + frame + 0.005]
    });
    let since = |t: &Telemetry| seconds(t.time_ms.wrapping_sub(inject.at_ms));
    let precession_at_clear = after.last().map(|t| measured(t, 0)).unwrap_or(f64::NAN);
    FaultReaction {
        injected_at_s: seconds(inject.at_ms),
        fault: detected.map(|t| format!("{:?}", t.fault)),
        detection_s: detected.map(since),
        expected_detection_s: expected,
        motors_off_s: off.map(since),
        stayed_off,
        precession_before_rad_s: before.map(|t| measured(t, 0)).unwrap_or(f64::NAN),
        precession_at_clear_rad_s: precession_at_clear,
        precession_stopped_s: precession_stopped.map(since),
        stopped_both_motors: stayed_off && precession_stopped.is_some(),
    }
}

fn residence_check(
    frames: &[Telemetry],
    accepted: bool,
    params: Option<&ParamValues>,
) -> ResidenceCheck {
    let rig_set = frames
        .last()
        .map(|t| [set(t, 0), set(t, 1)])
        .unwrap_or([f64::NAN; 2]);
    let target_s = f64::from(RESIDENCE_TARGET_MS) / 1000.0;
    let (mut bowl, mut split, mut flat) = (None, None, None);
    if let Some(p) = params {
        let scene = scene_of(p);
        if let Ok(w) = particle::omega_for_residence_time(&scene, Model::Coriolis, target_s) {
            bowl = Some(w);
            flat = host_residence_ms(&scene, w, Model::Flat);
            let angle = f64::from(p[ParamId::AxesMdeg.index()]) / 1000.0;
            let ratio = f64::from(p[ParamId::RatioPpm.index()]) / 1e6;
            if let Ok(g) = BowlGeometry::new(angle.to_radians())
                && let Ok(m) = g.split(w, ratio)
            {
                split = Some([m.precession_rad_s, m.spin_rad_s]);
            }
        }
    }
    let split_agrees = accepted
        && split.is_some_and(|s| {
            (s[0] - rig_set[0]).abs() <= 0.005 && (s[1] - rig_set[1]).abs() <= 0.005
        });
    ResidenceCheck {
        target_ms: RESIDENCE_TARGET_MS,
        accepted,
        host_bowl_rad_s: bowl,
        host_split_rad_s: split,
        rig_set_rad_s: rig_set,
        split_agrees,
        host_flat_at_target_ms: flat,
    }
}

/// What the run was, for the summary's header.
pub struct RunInfo {
    /// `host` or `qemu`.
    pub rig: String,
    /// One line.
    pub description: String,
    /// Why not QEMU.
    pub qemu_note: Option<String>,
    /// `--fast`.
    pub fast: bool,
    /// Wall time, s.
    pub wall_s: f64,
    /// Why the session ended early.
    pub aborted: Option<String>,
    /// The emulated board's console, last lines (empty on the host rig).
    pub board_console: Vec<String>,
    /// Bytes the host rig could not deliver.
    pub host_bytes_dropped: u64,
}

/// Builds the summary from the record.
pub fn summarise(
    info: RunInfo,
    tel: &[Telemetry],
    marks: &[Mark],
    params: Option<&ParamValues>,
    stats: &model_core::wire::DecodeStats,
    commands: Vec<super::session::CommandRecord>,
) -> Summary {
    let tol = TOLERANCES;
    let scene = params.map(scene_of);
    let next_after = |i: usize| marks.get(i + 1).map(|m| m.at_ms).unwrap_or(u32::MAX);
    let mut steps = Vec::new();
    let mut residence = None;
    let mut fault = None;
    for (i, m) in marks.iter().enumerate() {
        let frames = window(tel, m.at_ms, next_after(i));
        match m.kind {
            MarkKind::Setpoint => {
                let axes = if m.accepted {
                    (0..2)
                        .filter_map(|a| axis_step(&frames, m.at_ms, a, &tol))
                        .collect()
                } else {
                    Vec::new()
                };
                if m.name == "set residence time" {
                    residence = Some(residence_check(&frames, m.accepted, params));
                }
                steps.push(Step {
                    name: m.name.clone(),
                    at_s: seconds(m.at_ms),
                    window_s: seconds(
                        next_after(i)
                            .min(tel.last().map_or(0, |t| t.time_ms))
                            .saturating_sub(m.at_ms),
                    ),
                    accepted: m.accepted,
                    axes,
                    predicted: predicted(&frames, scene.as_ref(), &tol),
                });
            }
            MarkKind::Inject => {
                let clear = marks
                    .iter()
                    .skip(i)
                    .find(|c| matches!(c.kind, MarkKind::Clear | MarkKind::End))
                    .map_or(u32::MAX, |c| c.at_ms);
                fault = Some(fault_reaction(tel, m, clear, params, &tol));
            }
            MarkKind::Clear | MarkKind::Stop | MarkKind::End => {}
        }
    }
    let ended_at_rest = tel.last().is_some_and(|t| {
        t.state == DeviceState::Idle
            && measured(t, 0).abs() < tol.stopped_rad_s
            && measured(t, 1).abs() < tol.stopped_rad_s
    });
    let running: Vec<&AxisStep> = steps
        .iter()
        .filter(|s| s.accepted)
        .flat_map(|s| s.axes.iter())
        .collect();
    let checks = Checks {
        speeds_tracked: !running.is_empty() && running.iter().all(|a| a.tracked),
        fault_stopped_both_motors: fault.as_ref().is_some_and(|f| f.stopped_both_motors),
        residence_split_agrees: residence.as_ref().is_some_and(|r| r.split_agrees),
        link_clean: stats.frames_corrupt == 0
            && stats.frames_missing == 0
            && info.host_bytes_dropped == 0,
    };
    Summary {
        rig: info.rig,
        rig_description: info.description,
        qemu_note: info.qemu_note,
        fast: info.fast,
        device_s: tel
            .first()
            .zip(tel.last())
            .map_or(0.0, |(a, b)| seconds(b.time_ms.wrapping_sub(a.time_ms))),
        wall_s: info.wall_s,
        frames: crate::replay::stats_json(stats),
        telemetry_rows: tel.len(),
        aborted: info.aborted,
        board_console: info.board_console,
        host_bytes_dropped: info.host_bytes_dropped,
        params: params.map(|p| {
            ParamId::ALL
                .iter()
                .map(|id| (id.token().to_string(), serde_json::json!(p[id.index()])))
                .collect()
        }),
        tolerances: tol,
        steps,
        fault,
        residence,
        ended_at_rest,
        marks: marks.to_vec(),
        commands,
        checks,
    }
}

fn opt(v: Option<f64>, unit: &str) -> String {
    v.map_or("-".into(), |v| format!("{v:.3} {unit}"))
}

/// The summary for people.
pub fn text(s: &Summary) -> String {
    let mut o = String::new();
    o += &format!(
        "\n== demo summary ({} rig, {:.1} s device time, {:.1} s wall) ==\n",
        s.rig, s.device_s, s.wall_s
    );
    o += &format!(
        "frames ok {}  corrupt {}  missing {}  (telemetry rows {})\n",
        s.frames["frames_ok"],
        s.frames["frames_corrupt"],
        s.frames["frames_missing"],
        s.telemetry_rows
    );
    for st in &s.steps {
        o += &format!(
            "step '{}' at t={:.3} s{}\n",
            st.name,
            st.at_s,
            if st.accepted { "" } else { " (REJECTED)" }
        );
        for a in &st.axes {
            o += &format!(
                "  {:<10} {:.3} -> {:.3} rad/s  rise {}{}  settle(+/-{:.0}%) {}  overshoot {:.1}%  steady err {:.2}%  ripple {:.2}%  {}\n",
                a.axis,
                a.from_rad_s,
                a.set_rad_s,
                opt(a.rise_time_s, "s"),
                a.first_reading_s.map_or(String::new(), |f| format!(
                    " (first reading after {f:.3} s)"
                )),
                s.tolerances.settle_band * 100.0,
                opt(a.settling_time_s, "s"),
                a.overshoot_pct,
                a.steady_error_pct,
                a.steady_ripple_pct,
                if a.tracked { "ok" } else { "NOT TRACKED" }
            );
        }
        if let Some(p) = &st.predicted {
            o += &format!(
                "  bowl {:.3} rad/s: residence flat {} (host {}), Coriolis {} (host {})\n",
                p.bowl_rad_s,
                opt(p.flat_ms, "ms"),
                opt(p.host_flat_ms, "ms"),
                opt(p.coriolis_ms, "ms"),
                opt(p.host_coriolis_ms, "ms")
            );
        }
    }
    if let Some(r) = &s.residence {
        o += &format!(
            "residence target {} ms (Coriolis): host inverse bowl {} -> split {} ; rig set [{:.3}, {:.3}] rad/s ; flat model at that speed {} ; {}\n",
            r.target_ms,
            opt(r.host_bowl_rad_s, "rad/s"),
            r.host_split_rad_s
                .map_or("-".into(), |v| format!("[{:.3}, {:.3}] rad/s", v[0], v[1])),
            r.rig_set_rad_s[0],
            r.rig_set_rad_s[1],
            opt(r.host_flat_at_target_ms, "ms"),
            if r.split_agrees {
                "agree"
            } else {
                "DO NOT AGREE"
            }
        );
    }
    if let Some(f) = &s.fault {
        o += &format!(
            "fault at t={:.3} s: {} detected after {} (expected {}), both duties 0 after {}, stayed off {}, precession {:.3} -> {:.3} rad/s (stopped after {})\n",
            f.injected_at_s,
            f.fault.as_deref().unwrap_or("NONE"),
            opt(f.detection_s, "s"),
            f.expected_detection_s
                .map_or("-".into(), |[a, b]| format!("{a:.3}..{b:.3} s")),
            opt(f.motors_off_s, "s"),
            f.stayed_off,
            f.precession_before_rad_s,
            f.precession_at_clear_rad_s,
            opt(f.precession_stopped_s, "s"),
        );
    }
    o += &format!(
        "checks: speeds tracked {}, fault stopped both motors {}, residence split agrees {}, link clean {}, ended at rest {}\n",
        s.checks.speeds_tracked,
        s.checks.fault_stopped_both_motors,
        s.checks.residence_split_agrees,
        s.checks.link_clean,
        s.ended_at_rest
    );
    o
}

#[cfg(test)]
mod tests {
    use super::*;
    use model_core::wire::MotorTelemetry;

    const FRAME_MS: u32 = 20;

    /// A telemetry frame with both motors at `w` rad/s measured, set to `set`, driven at `duty_bp`.
    fn frame(time_ms: u32, set_rad_s: f64, w: [f64; 2], duty_bp: [i16; 2]) -> Telemetry {
        let motor = |axis: usize| MotorTelemetry {
            set_mrad_s: (set_rad_s * 1000.0).round() as i16,
            measured_mrad_s: (w[axis] * 1000.0).round() as i16,
            duty_bp: duty_bp[axis],
            pulses: 0,
        };
        Telemetry {
            time_ms,
            seq: 0,
            state: DeviceState::Running,
            fault: FaultCode::None,
            precession: motor(0),
            spin: motor(1),
            bowl_mrad_s: 0,
            residence_flat: Residence::Unavailable,
            residence_coriolis: Residence::Unavailable,
        }
    }

    fn sampled(y: impl Fn(f64) -> f64, set: f64, seconds: f64) -> Vec<Telemetry> {
        (0..=(seconds * 1000.0) as u32 / FRAME_MS)
            .map(|k| {
                let t_ms = k * FRAME_MS;
                let v = y(f64::from(t_ms) / 1000.0);
                frame(t_ms, set, [v, v], [5000, 5000])
            })
            .collect()
    }

    /// A first-order response: 10-90 % rise tau ln 9, 5 % settling tau ln 20, no overshoot,
    /// within the frame spacing (20 ms).
    #[test]
    fn first_order_step_measures_match_the_closed_forms() {
        let (tau, set) = (0.4, 2.0);
        let frames = sampled(|t| set * (1.0 - (-t / tau).exp()), set, 6.0);
        let a = axis_step(&frames, 0, 0, &TOLERANCES).unwrap();
        let rise = a.rise_time_s.unwrap();
        assert!((rise - tau * 9f64.ln()).abs() <= 0.021, "rise {rise}");
        let settle = a.settling_time_s.unwrap();
        // One frame, plus one more where the mrad/s rounding of the wire sits on the band edge.
        assert!(
            (settle - tau * 20f64.ln()).abs() <= 0.041,
            "settle {settle}"
        );
        assert_eq!(a.overshoot_pct, 0.0);
        assert!(a.steady_error_pct < 0.1);
        assert!(a.tracked);
    }

    /// A second-order response with damping 0.5 overshoots by exp(-zeta pi / sqrt(1 - zeta^2))
    /// = 16.3 % of the step.
    #[test]
    fn underdamped_overshoot_matches_the_closed_form() {
        let (zeta, wn, from, set) = (0.5f64, 6.0f64, 1.0, 3.0);
        let wd = wn * (1.0 - zeta * zeta).sqrt();
        let y = |t: f64| {
            let e = (-zeta * wn * t).exp();
            from + (set - from)
                * (1.0 - e * ((wd * t).cos() + zeta / (1.0 - zeta * zeta).sqrt() * (wd * t).sin()))
        };
        let frames = sampled(y, set, 6.0);
        let a = axis_step(&frames, 0, 0, &TOLERANCES).unwrap();
        let expected = 100.0 * (-zeta * std::f64::consts::PI / (1.0 - zeta * zeta).sqrt()).exp();
        assert!(
            (a.overshoot_pct - expected).abs() < 0.5,
            "{} vs {expected}",
            a.overshoot_pct
        );
        assert_eq!(a.from_rad_s, from);
    }

    /// A response that never gets within the band is not tracked (the check can fail).
    #[test]
    fn a_motor_that_stays_short_of_its_setpoint_is_not_tracked() {
        let frames = sampled(|t| 1.8 * (1.0 - (-t / 0.2).exp()), 2.0, 6.0);
        let a = axis_step(&frames, 0, 0, &TOLERANCES).unwrap();
        assert_eq!(a.settling_time_s, None);
        assert!(a.steady_error_pct > 9.0);
        assert!(!a.tracked);
    }

    fn faulted(mut t: Telemetry) -> Telemetry {
        t.state = DeviceState::Faulted;
        t.fault = FaultCode::SensorLostOrStallSpin;
        t
    }

    /// The fault reaction: detection and motors-off times from the frames; a duty left on after
    /// the fault, or a healthy motor still turning, is not "stopped both motors".
    #[test]
    fn fault_reaction_needs_both_duties_off_and_the_healthy_motor_at_rest() {
        let inject = Mark {
            name: "fault injected".into(),
            kind: MarkKind::Inject,
            at_ms: 1000,
            accepted: true,
        };
        let mut tel: Vec<Telemetry> = (0..50)
            .map(|k| frame(k * FRAME_MS, 2.0, [2.0, 2.0], [4000, 4000]))
            .collect();
        // Detected 0.6 s after the injection; the precession motor coasts down over 1 s.
        for k in 50..200u32 {
            let t_ms = k * FRAME_MS;
            let f = if t_ms >= 1600 {
                let w = (2.0 - 2.0 * f64::from(t_ms - 1600) / 1000.0).max(0.0);
                faulted(frame(t_ms, 0.0, [w, 0.0], [0, 0]))
            } else {
                frame(t_ms, 2.0, [2.0, 2.0], [4000, 4000])
            };
            tel.push(f);
        }
        let r = fault_reaction(&tel, &inject, 4000, None, &TOLERANCES);
        assert_eq!(r.detection_s, Some(0.6));
        assert_eq!(r.motors_off_s, Some(0.6));
        assert!(r.stayed_off && r.stopped_both_motors);
        // Below 0.05 rad/s once 975 ms into the coast: the frame at 980 ms, 1.58 s after injection.
        assert_eq!(r.precession_stopped_s, Some(1.58));

        // One duty comes back on while faulted: not stopped.
        let mut bad = tel.clone();
        bad[120].spin.duty_bp = 300;
        let r = fault_reaction(&bad, &inject, 4000, None, &TOLERANCES);
        assert!(!r.stayed_off && !r.stopped_both_motors);
    }
}

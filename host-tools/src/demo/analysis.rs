//! What the session showed, measured from the telemetry alone (what the PC receives): the step
//! responses of both motors ([`super::step_response`]), the fault reaction (here), and the
//! residence-time predictions checked against the model computed independently on the host in
//! f64 ([`super::physics_check`]), gathered into the summary ([`super::report`]).

use model_core::wire::{DeviceState, FaultCode, ParamId, ParamValues, Telemetry};

use super::frames::{duty_bp, measured, seconds, set, window};
use super::physics_check::{predicted, residence_check, scene_of};
use super::report::{
    AxisStep, Checks, FaultReaction, RunInfo, Step, Summary, TOLERANCES, Tolerances,
};
use super::script::{Mark, MarkKind};
use super::step_response::axis_step;

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
    // The supervisor's timeout: max(floor, WATCH_PITCHES expected pulse periods) at the spin
    // speed, counted from the last edge before the injection.
    let expected = before.zip(params).map(|(b, p)| {
        let teeth = f64::from(p[ParamId::Teeth2.index()]);
        let w = set(b, 1).abs().max(1e-3);
        let period = std::f64::consts::TAU / (teeth * w);
        let floor =
            f64::from(model_core::control::ControllerConfig::nominal().sensor_timeout_floor_s);
        let pitches = f64::from(model_core::control::supervisor::WATCH_PITCHES);
        let timeout = (pitches * period).max(floor);
        let frame = 1.0 / f64::from(p[ParamId::TelemetryHz.index()].max(1));
        [(timeout - period - frame).max(0.0), timeout + frame + 0.005]
    });
    let since = |t: &Telemetry| seconds(t.time_ms.wrapping_sub(inject.at_ms));
    let precession_at_clear = after.last().map(|t| measured(t, 0)).unwrap_or(f64::NAN);
    FaultReaction {
        injected_at_s: seconds(inject.at_ms),
        fault: detected.map(|t| t.fault.token().to_string()),
        fault_text: detected.map(|t| t.fault.words().to_string()),
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
    let scene = params.and_then(scene_of);
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
        frames: rig_client::decode_stats::stats_json(stats),
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

#[cfg(test)]
mod tests {
    use super::super::frames::fixtures::{FRAME_MS, frame};
    use super::*;
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

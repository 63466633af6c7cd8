//! The scripted session: what a lab engineer does with the rig, one step at a time, each
//! printed as it happens. Durations are device time, scaled to the session length.

use anyhow::{Result, bail};
use model_core::wire::{DeviceState, FaultCode, Frame, ParamId, ParamValues, Telemetry};

use super::session::Session;

/// Nominal session length the step durations below are written for, s.
pub const NOMINAL_SECONDS: f64 = 40.0;

/// Motor speeds of the first running step (precession, spin), mrad/s.
pub const FIRST_SPEEDS_MRAD_S: [i16; 2] = [1500, 1800];
/// Motor speeds of the "set motor speeds" step, mrad/s.
pub const SECOND_SPEEDS_MRAD_S: [i16; 2] = [2600, 3000];
/// The residence-time target: Coriolis model, ms.
pub const RESIDENCE_TARGET_MS: u32 = 600;
/// Motor speeds after the restart, mrad/s.
pub const RESTART_SPEEDS_MRAD_S: [i16; 2] = [1800, 2400];
/// A speed reading below this counts as at rest, mrad/s (the analysis's `stopped_rad_s`).
const AT_REST_MRAD_S: u16 = 50;
/// The injected fault: the spin sensor stops giving pulses.
pub const INJECTION: &str = "sensor2";

/// What a point of the session was.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MarkKind {
    /// New setpoints took effect with the loop running (start, speed, residence, restart).
    Setpoint,
    /// A fault was injected.
    Inject,
    /// The fault was cleared.
    Clear,
    /// STOP.
    Stop,
    /// The end of the session.
    End,
}

/// A point of the session on device time (the last telemetry frame before the rig's answer).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Mark {
    /// The step's name.
    pub name: String,
    /// What it was.
    pub kind: MarkKind,
    /// Device time, ms.
    pub at_ms: u32,
    /// The rig accepted the command.
    pub accepted: bool,
}

/// Step durations, device ms.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Timing {
    /// How long each running step is held.
    pub dwell_ms: u32,
    /// Longest wait for the fault to be detected and for the rig to reach Idle after STOP.
    pub wait_limit_ms: u32,
    /// The faulted rig is watched until both motors are at rest, at least this long.
    pub faulted_ms: u32,
    /// Pause after CLEAR and at the end.
    pub pause_ms: u32,
    /// Device seconds per wall second of the rig (above 1: faster than real time).
    pub device_per_wall: f64,
}

impl Timing {
    /// Durations for a session of about `seconds` device seconds.
    pub fn for_seconds(seconds: f64, device_per_wall: f64) -> Timing {
        let k = seconds / NOMINAL_SECONDS;
        let ms = |s: f64| (s * k * 1000.0).round() as u32;
        Timing {
            // At least the nominal rig's settling target (2.5 s at 12 pulses a revolution): a
            // step held shorter is judged on its settling, not its steady state (`--seconds 10`:
            // 1.75 s, and the rod's step from rest, with the spin starting beside it, read 2 %
            // off over a window still settling).
            dwell_ms: ms(7.0).max(2500),
            // A limit, not a duration: the wait ends when the event comes. Scaled down with a
            // short session it ended before the physics did (`--seconds 20`: 3 s, and a rig
            // coasting from 2.4 rad/s neither came to rest after its fault nor reached Idle
            // after STOP, so the demo's checks failed on a healthy rig).
            wait_limit_ms: ms(6.0).max(6000),
            faulted_ms: ms(3.0),
            pause_ms: ms(1.0),
            device_per_wall,
        }
    }
}

/// What the script collected besides the session record.
pub struct Outcome {
    /// The session's points.
    pub marks: Vec<Mark>,
    /// The rig's parameters at the start (PARAMS answer).
    pub params: Option<ParamValues>,
    /// The session stopped early, and why.
    pub aborted: Option<String>,
}

fn speeds(v: [i16; 2]) -> [String; 3] {
    ["speed".into(), v[0].to_string(), v[1].to_string()]
}

fn mark(s: &Session, name: &str, kind: MarkKind, accepted: bool) -> Mark {
    Mark {
        name: name.to_string(),
        kind,
        at_ms: s
            .record
            .commands
            .last()
            .and_then(|c| c.at_ms)
            .or(s.now_ms())
            .unwrap_or(0),
        accepted,
    }
}

/// A rig faster than real time gets its link watch (`LINK_TIMEOUT_MS`) scaled by its pace, so
/// that the PC keeps the wall time it has at real time: at 10x the default 3 s of device time
/// were 0.3 s of wall time, and a PC busy for that long (several fast demos in parallel on two
/// cores) faulted the rig for link loss mid-session. A watch that is off (0) stays off.
fn keep_link_watch_in_wall_time(s: &mut Session, values: &ParamValues, pace: f64) -> Result<()> {
    let now = values[ParamId::LinkTimeoutMs.index()];
    let (_, max) = ParamId::LinkTimeoutMs.range();
    if pace <= 1.0 || now <= 0 {
        return Ok(());
    }
    let scaled = (f64::from(now) * pace).min(f64::from(max)).round() as i32;
    let what = format!(
        "keep the link watch at {:.1} s of wall time (the rig runs {pace}x real time)",
        f64::from(now) / 1000.0
    );
    if !s.command(&what, &["set", "LINK_TIMEOUT_MS", &scaled.to_string()])? {
        s.event("the rig kept its link watch: a PC slower than it for that long faults it".into());
    }
    Ok(())
}

fn words(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

fn motors_off(t: &Telemetry) -> bool {
    t.state == DeviceState::Faulted && t.precession.duty_bp == 0 && t.spin.duty_bp == 0
}

/// Ctrl-C mid-session: the motors are stopped before the demo ends (a rig on another process,
/// the emulated board, would otherwise go on at its last speeds until its link watch), and
/// the words say whether they are.
fn stop_when_interrupted(s: &mut Session) -> String {
    let at_rest = |t: &Telemetry| {
        matches!(t.state, DeviceState::Idle | DeviceState::Faulted)
            && t.precession.duty_bp == 0
            && t.spin.duty_bp == 0
    };
    let stopped = s.command("stop (interrupted)", &["stop"]).and_then(|ok| {
        let off = s.wait_for(STOP_WAIT_MS, at_rest)?;
        Ok(ok && off.is_some())
    });
    match stopped {
        Ok(true) => "interrupted (Ctrl-C): STOP sent, the motors are off".into(),
        Ok(false) => format!(
            "interrupted (Ctrl-C): STOP sent, but the motors were not seen off within {} s",
            STOP_WAIT_MS / 1000
        ),
        Err(e) => format!("interrupted (Ctrl-C): STOP not confirmed: {e:#}"),
    }
}

/// How long (device time) an interrupted demo waits for the motors to stop: the ramp down from
/// the script's speeds and the shafts read at rest (about two seconds).
const STOP_WAIT_MS: u32 = 6000;

/// Injects a fault into the rig's simulated world (`sensor2`, `none`, ...) when the rig's
/// firmware does not take `INJECT` over the wire (real firmware on an emulated board).
pub type Injector<'a> = &'a mut dyn FnMut(&str) -> Result<()>;

/// Runs the session. An error of the link (no answer, port gone) ends it early; the record so
/// far is still summarised.
pub fn run(s: &mut Session, timing: Timing, injector: Option<Injector>) -> Outcome {
    let mut out = Outcome {
        marks: Vec::new(),
        params: None,
        aborted: None,
    };
    if let Err(e) = steps(s, timing, &mut out, injector) {
        s.event(format!("session aborted: {e:#}"));
        out.aborted = Some(if s.interrupted() {
            stop_when_interrupted(s)
        } else {
            format!("{e:#}")
        });
    }
    let end = s.now_ms().unwrap_or(0);
    out.marks.push(Mark {
        name: "end".into(),
        kind: MarkKind::End,
        at_ms: end,
        accepted: true,
    });
    out
}

fn steps(
    s: &mut Session,
    timing: Timing,
    out: &mut Outcome,
    mut injector: Option<Injector>,
) -> Result<()> {
    let d = timing;
    s.command("ask the rig's state", &["status"])?;
    let (_, params) = s.command_answer("read the parameters", &["params"])?;
    if let Frame::Params { values, .. } = params {
        out.params = Some(values);
        keep_link_watch_in_wall_time(s, &values, d.device_per_wall)?;
    }

    // 1. Start towards the first speeds (set while idle, taken at START).
    s.command("first speeds", &words(&speeds(FIRST_SPEEDS_MRAD_S)))?;
    let ok = s.command("start", &["start"])?;
    out.marks.push(mark(s, "start", MarkKind::Setpoint, ok));
    if !ok {
        bail!("the rig refused START");
    }
    s.wait_ms(d.dwell_ms)?;

    // 2. New motor speeds while running.
    let ok = s.command("set motor speeds", &words(&speeds(SECOND_SPEEDS_MRAD_S)))?;
    out.marks
        .push(mark(s, "set motor speeds", MarkKind::Setpoint, ok));
    s.wait_ms(d.dwell_ms)?;

    // 3. A target residence time: the rig's inverse gives the bowl speed, Eq. 2 splits it.
    let target = RESIDENCE_TARGET_MS.to_string();
    let ok = s.command("set residence time", &["rtime", "cori", &target])?;
    if !ok {
        s.event("the rig cannot set a residence time: the speeds stay".into());
    }
    out.marks
        .push(mark(s, "set residence time", MarkKind::Setpoint, ok));
    s.wait_ms(d.dwell_ms)?;

    // 4. Fault: the spin sensor goes dead. The rig must stop both motors.
    let injected = match injector.as_mut() {
        Some(inject) => {
            inject(INJECTION)?;
            s.event(format!(
                "inject a sensor fault: {INJECTION} in the emulated plant (the firmware answers \
                 INJECT with UNSUPPORTED, as on a real board)"
            ));
            // No command carries the time: the mark is now.
            Mark {
                name: "fault injected".into(),
                kind: MarkKind::Inject,
                at_ms: s.now_ms().unwrap_or(0),
                accepted: true,
            }
        }
        None => {
            let ok = s.command("inject a sensor fault", &["inject", INJECTION])?;
            mark(s, "fault injected", MarkKind::Inject, ok)
        }
    };
    out.marks.push(injected);
    let detected = s.wait_for(d.wait_limit_ms, |t| t.fault != FaultCode::None)?;
    match detected {
        Some(at) => {
            let fault = s.latest().map_or(FaultCode::None, |t| t.fault);
            s.event(format!(
                "fault detected at t={:.3} s: {}",
                f64::from(at) / 1000.0,
                fault.words()
            ));
            let already_off = s.latest().is_some_and(motors_off);
            let off = if already_off {
                s.now_ms()
            } else {
                s.wait_for(d.wait_limit_ms, motors_off)?
            };
            match off {
                Some(at) => s.event(format!(
                    "both motors off (duty 0) at t={:.3} s",
                    f64::from(at) / 1000.0
                )),
                None => s.event("the motors did NOT go off".into()),
            }
        }
        None => s.event(format!(
            "no fault reported within {:.1} s",
            f64::from(d.wait_limit_ms) / 1000.0
        )),
    }
    // Watch the motors coast to rest (the bridge coasts on a fault: no braking), then a little
    // longer to show they stay off.
    let coast_limit = d.wait_limit_ms.max(2 * d.faulted_ms);
    let watch_from = s.now_ms().unwrap_or(0);
    match s.wait_for(coast_limit, |t| {
        t.precession.measured_mrad_s.unsigned_abs() < AT_REST_MRAD_S
            && t.spin.measured_mrad_s.unsigned_abs() < AT_REST_MRAD_S
    })? {
        Some(at) => s.event(format!(
            "both speed readings at rest at t={:.3} s",
            f64::from(at) / 1000.0
        )),
        None => s.event(format!(
            "the motors did not come to rest within {:.1} s",
            f64::from(coast_limit) / 1000.0
        )),
    }
    let watched = s.now_ms().unwrap_or(0).wrapping_sub(watch_from);
    s.wait_ms(d.faulted_ms.saturating_sub(watched).max(d.pause_ms))?;

    // 5. Repair and clear.
    match injector.as_mut() {
        Some(inject) => {
            inject("none")?;
            s.event("sensor repaired in the emulated plant".into());
        }
        None => {
            s.command("sensor repaired", &["inject", "none"])?;
        }
    }
    let ok = s.command("clear the fault", &["clear"])?;
    out.marks
        .push(mark(s, "fault cleared", MarkKind::Clear, ok));
    s.wait_ms(d.pause_ms)?;

    // 6. Restart.
    s.command("restart speeds", &words(&speeds(RESTART_SPEEDS_MRAD_S)))?;
    let ok = s.command("restart", &["start"])?;
    out.marks.push(mark(s, "restart", MarkKind::Setpoint, ok));
    s.wait_ms(d.dwell_ms)?;

    // 7. Stop and wait for the rig to come to rest.
    let ok = s.command("stop", &["stop"])?;
    out.marks.push(mark(s, "stop", MarkKind::Stop, ok));
    match s.wait_for(d.wait_limit_ms, |t| t.state == DeviceState::Idle)? {
        Some(at) => s.event(format!("rig idle at t={:.3} s", f64::from(at) / 1000.0)),
        None => s.event("the rig did not reach Idle".into()),
    }
    s.wait_ms(d.pause_ms)?;
    Ok(())
}

//! The demo's report: what it measured and the verdicts, as serialised in its JSON summary.

use serde::Serialize;

use super::script::Mark;

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

/// The tolerances used. The settling band is the simulated experiments' own (+/-2 %,
/// `model_core::sim::SETTLING_BAND`), so the demo and `bowl sim step` measure settling alike.
/// The controller ramps at 4 rad/s^2 and its loop bandwidth is 8 rad/s, capped at 0.5 x the pulse
/// rate: with 12 pulses per revolution at 1.5 rad/s that cap is 1.4 rad/s (time constant 0.7 s).
/// The demo's steps settle within 2 s on the host rig and within 2.4 s on the emulated board,
/// and the pulse-based reading ripples by under 0.5 % (`bowl demo --fast --rig host`, and
/// `--rig qemu`); 5 s is the bound a step must meet.
pub const TOLERANCES: Tolerances = Tolerances {
    settle_band: model_core::sim::SETTLING_BAND as f64,
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
    /// Coriolis model (paper Eq. 10/11 with the corrected coefficients of docs/model.md), from
    /// telemetry, ms.
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
    /// The fault the rig reported (its protocol name).
    pub fault: Option<String>,
    /// The same in plain words.
    pub fault_text: Option<String>,
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

//! The control loop's charts (docs/control.md), from the simulated-rig experiments that `bowl sim sweep`
//! and `bowl sim stability` print:
//!
//! - `bowl chart settling`: 2 % settling time of the commissioned 0 -> 3 rad/s step against pulses
//!   per revolution, both axes, with the targets (2.5 s at 12 pulses/rev, 1.0 s at >= 60) and the
//!   pulse count above which the loop's bandwidth stops being set by the pulse rate.
//! - `bowl chart control-stability`: the limit cycle of a 0.5 rad/s hold against the per-pulse
//!   gain, for several pulse counts and loop (tick) rates, with the pulse-rate gain schedule and
//!   without it (the gain the schedule gives at 3 rad/s kept at every speed), the 5 % line and
//!   the runs that latched a fault.
//!
//! Both measure the simulator's *true* speed, not the controller's estimate. The runs are
//! independent, so they are spread over the machine's cores; results keep their order.

use model_core::control::{ControllerConfig, Fault};
use model_core::sim::experiments::{self, STEP_RUN_S, rig_with_pulses};

use super::plot::{Figure, HLine, Mark, Scale, Series, VLine};
use super::table::Table;

/// Step target of the settling chart, rad/s (as `bowl sim step`).
pub const STEP_TARGET_RAD_S: f32 = 3.0;
/// Speed of the low-speed hold of the stability chart, rad/s (the 0.5 rad/s of docs/control.md's stability target).
pub const HOLD_SPEED_RAD_S: f32 = 0.5;
/// Limit-cycle bound at 0.5 rad/s (docs/control.md), percent of the speed.
pub const LIMIT_CYCLE_BOUND_PCT: f64 = 5.0;
/// Settling target of the nominal rig (12 pulses/rev), s.
pub const NOMINAL_SETTLING_TARGET_S: f64 = 2.5;
/// Settling target with 60 or more pulses/rev, s.
pub const FINE_SETTLING_TARGET_S: f64 = 1.0;
/// Pulse count from which [`FINE_SETTLING_TARGET_S`] applies.
pub const FINE_FROM_PULSES: u16 = 60;
/// Seconds the hold settles before it is measured, and is measured (as `bowl sim stability`).
const HOLD_SETTLE_S: f32 = 20.0;
const HOLD_MEASURE_S: f32 = 20.0;
/// Amplitudes below this (percent) are drawn at it on the log axis; the CSV keeps the value.
const AMPLITUDE_FLOOR_PCT: f64 = 1e-3;
/// Where runs that latched a fault are marked (above any measured cycle), percent.
const FAULT_ROW_PCT: f64 = 3000.0;
/// A hold whose mean stayed this far off the speed (percent) never reached it: below the lowest
/// speed its pulses measure the motor is never driven, and its flat 0 % is no limit cycle.
const NEVER_HELD_ERROR_PCT: f64 = 50.0;

/// How much to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Extent {
    /// Every point of the chart.
    Full,
    /// The few points the tests assert on (pulse counts 1, 12, 60, 240; the stability chart at
    /// 12 pulses/rev and 1 kHz, gains 0.5, 1 and 2).
    Quick,
}

/// One commissioned step of the settling sweep.
#[derive(Clone, Copy, Debug)]
pub struct SettlingPoint {
    /// Pulses per revolution on both axes.
    pub pulses_per_rev: u16,
    /// `[precession, spin]` 2 % settling time, s (the run lasts [`STEP_RUN_S`]).
    pub settling_s: [f64; 2],
    /// Worse axis's overshoot, percent.
    pub overshoot_pct: f64,
    /// Fault latched during commissioning or the step (None: none).
    pub fault: Option<Fault>,
    /// Commissioning ended in Idle.
    pub commissioned: bool,
}

/// The pulse counts of the settling chart.
pub fn settling_pulse_counts(extent: Extent) -> &'static [u16] {
    match extent {
        Extent::Full => &[
            1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 40, 48, 60, 90, 120, 180, 240,
        ],
        Extent::Quick => &[1, 12, 60, 240],
    }
}

/// Runs the commissioned step (nominal rig and controller, seed `seed`) for every pulse count.
pub fn settling_points(extent: Extent, seed: u32) -> Vec<SettlingPoint> {
    crate::parallel::parallel(settling_pulse_counts(extent), |&n| {
        let o = experiments::commissioned_step(
            rig_with_pulses(n),
            ControllerConfig::nominal(),
            seed,
            STEP_TARGET_RAD_S,
            true,
            [0.0; 2],
        );
        SettlingPoint {
            pulses_per_rev: n,
            settling_s: [
                f64::from(o.reports[0].settling_time_s),
                f64::from(o.reports[1].settling_time_s),
            ],
            overshoot_pct: 100.0 * f64::from(o.reports[0].overshoot.max(o.reports[1].overshoot)),
            fault: o.fault,
            commissioned: o.commissioned,
        }
    })
}

/// Pulse count above which the nominal loop's bandwidth at 3 rad/s is its fixed ceiling rather
/// than `per_pulse_bandwidth x pulse rate` (the schedule in `model-core/src/control/pi.rs`).
pub fn pulse_limit_knee(cfg: &ControllerConfig, speed_rad_s: f32) -> f64 {
    // The spin axis, whose settling is the later one.
    let a = &cfg.axes[1];
    // The schedule holds its value above its top speed (`pi::SCHEDULE_TOP_RAD_S`).
    let scheduled_at = speed_rad_s.min(model_core::control::pi::SCHEDULE_TOP_RAD_S);
    let pulses_per_s_per_rev = f64::from(scheduled_at) / std::f64::consts::TAU;
    f64::from(a.bandwidth_rad_s) / (f64::from(a.per_pulse_bandwidth) * pulses_per_s_per_rev)
}

/// The settling chart and its CSV.
pub fn settling_chart(points: &[SettlingPoint]) -> (Figure, Table) {
    let mut table = Table::new(&[
        "pulses_per_rev",
        "pulse_rate_hz_at_3_rad_s",
        "precession_settling_s",
        "spin_settling_s",
        "worst_settling_s",
        "worst_overshoot_pct",
        "fault_code",
        "commissioned",
    ]);
    let rate = |n: u16| f64::from(n) * f64::from(STEP_TARGET_RAD_S) / std::f64::consts::TAU;
    for p in points {
        table.row(vec![
            p.pulses_per_rev.to_string(),
            format!("{:.3}", rate(p.pulses_per_rev)),
            format!("{:.3}", p.settling_s[0]),
            format!("{:.3}", p.settling_s[1]),
            format!("{:.3}", p.settling_s[0].max(p.settling_s[1])),
            format!("{:.3}", p.overshoot_pct),
            p.fault.map_or(0, Fault::code).to_string(),
            p.commissioned.to_string(),
        ]);
    }
    let x = |p: &SettlingPoint| f64::from(p.pulses_per_rev);
    let n_max = points.iter().map(x).fold(1.0, f64::max);
    let mut series = vec![
        Series {
            name: "spin (starts with the precession)".into(),
            points: points.iter().map(|p| (x(p), p.settling_s[1])).collect(),
            mark: Mark::LinePoints,
            color: 0,
        },
        Series {
            name: "precession".into(),
            points: points.iter().map(|p| (x(p), p.settling_s[0])).collect(),
            mark: Mark::LinePoints,
            color: 1,
        },
        Series {
            name: format!("target {FINE_SETTLING_TARGET_S} s at >= {FINE_FROM_PULSES} pulses/rev"),
            points: vec![
                (f64::from(FINE_FROM_PULSES), FINE_SETTLING_TARGET_S),
                (
                    n_max.max(f64::from(FINE_FROM_PULSES)),
                    FINE_SETTLING_TARGET_S,
                ),
            ],
            mark: Mark::Dashed,
            color: 8,
        },
    ];
    let faulted: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.fault.is_some() || !p.commissioned)
        .map(|p| (x(p), p.settling_s[0].max(p.settling_s[1])))
        .collect();
    if !faulted.is_empty() {
        series.push(Series {
            name: "fault latched / not commissioned".into(),
            points: faulted,
            mark: Mark::Crosses,
            color: 6,
        });
    }
    let cfg = ControllerConfig::nominal();
    let knee = pulse_limit_knee(&cfg, STEP_TARGET_RAD_S);
    let fig = Figure {
        title: "Settling time of the 0 -> 3 rad/s step against pulses per revolution".into(),
        x_label: "pulses per revolution (log)".into(),
        y_label: "2 % settling time of the true speed, s".into(),
        x_scale: Scale::Log,
        y_scale: Scale::Linear,
        series,
        // Across the plot, clear of the frame (as a series, the axis ended on it).
        hlines: vec![HLine {
            y: NOMINAL_SETTLING_TARGET_S,
            label: format!("target {NOMINAL_SETTLING_TARGET_S} s (nominal, 12 pulses/rev)"),
            color: 7,
        }],
        vlines: vec![
            VLine {
                x: 12.0,
                // Unlabelled (the 2.5 s target's label names the nominal rig): this also puts
                // the next label one row lower.
                label: String::new(),
                color: 7,
            },
            VLine {
                x: knee,
                label: format!(" loop bandwidth no longer pulse-limited (N = {knee:.0})"),
                color: 2,
            },
        ],
        notes: vec![
            "Nominal rig and controller, commissioned first,".into(),
            "then both axes 0 -> 3 rad/s (ramp 6 rad/s^2,".into(),
            "0.5 s); seed 1; the simulator's true speed.".into(),
            format!("Left of N = {knee:.0} the loop bandwidth is"),
            format!(
                "{} x pulse rate at <= 2.1 rad/s (the schedule);",
                cfg.axes[1].per_pulse_bandwidth
            ),
            format!(
                "right of it, the {} rad/s ceiling. On this step",
                cfg.axes[1].bandwidth_rad_s
            ),
            "the identified model's feedforward, the kick".into(),
            "and the ramp set the time: the loop corrects".into(),
            "little, so the pulse rate barely shows.".into(),
            format!("A run lasts {STEP_RUN_S} s: a point there never settled."),
        ],
    };
    (fig, table)
}

/// One loop configuration of the stability chart: tick rate and pulses per revolution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoopSetup {
    /// Control tick rate, Hz.
    pub tick_hz: u32,
    /// Pulses per revolution.
    pub pulses_per_rev: u16,
}

/// One low-speed hold.
#[derive(Clone, Copy, Debug)]
pub struct HoldPoint {
    /// The loop.
    pub setup: LoopSetup,
    /// Per-pulse gain: closed-loop bandwidth per pulse per second, rad/pulse.
    pub per_pulse_bandwidth: f64,
    /// With the pulse-rate schedule (false: the gain it gives at 3 rad/s, kept).
    pub scheduled: bool,
    /// Half the peak-to-peak excursion of the true spin speed over the measured window, percent.
    pub half_peak_to_peak_pct: f64,
    /// |mean - setpoint| over the window, percent.
    pub mean_error_pct: f64,
    /// Fault latched (None: none).
    pub fault: Option<Fault>,
}

/// The loop setups and gains of the stability chart.
pub fn stability_grid(extent: Extent) -> (Vec<LoopSetup>, &'static [f32]) {
    let s = |tick_hz, pulses_per_rev| LoopSetup {
        tick_hz,
        pulses_per_rev,
    };
    match extent {
        Extent::Full => (
            vec![
                s(1000, 1),
                s(1000, 4),
                s(1000, 12),
                s(1000, 60),
                s(250, 12),
                s(100, 12),
            ],
            &[0.1, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0],
        ),
        Extent::Quick => (vec![s(1000, 12)], &[0.5, 1.0, 2.0]),
    }
}

/// Runs the 0.5 rad/s hold (no disturbances, true model; see
/// `experiments::low_speed_hold_at_rate`) for every setup, gain and schedule choice.
pub fn hold_points(extent: Extent, seed: u32) -> Vec<HoldPoint> {
    let (setups, gains) = stability_grid(extent);
    let mut jobs = Vec::new();
    for &setup in &setups {
        for &g in gains {
            for scheduled in [true, false] {
                jobs.push((setup, g, scheduled));
            }
        }
    }
    crate::parallel::parallel(&jobs, |&(setup, g, scheduled)| {
        let (r, fault) = experiments::low_speed_hold_at_rate(
            setup.tick_hz,
            seed,
            setup.pulses_per_rev,
            HOLD_SPEED_RAD_S,
            g,
            scheduled,
            HOLD_SETTLE_S,
            HOLD_MEASURE_S,
        );
        HoldPoint {
            setup,
            per_pulse_bandwidth: f64::from(g),
            scheduled,
            half_peak_to_peak_pct: 100.0 * f64::from(r.half_peak_to_peak),
            mean_error_pct: 100.0 * f64::from(r.steady_state_error),
            fault,
        }
    })
}

fn pulse_rate_hz(n: u16, speed_rad_s: f32) -> f64 {
    f64::from(n) * f64::from(speed_rad_s) / std::f64::consts::TAU
}

/// The stability chart and its CSV.
pub fn stability_chart(points: &[HoldPoint]) -> (Figure, Table) {
    let mut table = Table::new(&[
        "tick_hz",
        "pulses_per_rev",
        "pulse_rate_hz",
        "per_pulse_bandwidth",
        "scheduled",
        "half_peak_to_peak_pct",
        "fault_code",
        "mean_error_pct",
    ]);
    for p in points {
        table.row(vec![
            p.setup.tick_hz.to_string(),
            p.setup.pulses_per_rev.to_string(),
            format!(
                "{:.3}",
                pulse_rate_hz(p.setup.pulses_per_rev, HOLD_SPEED_RAD_S)
            ),
            // The gain as given (f32), so 0.1 reads "0.1".
            (p.per_pulse_bandwidth as f32).to_string(),
            p.scheduled.to_string(),
            format!("{:.3}", p.half_peak_to_peak_pct),
            p.fault.map_or(0, Fault::code).to_string(),
            format!("{:.3}", p.mean_error_pct),
        ]);
    }
    let mut setups: Vec<LoopSetup> = Vec::new();
    for p in points {
        if !setups.contains(&p.setup) {
            setups.push(p.setup);
        }
    }
    // A run that latched a fault has no limit cycle to measure (the motors were stopped): its
    // point is a gap in the line and a cross on the fault row instead.
    let never_held = |p: &HoldPoint| p.mean_error_pct >= NEVER_HELD_ERROR_PCT;
    let drawn = |p: &HoldPoint| match p.fault {
        Some(_) => f64::NAN,
        None if never_held(p) => f64::NAN,
        None => p.half_peak_to_peak_pct.max(AMPLITUDE_FLOOR_PCT),
    };
    // A setup whose shaft never reached the speed at any gain gets no line (it was drawn as a
    // perfect hold along the floor) and a note instead.
    let unheld: Vec<LoopSetup> = setups
        .iter()
        .copied()
        .filter(|s| {
            points
                .iter()
                .filter(|p| p.setup == *s && p.fault.is_none())
                .all(never_held)
        })
        .collect();
    let mut series = Vec::new();
    for (i, s) in setups.iter().enumerate() {
        if unheld.contains(s) {
            continue;
        }
        let label = format!(
            "N {} ({:.2} pulses/s), {} Hz",
            s.pulses_per_rev,
            pulse_rate_hz(s.pulses_per_rev, HOLD_SPEED_RAD_S),
            s.tick_hz
        );
        for (scheduled, mark, what) in [
            (true, Mark::LinePoints, "scheduled"),
            (false, Mark::DashedPoints, "fixed gain"),
        ] {
            series.push(Series {
                name: format!("{label}, {what}"),
                points: points
                    .iter()
                    .filter(|p| p.setup == *s && p.scheduled == scheduled)
                    .map(|p| (p.per_pulse_bandwidth, drawn(p)))
                    .collect(),
                mark,
                color: i,
            });
        }
    }
    let g_min = points
        .iter()
        .map(|p| p.per_pulse_bandwidth)
        .fold(f64::INFINITY, f64::min);
    let g_max = points
        .iter()
        .map(|p| p.per_pulse_bandwidth)
        .fold(f64::NEG_INFINITY, f64::max);
    if g_min.is_finite() {
        series.push(Series {
            name: format!("{LIMIT_CYCLE_BOUND_PCT} % bound"),
            points: vec![
                (g_min, LIMIT_CYCLE_BOUND_PCT),
                (g_max, LIMIT_CYCLE_BOUND_PCT),
            ],
            mark: Mark::Dashed,
            color: 8,
        });
    }
    // One row of crosses per loop setup that faulted, in its colour, a little apart so
    // crosses at the same gain stay distinguishable.
    let mut row = FAULT_ROW_PCT;
    for (i, s) in setups.iter().enumerate() {
        let faulted: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.setup == *s && p.fault.is_some())
            .map(|p| (p.per_pulse_bandwidth, row))
            .collect();
        if !faulted.is_empty() {
            series.push(Series {
                name: format!(
                    "N {}, {} Hz: fault latched, motors stopped",
                    s.pulses_per_rev, s.tick_hz
                ),
                points: faulted,
                mark: Mark::Crosses,
                color: i,
            });
            row *= 1.6;
        }
    }
    let nominal = f64::from(ControllerConfig::nominal().axes[1].per_pulse_bandwidth);
    let mut fig = Figure {
        title: format!("Limit cycle holding {HOLD_SPEED_RAD_S} rad/s against the per-pulse gain"),
        x_label: "per-pulse gain: loop bandwidth / pulse rate, rad per pulse (log)".into(),
        y_label: "half peak-to-peak of the true speed, % (log)".into(),
        x_scale: Scale::Log,
        y_scale: Scale::Log,
        series,
        hlines: Vec::new(),
        vlines: vec![VLine {
            x: nominal,
            label: format!(" nominal gain {nominal}"),
            color: 7,
        }],
        notes: vec![
            "Nominal rig, true model, no disturbances;".into(),
            format!(
                "{HOLD_SPEED_RAD_S} rad/s held {HOLD_SETTLE_S} s, then measured {HOLD_MEASURE_S} s."
            ),
            "Scheduled: bandwidth = gain x pulse rate at the".into(),
            "reference speed (what the code does).".into(),
            "Fixed gain: the bandwidth that gives at 3 rad/s,".into(),
            "kept at 0.5 rad/s (6x the scheduled one, up to".into(),
            "the 8 rad/s ceiling).".into(),
            "Each fault here is over-speed: the cycle grew".into(),
            "until the supervisor stopped both motors;".into(),
            format!("faulted runs are the crosses above {FAULT_ROW_PCT} %."),
            format!("Amplitudes below {AMPLITUDE_FLOOR_PCT} % drawn at {AMPLITUDE_FLOOR_PCT} %"),
            "(the CSV keeps the value).".into(),
        ],
    };
    for s in &unheld {
        fig.notes.push(format!(
            "Not drawn: N {}, {} Hz never reached {HOLD_SPEED_RAD_S} rad/s",
            s.pulses_per_rev, s.tick_hz
        ));
        fig.notes
            .push("(too slow for its pulses; see the CSV).".into());
    }
    (fig, table)
}

#[cfg(test)]
mod tests;

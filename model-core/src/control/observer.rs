//! An angle-domain observer of one shaft: angle since the last edge, speed and a load term,
//! propagated every tick by the identified plant driven by the applied duty and corrected at
//! each edge by the angle the wheel's teeth measured (issue 27, part 1).
//!
//! # Model
//! The identified first-order plant (`MotorModel`, docs/control.md "Commissioning"), in the
//! shaft's direction of rotation (a magnitude, like the estimator):
//! `tau dw/dt = (d - friction_duty - load) / (volts_per_rad_s / V) - w`, `w >= 0`,
//! stepped by Backward Euler as the loop's own model (`pi.rs`) is. `d` is the duty that drives
//! the plant the identified model describes: the applied duty less what the controller adds
//! to cancel what that model does not contain (the spin's reaction on the precession axis,
//! the once-per-revolution load), so `load` is only what the model does not know (material
//! poured in since commissioning, a worn bearing), in duty. A shaft whose drive is below
//! its friction stops there and does not turn backwards (one sensor cannot tell).
//!
//! # Correction at an edge
//! The measured angle is the edge's: the pitches the tooth map counts for the gaps since the
//! last edge (the learned tooth offsets applied, teeth.rs). The angle is exact at an edge up to
//! the timer's resolution, so the angle state takes it outright (alpha = 1 of an
//! alpha-beta-gamma tracker); the innovation `e = measured - predicted` (pitches) over the
//! interval `T` says the shaft's mean speed over it differed from the prediction by
//! `e pitch / T`, of which the speed takes [`SPEED_GAIN`] and the load [`LOAD_GAIN`] (as duty
//! through the model's `volts_per_rad_s / V`). The gains are per edge, so the observer's
//! bandwidth is scheduled on the pulse rate (as ODrive's encoder PLL's is on its bandwidth, with
//! `kp = 2 bw`, `ki = bw^2 / 4`): where the plant settles within a pulse period, the load's
//! error shrinks by `1 - gamma` per edge (halves within three edges); raised to 0.8 / 0.5
//! the observer was tried as the loop's speed and not kept (docs/control.md, "The observer in
//! the loop").
//!
//! # What it gives
//! - [`AngleObserver::predicted_pitches`]: the angle expected at an edge time, which tells a
//!   missing pulse (an interval of `k` expected pitches, `k` = 2 or 3) from a shaft that slowed
//!   (the observer, driven by the throttled duty, expected about one pitch);
//! - [`AngleObserver::speed_rad_s`]: the speed the sensor watch integrates into expected travel.
//!
//! [`AngleObserver::track`] is the controller's one call per axis and tick: it hands the
//! estimator the expected angle, runs it on the tick's edges, then propagates and corrects.

use super::config::AxisConfig;
use super::estimator::{PulseSpeedEstimator, pulses_expected};

/// Share of an edge's mean-speed error the speed takes.
pub const SPEED_GAIN: f32 = 0.5;
/// Share of an edge's mean-speed error, as duty, the load takes.
pub const LOAD_GAIN: f32 = 0.25;
/// An edge whose innovation is below this many pitches counts as tracked.
pub const TRACKED_PITCHES: f32 = 0.25;
/// Consecutive tracked edges after which the observer's prediction is trusted (for the
/// missing-pulse inference).
pub const TRACKED_EDGES: u8 = 3;
/// The largest load the observer takes, in magnitude, duty (a bound against a runaway estimate
/// of a shaft held without edges; a real load above this stalls any rig).
pub const LOAD_LIMIT_DUTY: f32 = 1.0;

/// Per-axis constants of the observer, from the configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObserverConstants {
    dt_s: f32,
    pitch_rad: f32,
    per_pitch_rad: f32,
    alpha: f32,
    duty_per_rad_s: f32,
    friction_duty: f32,
}

impl ObserverConstants {
    /// For `axis` at tick period `dt_s` and supply `supply_v`.
    pub const fn new(axis: &AxisConfig, dt_s: f32, supply_v: f32) -> Self {
        let pitch_rad = core::f32::consts::TAU / axis.pulses_per_rev as f32;
        Self {
            dt_s,
            pitch_rad,
            per_pitch_rad: 1.0 / pitch_rad,
            alpha: dt_s / (axis.model.time_constant_s + dt_s),
            duty_per_rad_s: axis.model.volts_per_rad_s / supply_v,
            friction_duty: axis.model.friction_duty,
        }
    }
}

/// The observer's state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngleObserver {
    speed_rad_s: f32,
    load_duty: f32,
    /// Angle turned since the last edge, pitches (the reference edge: the estimator's last).
    since_edge_pitches: f32,
    /// Time since the last edge, s.
    since_edge_s: f32,
    /// There is a reference edge (an edge since the observer started or restarted).
    has_edge: bool,
    /// Consecutive edges whose innovation was below [`TRACKED_PITCHES`].
    tracked: u8,
    /// The last innovation, pitches.
    innovation: f32,
    /// The load is held, not learned, at the edges (see [`AngleObserver::hold_load`]).
    load_held: bool,
    /// The last edge was ambiguous (see [`AngleObserver::correct`]) and not learned from.
    skipped: bool,
    /// The speed the applied duty drives the identified plant to with the learned load, but
    /// without the edges' corrections of the speed, rad/s: see [`AngleObserver::driven_rad_s`].
    driven_rad_s: f32,
}

impl AngleObserver {
    /// At rest, no load known, no edge.
    pub const REST: Self = Self {
        speed_rad_s: 0.0,
        load_duty: 0.0,
        since_edge_pitches: 0.0,
        since_edge_s: 0.0,
        has_edge: false,
        tracked: 0,
        innovation: 0.0,
        load_held: false,
        skipped: false,
        driven_rad_s: 0.0,
    };

    /// One tick of the plant driven by `duty` (in the shaft's direction: negative brakes).
    #[inline(always)]
    pub fn predict(&mut self, k: &ObserverConstants, duty: f32) {
        let target = (duty - k.friction_duty - self.load_duty) / k.duty_per_rad_s;
        let w = self.speed_rad_s + (target - self.speed_rad_s) * k.alpha;
        // No backward turning, and never a non-finite state from a non-finite input.
        self.speed_rad_s = if w > 0.0 { w } else { 0.0 };
        self.since_edge_pitches += self.speed_rad_s * k.dt_s * k.per_pitch_rad;
        self.since_edge_s += k.dt_s;
        // The duty's own speed with the load learned so far (held while slowing): what the
        // shaft runs at under a steady duty, and above it while the loop pushes.
        let v = self.driven_rad_s + (target - self.driven_rad_s) * k.alpha;
        self.driven_rad_s = if v > 0.0 { v } else { 0.0 };
    }

    /// The first edge after rest, `ago_s` before now: the angle's reference, no innovation.
    pub fn restart(&mut self, k: &ObserverConstants, ago_s: f32) {
        self.has_edge = true;
        self.tracked = 0;
        self.innovation = 0.0;
        self.since_edge_s = ago_s;
        self.since_edge_pitches = self.speed_rad_s * ago_s * k.per_pitch_rad;
    }

    /// An edge `ago_s` before now, `measured_pitches` after the reference edge (the tooth
    /// map's length of the gaps between them).
    #[inline(never)]
    pub fn correct(&mut self, k: &ObserverConstants, measured_pitches: f32, ago_s: f32) {
        if !self.has_edge {
            self.restart(k, ago_s);
            return;
        }
        let interval_s = self.since_edge_s - ago_s;
        let predicted = self.predicted_pitches(k, ago_s);
        let e = measured_pitches - predicted;
        self.innovation = e;
        // An edge a whole pitch or more short of an expectation of 2 or 3 pitches, not taken
        // as missing pulses (the observer did not track yet, or was not let judge): a dropped
        // pulse or a shaft that lagged, no telling which. Learned from, a dropped pulse takes a
        // quarter off the speed (e = -1 over two pitches) and puts it into the load, and the
        // observer then misses its next edges too. Once is skipped; a shaft that really lags
        // shows it again at the next edge, and is learned from then.
        let ambiguous = e < -0.7 && pulses_expected(predicted) > 1 && !self.skipped;
        self.skipped = ambiguous;
        if interval_s > 0.0 && e.is_finite() && !ambiguous {
            let mean_error_rad_s = e * k.pitch_rad / interval_s;
            let w = self.speed_rad_s + SPEED_GAIN * mean_error_rad_s;
            self.speed_rad_s = if w > 0.0 { w } else { 0.0 };
            if !self.load_held {
                let load = self.load_duty - LOAD_GAIN * k.duty_per_rad_s * mean_error_rad_s;
                self.load_duty = load.clamp(-LOAD_LIMIT_DUTY, LOAD_LIMIT_DUTY);
            }
        }
        self.tracked = if e.abs() < TRACKED_PITCHES {
            self.tracked.saturating_add(1)
        } else {
            0
        };
        self.since_edge_s = ago_s;
        self.since_edge_pitches = self.speed_rad_s * ago_s * k.per_pitch_rad;
    }

    /// The angle since the reference edge the observer expected `ago_s` before now, pitches.
    #[inline(always)]
    pub fn predicted_pitches(&self, k: &ObserverConstants, ago_s: f32) -> f32 {
        self.since_edge_pitches - self.speed_rad_s * ago_s * k.per_pitch_rad
    }

    /// One control tick of the estimator under this observer: the observer's expected angle
    /// judges missing pulses among `edges` (once it tracks, and only while `infer`), then the
    /// plant driven by `duty` (the duty applied since the last tick, in the shaft's direction,
    /// less what it held beyond the identified model) is propagated to `now` and corrected by
    /// the edges. Returns the estimator's speed (see [`PulseSpeedEstimator::tick`]).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn track(
        &mut self,
        k: &ObserverConstants,
        est: &mut PulseSpeedEstimator,
        now: u32,
        edges: &[u32],
        steady: bool,
        infer: bool,
        duty: f32,
    ) -> f32 {
        if infer && self.tracking() {
            est.expect_travel(self.since_edge_pitches, self.speed_rad_s * k.per_pitch_rad);
        } else {
            est.expect_travel(0.0, 0.0);
        }
        let speed = est.tick(now, edges, steady, |_, _| {});
        self.predict(k, duty);
        if let Some((restarted, pitches, ago_s)) = est.tick_edges() {
            if restarted {
                self.restart(k, ago_s);
            } else {
                self.correct(k, pitches, ago_s);
            }
        }
        speed
    }

    /// Holds the load (`true`) or learns it again at the edges (`false`). The controller holds
    /// it while the loop's reference came down (the loop's "slowing", pi.rs): a shaft then
    /// decelerates as its true inertia and friction let it, and the identified first-order
    /// model's error in that (its time constant; family-60's p25 decelerates 19 % slower than
    /// its identified model) is no load. Learned, it took the load the shaft carried at 4 rad/s
    /// out of the estimate on the way down to 0.2 rad/s; at the duty that holds that load the
    /// observer then ran ahead of the shaft (0.37 against 0.11 rad/s) and the expected-edge
    /// watch faulted a healthy, turning shaft.
    pub fn hold_load(&mut self, held: bool) {
        self.load_held = held;
    }

    /// Speed, rad/s (magnitude).
    pub fn speed_rad_s(&self) -> f32 {
        self.speed_rad_s
    }
    /// The speed the duty the loop applied drives the identified plant to, through its lag,
    /// rad/s: the observer's propagation with the load it learned but without the edges'
    /// corrections of its speed. At a steady duty it is the speed the shaft holds; the edges
    /// do not pull it along, so a shaft driven by something other than the loop (a bridge stuck
    /// on) runs away from it, while a shaft the loop itself pushed (a breakaway push from a
    /// crawl) is expected as fast as that push drives it.
    pub fn driven_rad_s(&self) -> f32 {
        self.driven_rad_s
    }
    /// The speed `duty` (in the shaft's direction, less what it holds beyond the identified
    /// model) drives the identified plant towards, less the speed now, rad/s: the shaft's
    /// expected acceleration times its time constant, with the load its edges showed and its
    /// speed as they corrected it.
    #[inline(always)]
    pub fn drive_rad_s(&self, k: &ObserverConstants, duty: f32) -> f32 {
        (duty - k.friction_duty - self.load_duty) / k.duty_per_rad_s - self.speed_rad_s
    }
    /// Seconds the identified plant, from `speed_rad_s` on zero duty, takes at most to coast to
    /// rest against its friction and the load learned if that drags (a negative load is the
    /// model's error while driven, and drives no coasting shaft): `tau ln(1 + x)` with `x` the
    /// speed over the drag's, bounded above by `tau x / sqrt(1 + x)` (within 26 % for `x` up
    /// to 10; a square root is one instruction on the Cortex-M4F, a logarithm a library call).
    /// Infinite when nothing drags in the model.
    pub fn coast_s(&self, k: &ObserverConstants, speed_rad_s: f32) -> f32 {
        let load = if self.load_duty > 0.0 {
            self.load_duty
        } else {
            0.0
        };
        let drag_rad_s = (k.friction_duty + load) / k.duty_per_rad_s;
        if drag_rad_s.is_nan() || drag_rad_s <= 0.0 {
            return f32::INFINITY;
        }
        // alpha = dt / (tau + dt).
        let tau_s = k.dt_s * (1.0 - k.alpha) / k.alpha;
        let x = speed_rad_s / drag_rad_s;
        tau_s * x / libm::sqrtf(1.0 + x)
    }
    /// Load the model does not know, duty.
    pub fn load_duty(&self) -> f32 {
        self.load_duty
    }
    /// Angle since the last edge, pitches.
    pub fn since_edge_pitches(&self) -> f32 {
        self.since_edge_pitches
    }
    /// The last innovation, pitches.
    pub fn innovation_pitches(&self) -> f32 {
        self.innovation
    }
    /// The last [`TRACKED_EDGES`] edges each came within [`TRACKED_PITCHES`] of the prediction.
    pub fn tracking(&self) -> bool {
        self.tracked >= TRACKED_EDGES
    }
}

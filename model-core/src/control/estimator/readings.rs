//! What the estimator tells the controller, the loop and the supervisor: its readings (the
//! estimate, the speed over the last one or two intervals and over a revolution), whether it
//! has a measurement, and its counters. Read-only, apart from forgetting the wheel's teeth.

use super::{Gap, PulseSpeedEstimator, WindowEvents, WindowSample};
use crate::control::teeth::ToothMap;

impl PulseSpeedEstimator {
    /// The window events of the last tick, for a loop that compares the measurement with a
    /// model over exactly the same interval (see `pi`).
    pub fn window_events(&self) -> WindowEvents {
        let ago = |at: u32| self.clock.wrapping_sub(at) as f32 * self.s_per_tick;
        WindowEvents {
            restarted_s_ago: self.restart_at.map(ago),
            closed: self.closed_at.map(|at| WindowSample {
                ago_s: ago(at),
                span_s: self.closed_span as f32 * self.s_per_tick,
                raw_speed_rad_s: self.closed_raw,
            }),
            bound_active: self.bound_active,
        }
    }

    /// The last estimate, rad/s (magnitude).
    pub fn speed_rad_s(&self) -> f32 {
        self.speed
    }
    /// True once at least one pulse interval has been measured since the shaft last stopped.
    pub fn is_valid(&self) -> bool {
        self.valid
    }
    /// True if the last tick produced a new raw sample.
    pub fn updated(&self) -> bool {
        self.closed_at.is_some()
    }
    /// Speed over the last pulse interval alone, rad/s (0 before a first interval since rest):
    /// the newest evidence of the speed, unfiltered, for the runaway check.
    pub fn edge_speed_rad_s(&self) -> f32 {
        if self.has_edge && self.last_interval > 0 {
            self.rad_ticks_per_pulse_s / self.last_interval as f32
        } else {
            0.0
        }
    }
    /// Speed over the last two pulse intervals, rad/s (0 before two intervals since rest): a
    /// wheel's tooth offsets (each at most 5 % of a pitch) shorten one interval by up to 10 %
    /// but two neighbouring ones together by at most 5 %, so a smaller excess is evidence.
    pub fn pair_speed_rad_s(&self) -> f32 {
        if self.has_edge && self.prev_interval > 0 && self.last_interval > 0 {
            2.0 * self.rad_ticks_per_pulse_s
                / (self.prev_interval as f32 + self.last_interval as f32)
        } else {
            0.0
        }
    }
    /// Mean speed over the last whole revolution, rad/s (0 until the tooth map's chain spans a
    /// revolution at a steady reference): neither tooth offsets nor a once-per-revolution load
    /// move it, so a small lasting excess shows in it.
    pub fn revolution_speed_rad_s(&self) -> f32 {
        match self.teeth.revolution_ticks() {
            Some(t) => core::f32::consts::TAU * self.ticks_per_s / t as f32,
            None => 0.0,
        }
    }
    /// True when no edge has come since the shaft last stopped (or ever).
    pub fn at_rest(&self) -> bool {
        !self.has_edge
    }
    /// True when the estimate is exactly zero (stopped or never moved).
    pub fn is_stopped(&self) -> bool {
        self.speed == 0.0
    }
    /// Seconds since the last accepted edge (0 if none since the last stop).
    pub fn since_edge_s(&self) -> f32 {
        if self.has_edge {
            self.clock.wrapping_sub(self.last_edge) as f32 / self.ticks_per_s
        } else {
            0.0
        }
    }
    /// Edges accepted so far (wrapping counter).
    pub fn accepted_edges(&self) -> u32 {
        self.accepted
    }
    /// Edges rejected as bounces so far.
    pub fn rejected_edges(&self) -> u32 {
        self.rejected
    }
    /// Pulses inferred as missing so far.
    pub fn inferred_missing(&self) -> u32 {
        self.missing
    }
    /// The sensor dropped a pulse within the last [`DROP_MEMORY_PULSES`](super::DROP_MEMORY_PULSES): the next interval may
    /// be two or three pitches (the sensor watch then waits for
    /// [`DROPPING_WATCH_PITCHES`](crate::control::supervisor::DROPPING_WATCH_PITCHES)).
    pub fn dropping(&self) -> bool {
        self.drop_memory > 0
    }
    /// Edges whose timestamp was after the tick's `now` (placed at `now`).
    pub fn late_edges(&self) -> u32 {
        self.late_edges
    }
    /// Radians per pulse.
    pub fn rad_per_pulse(&self) -> f32 {
        self.rad_per_pulse
    }
    /// Forgets the learned tooth offsets (the shaft turns the other way: the gaps come in the
    /// opposite order).
    pub fn forget_teeth(&mut self) {
        self.teeth.forget();
    }
    /// The tooth map learns from every single-pulse gap of the next tick if `on` (the shaft
    /// held at a steady duty by commissioning), whatever the tick's `steady` says of the rest.
    pub fn learn_teeth(&mut self, on: bool) {
        self.learn_teeth = on;
    }
    /// The wheel turns about the vertical ([`ToothMap::about_the_vertical`]).
    pub const fn about_the_vertical(&mut self) {
        self.teeth.about_the_vertical();
    }
    /// Revolutions of tooth offsets learned since the last [`Self::forget_teeth`].
    pub fn teeth_revolutions_learned(&self) -> u16 {
        self.teeth.revolutions_learned()
    }
    /// Extended clock at the last tick, timer ticks (wrapping).
    pub fn clock_ticks(&self) -> u32 {
        self.clock
    }
    /// The last gap measured alone (one pulse); its `serial` tells a new one from the last.
    pub fn last_gap(&self) -> Gap {
        self.last_gap
    }
    /// The sensor wheel as counted and learned.
    pub fn teeth(&self) -> &ToothMap {
        &self.teeth
    }
    /// Seconds per timer tick.
    pub fn s_per_tick(&self) -> f32 {
        self.s_per_tick
    }
}

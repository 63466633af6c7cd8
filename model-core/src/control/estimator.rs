//! Shaft speed from proximity-sensor edges.
//!
//! # Inputs
//! Edge timestamps come from a free-running capture timer (`timer_hz`, 16 or 32 bits, wrapping).
//! Once per control tick the estimator gets the timer's current value and the edges captured
//! since the previous tick. It keeps an *extended clock* (a `u32` tick count that never wraps
//! within a pulse period) by adding the wrapped difference between consecutive ticks, so a
//! 16-bit timer at 1 MHz (wrapping every 65 ms) still measures a pulse period of seconds. This
//! needs at least one tick per timer wrap, which the configuration check guarantees.
//!
//! # Method (M/T: period at low speed, counting at high speed)
//! Every accepted edge adds its pulses to a counting window. When the window spans at least
//! [`WINDOW_S`], the raw speed is `pulses * pitch / (time from the window's first to last edge)`
//! and a new window starts at that edge. At low speed one pulse interval is longer than the window,
//! so this is a period measurement; at high speed several pulses fall in the window, so it is a
//! count over a window whose ends are exact edge times (no +/-1 count quantisation). The raw
//! speed goes through an exponential filter with the configured weight.
//!
//! # Stall bound
//! Between edges the shaft has turned less than one pitch since the last edge, so the speed is at
//! most `pitch / time since the last edge`. Once that bound is below the filtered value, it is
//! the estimate (at steady speed the bound allows two pitches, so that one missing pulse does not
//! halve the reading): a stopping shaft reads a falling speed, and after [`STALL_PITCHES`]
//! pitches at the lowest speed ([`lowest_speed_rad_s`]) without an edge it reads exactly zero
//! and the estimator starts afresh.
//!
//! # Bounce and missing pulses
//! An edge closer to the previous accepted edge than half the pulse period at the over-speed
//! limit, or than 40 % of the last measured period, is a bounce and is ignored (counted in
//! [`PulseSpeedEstimator::rejected_edges`]). An interval is taken as `k` = 2 or 3 pulses with
//! the middle ones missing (counted in [`PulseSpeedEstimator::inferred_missing`]) when the
//! shaft's observer ([`super::observer`], through [`PulseSpeedEstimator::expect_travel`])
//! expected `k` pitches over it (within 0.3), where the controller lets it judge (steady, or the
//! sensor dropping pulses lately: [`PulseSpeedEstimator::dropping`]): a shaft that slowed gives a
//! long interval too, but its observer, driven by the throttled duty, expected one pitch. Without
//! an observer (the estimator on its own) the rule is the last measured period's.
//!
//! # Tooth offsets
//! Each window counts its gaps by their learned lengths ([`super::teeth::ToothMap`]): at
//! steady speed the estimator learns how long each gap of the wheel is, so a worn or unevenly
//! cut wheel does not read as speed ripple. The lockout, the missing-pulse inference and the
//! stall bound keep using the nominal pitch.
//!
//! # Direction
//! One proximity sensor cannot tell the direction of rotation: the estimate is a magnitude.
//! The controller gives it the sign of the commanded (ramped) direction, and the planner only
//! reverses once this estimator reads zero.

use super::config::AxisConfig;
use super::teeth::ToothMap;

mod build;
mod readings;

/// Shortest counting window, s: at high pulse rates a raw sample averages over at least this.
pub const WINDOW_S: f32 = 0.025;

/// Longest pulse period the controller works with, s: below the speed that gives it, a shaft
/// cannot be measured often enough to be held (one sample per 4 s).
pub const MAX_PULSE_PERIOD_S: f32 = 4.0;

/// Pitches without an edge at the lowest speed after which the estimate reads zero: two, so
/// that tooth offsets and jitter at the lowest speed never read a turning shaft as stopped.
pub const STALL_PITCHES: f32 = 2.0;

/// Pulses after an inferred missing one during which the sensor counts as dropping pulses
/// ([`PulseSpeedEstimator::dropping`]): 21 revolutions of a 12-tooth wheel. A worn target or a
/// marginal gap drops pulses all along; this spans five mean gaps between drops of a sensor
/// that drops one pulse in fifty (with 64, a sensor dropping one in twenty went 64 pulses
/// without a drop often enough that its next two in a row faulted a healthy rig).
pub const DROP_MEMORY_PULSES: u16 = 256;

/// The lowest speed an axis may be commanded to, rad/s: the configured minimum, raised to the
/// speed whose pulse period is [`MAX_PULSE_PERIOD_S`] (`2 pi / (N * 4 s)`: 1.57 rad/s at one
/// pulse per revolution, 0.13 rad/s at 12).
pub const fn lowest_speed_rad_s(axis: &AxisConfig) -> f32 {
    let by_pulses = core::f32::consts::TAU / (axis.pulses_per_rev as f32 * MAX_PULSE_PERIOD_S);
    if by_pulses > axis.min_speed_rad_s {
        by_pulses
    } else {
        axis.min_speed_rad_s
    }
}

/// A closed counting window: the raw speed over a known interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowSample {
    /// How long before the tick's `now` the window closed (its last edge), s.
    pub ago_s: f32,
    /// The window's span, first to last edge, s.
    pub span_s: f32,
    /// Mean speed over the window, rad/s (magnitude, unfiltered).
    pub raw_speed_rad_s: f32,
}

/// What happened to the counting window during the last tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowEvents {
    /// A new measurement began (first edge after rest) this long before `now`, s.
    pub restarted_s_ago: Option<f32>,
    /// A window closed.
    pub closed: Option<WindowSample>,
    /// The stall bound is below the filtered speed: the shaft is slowing between edges.
    pub bound_active: bool,
}

/// Speed estimator of one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PulseSpeedEstimator {
    mask: u32,
    rad_per_pulse: f32,
    ticks_per_s: f32,
    s_per_tick: f32,
    rad_ticks_per_pulse_s: f32,
    lockout_ticks: u32,
    window_ticks: u32,
    stall_ticks: u32,
    filter_weight: f32,

    prev_now: u32,
    clock: u32,
    has_edge: bool,
    last_edge: u32,
    last_interval: u32,
    /// The pulse interval before the last, ticks (0 until there are two since rest).
    prev_interval: u32,
    win_start: u32,
    win_pulses: u32,
    /// The window's angle in pitches, by the learned gap lengths.
    win_pitches: f32,
    teeth: ToothMap,
    /// The tooth map learns this tick whatever the caller's `steady` says (commissioning's
    /// hold at both high duties: [`Self::learn_teeth`]); cleared at the end of each tick.
    learn_teeth: bool,
    valid: bool,
    raw_period_ticks: f32,
    lockout_now: u32,
    missing_from: u32,
    /// An observer of the shaft judges missing pulses (see [`Self::expect_travel`]); without
    /// one the last raw period does, at a steady speed.
    observed: bool,
    /// The pitches the observer expects the shaft to have turned since the last edge at
    /// `clock`, and per timer tick after it (both 0: no inference).
    expect_pitches: f32,
    expect_pitches_per_tick: f32,
    /// Edges of this tick: a first edge after rest came, the pitches since the edge before the
    /// tick (or since the restart), and how many were accepted.
    tick_restarted: bool,
    tick_pitches: f32,
    tick_edges: u32,
    speed_filt: f32,
    speed: f32,
    bound_active: bool,
    /// Pitches the stall bound allows since the last edge: 2 or 1 as the caller says the speed
    /// is steady or not, but never rising between edges (a reference that comes to rest at 0
    /// turns "steady" while the shaft coasts, and the reading must not jump up then).
    bound_pitches: u32,
    restart_at: Option<u32>,
    closed_at: Option<u32>,
    closed_span: u32,
    closed_raw: f32,
    accepted: u32,
    rejected: u32,
    missing: u32,
    /// Pulses still to come before the sensor no longer counts as dropping (see
    /// [`DROP_MEMORY_PULSES`]).
    drop_memory: u16,
    late_edges: u32,
    /// The last gap measured alone (one pulse, an interval since the edge before).
    last_gap: Gap,
}

/// One gap of the sensor wheel as the last single-pulse edge measured it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Gap {
    /// Counts the edges accepted (wrapping), as [`PulseSpeedEstimator::accepted_edges`] did
    /// when this gap ended: two gaps follow each other when their counts do.
    pub serial: u32,
    /// The gap's index around the wheel (see [`ToothMap::index`]).
    pub index: u16,
    /// Its length, pitches, by the learned gap lengths.
    pub pitches: f32,
    /// Its duration, timer ticks (0: no gap yet).
    pub ticks: u32,
    /// The extended clock when it ended.
    pub end: u32,
}

impl PulseSpeedEstimator {
    /// One control tick: `now` is the capture timer's value read *after* the edges were
    /// collected, `edges` the timestamps captured since the previous tick, oldest first.
    /// `steady` allows the missing-pulse inference (the reference has not changed lately).
    /// `on_edge(extended_ticks, pulses)` is called for each accepted edge.
    ///
    /// Returns the speed magnitude, rad/s.
    #[inline(always)]
    pub fn tick(
        &mut self,
        now: u32,
        edges: &[u32],
        steady: bool,
        mut on_edge: impl FnMut(u32, u32),
    ) -> f32 {
        // The first tick after construction measures its span from timer value 0: the extended
        // clock is relative, so that only shifts its origin.
        let span = now.wrapping_sub(self.prev_now) & self.mask;
        self.restart_at = None;
        self.closed_at = None;
        self.tick_restarted = false;
        self.tick_pitches = 0.0;
        self.tick_edges = 0;
        for &t in edges {
            let mut offset = t.wrapping_sub(self.prev_now) & self.mask;
            if offset > span {
                // Captured after `now` was read (a race in the caller) or stale: place it at
                // `now`, count it, never lose it.
                offset = span;
                self.late_edges = self.late_edges.wrapping_add(1);
            }
            let at = self.clock.wrapping_add(offset);
            if let Some(pulses) = self.edge(at, steady) {
                on_edge(at, pulses);
            }
        }
        if edges.is_empty() {
            // A tick without an edge has time to learn the wheel's gaps.
            self.teeth.learn_pending();
        }
        // For this tick only: commissioning sets it before each tick of its hold, so nothing
        // that ends commissioning (a STOP, a fault) can leave the map learning.
        self.learn_teeth = false;
        self.clock = self.clock.wrapping_add(span);
        self.prev_now = now;
        // 2 since the last edge only while steady throughout (an edge sets 2).
        if !steady {
            self.bound_pitches = 1;
        }
        self.speed = self.bounded_speed(self.bound_pitches);
        self.speed
    }

    fn edge(&mut self, at: u32, steady: bool) -> Option<u32> {
        if !self.has_edge {
            self.has_edge = true;
            self.last_edge = at;
            self.win_start = at;
            self.win_pulses = 0;
            self.win_pitches = 0.0;
            self.restart_at = Some(at);
            self.tick_restarted = true;
            self.tick_pitches = 0.0;
            self.tick_edges = 1;
            self.expect_pitches = 0.0;
            self.expect_pitches_per_tick = 0.0;
            self.last_interval = 0;
            self.prev_interval = 0;
            self.accepted = self.accepted.wrapping_add(1);
            // The next tooth, but no interval to learn from.
            self.teeth.edge(0, 1, false);
            return Some(1);
        }
        let dt = at.wrapping_sub(self.last_edge);
        // `lockout_now` = max(absolute lockout, 40 % of the filtered period), kept up to date
        // when the period changes, so the common path is integer compares only. The relative
        // part only holds at steady speed: while the speed changes (a ramp, a commissioning
        // step) the period can more than halve between two edges, and a real edge must never
        // be dropped; the absolute lockout (half the period at the over-speed limit) still
        // rejects contact bounce.
        let lockout = if steady {
            self.lockout_now
        } else {
            self.lockout_ticks
        };
        if dt < lockout {
            self.rejected = self.rejected.wrapping_add(1);
            return None;
        }
        let mut pulses = 1u32;
        if self.observed {
            // The observer's angle at this edge: an interval counts as `k` pulses only when the
            // observer, driven by the duty that was applied, expected `k` pitches over it. A
            // shaft slowing to a lower reference gives intervals of 2 or 3 of its last periods,
            // but the observer, slowing with it, expected about one pitch. When the observer
            // says nothing (its expectation 0: not tracking, or its caller keeps it from judging:
            // the controller lets it while steady or while the sensor drops pulses, never while
            // slowing) the edge is one pulse.
            let since_tick = at.wrapping_sub(self.clock) as f32;
            let predicted = self.expect_pitches + self.expect_pitches_per_tick * since_tick;
            pulses = pulses_expected(predicted);
            if pulses > 1 {
                self.missing = self.missing.wrapping_add(pulses - 1);
            }
            // The next edge of this tick counts its expectation from this one.
            self.expect_pitches = -self.expect_pitches_per_tick * since_tick;
        } else if steady && dt > self.missing_from {
            // Without an observer (the estimator on its own): the last raw period.
            let k = whole_periods(dt as f32, self.raw_period_ticks);
            if k >= 2 {
                pulses = k;
                self.missing = self.missing.wrapping_add(k - 1);
            }
        }
        self.accepted = self.accepted.wrapping_add(1);
        self.last_edge = at;
        self.drop_memory = if pulses > 1 {
            DROP_MEMORY_PULSES
        } else {
            self.drop_memory.saturating_sub(1)
        };
        // A sensor that drops pulses may drop two in a row: the bound then allows three
        // pitches, so two missing pulses do not read the shaft a third slower.
        self.bound_pitches = if self.drop_memory > 0 { 3 } else { 2 };
        self.prev_interval = self.last_interval;
        self.last_interval = dt / pulses;
        self.win_pulses += pulses;
        let pitches = self.teeth.edge(dt, pulses, steady || self.learn_teeth);
        self.win_pitches += pitches;
        self.tick_pitches += pitches;
        self.tick_edges += 1;
        if pulses == 1 {
            self.last_gap = Gap {
                serial: self.accepted,
                index: self.teeth.index(),
                pitches,
                ticks: dt,
                end: at,
            };
        }
        let wspan = at.wrapping_sub(self.win_start);
        if wspan >= self.window_ticks {
            let period = wspan as f32 / self.win_pulses as f32;
            let raw = self.rad_ticks_per_pulse_s * self.win_pitches / wspan as f32;
            if self.valid {
                self.speed_filt += self.filter_weight * (raw - self.speed_filt);
            } else {
                self.speed_filt = raw;
                self.valid = true;
            }
            // Bounce and missing-pulse thresholds from the last raw period (the error of one
            // sample only moves them by its own few percent).
            self.raw_period_ticks = period;
            let rel = (0.4 * period) as u32;
            self.lockout_now = if rel > self.lockout_ticks {
                rel
            } else {
                self.lockout_ticks
            };
            self.missing_from = (1.6 * period) as u32;
            self.closed_at = Some(at);
            self.closed_span = wspan;
            self.closed_raw = raw;
            self.win_start = at;
            self.win_pulses = 0;
            self.win_pitches = 0.0;
        }
        Some(pulses)
    }

    /// The observer's expectation for this tick's edges: `pitches` turned since the last edge
    /// at the previous tick and `pitches_per_s` after it (both 0 while the observer is not
    /// trusted: no pulse is then inferred missing). Once called, the observer judges missing
    /// pulses at a steady speed (replacing the rule of the last raw period).
    pub fn expect_travel(&mut self, pitches: f32, pitches_per_s: f32) {
        self.observed = true;
        self.expect_pitches = pitches;
        self.expect_pitches_per_tick = pitches_per_s * self.s_per_tick;
    }

    /// The edges of the last tick, for an observer: None without an accepted edge; otherwise
    /// whether the first was a start after rest, the pitches (by the learned gap lengths) from
    /// the edge before the tick (or from that start) to the last, and how long before the
    /// tick's `now` the last came, s.
    pub fn tick_edges(&self) -> Option<(bool, f32, f32)> {
        if self.tick_edges == 0 {
            return None;
        }
        let ago = self.clock.wrapping_sub(self.last_edge) as f32 * self.s_per_tick;
        Some((self.tick_restarted, self.tick_pitches, ago))
    }

    /// `pitches`: how many pitches the shaft may have turned since the last edge (2 at steady
    /// speed, where one missing pulse must not halve the reading; 1 otherwise; see
    /// `bound_pitches`).
    /// Stopped (or slower than the minimum speed): forget the old reference edge so the next
    /// edge starts a fresh measurement instead of a bogus long period.
    fn forget_edges(&mut self) {
        self.has_edge = false;
        self.valid = false;
        self.speed_filt = 0.0;
        self.raw_period_ticks = 0.0;
        self.lockout_now = self.lockout_ticks;
        self.missing_from = u32::MAX;
    }

    /// The shaft is at rest, as the controller knows from its drive (off, and the plant model
    /// coasted to rest: `AxisState::settle_coasted`) before two pitches at the lowest speed
    /// have passed without an edge: the estimate reads zero from now on, as after that bound.
    pub fn settle_at_rest(&mut self) {
        self.forget_edges();
        self.speed = 0.0;
    }

    fn bounded_speed(&mut self, pitches: u32) -> f32 {
        self.bound_active = false;
        if !self.has_edge {
            return 0.0;
        }
        let since = self.clock.wrapping_sub(self.last_edge);
        if since > self.stall_ticks {
            self.forget_edges();
            return 0.0;
        }
        if !self.valid {
            return 0.0;
        }
        if since > self.last_interval.saturating_mul(pitches) && since > 0 {
            let bound = pitches as f32 * self.rad_ticks_per_pulse_s / since as f32;
            if bound < self.speed_filt {
                self.bound_active = true;
                return bound;
            }
        }
        self.speed_filt
    }
}

/// How many whole `period`s the interval `dt` is, when it lies within 0.3 of a whole number
/// below 3.4 (2 or 3 pulses with the middle ones missing); 1 otherwise (or for no period).
fn whole_periods(dt: f32, period: f32) -> u32 {
    let ratio = dt / period;
    // Also catches no period (0: infinite ratio) and NaN.
    if !(ratio.is_finite() && ratio > 0.0) {
        return 1;
    }
    if ratio >= 3.4 {
        return 1;
    }
    let k = (ratio + 0.5) as u32;
    let off = ratio - k as f32;
    if k >= 1 && off > -0.3 && off < 0.3 {
        k
    } else {
        1
    }
}

/// How many pulses an edge stands for, given the pitches the observer expected since the
/// previous edge: `k` (2 or 3, the middle ones missing) when the expectation lies within 0.3
/// of `k`; 1 otherwise (or for a non-finite expectation).
pub fn pulses_expected(predicted_pitches: f32) -> u32 {
    if !(predicted_pitches.is_finite() && predicted_pitches > 1.7 && predicted_pitches < 3.3) {
        return 1;
    }
    let k = (predicted_pitches + 0.5) as u32;
    let off = predicted_pitches - k as f32;
    if off > -0.3 && off < 0.3 { k } else { 1 }
}

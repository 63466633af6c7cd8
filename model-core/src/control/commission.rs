//! Commissioning: open-loop identification of each axis from duty steps and edge times.
//!
//! # Routine (spin first, then precession; one at a time, the other at zero duty)
//! 0. *Breakaway search*: from rest the duty rises at [`BREAKAWAY_RATE_PER_S`] (slower with
//!    fewer than 12 pulses per revolution, in proportion) until the sensor
//!    gives an edge; that duty breaks stiction (a fixed low duty never breaks away a stiff
//!    shaft). No edge by [`BREAKAWAY_MAX_DUTY`] refuses: the shaft is blocked or the sensor dead.
//! 1. *Low step*: duty `max(low_duty, breakaway + 0.1)`, held at least `step_time_s` and until
//!    the edges in the step's second half run from a tooth round to the same tooth again
//!    (whole revolutions of gaps, more than `min_fit_edges` edges and at least one
//!    revolution; a slow shaft's fit starts [`SETTLE_TAUS`] of its time constants after the
//!    step instead, the step held on for it): the angle between the first and the last over their time is the step's
//!    mean speed exactly, whatever the teeth's offsets and a once-per-revolution load
//!    ([`LineFit::solve_span`]; a least-squares slope over one or two revolutions is tilted
//!    by the tooth pattern). The spin's steps then hold on, the fit complete, until their second
//!    half spans a revolution and three edges: the load pattern's revolution (load_pattern.rs
//!    tells the load from the wheel by the two steps). The line through (edge time, edge angle) with that slope gives the steady speed `w_L` and the angle at the step.
//! 2. *High step*: duty `max(high_duty, low + 0.2)` (at most 0.95), same rule, gives `w_H` and
//!    the line's intercept.
//! 3. *Coast*: zero duty until the estimator reads zero, then the next axis.
//! 4. *Reaction* (after the precession's high step, which keeps running): the spin's duty
//!    ramps from zero to its own high duty over [`REACTION_RAMP_S`] (a step's reaction can stall
//!    a light rod under a heavy bowl; the lost angle does not depend on the profile). Its
//!    acceleration reacts on the rod and the precession loses an angle; once both have
//!    settled, a line fitted as in the steps gives the precession's angle, and its gap to the
//!    high step's line (at the middle of the spin's ramp) measures the reaction. Then the spin's duty ramps down the same way while the precession
//!    holds its duty (a coasting light rod would be driven over its speed limit by a heavy
//!    bowl's slowing down), and both coast.
//!
//! # What is estimated
//! - Steady state `d V = a |w| + c`: two points give the effective back-EMF constant
//!   `a = V (d_H - d_L) / (w_H - w_L)` (V per rad/s; it includes viscous friction, see
//!   [`MotorModel`]) and the friction duty `c / V = d_L - a w_L / V`.
//! - Time constant: for a first-order response to the step at `t_s`, the angle approaches the
//!   asymptote `theta(t) = theta(t_s) + w_H (t - t_s) - (w_H - w_L) tau`. The low step's line gives
//!   `theta(t_s)`, the high step's line the asymptote, so
//!   `tau = (theta_L(t_s) - theta_H(t_s)) / (w_H - w_L)`. Angles are edge counts times the pitch,
//!   counted continuously across both steps, so the unknown angle of the first edge cancels.
//!   This works with sparse pulses (one pitch may take longer than tau), where timing the 63 %
//!   point of a speed step could not.
//!
//! - Reaction: the precession obeys `tau1 dw1/dt + w1 = K1 (d1 - c1 - g dw2/dt)` with
//!   `K1 = V / volts_per_rad_s` and `g` the duty that cancels a unit spin acceleration. At
//!   constant `d1`, integrating over the transient (steady before and after) gives the lost
//!   angle `dtheta1 = -K1 g dw2`, so `g = -dtheta1 / (K1 dw2)` with `dw2` the spin's speed at its
//!   high duty (its own high step's fit). This measures the coupling and the two motors'
//!   torque ratio together, which the axes' geometry alone cannot (it assumes the same motor
//!   type on both axes). A reaction that cannot be fitted leaves `g = 0`, and the controller
//!   falls back to the geometry.
//!
//! The feedforward and the PI gains follow from the model (see `pi`).

use super::config::{CommissioningConfig, MotorModel};

mod fit;
mod line_fit;
pub use line_fit::LineFit;

/// Duty rise of the breakaway search, per second.
pub const BREAKAWAY_RATE_PER_S: f32 = 0.2;
/// The breakaway search starts at this duty.
pub const BREAKAWAY_START_DUTY: f32 = 0.05;
/// The breakaway search gives up at this duty.
pub const BREAKAWAY_MAX_DUTY: f32 = 0.9;
/// The spin's duty ramp while the reaction is measured, s.
pub const REACTION_RAMP_S: f32 = 2.0;
/// Longest hold at both high duties after the reaction's fit starts, waiting for the tooth
/// maps (a wheel too slow or too fine to learn does not hold commissioning up longer), s.
pub const WHEEL_HOLD_MAX_S: f32 = 10.0;
/// Largest duty of the high step.
const TOP_DUTY: f32 = 0.95;
/// A step's fit starts at least this many of the shaft's time constants after the step: its
/// speed is then within e^-5 (0.7 %) of the step's change from the steady one. From half the
/// step time alone, a heavy rod (tau 0.4-0.7 s) was fitted while still accelerating: its time
/// constant identified 0.63-0.80 of the truth and its friction duty 3-16 % off (docs/control.md).
pub const SETTLE_TAUS: f32 = 5.0;
/// The latest a step's fit starts after the step, s (a time constant beyond a second and a half
/// is no gearmotor's; the step is not held up longer for it).
pub const SETTLE_MAX_S: f32 = 8.0;

/// Where the routine stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Phase {
    /// Rising duty until the shaft breaks away.
    Breakaway,
    /// Low duty step on the axis.
    Low,
    /// High duty step on the axis.
    High,
    /// The precession's high step continues while the spin steps (its reaction is measured).
    Reaction,
    /// Coasting to rest.
    Coast,
    /// Both axes identified.
    Done,
}

/// Why identification failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum IdentifyError {
    /// Too few edges to fit a line in a step (sensor or shaft problem).
    TooFewEdges,
    /// The high step was not faster than the low step.
    NoSpeedIncrease,
    /// The identified model fails the plausibility check.
    Implausible,
    /// The routine exceeded its timeout.
    Timeout,
    /// No edge even at the breakaway search's highest duty.
    NoBreakaway,
}

impl IdentifyError {
    /// The reason in plain words, for a refusal message.
    pub fn reason(self) -> &'static str {
        match self {
            IdentifyError::TooFewEdges => {
                "too few sensor edges to fit a speed: check the sensor, or free the shaft"
            }
            IdentifyError::NoSpeedIncrease => {
                "the shaft did not turn faster at the higher duty: check the motor and its load"
            }
            IdentifyError::Implausible => {
                "the identified motor model is outside the plausible range"
            }
            IdentifyError::Timeout => "identification took longer than its timeout",
            IdentifyError::NoBreakaway => {
                "the shaft gave no sensor edge even at 90 % duty: it is blocked or the sensor is dead"
            }
        }
    }
}

/// One axis's identification result, with the raw fit for reports.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Identified {
    /// The model for feedforward and gains.
    pub model: MotorModel,
    /// Steady speed at the low duty, rad/s.
    pub low_speed_rad_s: f32,
    /// Steady speed at the high duty, rad/s.
    pub high_speed_rad_s: f32,
}

/// The identification routine's state (driven by the controller's tick).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Commissioning {
    cfg: CommissioningConfig,
    supply_v: f32,
    axis: usize,
    phase: Phase,
    t0_ticks: Option<u32>,
    ticks_per_s: f32,
    coast_s: f32,
    total_s: f32,
    step_at_s: f32,
    /// When this step's fit starts, s on the axis's clock: half the step time after the step,
    /// later for a slow shaft ([`SETTLE_TAUS`]).
    fit_from_s: f32,
    angle_pulses: u32,
    low_fit: LineFit,
    high_fit: LineFit,
    pulses_per_rev: [u32; 2],
    duty: f32,
    breakaway_duty: f32,
    low_duty: f32,
    high_duty: f32,
    /// The spin's high duty, applied again during the reaction phase.
    spin_high_duty: f32,
    /// The precession's angle after the spin step has settled.
    reaction_fit: LineFit,
    /// From the spin step, s on the precession's clock: when the fit starts.
    reaction_fit_from_s: f32,
    /// When the spin's ramp down started (the reaction measured, `fit_done`, and the wheels
    /// learned or the hold's limit reached), s on the precession's clock.
    reaction_done_s: Option<f32>,
    results: [Option<Identified>; 2],
    /// See [`Commissioning::steady_step`].
    steady_step: u8,
    /// Pulses in this step's second half, and whether its fit is complete (the step then
    /// holds on, its fit unchanged, until the load pattern has its revolution; the spin only).
    steady_pulses: u32,
    fit_done: bool,
    /// See [`Commissioning::wheels_steady`].
    wheels_steady: bool,
}

impl Commissioning {
    /// A routine starting with the spin axis (its reaction torque may drag the coasting
    /// precession axis; the precession axis is identified afterwards, with the spin at rest).
    /// `pulses_per_rev`: of each axis, `[precession, spin]`.
    pub fn new(
        cfg: CommissioningConfig,
        supply_v: f32,
        ticks_per_s: f32,
        pulses_per_rev: [u16; 2],
    ) -> Self {
        Self {
            cfg,
            supply_v,
            axis: 1,
            phase: Phase::Breakaway,
            t0_ticks: None,
            ticks_per_s,
            coast_s: 0.0,
            total_s: 0.0,
            step_at_s: 0.0,
            fit_from_s: 0.0,
            angle_pulses: 0,
            low_fit: LineFit::default(),
            high_fit: LineFit::default(),
            pulses_per_rev: [pulses_per_rev[0] as u32, pulses_per_rev[1] as u32],
            duty: BREAKAWAY_START_DUTY,
            breakaway_duty: 0.0,
            low_duty: cfg.low_duty,
            high_duty: cfg.high_duty,
            spin_high_duty: 0.0,
            reaction_fit: LineFit::default(),
            reaction_fit_from_s: 0.0,
            reaction_done_s: None,
            results: [None, None],
            steady_step: 0,
            steady_pulses: 0,
            fit_done: false,
            wheels_steady: false,
        }
    }

    /// The step (1 low, 2 high) whose duty has been held for half the step time, else 0.
    pub fn steady_step(&self) -> u8 {
        self.steady_step
    }

    /// Both shafts run steady at their high duties (the reaction's settled part and the hold
    /// after it): the tooth maps learn the wheels (teeth.rs) here, so that the first start
    /// after commissioning already reads each gap at its length; before this the map needs
    /// about three revolutions of a start's steady speed (6.3 s each at 1 rad/s).
    pub fn wheels_steady(&self) -> bool {
        self.wheels_steady
    }

    /// The axis being identified and the phase.
    pub fn progress(&self) -> (usize, Phase) {
        (self.axis, self.phase)
    }

    /// Results so far.
    pub fn results(&self) -> [Option<Identified>; 2] {
        self.results
    }

    /// An accepted edge on the axis under test at `at_ticks` on the estimator's extended clock,
    /// carrying `pulses` pulses (more than one if the estimator inferred missing ones).
    pub fn on_edge(&mut self, at_ticks: u32, pulses: u32, rad_per_pulse: f32) {
        if self.phase == Phase::Coast || self.phase == Phase::Done {
            return;
        }
        let Some(t0) = self.t0_ticks else { return };
        if self.phase == Phase::Breakaway {
            // Moving: the low step starts now, from this edge's angle.
            self.breakaway_duty = self.duty;
            self.low_duty = self.cfg.low_duty.max(self.duty + 0.1).min(TOP_DUTY - 0.2);
            self.high_duty = self.cfg.high_duty.max(self.low_duty + 0.2).min(TOP_DUTY);
            self.phase = Phase::Low;
            self.fit_from_s = 0.5 * self.cfg.step_time_s;
            self.t0_ticks = Some(at_ticks);
            self.angle_pulses = 0;
            return;
        }
        let t_s = at_ticks.wrapping_sub(t0) as f32 / self.ticks_per_s;
        self.angle_pulses += pulses;
        let angle = self.angle_pulses as f32 * rad_per_pulse;
        if self.phase == Phase::Reaction {
            // Until the reaction is measured (`fit_done`); the hold for the wheels after it
            // adds nothing to its line.
            if t_s >= self.reaction_fit_from_s && !self.fit_done {
                self.reaction_fit.add(t_s, angle);
            }
            return;
        }
        // From the step's second half only (later for a slow shaft): by then the speed is steady.
        if t_s >= self.fit_from_s {
            self.steady_pulses += pulses;
            if self.fit_done {
                return;
            }
            match self.phase {
                Phase::Low => self.low_fit.add(t_s, angle),
                _ => self.high_fit.add(t_s, angle),
            }
        }
    }

    /// Advances by `dt_s`; `clock_ticks` is the estimator's extended clock now, `stopped` is
    /// true when both axes' estimators read zero, `wheels_learned` when both tooth maps have
    /// learned their wheels ([`Self::wheels_steady`]). Returns the duties to apply, or the error that ends the
    /// routine.
    pub fn step(
        &mut self,
        dt_s: f32,
        clock_ticks: u32,
        stopped: bool,
        wheels_learned: bool,
    ) -> Result<[f32; 2], IdentifyError> {
        self.total_s += dt_s;
        if self.total_s > self.cfg.timeout_s {
            return Err(IdentifyError::Timeout);
        }
        let t0 = *self.t0_ticks.get_or_insert(clock_ticks);
        let t_s = clock_ticks.wrapping_sub(t0) as f32 / self.ticks_per_s;
        let n = self.pulses_per_rev[self.axis].max(1);
        // At least a revolution of gaps, and the configured least number of edges.
        let min_edges = (self.cfg.min_fit_edges as u32).max(n);
        // A fit ends on the tooth it began with (whole revolutions of gaps between its first
        // edge and its last: `LineFit::solve_span`).
        let same_tooth = |count: u32| count > min_edges && (count - 1).is_multiple_of(n);
        // Once a step's fit spans whole revolutions it is complete (and unchanged from here);
        // the step holds on until its second half also has a whole revolution of gaps and
        // their neighbours for the load pattern (load_pattern.rs tells the load from the wheel
        // by the two steps). The spin's steps only: the rod's high step's line is the
        // reaction's reference (held longer, the measured reaction moved: docs/control.md),
        // and without it its low step's revolution would serve nothing.
        let load_ready = self.axis == 0 || self.steady_pulses >= n + 3;
        let mut duty = 0.0;
        match self.phase {
            Phase::Breakaway => {
                self.duty = BREAKAWAY_START_DUTY + search_rate_per_s(n) * t_s;
                if self.duty > BREAKAWAY_MAX_DUTY {
                    return Err(IdentifyError::NoBreakaway);
                }
                duty = self.duty;
            }
            Phase::Low => {
                duty = self.low_duty;
                if !self.fit_done && t_s >= self.cfg.step_time_s && same_tooth(self.low_fit.count())
                {
                    // From the crawl the search left it at (about rest), the line's intercept
                    // lags the step by `w_L tau`: a lower bound of the time constant.
                    let tau = self.low_fit.solve_span().map_or(0.0, |(b, w)| -b / w);
                    self.fit_done = self.settled(0.0, tau);
                }
                if self.fit_done && load_ready {
                    self.fit_done = false;
                    self.steady_pulses = 0;
                    self.step_at_s = t_s;
                    self.fit_from_s = t_s + 0.5 * self.cfg.step_time_s;
                    self.phase = Phase::High;
                    duty = self.high_duty;
                }
            }
            Phase::High => {
                duty = self.high_duty;
                let count = self.high_fit.count();
                if !self.fit_done
                    && t_s - self.step_at_s >= self.cfg.step_time_s
                    && same_tooth(count)
                {
                    let tau = self.step_lines().map_or(0.0, |l| l.2);
                    self.fit_done = self.settled(self.step_at_s, tau);
                }
                if self.fit_done && load_ready {
                    self.fit_done = false;
                    self.steady_pulses = 0;
                    self.results[self.axis] = Some(self.identify()?);
                    if self.axis == 1 {
                        self.spin_high_duty = self.high_duty;
                        self.phase = Phase::Coast;
                        self.coast_s = 0.0;
                        duty = 0.0;
                    } else {
                        self.start_reaction(t_s);
                    }
                }
            }
            Phase::Reaction => {
                duty = self.high_duty;
                if let Some(done_s) = self.reaction_done_s {
                    if t_s - done_s >= REACTION_RAMP_S {
                        self.phase = Phase::Coast;
                        self.coast_s = 0.0;
                        duty = 0.0;
                    }
                } else {
                    if !self.fit_done
                        && t_s >= self.reaction_fit_from_s + 0.5 * self.cfg.step_time_s
                        && same_tooth(self.reaction_fit.count())
                    {
                        self.measure_reaction();
                        self.fit_done = true;
                    }
                    // Both shafts steady at their high duties: held on until both wheels are
                    // learned (or the hold's limit), so the first start reads its teeth.
                    if self.fit_done
                        && (wheels_learned || t_s >= self.reaction_fit_from_s + WHEEL_HOLD_MAX_S)
                    {
                        self.reaction_done_s = Some(t_s);
                    }
                }
            }
            Phase::Coast => {
                self.coast_s += dt_s;
                if stopped && self.coast_s > 0.05 {
                    if self.axis == 1 {
                        self.axis = 0;
                        self.phase = Phase::Breakaway;
                        self.duty = BREAKAWAY_START_DUTY;
                        self.t0_ticks = None;
                        self.total_s = 0.0;
                        self.angle_pulses = 0;
                        self.low_fit = LineFit::default();
                        self.high_fit = LineFit::default();
                    } else {
                        self.phase = Phase::Done;
                    }
                }
            }
            Phase::Done => {}
        }
        self.wheels_steady = self.phase == Phase::Reaction
            && self.reaction_done_s.is_none()
            && t_s >= self.reaction_fit_from_s;
        self.steady_step = match self.phase {
            Phase::Low if self.axis == 1 && t_s >= self.fit_from_s => 1,
            Phase::High if self.axis == 1 && t_s >= self.fit_from_s => 2,
            _ => 0,
        };
        let mut duties = [0.0; 2];
        duties[self.axis] = duty;
        if self.phase == Phase::Reaction {
            let ramp = match self.reaction_done_s {
                None => (t_s - self.step_at_s) / REACTION_RAMP_S,
                Some(done_s) => 1.0 - (t_s - done_s) / REACTION_RAMP_S,
            };
            duties[1] = self.spin_high_duty * ramp.clamp(0.0, 1.0);
        }
        Ok(duties)
    }
}

/// The breakaway search's duty rise with `n` pulses per revolution: with sparse pulses the
/// first edge comes up to a pitch after the shaft starts, so the duty rises slower and
/// overshoots the breakaway duty as little.
fn search_rate_per_s(n: u32) -> f32 {
    let sparse = if n < 12 { n as f32 / 12.0 } else { 1.0 };
    BREAKAWAY_RATE_PER_S * sparse
}

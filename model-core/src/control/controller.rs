//! The top-level controller: both axes, the supervisor, the planner and commissioning.

use super::commission::{Commissioning, Identified, IdentifyError, Phase};
use super::config::{ConfigError, ControllerConfig, in_range};
use super::estimator::{PulseSpeedEstimator, lowest_speed_rad_s};
use super::pi::{LoopConstants, LoopInput, SpeedLoop};
use super::planner::{
    BowlSpeedForResidence, InverseFailure, ResidenceForBowlSpeed, SetpointPlanner, split_combined,
};
use super::supervisor::{Fault, SensorWatch, State, fault_code};
use crate::bowl::{MotorSpeeds, combined_speed_from_trig};

/// Why a command was refused. A refused command changes nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Rejection {
    /// A value was NaN or infinite.
    NotFinite,
    /// A speed's magnitude is above this axis's `max_speed_rad_s` (0 = precession, 1 = spin).
    AboveMaxSpeed(u8),
    /// A nonzero speed's magnitude is below this axis's `min_speed_rad_s`, the lowest speed the
    /// pulse sensor can hold (zero itself is accepted).
    BelowMinSpeed(u8),
    /// The target residence time is not a positive, finite number of seconds.
    InvalidResidenceTime,
    /// The particle model's inverse gave no bowl speed for the target residence time.
    Inverse(InverseFailure),
    /// Eq. 2 could not split the bowl speed at the configured ratio.
    SplitFailed,
    /// The command is not allowed in this state.
    WrongState(State),
    /// A fault is latched: clear it first.
    Faulted(Fault),
    /// `clear_fault` was sent with no fault latched.
    NotFaulted,
    /// The parameters failed validation (the configuration error says which).
    InvalidConfig(ConfigError),
    /// Loop tuning values out of range (bandwidth in (0.01, 1000] rad/s, per-pulse bandwidth
    /// in (0.01, 10]).
    InvalidTuning,
}

/// Per-axis part of the status snapshot.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AxisStatus {
    /// Commanded target, rad/s (signed).
    pub target_rad_s: f32,
    /// Ramped reference the loop follows now, rad/s.
    pub reference_rad_s: f32,
    /// Measured speed with the commanded sign, rad/s.
    pub measured_rad_s: f32,
    /// Duty applied, -1..=1 (0 = bridge coasting).
    pub duty: f32,
    /// Edges accepted since start (wrapping).
    pub pulses: u32,
    /// Edges rejected as bounces.
    pub rejected_edges: u32,
    /// Pulses inferred as missing.
    pub inferred_missing: u32,
    /// The estimator has a valid measurement.
    pub measurement_valid: bool,
}

/// A snapshot of the controller for telemetry.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Status {
    /// Operating state.
    pub state: State,
    /// Latched fault, if any.
    pub fault: Option<Fault>,
    /// Fault code (0 = none), see [`Fault::code`].
    pub fault_code: u8,
    /// Per axis, indexed by `PRECESSION` and `SPIN`.
    pub axes: [AxisStatus; 2],
    /// Combined bowl speed of the targets (Eq. 2), rad/s.
    pub combined_target_rad_s: f32,
    /// Combined bowl speed of the measured speeds (Eq. 2), rad/s.
    pub combined_measured_rad_s: f32,
}

/// The rig's controller. See the module docs of [`crate::control`] for the contract.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Controller {
    cfg: ControllerConfig,
    dt_s: f32,
    est: [PulseSpeedEstimator; 2],
    k: [LoopConstants; 2],
    loops: [SpeedLoop; 2],
    watch: [SensorWatch; 2],
    planner: SetpointPlanner,
    max_step: [f32; 2],
    state: State,
    fault: Option<Fault>,
    config_error: Option<ConfigError>,
    host_silence_s: f32,
    duties: [f32; 2],
    measured: [f32; 2],
    direction: [f32; 2],
    commissioning: Option<Commissioning>,
    identified: [Option<Identified>; 2],
    identify_error: Option<IdentifyError>,
    feedback: bool,
    cos_axes: f32,
    sin_axes: f32,
    host_watch: bool,
    reached: bool,
}

/// An edge interval faster than this many times the plant model's speed (plus the margin) is a
/// runaway: tooth offsets (up to 10 % on one interval), a 10 % overshoot and the breakaway of a
/// stiff shaft at the lowest speed stay inside.
const RUNAWAY_RATIO: f32 = 1.2;
/// See [`RUNAWAY_RATIO`], rad/s.
const RUNAWAY_MARGIN_RAD_S: f32 = 0.3;

impl Controller {
    /// A controller in [`State::Idle`] for a configuration that passes validation.
    ///
    /// A `const fn`: firmware can build its controller in a `static` from a configuration
    /// the compiler has checked.
    pub const fn new(cfg: ControllerConfig) -> Result<Self, ConfigError> {
        match cfg.validate() {
            Ok(()) => Ok(Self::build(cfg)),
            Err(e) => Err(e),
        }
    }

    /// Like [`Controller::new`], but an invalid configuration gives a controller running the
    /// nominal configuration with [`Fault::InvalidConfiguration`] latched; the fault cannot be
    /// cleared until [`Controller::set_parameters`] succeeds. For firmware that must boot.
    pub fn new_or_faulted(cfg: ControllerConfig) -> Self {
        match cfg.validate() {
            Ok(()) => Self::build(cfg),
            Err(e) => {
                let mut c = Self::build(ControllerConfig::nominal());
                c.config_error = Some(e);
                c.latch(Fault::InvalidConfiguration);
                c
            }
        }
    }

    const fn build(cfg: ControllerConfig) -> Self {
        let dt_s = 1.0 / cfg.tick_hz as f32;
        let a0 = cfg.axes[0];
        let a1 = cfg.axes[1];
        Self {
            cfg,
            dt_s,
            est: [
                PulseSpeedEstimator::new(&cfg, &a0),
                PulseSpeedEstimator::new(&cfg, &a1),
            ],
            k: [
                LoopConstants::new(&a0, dt_s, cfg.supply_v),
                LoopConstants::new(&a1, dt_s, cfg.supply_v),
            ],
            loops: [SpeedLoop::REST; 2],
            watch: [SensorWatch::CLEAR; 2],
            planner: SetpointPlanner::REST,
            max_step: [a0.accel_limit_rad_s2 * dt_s, a1.accel_limit_rad_s2 * dt_s],
            state: State::Idle,
            fault: None,
            config_error: None,
            host_silence_s: 0.0,
            duties: [0.0; 2],
            measured: [0.0; 2],
            direction: [1.0; 2],
            commissioning: None,
            identified: [None; 2],
            identify_error: None,
            feedback: true,
            cos_axes: cos_const(cfg.axes_angle_rad),
            sin_axes: sin_const(cfg.axes_angle_rad),
            host_watch: cfg.host_timeout_s > 0.0,
            reached: false,
        }
    }

    /// One control tick, called at exactly `tick_hz`.
    ///
    /// `now_ticks` is the capture timer read *after* collecting `edges`; `edges[axis]` holds
    /// the timestamps captured on that axis since the previous tick, oldest first. Returns the
    /// duties `[precession, spin]` in -1..=1 (sign = direction; 0 = coast).
    pub fn tick(&mut self, now_ticks: u32, edges: [&[u32]; 2]) -> [f32; 2] {
        if self.state == State::Commissioning {
            return self.tick_commissioning(now_ticks, edges);
        }
        let dt = self.dt_s;
        let steady = self.planner.steady_s();
        let mut seen = [false; 2];
        for i in 0..2 {
            let before = self.est[i].accepted_edges();
            let speed = self.est[i].tick(now_ticks, edges[i], steady[i] > 0.5, |_, _| {});
            seen[i] = self.est[i].accepted_edges() != before;
            self.measured[i] = self.direction[i] * speed;
            // Runaway (a bridge stuck on): once both axes have reached their references, an
            // edge that came far sooner than the plant model expects faults at once, without
            // waiting for the filtered speed to reach the absolute limit.
            let runaway = self.reached
                && seen[i]
                && self.est[i].edge_speed_rad_s()
                    > RUNAWAY_RATIO * self.loops[i].model_rad_s().abs() + RUNAWAY_MARGIN_RAD_S;
            if speed > self.cfg.axes[i].overspeed_rad_s || runaway {
                self.latch(Fault::Overspeed(i as u8));
            }
        }
        match self.state {
            State::SpinningUp | State::Running | State::Stopping => {
                self.closed_loop_step(dt, &seen)
            }
            _ => self.duties = [0.0; 2],
        }
        self.after_tick(dt)
    }

    /// The tick while commissioning: the estimators also feed the identification routine.
    #[inline(never)]
    fn tick_commissioning(&mut self, now_ticks: u32, edges: [&[u32]; 2]) -> [f32; 2] {
        let dt = self.dt_s;
        let mut seen = [false; 2];
        let comm_axis = match &self.commissioning {
            Some(c) => c.progress().0,
            None => 2,
        };
        for i in 0..2 {
            let rad_per_pulse = self.est[i].rad_per_pulse();
            let mut comm = if i == comm_axis {
                self.commissioning.as_mut()
            } else {
                None
            };
            let seen_i = &mut seen[i];
            let speed = self.est[i].tick(now_ticks, edges[i], false, |at, pulses| {
                *seen_i = true;
                if let Some(c) = comm.as_deref_mut() {
                    c.on_edge(at, pulses, rad_per_pulse);
                }
            });
            self.measured[i] = self.direction[i] * speed;
            if speed > self.cfg.axes[i].overspeed_rad_s {
                self.latch(Fault::Overspeed(i as u8));
            }
        }
        if self.state == State::Commissioning {
            self.commission_step(dt, &seen);
        }
        self.after_tick(dt)
    }

    /// Host-silence watch and the final say of a latched fault, common to both ticks.
    #[inline(always)]
    fn after_tick(&mut self, dt: f32) -> [f32; 2] {
        if self.host_watch && !matches!(self.state, State::Idle | State::Fault) {
            self.host_silence_s += dt;
            if self.host_silence_s > self.cfg.host_timeout_s {
                self.latch(Fault::HostSilent);
            }
        }
        if self.fault.is_some() {
            self.duties = [0.0; 2];
        }
        self.duties
    }

    #[inline(never)]
    fn closed_loop_step(&mut self, dt: f32, seen: &[bool; 2]) {
        let stopped = [self.est[0].is_stopped(), self.est[1].is_stopped()];
        let r0 = self.planner.ramped()[0];
        // Precession established: measured at half its reference or more, or (sparse pulses:
        // N = 1 needs two pulse periods for a first measurement) its ramp done for a second.
        let established = !self.planner.spin_released()
            && r0 != 0.0
            && ((self.est[0].is_valid() && self.measured[0].abs() >= 0.5 * r0.abs())
                || self.planner.steady_s()[0] > 1.0);
        let ramped = self.planner.step(dt, self.max_step, stopped, established);
        // Spin first: its model's acceleration feeds the precession axis's decoupling.
        if self.axis_loop(1, ramped[1], 0.0, seen[1], dt) {
            return;
        }
        // The spin's accelerating torque reacts on the rod: J2 a2 projected on the vertical.
        // With J2 a2 = tau2 k2 a2 dr_p/dt / R2 and the same motor type on both axes, the
        // precession duty that cancels it is cos(angle) * (r - r_p) * duty_per_rad_s of the spin
        // model.
        let decouple =
            self.cos_axes * (ramped[1] - self.loops[1].model_rad_s()) * self.k[1].duty_per_rad_s();
        if self.axis_loop(0, ramped[0], decouple, seen[0], dt) {
            return;
        }
        let target = self.planner.targets();
        match self.state {
            State::Stopping => {
                if ramped == [0.0; 2] && stopped == [true; 2] {
                    self.state = State::Idle;
                }
            }
            _ => {
                let reached = (0..2).all(|i| {
                    ramped[i] == target[i]
                        && (self.measured[i] - ramped[i]).abs() <= 0.05 * ramped[i].abs() + 0.05
                });
                self.state = if reached {
                    self.reached = true;
                    State::Running
                } else {
                    State::SpinningUp
                };
            }
        }
    }

    /// One axis's loop and sensor watch; true if it latched a fault.
    #[inline(always)]
    fn axis_loop(&mut self, i: usize, r: f32, extra_duty: f32, seen: bool, dt: f32) -> bool {
        if r > 0.0 {
            self.direction[i] = 1.0;
        } else if r < 0.0 {
            self.direction[i] = -1.0;
        }
        let input = LoopInput {
            reference_rad_s: r,
            measured_rad_s: self.measured[i],
            direction: self.direction[i],
            measurement_valid: self.est[i].is_valid(),
            events: self.est[i].window_events(),
            feedback: self.feedback,
            extra_duty,
            at_rest: self.est[i].at_rest(),
        };
        let duty = self.loops[i].step(&self.k[i], input);
        self.duties[i] = duty;
        // Expected edges are watched whatever the duty: at low speed the duty that holds the
        // shaft can be below any fixed threshold.
        if self.watch[i].step(
            dt,
            duty.abs(),
            0.0,
            seen,
            self.cfg.sensor_timeout_floor_s,
            self.loops[i].model_rad_s(),
            self.est[i].rad_per_pulse(),
        ) {
            self.latch(Fault::SensorLostOrStall(i as u8));
            return true;
        }
        false
    }

    #[inline(never)]
    fn commission_step(&mut self, dt: f32, seen: &[bool; 2]) {
        let Some(c) = self.commissioning.as_mut() else {
            self.state = State::Idle;
            return;
        };
        let axis = c.progress().0;
        let clock = self.est[axis].clock_ticks();
        match c.step(
            dt,
            clock,
            self.est[0].is_stopped() && self.est[1].is_stopped(),
        ) {
            Err(e) => {
                self.identify_error = Some(e);
                self.commissioning = None;
                // No edge at any duty: a dead sensor or a blocked shaft, the same fault as
                // in closed loop; anything else leaves the configuration unidentified.
                self.latch(if e == IdentifyError::NoBreakaway {
                    Fault::SensorLostOrStall(axis as u8)
                } else {
                    Fault::InvalidConfiguration
                });
            }
            Ok(duties) => {
                self.duties = duties;
                if c.progress().1 == Phase::Done {
                    let results = c.results();
                    self.commissioning = None;
                    self.identified = results;
                    let mut cfg = self.cfg;
                    for (i, r) in results.iter().enumerate() {
                        if let Some(r) = r {
                            cfg.axes[i].model = r.model;
                        }
                    }
                    match cfg.validate() {
                        Ok(()) => {
                            self.rebuild_keep_state(cfg);
                            self.state = State::Idle;
                        }
                        Err(e) => {
                            self.config_error = Some(e);
                            self.latch(Fault::InvalidConfiguration);
                        }
                    }
                    return;
                }
                // Blocked shaft or dead sensor during identification: the expected period is
                // unknown, so allow 3 periods at the lowest speed.
                for (i, &seen_i) in seen.iter().enumerate() {
                    if self.watch[i].step(
                        dt,
                        self.duties[i].abs(),
                        self.cfg.stall_duty,
                        seen_i,
                        self.cfg.sensor_timeout_floor_s,
                        self.cfg.axes[i].min_speed_rad_s,
                        self.est[i].rad_per_pulse(),
                    ) {
                        self.identify_error = Some(IdentifyError::TooFewEdges);
                        self.latch(Fault::SensorLostOrStall(i as u8));
                        return;
                    }
                }
            }
        }
    }

    /// Replaces the configuration, keeping the estimators' clocks.
    #[inline(never)]
    fn rebuild_keep_state(&mut self, cfg: ControllerConfig) {
        let est = self.est;
        let identified = self.identified;
        let feedback = self.feedback;
        *self = Self::build(cfg);
        self.est = est;
        self.identified = identified;
        self.feedback = feedback;
    }

    #[cold]
    #[inline(never)]
    fn latch(&mut self, fault: Fault) {
        if self.fault.is_none() {
            self.fault = Some(fault);
        }
        self.state = State::Fault;
        self.duties = [0.0; 2];
        self.loops = [SpeedLoop::REST; 2];
        self.watch = [SensorWatch::CLEAR; 2];
        self.planner.reset();
        self.commissioning = None;
    }

    const fn check_speed(&self, axis: usize, w: f32) -> Result<(), Rejection> {
        if !w.is_finite() {
            return Err(Rejection::NotFinite);
        }
        let a = &self.cfg.axes[axis];
        let m = w.abs();
        if m > a.max_speed_rad_s {
            return Err(Rejection::AboveMaxSpeed(axis as u8));
        }
        if m != 0.0 && m < lowest_speed_rad_s(a) {
            return Err(Rejection::BelowMinSpeed(axis as u8));
        }
        Ok(())
    }

    const fn latched(&self) -> Fault {
        match self.fault {
            Some(f) => f,
            None => Fault::InvalidConfiguration,
        }
    }

    const fn check_state_for_setpoint(&self) -> Result<(), Rejection> {
        match self.state {
            State::Fault => Err(Rejection::Faulted(self.latched())),
            State::Commissioning | State::Stopping => Err(Rejection::WrongState(self.state)),
            _ => Ok(()),
        }
    }

    /// Sets both motor speeds, rad/s (signed; sign = direction). Zero, or a magnitude within
    /// `[min_speed_rad_s, max_speed_rad_s]` of the axis. Allowed in Idle (taken at `start`),
    /// SpinningUp and Running; the planner ramps to it.
    pub const fn set_motor_speeds(
        &mut self,
        precession_rad_s: f32,
        spin_rad_s: f32,
    ) -> Result<(), Rejection> {
        self.host_silence_s = 0.0;
        if let Err(e) = self.check_state_for_setpoint() {
            return Err(e);
        }
        if let Err(e) = self.check_speed(0, precession_rad_s) {
            return Err(e);
        }
        if let Err(e) = self.check_speed(1, spin_rad_s) {
            return Err(e);
        }
        self.planner.set_targets([precession_rad_s, spin_rad_s]);
        // A new setpoint: the runaway check waits until it is reached (a heavy shaft may
        // coast down slower than the ramp).
        self.reached = false;
        Ok(())
    }

    /// Sets the motor speeds from a target residence time, s: the particle model's inverse
    /// gives the combined bowl speed, Eq. 2 splits it at `spin_per_precession`, and the result
    /// must pass the same checks as [`Controller::set_motor_speeds`]. Returns the speeds set.
    pub fn set_target_residence_time(
        &mut self,
        target_s: f32,
        model: &dyn BowlSpeedForResidence,
    ) -> Result<[f32; 2], Rejection> {
        self.host_silence_s = 0.0;
        self.check_state_for_setpoint()?;
        if !in_range(target_s, 1e-6, 1e6) {
            return Err(Rejection::InvalidResidenceTime);
        }
        let omega = model.omega_rad_s(target_s).map_err(Rejection::Inverse)?;
        let speeds = split_combined(
            omega,
            self.cos_axes,
            self.sin_axes,
            self.cfg.spin_per_precession,
        )
        .ok_or(Rejection::SplitFailed)?;
        self.check_speed(0, speeds[0])?;
        self.check_speed(1, speeds[1])?;
        self.planner.set_targets(speeds);
        self.reached = false;
        Ok(speeds)
    }

    /// Starts the closed loop (Idle -> SpinningUp) toward the current targets.
    pub const fn start(&mut self) -> Result<(), Rejection> {
        self.host_silence_s = 0.0;
        match self.state {
            State::Idle => {
                self.loops = [SpeedLoop::REST; 2];
                self.watch = [SensorWatch::CLEAR; 2];
                self.reached = false;
                self.state = State::SpinningUp;
                Ok(())
            }
            State::Fault => Err(Rejection::Faulted(self.latched())),
            s => Err(Rejection::WrongState(s)),
        }
    }

    /// Stops: ramps both axes to zero (Stopping, then Idle once both read zero). Aborts
    /// commissioning at once (zero duty). In Idle or Fault it does nothing and succeeds.
    pub fn stop(&mut self) -> Result<(), Rejection> {
        self.host_silence_s = 0.0;
        match self.state {
            State::SpinningUp | State::Running => {
                self.planner.set_targets([0.0; 2]);
                self.reached = false;
                self.state = State::Stopping;
            }
            State::Commissioning => {
                self.commissioning = None;
                self.duties = [0.0; 2];
                self.state = State::Idle;
            }
            State::Idle | State::Stopping | State::Fault => {}
        }
        Ok(())
    }

    /// Clears a latched fault (Fault -> Idle, targets zero). Refused while the configuration
    /// is invalid.
    pub fn clear_fault(&mut self) -> Result<(), Rejection> {
        self.host_silence_s = 0.0;
        if self.state != State::Fault {
            return Err(Rejection::NotFaulted);
        }
        if let Some(e) = self.config_error {
            return Err(Rejection::InvalidConfig(e));
        }
        self.fault = None;
        self.state = State::Idle;
        self.planner.reset();
        Ok(())
    }

    /// Replaces all parameters (Idle or Fault only). A valid configuration also lifts the
    /// block on clearing an invalid-configuration fault (the fault stays latched until cleared).
    pub fn set_parameters(&mut self, cfg: ControllerConfig) -> Result<(), Rejection> {
        self.host_silence_s = 0.0;
        if !matches!(self.state, State::Idle | State::Fault) {
            return Err(Rejection::WrongState(self.state));
        }
        cfg.validate().map_err(Rejection::InvalidConfig)?;
        let (state, fault) = (self.state, self.fault);
        self.rebuild_keep_state(cfg);
        self.state = state;
        self.fault = fault;
        Ok(())
    }

    /// Changes one axis's loop bandwidth and per-pulse bandwidth while running (bumpless: the
    /// integral absorbs the proportional change). Refused during commissioning.
    pub fn set_loop_tuning(
        &mut self,
        axis: usize,
        bandwidth_rad_s: f32,
        per_pulse_bandwidth: f32,
    ) -> Result<(), Rejection> {
        self.host_silence_s = 0.0;
        if self.state == State::Commissioning {
            return Err(Rejection::WrongState(self.state));
        }
        if axis > 1
            || !in_range(bandwidth_rad_s, 0.01, 1000.0)
            || !in_range(per_pulse_bandwidth, 0.01, 10.0)
        {
            return Err(Rejection::InvalidTuning);
        }
        let mut a = self.cfg.axes[axis];
        a.bandwidth_rad_s = bandwidth_rad_s;
        a.per_pulse_bandwidth = per_pulse_bandwidth;
        self.cfg.axes[axis] = a;
        self.k[axis] = LoopConstants::new(&a, self.dt_s, self.cfg.supply_v);
        Ok(())
    }

    /// Starts the identification routine (Idle only); at the end the identified models
    /// replace the configured ones and the state returns to Idle, or an implausible result
    /// latches [`Fault::InvalidConfiguration`].
    pub fn start_commissioning(&mut self) -> Result<(), Rejection> {
        self.host_silence_s = 0.0;
        match self.state {
            State::Idle => {
                self.commissioning = Some(Commissioning::new(
                    self.cfg.commissioning,
                    self.cfg.supply_v,
                    self.cfg.timer_hz as f32,
                    [
                        self.cfg.axes[0].pulses_per_rev,
                        self.cfg.axes[1].pulses_per_rev,
                    ],
                ));
                self.identify_error = None;
                self.watch = [SensorWatch::CLEAR; 2];
                self.state = State::Commissioning;
                Ok(())
            }
            State::Fault => Err(Rejection::Faulted(self.latched())),
            s => Err(Rejection::WrongState(s)),
        }
    }

    /// Resets the host-silence timer (any command does too).
    pub fn host_heartbeat(&mut self) {
        self.host_silence_s = 0.0;
    }

    /// Feedback on or off (diagnostics and the test that shows the feedforward alone is not
    /// enough). On by default.
    pub fn set_feedback_enabled(&mut self, on: bool) {
        self.feedback = on;
    }

    /// Operating state.
    pub fn state(&self) -> State {
        self.state
    }

    /// Latched fault, if any.
    pub fn fault(&self) -> Option<Fault> {
        self.fault
    }

    /// The configuration in force (with identified models after commissioning).
    pub fn config(&self) -> &ControllerConfig {
        &self.cfg
    }

    /// The speed loop's gains on `axis` at its full bandwidth (the schedule lowers both in
    /// proportion at sparse pulses): `(kp, ki)` in duty per rad/s and duty per rad.
    pub fn loop_gains(&self, axis: usize) -> Option<(f32, f32)> {
        let k = self.k.get(axis)?;
        let wc = self.cfg.axes.get(axis)?.bandwidth_rad_s;
        Some((k.kp(wc), k.ki_per_s(wc)))
    }

    /// Results of the last commissioning run, per axis.
    pub fn identified(&self) -> [Option<Identified>; 2] {
        self.identified
    }

    /// Why the last commissioning run failed, if it did.
    pub fn identify_error(&self) -> Option<IdentifyError> {
        self.identify_error
    }

    /// Status snapshot for telemetry (computes Eq. 2; call at telemetry rate, not per tick).
    pub fn status(&self) -> Status {
        let targets = self.planner.targets();
        let ramped = self.planner.ramped();
        let mut axes = [AxisStatus::default(); 2];
        for (i, a) in axes.iter_mut().enumerate() {
            *a = AxisStatus {
                target_rad_s: targets[i],
                reference_rad_s: ramped[i],
                measured_rad_s: self.measured[i],
                duty: self.duties[i],
                pulses: self.est[i].accepted_edges(),
                rejected_edges: self.est[i].rejected_edges(),
                inferred_missing: self.est[i].inferred_missing(),
                measurement_valid: self.est[i].is_valid(),
            };
        }
        let combined = |w: [f32; 2]| {
            combined_speed_from_trig(
                self.cos_axes,
                self.sin_axes,
                MotorSpeeds {
                    precession_rad_s: w[0],
                    spin_rad_s: w[1],
                },
            )
            .unwrap_or(0.0)
        };
        Status {
            state: self.state,
            fault: self.fault,
            fault_code: fault_code(self.fault),
            axes,
            combined_target_rad_s: combined(targets),
            combined_measured_rad_s: combined(self.measured),
        }
    }

    /// Predicted residence time at the measured combined bowl speed, s, from a forward particle
    /// model (flat or Coriolis). For telemetry: call at the telemetry rate, never per tick.
    pub fn predicted_residence_time_s(&self, model: &dyn ResidenceForBowlSpeed) -> Option<f32> {
        let w = self.status().combined_measured_rad_s;
        if w > 0.0 {
            model.residence_time_s(w)
        } else {
            None
        }
    }
}

/// sin(z) for |z| <= pi/2 in f32, usable in `const fn`: the Taylor series to z^23 in Horner
/// form (truncation below 1e-15 there; f32 rounding dominates, a few 1e-8). No libm sine or
/// cosine and no f64 arithmetic reach the firmware image this way.
const fn sin_series(z: f32) -> f32 {
    let z2 = z * z;
    // sin z = z (1 - z^2/(2*3) (1 - z^2/(4*5) (1 - ...))), innermost term first.
    let mut acc = 1.0f32;
    let mut k = 11;
    while k > 0 {
        acc = 1.0 - z2 / ((2 * k) as f32 * (2 * k + 1) as f32) * acc;
        k -= 1;
    }
    z * acc
}

/// cos(x) for x in [0, pi) (the configuration's axes angle), usable in `const fn`:
/// cos x = sin(pi/2 - x), |pi/2 - x| <= pi/2. (libm's `cosf` is not a `const fn`.)
const fn cos_const(x: f32) -> f32 {
    sin_series(core::f32::consts::FRAC_PI_2 - x)
}

/// sin(x) for x in [0, pi): sin x = cos(pi/2 - x) = sqrt(1 - sin^2(pi/2 - x)) would need a
/// square root; instead sin x = sin(pi - x) folds x into [0, pi/2], where the series holds.
const fn sin_const(x: f32) -> f32 {
    let folded = if x > core::f32::consts::FRAC_PI_2 {
        core::f32::consts::PI - x
    } else {
        x
    };
    sin_series(folded)
}

#[cfg(test)]
mod tests {
    #[test]
    fn cos_const_matches_libm() {
        let mut x = 0.0f32;
        while x < core::f32::consts::PI {
            let d = (super::cos_const(x) - libm::cosf(x)).abs();
            assert!(d < 2e-7, "x {x}: {d}");
            let d = (super::sin_const(x) - libm::sinf(x)).abs();
            assert!(d < 2e-7, "sin x {x}: {d}");
            x += 0.01;
        }
    }
}

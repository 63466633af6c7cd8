//! The host's commands. Each one, accepted or refused, is word from the host: it resets the
//! host-silence timer, in one place, [`Controller::command`] (the two `const` commands, which
//! cannot take its closure, do the same first thing by hand).

use super::Controller;
use super::Rejection;
use crate::control::commission::Commissioning;
use crate::control::config::{ControllerConfig, in_range};
use crate::control::estimator::lowest_speed_rad_s;
use crate::control::pi::LoopConstants;
use crate::control::planner::{BowlSpeedForResidence, split_combined};
use crate::control::supervisor::{Fault, SensorWatch, State};

/// The host-silence watch: a running rig faults when the host has sent nothing for longer
/// than the configured timeout (0 = no watch).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct HostWatch {
    enabled: bool,
    silence_s: f32,
}

impl HostWatch {
    /// A watch for `timeout_s` (0 or less: off), the host just heard.
    pub(super) const fn new(timeout_s: f32) -> Self {
        Self {
            enabled: timeout_s > 0.0,
            silence_s: 0.0,
        }
    }

    /// The host spoke.
    pub(super) const fn heard(&mut self) {
        self.silence_s = 0.0;
    }

    /// Counts `dt_s` of silence; true once it exceeds `timeout_s` (never when off).
    #[inline(always)]
    pub(super) fn silent_after(&mut self, dt_s: f32, timeout_s: f32) -> bool {
        if !self.enabled {
            return false;
        }
        self.silence_s += dt_s;
        self.silence_s > timeout_s
    }
}

impl Controller {
    /// Runs a host command: first the host is heard (a refused command also shows the host is
    /// alive), then `run`.
    fn command<T>(
        &mut self,
        run: impl FnOnce(&mut Self) -> Result<T, Rejection>,
    ) -> Result<T, Rejection> {
        self.host.heard();
        run(self)
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
    /// ChangingSpeed and Running; the planner ramps to it.
    pub const fn set_motor_speeds(
        &mut self,
        precession_rad_s: f32,
        spin_rad_s: f32,
    ) -> Result<(), Rejection> {
        // What `command` does; a `const fn` (the benchmark builds its controller at compile
        // time) cannot take a closure or use `?`.
        self.host.heard();
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
        // A new setpoint: the runaway check waits until it is reached (a heavy shaft may coast
        // down slower than the ramp).
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
        self.command(|c| {
            c.check_state_for_setpoint()?;
            if !in_range(target_s, 1e-6, 1e6) {
                return Err(Rejection::InvalidResidenceTime);
            }
            let omega = model.omega_rad_s(target_s).map_err(Rejection::Inverse)?;
            let speeds = split_combined(omega, c.cos_axes, c.sin_axes, c.cfg.spin_per_precession)
                .ok_or(Rejection::SplitFailed)?;
            c.check_speed(0, speeds[0])?;
            c.check_speed(1, speeds[1])?;
            c.planner.set_targets(speeds);
            c.reached = false;
            Ok(speeds)
        })
    }

    /// Starts the closed loop (Idle -> ChangingSpeed) toward the current targets.
    pub const fn start(&mut self) -> Result<(), Rejection> {
        // What `command` does, in a `const fn` (see `set_motor_speeds`).
        self.host.heard();
        match self.state {
            State::Idle => {
                self.axes[0].rest_loop();
                self.axes[1].rest_loop();
                self.reached = false;
                self.state = State::ChangingSpeed;
                Ok(())
            }
            State::Fault => Err(Rejection::Faulted(self.latched())),
            s => Err(Rejection::WrongState(s)),
        }
    }

    /// Stops: ramps both axes to zero (Stopping, then Idle once both read zero). Aborts
    /// commissioning at once (zero duty). In Idle or Fault it does nothing and succeeds.
    pub fn stop(&mut self) -> Result<(), Rejection> {
        self.command(|c| {
            match c.state {
                State::ChangingSpeed | State::Running => {
                    c.planner.set_targets([0.0; 2]);
                    c.reached = false;
                    c.state = State::Stopping;
                }
                State::Commissioning => {
                    c.commissioning = None;
                    c.set_duties_zero();
                    c.state = State::Idle;
                }
                State::Idle | State::Stopping | State::Fault => {}
            }
            Ok(())
        })
    }

    /// Clears a latched fault (Fault -> Idle, targets zero). Refused while the configuration
    /// is invalid.
    pub fn clear_fault(&mut self) -> Result<(), Rejection> {
        self.command(|c| {
            if c.state != State::Fault {
                return Err(Rejection::NotFaulted);
            }
            if let Some(e) = c.config_error {
                return Err(Rejection::InvalidConfig(e));
            }
            c.fault = None;
            c.state = State::Idle;
            c.planner.reset();
            // The supply closes again: a bridge still shorted trips within a sample.
            c.supply_cut = false;
            Ok(())
        })
    }

    /// Replaces all parameters (Idle or Fault only). A valid configuration also lifts the
    /// block on clearing an invalid-configuration fault (the fault stays latched until cleared).
    pub fn set_parameters(&mut self, cfg: ControllerConfig) -> Result<(), Rejection> {
        self.command(|c| {
            if !matches!(c.state, State::Idle | State::Fault) {
                return Err(Rejection::WrongState(c.state));
            }
            cfg.validate().map_err(Rejection::InvalidConfig)?;
            let (state, fault) = (c.state, c.fault);
            let targets = c.planner.targets();
            c.rebuild_keep_state(cfg);
            c.state = state;
            c.fault = fault;
            // The speeds asked for (SPEED or RTIME) stay asked for, where the new limits allow
            // them: rebuilt from scratch they were zeroed without a word, and the next START
            // answered ok with both motors still.
            if c.check_speed(0, targets[0]).is_ok() && c.check_speed(1, targets[1]).is_ok() {
                c.planner.set_targets(targets);
            }
            Ok(())
        })
    }

    /// Changes one axis's loop bandwidth and per-pulse bandwidth while running (bumpless: the
    /// integral absorbs the proportional change). Refused during commissioning.
    pub fn set_loop_tuning(
        &mut self,
        axis: usize,
        bandwidth_rad_s: f32,
        per_pulse_bandwidth: f32,
    ) -> Result<(), Rejection> {
        self.command(|c| {
            if c.state == State::Commissioning {
                return Err(Rejection::WrongState(c.state));
            }
            if axis > 1
                || !in_range(bandwidth_rad_s, 0.01, 1000.0)
                || !in_range(per_pulse_bandwidth, 0.01, 10.0)
            {
                return Err(Rejection::InvalidTuning);
            }
            let mut a = c.cfg.axes[axis];
            a.bandwidth_rad_s = bandwidth_rad_s;
            a.per_pulse_bandwidth = per_pulse_bandwidth;
            c.cfg.axes[axis] = a;
            c.axes[axis].k = LoopConstants::new(&a, c.dt_s, c.cfg.supply_v);
            Ok(())
        })
    }

    /// Starts the identification routine (Idle only); at the end the identified models
    /// replace the configured ones and the state returns to Idle, or an implausible result
    /// latches [`Fault::InvalidConfiguration`].
    pub fn start_commissioning(&mut self) -> Result<(), Rejection> {
        self.command(|c| match c.state {
            State::Idle => {
                c.commissioning = Some(Commissioning::new(
                    c.cfg.commissioning,
                    c.cfg.supply_v,
                    c.cfg.timer_hz as f32,
                    [c.cfg.axes[0].pulses_per_rev, c.cfg.axes[1].pulses_per_rev],
                ));
                c.identify_error = None;
                c.axes[0].watch = SensorWatch::CLEAR;
                c.axes[1].watch = SensorWatch::CLEAR;
                c.state = State::Commissioning;
                Ok(())
            }
            State::Fault => Err(Rejection::Faulted(c.latched())),
            s => Err(Rejection::WrongState(s)),
        })
    }

    /// Resets the host-silence timer (any command does too).
    pub fn host_heartbeat(&mut self) {
        self.host.heard();
    }
}

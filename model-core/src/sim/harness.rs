//! The closed loop: the controller ticking against the simulated rig, and the step-response
//! measures computed on the rig's *true* speed, online (no storage).

use super::plant::Plant;
use crate::control::{Controller, State};

/// The controller and the rig, stepped together one control period at a time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosedLoop {
    /// The simulated rig.
    pub rig: Plant,
    /// The controller under test.
    pub ctrl: Controller,
    dt_s: f32,
    duties: [f32; 2],
}

impl ClosedLoop {
    /// Couples a controller to a rig; the control period is the controller's tick.
    pub fn new(rig: Plant, ctrl: Controller) -> Self {
        let dt_s = 1.0 / ctrl.config().tick_hz as f32;
        Self {
            rig,
            ctrl,
            dt_s,
            duties: [0.0; 2],
        }
    }

    /// One control period: the controller sees the edges of the last period and the timer now,
    /// and its duties drive the rig through the next period.
    pub fn tick(&mut self) -> [f32; 2] {
        let now = self.rig.now_ticks();
        let currents = [self.rig.sensed_current_a(0), self.rig.sensed_current_a(1)];
        let edges = [self.rig.edges(0), self.rig.edges(1)];
        let duties = self.ctrl.tick_with_currents(now, edges, currents);
        if self.ctrl.supply_cut_requested() {
            self.rig.cut_supply();
        }
        self.rig.advance(duties, self.dt_s);
        self.duties = duties;
        duties
    }

    /// Duties applied in the last period.
    pub fn duties(&self) -> [f32; 2] {
        self.duties
    }

    /// Control period, s.
    pub fn dt_s(&self) -> f32 {
        self.dt_s
    }

    /// Runs `seconds`, calling `each` after every tick.
    pub fn run(&mut self, seconds: f32, mut each: impl FnMut(&Self)) {
        let n = (seconds / self.dt_s) as u32;
        for _ in 0..n {
            self.tick();
            each(self);
        }
    }

    /// Runs commissioning to its end (Idle again) or a fault, at most `max_s` seconds.
    /// Returns the final state.
    pub fn commission(&mut self, max_s: f32) -> State {
        if self.ctrl.start_commissioning().is_err() {
            return self.ctrl.state();
        }
        let n = (max_s / self.dt_s) as u32;
        for _ in 0..n {
            self.tick();
            if self.ctrl.state() != State::Commissioning {
                break;
            }
        }
        self.ctrl.state()
    }
}

/// The settling band of the simulated experiments: +/-2 % of the setpoint.
pub const SETTLING_BAND: f32 = 0.02;

/// Step-response measures of one signal stepping from one level to a constant setpoint,
/// accumulated online. The one definition of rise, overshoot, settling and steady error: the
/// simulated experiments and the demo's telemetry analysis both use it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepMetrics {
    from: f32,
    setpoint: f32,
    band: f32,
    steady_from_s: f32,
    t10: Option<f32>,
    t90: Option<f32>,
    /// Largest excursion past the setpoint, in the step's direction.
    excess: f32,
    last_outside_s: f32,
    last_sample_outside: bool,
    n: f32,
    sum: f64,
    sum_sq: f64,
    min_steady: f32,
    max_steady: f32,
}

/// The measures, as fractions of the setpoint and seconds from the step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    /// 10 % to 90 % rise time, s (infinite if never reached).
    pub rise_time_s: f32,
    /// Peak past the setpoint, fraction of the change (of the setpoint for a step from rest;
    /// 0 if none).
    pub overshoot: f32,
    /// Last time outside the settling band, s (the settling time; 0 if never outside).
    pub settling_time_s: f32,
    /// The newest sample was inside the band (a run that ends outside never settled).
    pub settled: bool,
    /// |mean over the steady window - setpoint|, fraction of the setpoint.
    pub steady_state_error: f32,
    /// RMS of the deviation from the steady window's mean, fraction of the setpoint.
    pub rms_ripple: f32,
    /// Half the peak-to-peak excursion in the steady window, fraction of the setpoint.
    pub half_peak_to_peak: f32,
}

impl StepMetrics {
    /// Measures a step from rest to `setpoint` with the +/-2 % band ([`SETTLING_BAND`]); the
    /// steady window starts `steady_from_s` after the step.
    pub fn new(setpoint: f32, steady_from_s: f32) -> Self {
        Self::between(0.0, setpoint, SETTLING_BAND, steady_from_s)
    }

    /// Measures a step from `from` to `setpoint`: rise from 10 % to 90 % of the change,
    /// overshoot as a fraction of the change, settled inside +/-`band` x |setpoint|; the steady
    /// window starts `steady_from_s` after the step.
    pub fn between(from: f32, setpoint: f32, band: f32, steady_from_s: f32) -> Self {
        Self {
            from,
            setpoint,
            band,
            steady_from_s,
            t10: None,
            t90: None,
            excess: f32::MIN,
            last_outside_s: 0.0,
            last_sample_outside: false,
            n: 0.0,
            sum: 0.0,
            sum_sq: 0.0,
            min_steady: f32::MAX,
            max_steady: f32::MIN,
        }
    }

    /// Adds the sample `y` at `t_s` after the step.
    pub fn add(&mut self, t_s: f32, y: f32) {
        let sp = self.setpoint;
        let change = sp - self.from;
        let direction = if change < 0.0 { -1.0 } else { 1.0 };
        let progress = (y - self.from) * direction;
        if self.t10.is_none() && progress >= 0.1 * change.abs() {
            self.t10 = Some(t_s);
        }
        if self.t90.is_none() && progress >= 0.9 * change.abs() {
            self.t90 = Some(t_s);
        }
        self.excess = self.excess.max((y - sp) * direction);
        self.last_sample_outside = (y - sp).abs() > self.band * sp.abs();
        if self.last_sample_outside {
            self.last_outside_s = t_s;
        }
        if t_s >= self.steady_from_s {
            self.n += 1.0;
            self.sum += y as f64;
            self.sum_sq += (y as f64) * (y as f64);
            self.min_steady = self.min_steady.min(y);
            self.max_steady = self.max_steady.max(y);
        }
    }

    /// The measures so far.
    pub fn report(&self) -> StepReport {
        let sp = self.setpoint.abs().max(f32::MIN_POSITIVE);
        let change = (self.setpoint - self.from).abs().max(f32::MIN_POSITIVE);
        let rise = match (self.t10, self.t90) {
            (Some(a), Some(b)) => b - a,
            _ => f32::INFINITY,
        };
        let (mean, var) = if self.n > 0.0 {
            let m = self.sum / self.n as f64;
            (m, (self.sum_sq / self.n as f64 - m * m).max(0.0))
        } else {
            (f64::NAN, f64::NAN)
        };
        StepReport {
            rise_time_s: rise,
            overshoot: (self.excess / change).max(0.0),
            settling_time_s: self.last_outside_s,
            settled: !self.last_sample_outside,
            steady_state_error: ((mean as f32) - self.setpoint).abs() / sp,
            rms_ripple: libm::sqrt(var) as f32 / sp,
            half_peak_to_peak: 0.5 * (self.max_steady - self.min_steady) / sp,
        }
    }
}

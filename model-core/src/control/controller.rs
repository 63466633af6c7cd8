//! The top-level controller: both axes, the supervisor, the planner and commissioning.
//!
//! - this file: the state and the control tick;
//! - [`build`]: its construction from a configuration, and a configuration replaced;
//! - [`axis`]: one motor axis's runtime state (estimator, loop, sensor watch, outputs);
//! - [`commands`]: the host's commands, each of which also counts as hearing from the host;
//! - [`current`]: the current sense's samples, trips and the supply cut;
//! - [`commissioning`]: the tick while commissioning runs, and its end;
//! - [`status`]: what the controller tells: its state, fault, models and the telemetry snapshot.

mod axis;
mod build;
mod commands;
mod commissioning;
mod current;
mod status;

pub use status::{AxisStatus, Status};

use super::const_trig::cos_const;

use axis::AxisState;
use commands::HostWatch;

use super::commission::{Commissioning, Identified, IdentifyError};
use super::config::{ConfigError, ControllerConfig};
use super::pi::LoopInput;
use super::planner::{InverseFailure, SetpointPlanner};
use super::supervisor::{
    DRIVEN_BELOW_MODEL_DUTY, DROPPING_WATCH_PITCHES, Fault, PAIR_RUNAWAY_MARGIN_RAD_S,
    PAIR_RUNAWAY_RATIO, PAIR_RUNAWAY_STEADY_S, REVOLUTION_RUNAWAY_DUTY,
    REVOLUTION_RUNAWAY_MARGIN_RAD_S, REVOLUTION_RUNAWAY_RATIO, SETTLED_AFTER_S, State,
    WATCH_PITCHES, closed_loop_state, edge_runaway,
};

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

/// The rig's controller. See the module docs of [`crate::control`] for the contract.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Controller {
    cfg: ControllerConfig,
    dt_s: f32,
    /// Precession, spin.
    axes: [AxisState; 2],
    planner: SetpointPlanner,
    state: State,
    fault: Option<Fault>,
    /// Why the configuration was refused (blocks clearing the fault until replaced).
    config_error: Option<ConfigError>,
    host: HostWatch,
    commissioning: Option<Commissioning>,
    identified: [Option<Identified>; 2],
    identify_error: Option<IdentifyError>,
    feedback: bool,
    /// cos and sin of the axes angle (paper Eq. 2), computed once per configuration.
    cos_axes: f32,
    sin_axes: f32,
    /// Precession duty per rad/s of the spin's reference above its model speed: cancels the
    /// spin's reaction (see [`decouple_duty_per_rad_s`]).
    decouple_duty_per_rad_s: f32,
    /// Both references were reached since the last start or setpoint (arms the runaway check).
    reached: bool,
    /// The supply cut is asked open: a bridge drove harder than it was told.
    supply_cut: bool,
}

/// Precession duty per rad/s of `r - r_p` of the spin (its model accelerates at
/// `(r - r_p) / tau2`): the measured reaction `g / tau2` when commissioning measured it;
/// otherwise the geometry's estimate `cos(angle) volts_per_rad_s,spin / V` (the spin's
/// reaction `J2 dw2/dt` projected on the vertical, with `J2 dw2/dt = tau2 k2 a2 / R2 dw2/dt` and
/// the same motor type on both axes).
const fn decouple_duty_per_rad_s(cfg: &ControllerConfig) -> f32 {
    let spin = cfg.axes[1].model;
    let g = cfg.axes[0].model.reaction_duty_s2_per_rad;
    if g != 0.0 {
        g / spin.time_constant_s
    } else {
        cos_const(cfg.axes_angle_rad) * spin.volts_per_rad_s / cfg.supply_v
    }
}

/// The runaway rules near the top speed, where full duty takes the shaft too little above its
/// reference for one interval to show it: the two-interval rule (see [`PAIR_RUNAWAY_RATIO`]),
/// the whole revolution's mean (see [`REVOLUTION_RUNAWAY_RATIO`]) and the duty fallen below the
/// model (see [`DRIVEN_BELOW_MODEL_DUTY`]). Out of line: they run only on edges near the top
/// speed and keep the tick's common path short.
#[cold]
#[inline(never)]
fn near_top_runaway(a: &AxisState, model_rad_s: f32, steady_s: f32) -> bool {
    // `model_rad_s` > 0 here: the feedforward of the shaft's direction, made positive.
    // The model's duty, but no more than the bridge can give: a shaft whose model asks for more
    // than the duty limit (a heavy plant near the top speed) runs saturated, short of its
    // reference, and that is no runaway (4 rad/s faulted a healthy plant of an unseen family).
    let model_duty = a.k.feedforward(model_rad_s).min(a.k.duty_limit());
    let duty_below_model = model_duty - a.duty * a.direction;
    (steady_s > PAIR_RUNAWAY_STEADY_S
        && a.est.pair_speed_rad_s() > PAIR_RUNAWAY_RATIO * model_rad_s + PAIR_RUNAWAY_MARGIN_RAD_S)
        || duty_below_model > DRIVEN_BELOW_MODEL_DUTY
        || (duty_below_model > REVOLUTION_RUNAWAY_DUTY
            && revolution_runaway(a.est.revolution_speed_rad_s(), model_rad_s, steady_s))
}

/// The whole-revolution rule (see [`REVOLUTION_RUNAWAY_RATIO`]): only once the last revolution
/// began after the loop had settled.
fn revolution_runaway(revolution_rad_s: f32, model_rad_s: f32, steady_s: f32) -> bool {
    revolution_rad_s > REVOLUTION_RUNAWAY_RATIO * model_rad_s + REVOLUTION_RUNAWAY_MARGIN_RAD_S
        && steady_s > SETTLED_AFTER_S + core::f32::consts::TAU / revolution_rad_s
}

impl Controller {
    /// One control tick, called at exactly `tick_hz`.
    ///
    /// `now_ticks` is the capture timer read *after* collecting `edges`; `edges[axis]` holds
    /// the timestamps captured on that axis since the previous tick, oldest first. Returns the
    /// duties `[precession, spin]` in -1..=1 (sign = direction; 0 = coast).
    pub fn tick(&mut self, now_ticks: u32, edges: [&[u32]; 2]) -> [f32; 2] {
        self.tick_with_currents(now_ticks, edges, [None; 2])
    }

    /// [`Controller::tick`] on a board with current sense: `currents_a[axis]` is the bridge's
    /// current-sense reading at the end of the last period (under the duty this controller
    /// returned last tick), A, signed in the motor's positive direction, sampled in step with
    /// the PWM; None where the axis has no current sense. Every sample is checked against
    /// the over-current and model limits (see [`CurrentWatch`]): a trip latches
    /// [`Fault::OverCurrent`] or [`Fault::CurrentAboveModel`] in this tick, and a bridge that
    /// drives harder than it is told (a current at zero duty, or more than the duty drives into
    /// a held shaft) or an over-current also asks for the supply cut
    /// ([`Controller::supply_cut_requested`]).
    ///
    /// [`CurrentWatch`]: super::supervisor::CurrentWatch
    pub fn tick_with_currents(
        &mut self,
        now_ticks: u32,
        edges: [&[u32]; 2],
        currents_a: [Option<f32>; 2],
    ) -> [f32; 2] {
        // The duties the readings were taken under (a trip on one axis zeroes both).
        let applied = [self.axes[0].duty, self.axes[1].duty];
        for (i, c) in currents_a.iter().enumerate() {
            if let Some(reading) = *c {
                self.current_sample(i, reading, applied[i]);
            }
        }
        if self.state == State::Commissioning {
            return self.tick_commissioning(now_ticks, edges);
        }
        let dt = self.dt_s;
        let steady = self.planner.steady_s();
        let mut seen = [false; 2];
        for i in 0..2 {
            let a = &mut self.axes[i];
            let before = a.est.accepted_edges();
            // Steady as the shaft shows it, not only by the reference's age: the reference
            // unchanged for half a second *and* the measurement within 10 % of the plant model
            // the loop runs. It sets the estimator's relative lockout, its two-pitch stall bound
            // and tooth learning; missing pulses are the observer's to judge (below).
            let model = a.speed_loop.model_rad_s().abs();
            let steady_i = steady[i] > 0.5
                && a.est.is_valid()
                && (a.measured.abs() - model).abs() <= 0.1 * model;
            a.steady = steady_i;
            // The observer (observer.rs) judges missing pulses by its expected angle, and is
            // driven by last tick's duty less what that held beyond the model.
            let duty = (a.duty - a.extra_duty) * a.direction;
            // A deceleration is no load, for the observer as for the loop (observer.rs).
            let slowing = a.speed_loop.slowing();
            a.obs.hold_load(slowing);
            // Missing pulses are inferred while the observer tracks, at a steady speed or once
            // the sensor has dropped one (a drop not inferred leaves the reading outside
            // "steady", and no later one was), never while slowing: the observer knows no
            // stiction, and a shaft sticking on its way down to the lowest speed took two
            // expected pitches for one (family-60 p18, 3 -> 0.2 rad/s); crawling at 0.2 rad/s,
            // healthy shafts of family-60 did too where not steady.
            let infer = !slowing && (steady_i || a.est.dropping());
            let speed = a.obs.track(
                &a.ok, &mut a.est, now_ticks, edges[i], steady_i, infer, duty,
            );
            seen[i] = a.est.accepted_edges() != before;
            a.measured = a.direction * speed;
            if seen[i] && steady_i {
                a.current.note_turning();
            }
            // Runaway (a bridge stuck on): once both axes have reached their references, an
            // edge that came far sooner than the plant model expects faults at once, without
            // waiting for the filtered speed to reach the absolute limit.
            let runaway = self.reached && seen[i] && {
                edge_runaway(a.est.edge_speed_rad_s(), model, a.obs.driven_rad_s())
                    || (model > a.k.pair_runaway_above_rad_s()
                        && near_top_runaway(a, model, steady[i]))
            };
            if speed > self.cfg.axes[i].overspeed_rad_s || runaway {
                self.latch(Fault::Overspeed(i as u8));
            }
        }
        match self.state {
            State::ChangingSpeed | State::Running | State::Stopping => {
                self.closed_loop_step(dt, &seen)
            }
            _ => {
                self.set_duties_zero();
                // The drive is off: a shaft still coasting after a fault reads at rest as
                // after a STOP (`settle_coasted`), not 5 s later by the estimator's bound.
                for a in &mut self.axes {
                    a.settle_coasted(true);
                }
            }
        }
        self.after_tick(dt)
    }

    /// Host-silence watch and the final say of a latched fault, common to both ticks.
    #[inline(always)]
    fn after_tick(&mut self, dt: f32) -> [f32; 2] {
        if !matches!(self.state, State::Idle | State::Fault)
            && self.host.silent_after(dt, self.cfg.host_timeout_s)
        {
            self.latch(Fault::HostSilent);
        }
        if self.fault.is_some() {
            self.set_duties_zero();
        }
        [self.axes[0].duty, self.axes[1].duty]
    }

    /// Both duties 0 (coast), and nothing held beyond the model: the observer's plant coasts on
    /// zero duty (a stale decoupling or load duty drove it on after a fault).
    #[inline(always)]
    fn set_duties_zero(&mut self) {
        for a in &mut self.axes {
            a.duty = 0.0;
            a.extra_duty = 0.0;
        }
    }

    #[inline(never)]
    fn closed_loop_step(&mut self, dt: f32, seen: &[bool; 2]) {
        let off = self.planner.ramped();
        for (a, off) in self.axes.iter_mut().zip(off) {
            a.settle_coasted(off == 0.0);
        }
        let [p, s] = &self.axes;
        let stopped = [p.est.is_stopped(), s.est.is_stopped()];
        let max_step = [p.max_step, s.max_step];
        let ramped = self.planner.step(dt, max_step, stopped);
        // Spin first: its expected acceleration feeds the precession axis's decoupling.
        if self.axis_loop(1, ramped[1], 0.0, seen[1], dt) {
            return;
        }
        // The spin's accelerating torque reacts on the rod. Its acceleration times tau2 is
        // expected where both its model (`(r - r_p) / tau2`) and the duty it was just given
        // through its identified plant (its observer, with the speed and load its edges showed)
        // say it accelerates, as the smaller of the two: a spin its stiction or material holds
        // back accelerates less than its model, and the model's reaction drove the rod ahead;
        // the observer alone (it knows no stiction, and learns the material slowly) fed the rod
        // a reaction the spin did not have (docs/control.md, "The rod decoupled by what the
        // spin does").
        let s = &self.axes[1];
        let duty = (s.duty - s.extra_duty) * s.direction;
        let by_duty = s.direction * s.obs.drive_rad_s(&s.ok, duty);
        // The ramp's, not the led reference's (pi.rs `lead`): a led spin's model accelerates at
        // `(led - r_p) / tau`, and fed that, the eleven families' shares within 2 % by 3 s from
        // rest to 1 rad/s summed 1079.2 against 1080.9 (docs/control.md, "The reference's lead").
        // Once the spin is measured, its model accelerates by what its correction is still to
        // give too: a loaded spin's start reading raises its integral to the load it read, and
        // the spin then catches up through its lag as the reference's model no longer does.
        // Left out, the rod got none of that reaction, dipped 3 % and read the dip as load
        // (seed 10 p06's rod: 3 % past 1 rad/s, 2 % at 3.90 s; now 0.8 %, 1.73 s; docs/control.md,
        // "The crawl's push in the correction"). Only speeding up: a correction coming down
        // after a reading that ran ahead of the load is no deceleration the shaft makes (the
        // correction's model leaves out the load it then reads), and fed as one it starved
        // rods at the lowest speed (family-60 p50, 0 -> 0.2 rad/s: 4 -> 30 % past).
        let to_come = s.speed_loop.correction_to_come_rad_s(&s.k);
        let correction = if s.est.is_valid() && to_come * s.direction > 0.0 {
            to_come
        } else {
            0.0
        };
        let by_model = ramped[1] - s.speed_loop.model_rad_s() + correction;
        // With current sense a spin at rest whose current has not shown its breakaway is
        // held (by stiction, or material the model does not know): its motor's torque and
        // what holds it cancel on the rod, so there is no reaction to decouple. Fed, a fast
        // rod ran 13 % past 1 rad/s while its spin's material held it for a second (seed 3
        // p19; docs/control.md, "A start read the same way with current sense"). Without
        // current sense nothing tells a held spin from one that starts until its first edge,
        // which comes after the acceleration the decoupling is for.
        let held = s.current.amps_per_duty() > 0.0 && !s.speed_loop.turning();
        let lag = if by_duty * by_model > 0.0 && !held {
            // The smaller in magnitude (`clamp` would bring a panic path into the tick).
            by_model.min(by_duty.abs()).max(-by_duty.abs())
        } else {
            0.0
        };
        let decouple = self.decouple_duty_per_rad_s * lag;
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
                let measured = [self.axes[0].measured, self.axes[1].measured];
                self.state = closed_loop_state(self.state, ramped, target, measured);
                if self.state == State::Running {
                    self.reached = true;
                }
            }
        }
    }

    /// One axis's loop and sensor watch; true if it latched a fault.
    #[inline(always)]
    fn axis_loop(&mut self, i: usize, r: f32, extra_duty: f32, seen: bool, dt: f32) -> bool {
        let a = &mut self.axes[i];
        let was = a.direction;
        if r > 0.0 {
            a.direction = 1.0;
        } else if r < 0.0 {
            a.direction = -1.0;
        }
        if a.direction != was {
            // The wheel's gaps now pass in the opposite order: the load pattern is learned anew.
            a.load.forget_all();
        } else if r == 0.0 {
            // The shaft is let go: what the loop learned is learned anew.
            a.load.forget();
        }
        if a.direction != was {
            // The wheel's gaps now pass in the opposite order.
            a.est.forget_teeth();
        }
        // The once-per-revolution load ahead of the loop (load_pattern.rs); `a.duty` is what
        // drove the shaft since the last tick.
        let model = a.speed_loop.model_rad_s().abs();
        let load = a.load.tick(&a.est, a.duty, a.direction, a.steady, model);
        let extra_duty = extra_duty + if self.feedback { load } else { 0.0 };
        a.extra_duty = extra_duty;
        let input = LoopInput {
            reference_rad_s: r,
            measured_rad_s: a.measured,
            direction: a.direction,
            measurement_valid: a.est.is_valid(),
            events: a.est.window_events(),
            feedback: self.feedback,
            extra_duty,
            at_rest: a.est.at_rest(),
            torque_duty: a.torque_duty.take(),
            // The rod only (pi.rs, `early`).
            early_edge_drops_kick: i == 0,
        };
        let duty = a.speed_loop.step(&a.k, input);
        a.duty = duty;
        if a.speed_loop.take_breakaway() {
            // The current showed the shaft start turning now: its first edge is due a pitch
            // from here, not from the start of a long hold (breakaway.rs).
            a.watch.reset();
        }
        // Expected edges are watched whatever the duty: at low speed the duty that holds the
        // shaft can be below any fixed threshold. The travel expected is the observer's once
        // it tracks the shaft (a shaft that lags its reference, saturated or slowing as its
        // inertia lets it, is expected where it is); from rest, where the observer knows no
        // stiction, the loop's plant model's.
        let expected_rad_s = if a.obs.tracking() {
            a.obs.speed_rad_s()
        } else {
            a.speed_loop.model_rad_s()
        };
        if a.watch.step(
            dt,
            duty.abs(),
            0.0,
            seen,
            self.cfg.sensor_timeout_floor_s,
            expected_rad_s,
            a.est.rad_per_pulse(),
            if a.est.dropping() {
                DROPPING_WATCH_PITCHES
            } else {
                WATCH_PITCHES
            },
        ) {
            self.latch(self.lost_edges_fault(i));
            return true;
        }
        false
    }

    #[cold]
    #[inline(never)]
    fn latch(&mut self, fault: Fault) {
        if self.fault.is_none() {
            self.fault = Some(fault);
        }
        self.state = State::Fault;
        for a in &mut self.axes {
            a.duty = 0.0;
            a.rest_loop();
        }
        self.planner.reset();
        self.commissioning = None;
    }

    /// The board's hardware stop (its break input) tripped: latch [`Fault::HardwareStop`] (a
    /// fault already latched is kept). The board calls it at every tick while the stop's line
    /// is active, so a CLEAR holds only once the line is released.
    pub fn hardware_stop(&mut self) {
        self.latch(Fault::HardwareStop);
    }

    /// Feedback on or off (diagnostics and the test that shows the feedforward alone is not
    /// enough). On by default.
    pub fn set_feedback_enabled(&mut self, on: bool) {
        self.feedback = on;
    }
}

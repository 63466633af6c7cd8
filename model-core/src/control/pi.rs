//! The speed loop of one axis: feedforward from the identified motor model plus a discrete PI
//! on the measured speed, with gain scheduling, anti-windup, clamp and slew limit.
//!
//! # Structure (two degrees of freedom)
//! `duty = ff(r) + Kp e + I`:
//! - `ff(r) = sign(r) (friction_duty + |r| volts_per_rad_s / V)`: the steady-state duty of the
//!   identified model, so the loop only corrects the model's error.
//! - `e` compares like with like. The pulse estimate is the *mean* speed over a counting window
//!   that ended at an edge, up to a pulse period ago; comparing it with today's reference would
//!   wind the integral up on every ramp (a lag of up to a pulse period, 175 ms at 3 rad/s with
//!   12 pulses/rev) and overshoot afterwards. So the loop runs the identified plant model
//!   (`r_p`: the reference through the first-order lag `tau`), integrates the model's angle over
//!   the same window as the estimator, and takes `e = model mean - measured mean` over exactly
//!   that window. `e` is then held (and filtered with the estimator's weight) until the next
//!   window closes. Between edges, once the stall bound says the shaft is slower than its last
//!   measurement, `e` is at least `r_p - bound`.
//! - The reference's lead: a shaft slower than [`REFERENCE_TAU_S`] is fed, and modelled with,
//!   a reference ahead of the ramp by `(tau / REFERENCE_TAU_S - 1) (r - r_p)` while its model
//!   is behind, so it follows a model of that lag instead of its own (wpilib's `kA`).
//! - The window's dead time is modelled (a Smith predictor): the duty the feedback applied is
//!   run through the same model (`c`), a window reads the load `L = model mean + c mean -
//!   measured mean`, and `e = L - c` now, so what the correction already does is not asked for
//!   again through the next window (docs/control.md, "From rest to 1 rad/s").
//!
//! # Gains
//! The plant from duty to speed is `K / (tau s + 1)` with `K = V / volts_per_rad_s`. The PI zero
//! cancels the pole (`Ti = tau`) and `Kp = wc tau / K`, `Ki = wc / K` give a first-order closed
//! loop of bandwidth `wc`. `wc = min(bandwidth, per_pulse_bandwidth * pulse_rate)`, with the pulse
//! rate at the reference speed up to [`SCHEDULE_TOP_RAD_S`]: sparse pulses sample the speed
//! slowly, and a loop faster than about a fifth of the sample rate rings or limit-cycles (see
//! docs/control.md's stability map); above that speed a loop as fast as the revolution chases
//! the wheel's once-per-revolution pattern.
//!
//! # Anti-windup, bumpless changes, zero setpoint
//! The integral stores its *output* (duty), so changing `Ki` never moves the duty; when `Kp`
//! changes the integral absorbs `(Kp_old - Kp_new) e`, so neither does that. Integration stops
//! (conditional integration) while the output is clamped or slew-limited in the direction the
//! error pushes, which holds a blocked motor's integral instead of letting it run away, and while
//! the estimator has no valid measurement (no pulse interval yet). At a zero reference the output
//! is exactly zero and the integral is cleared: no hum, no creep.
//!
//! # Breaking stiction
//! Stiction needs more torque than sliding friction, so the feedforward alone (which holds
//! Coulomb friction) does not start a shaft from rest. Two mechanisms do, neither depending on
//! the loop's gain (which the pulse-rate schedule makes small at low speed):
//! - The kick: when commissioning identified a breakaway duty above the friction duty, a shaft
//!   at rest gets the difference on top of the feedforward (less what the reference alone
//!   already adds) until a model of the shaft driven by the applied duty reaches the reference.
//!   A gradual push would overshoot stiction by as much as it rises before the first edge can
//!   tell, up to a pitch of travel; the kick gives the known amount at once.
//! - The push: a shaft at rest (no edge since it last stopped) whose plant model has turned
//!   [`STUCK_PITCHES`] gets a push that starts from the kick's level and rises in proportion to
//!   the reference, to [`PUSH_SPAN_DUTY`] above it by the time the expected-edge watch would
//!   fault, until the first edge comes; then it drops to zero and the integral keeps
//!   [`PUSH_KEPT`] of what started the shaft (the push, or the kick): stiction and whatever
//!   load the model does not know (material poured in since commissioning). Keeping only what
//!   was found beyond the kick left loaded shafts crawling below 0.2 rad/s until the watch
//!   faulted them (2 to 6 healthy plants per 60-plant family); keeping half the kick costs
//!   overshoot on an unloaded shaft (35 % on the nominal rig at 0.5 rad/s). A kick kept at a
//!   first edge that came while the planner still ramped the reference up follows, until the
//!   first measurement, the kick the rising reference still needs (docs/control.md, "From rest
//!   to 1 rad/s: the floor of a start from pulses").
//! - The crawl's reading: a loaded shaft may crawl between its first and second edge, and the
//!   push rises again. When that window closes with the push on, its mean speed against the
//!   mean duty that drove it reads the load the model does not know, and the integral takes
//!   it at once. Fed to the loop as an error instead, the crawl's low mean wound the integral
//!   up while the push had already started the shaft: 15..25 % too fast for 5 s on loaded
//!   spin axes, which at a pulse a second the loop corrects only slowly.
//! - The start's reading: the first measurement of a shaft the kick started (not the push),
//!   over a window of at least [`START_READ_MIN_S`], reads the load against the model with
//!   the correction, and the integral takes it at once: what was kept of the kick is replaced
//!   by what the shaft needs, where the loop at its low-speed bandwidth took 10 s and more.
//!   A pushed shaft's first window carries its leap (stored in stiction the model does not
//!   know) and is left to the loop, unless the current showed its breakaway (the push ended
//!   there, and the back-EMF band held the shaft until the edge); its second window is read.
//! - With current sense (breakaway.rs): the back-EMF shows the breakaway at once, where the
//!   first edge may come a second later. The kick then lasts until the current shows it (not
//!   until the model says it should have), kick and push drop there to feedforward + integral
//!   (half a push kept, nothing of the kick), and until the first measurement the integral
//!   holds the back-EMF speed in a band around the model speed.
//!
//! Both only start a shaft from rest: once the loop has seen it move, a shaft that goes quiet is
//! not pushed (a dead sensor on a turning shaft would otherwise run it away before the
//! supervisor's expected-edge watch faults it), except at the bottom of a step-down, where the
//! integral learned at the higher speed can leave a healthy shaft stopped (`quiet` in
//! [`SpeedLoop::step`]; docs/control.md, "A shaft that went quiet"). "From rest" is the loop's view: no window closed
//! since the loop started, whatever edge the estimator still holds from before (a restart after
//! a fault or a zero reference, see `rest` in [`SpeedLoop::step`]).

use super::breakaway::{Breakaway, FUSED_BAND_SHARE};
use super::estimator::WindowEvents;

mod constants;
mod start;
mod state;
mod tuning;
mod window;
pub use constants::{LoopConstants, SCHEDULE_TOP_RAD_S, bandwidth_ceiling_rad_s};
pub use state::SpeedLoop;
pub use tuning::{
    CRAWL_READ_MIN_S, LEAD_MARGIN_DUTY, PUSH_KEPT, PUSH_SPAN_DUTY, QUIET_PITCHES, REFERENCE_TAU_S,
    SECOND_READING_CHANGE_SHARE, SECOND_READING_LESSER_MISMATCH_SHARE,
    SECOND_READING_MISMATCH_SHARE, START_READ_MIN_S, STUCK_PITCHES,
};

/// Inputs of one loop step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopInput {
    /// Ramped reference, rad/s (signed: the commanded direction).
    pub reference_rad_s: f32,
    /// Measured speed (with the stall bound) with the commanded sign, rad/s.
    pub measured_rad_s: f32,
    /// Sign of the commanded direction, +1 or -1.
    pub direction: f32,
    /// The estimator has a valid measurement.
    pub measurement_valid: bool,
    /// The estimator's window events of this tick.
    pub events: WindowEvents,
    /// Feedback on (false only in the open-loop test of the feedback's necessity).
    pub feedback: bool,
    /// Extra feedforward duty (the precession axis's decoupling of the spin reaction).
    pub extra_duty: f32,
    /// No edge since the shaft last stopped (the estimator's view).
    pub at_rest: bool,
    /// The current-sense reading under the last period's duty as the duty that drives it into
    /// a held shaft (`(i - offset) / g`, in the commanded direction; breakaway.rs); None
    /// without current sense or before the supervisor learned the offset and `g`.
    pub torque_duty: Option<f32>,
    /// A first edge that does not show the shaft behind its model keeps nothing of the kick
    /// (the rod: see `early` in [`SpeedLoop::step`]).
    pub early_edge_drops_kick: bool,
}

impl SpeedLoop {
    /// One fixed-rate step; returns the duty in `[-duty_limit, duty_limit]`.
    #[inline(always)]
    pub fn step(&mut self, k: &LoopConstants, input: LoopInput) -> f32 {
        let r = input.reference_rad_s;
        if r == 0.0 {
            *self = Self::REST;
            return 0.0;
        }
        let r_abs = r.abs();
        // The reference the feedforward and the model take (the reference's lead, above).
        let led = k.led_reference(r, r_abs, self.model_rad_s, input.direction);
        // The plant model's speed and its angle over the estimator's current window.
        self.model_rad_s += (led - self.model_rad_s) * k.model_alpha;
        let rp = self.model_rad_s;
        self.model_angle_rad += rp * k.dt_s;
        // What the feedback's own correction has done to the shaft, by the same model: a
        // window closes up to a pitch after the speed it measures, and the correction applied
        // since then is not in it (the loop's dead time; see `e` below).
        self.correction_rad_s +=
            self.correction_duty * k.kick_gain_per_tick - self.correction_rad_s * k.model_alpha;
        let c = self.correction_rad_s;
        self.correction_angle_rad += c * k.dt_s;
        // A shaft already turning when the loop started (a coasting restart: the estimator
        // holds its edges) has carried its load all along: its whole deficit shows.
        if self.reference_abs_rad_s == 0.0 && !input.at_rest {
            self.load_lag = 1.0;
        }
        self.load_lag += (1.0 - self.load_lag) * k.model_alpha;
        self.load_lag_angle += self.load_lag * k.dt_s;
        self.start_lag -= self.start_lag * k.model_alpha;
        self.start_lag_angle += self.start_lag * k.dt_s;
        let ev = input.events;
        // Slowing down: the model above the reference. Its windows, and every window that
        // began before the model came down to the reference, compare a shaft that decelerates
        // as its inertia lets it with a model that may decelerate faster; their "too fast" is
        // not a load the integral should hold.
        if rp.abs() > 1.02 * r_abs {
            self.slowing = true;
            self.stepped_down = true;
            self.model_down_quiet_s = 0.0;
        } else {
            self.model_down_quiet_s += k.dt_s;
        }
        if let Some(w) = ev.closed
            && w.ago_s + w.span_s < self.model_down_quiet_s
        {
            self.slowing = false;
        }
        // An integral below zero says the model asks more than the shaft needs at that speed.
        // Material only drags, so (with the identified friction duty not above the true one)
        // that is the model's slope, `volts_per_rad_s`, too steep: an error in proportion to
        // the speed, so on the way down it shrinks with the reference. Carried whole to the
        // lowest speed it starved the shaft (seed 8 p00, slope 5 % steep: -0.014 duty learned
        // at 4 rad/s, 0.017 short at 0.2 rad/s, a crawl and a false fault). Scaled, it stays a
        // lower bound of the truth (load + slope error x speed), so it never drives harder
        // than the shaft needs.
        if self.slowing && self.integral * input.direction < 0.0 && r_abs < self.reference_abs_rad_s
        {
            self.integral *= r_abs / self.reference_abs_rad_s;
        }
        self.reference_abs_rad_s = r_abs;
        // The model's travel since the loop left rest, the kick's speed included (see `early`
        // at the first edge below), before a first edge restarts the count.
        let travel_rad = (self.model_angle_rad + self.correction_angle_rad) * input.direction;
        if let Some(ago) = ev.restarted_s_ago {
            self.model_angle_rad = rp * ago;
            self.correction_angle_rad = c * ago;
            self.load_lag_angle = self.load_lag * ago;
            // The shaft's mismatch against its model starts here (the kick's true leap is not
            // the model's), and decays through the lag.
            self.start_lag = 1.0;
            self.start_lag_angle = ago;
            self.window_open = true;
        }
        if let Some(w) = ev.closed
            && !self.window_open
        {
            // The loop started in the middle of a window: compare from the next one on.
            self.model_angle_rad = rp * w.ago_s;
            self.correction_angle_rad = c * w.ago_s;
            self.load_lag_angle = self.load_lag * w.ago_s;
            self.start_lag_angle = self.start_lag * w.ago_s;
            self.window_open = true;
        } else if let Some(w) = ev.closed
            && w.span_s > 0.0
        {
            self.read_window(k, input, w, rp, c);
        }
        // The error is that load less what the correction already gives the shaft now (a
        // Smith predictor: the window's dead time is taken out of the loop by the model).
        // Held as the window's shortfall against the reference alone, the integral kept
        // rising for the whole next window on a shaft already at its speed: 2 to 6 %
        // overshoot from rest to 1 rad/s and 2 % settling after 3 s on most axes.
        let mut e = if input.feedback && self.have_error {
            self.error - c
        } else {
            0.0
        };
        if !input.measurement_valid {
            self.have_error = false;
            self.error = 0.0;
            e = 0.0;
        }
        // The first edge from rest (`first_edge`, start.rs). "From rest" is the loop's view: no
        // window closed since the loop started. A shaft let go by a fault, a STOP or a zero
        // reference may have stopped between two edges while the estimator, which calls it stopped
        // only after two pitches at the lowest speed (8 s at 12 pulses a revolution), still holds
        // the edge from before: its reading is then only the stall bound, an upper bound from an
        // old edge. Restarted from there, it got no kick and no push, and the loop integrated the
        // model against that bound until the first edge came (up to a pitch of travel later): 13 to
        // 31 % overshoot at 2 rad/s on the nominal rig and the seeded family, a false runaway fault
        // on the emulated Black Pill (issue 27). It starts like a shaft at rest instead.
        let rest = input.at_rest || !self.window_open;
        // With current sense, the back-EMF shows the breakaway at once (breakaway.rs): the kick
        // and the push stop there, and what started the shaft is not kept (the current showed
        // no load holding it back; one that does is found below).
        let released = match input.torque_duty {
            Some(c) => self.sample_current(k, input, c, rest && !self.moved, r_abs),
            None => false,
        };
        let first_edge = !rest && !self.moved;
        if first_edge {
            self.first_edge(k, input, released, travel_rad, r_abs);
        }
        if !rest {
            self.moved = true;
        }
        // The kick kept at a first edge that came while the planner still ramped the reference
        // up is half of what the reference then needed above its feedforward; the reference
        // needs less as it rises (`kick_level` falls with it), and so does what is kept, until
        // the first measurement hands the integral to the loop. Kept whole, half the kick at
        // 0.33 of 1 rad/s held family-60 p28's precession 17 % past 1 rad/s until then (the
        // kick at 1 rad/s: 0.004 duty; kept: 0.034).
        if self.kept_kick > 0.0 {
            let now = PUSH_KEPT * k.kick_level(r_abs);
            if input.measurement_valid {
                self.kept_kick = 0.0;
            } else if now < self.kept_kick {
                self.integral -= (self.kept_kick - now) * input.direction;
                self.kept_kick = now;
            }
        }
        // Push a shaft that should have given an edge by now: from rest before it first moved,
        // or crawling between its first and second edge (no measurement yet). Never a shaft
        // that went quiet after moving (the estimator reset it to rest): that is the
        // supervisor's to judge, and pushing it would run away a shaft with a dead sensor.
        let starting = rest && !self.moved && !released;
        let crawling = !input.at_rest && !input.measurement_valid && !released;
        // A shaft that went quiet at the bottom of a step-down: it moved, the model has
        // reached the lower reference, the stall bound is active, and the model has turned
        // [`QUIET_PITCHES`] past the last edge. The integral learned at the higher speed carries the
        // identified slope's error there (docs/control.md, "Step-downs to the lowest speed"):
        // a healthy shaft stopped under it (seed 14 p05, 0.053 duty where 0.077 holds 0.2
        // rad/s) and nothing started it again before the expected-edge watch faulted it. It
        // gets the push a start gets, from the kick's level; a dead sensor is still the
        // watch's to fault (the push spans the same pitches the start's does).
        let quiet = self.stepped_down
            && self.model_angle_rad.abs() > QUIET_PITCHES * k.stuck_angle_rad / STUCK_PITCHES
            && self.moved
            && !rest
            && input.measurement_valid
            && ev.bound_active
            && self.model_down_quiet_s > 0.0
            && !released;
        // The kick: from rest, the identified breakaway duty, just long enough for the model
        // driven by it to reach the reference; then the feedforward holds Coulomb friction.
        // Stiction needs more than sliding does, and a gradual push overshoots it by as much
        // as it rises before the first edge can tell (up to a pitch of travel).
        let mut kick = 0.0;
        // With current sense the kick lasts until the current shows the breakaway (`starting`
        // ends there), not until the model says it should have: a shaft the kick did not
        // start (material since commissioning) is not left at the feedforward until the push.
        let kick_on = self.kick_rad_s < r_abs || input.torque_duty.is_some();
        if starting && input.feedback && self.push == 0.0 {
            if kick_on {
                kick = k.kick_level(led.abs());
            }
            // Driven by the applied duty (the slew limit holds it back at first) above
            // friction: the true breakaway lies below the identified one (the search's duty
            // kept rising until the first edge), so the shaft may already slide. Run on every
            // tick of the start, the kick's off ones too: once it reached the ramping
            // reference, the kick went off and on from tick to tick while the model stood
            // still, the slew limit held the duty at the breakaway's, and a light rod whose
            // breakaway commissioning read 3.4x high ran on to 18 % past 1 rad/s before its
            // first edge (family-60 p29; docs/control.md, "The kick's model runs through the
            // whole start").
            let applied_excess = self.duty.abs() - k.friction_duty;
            if applied_excess > 0.0 {
                self.kick_rad_s +=
                    (applied_excess - self.kick_rad_s * k.duty_per_rad_s) * k.kick_gain_per_tick;
            }
        }
        if (starting || crawling || quiet)
            && input.feedback
            && self.model_angle_rad.abs() > k.stuck_angle_rad
            && self.push < 1.0
        {
            // Not started by the kick: push on from its level.
            let kick_level = k.kick_level(r_abs);
            if self.push < kick_level {
                self.push = kick_level;
            }
            self.push += k.push_per_rad_tick * r_abs;
            self.pushed = true;
            self.push_rad_s += self.push * k.kick_gain_per_tick - self.push_rad_s * k.model_alpha;
            self.push_angle_rad += self.push_rad_s * k.dt_s;
        }
        // The stall bound is only active with a valid measurement, and counts only from an
        // edge the loop has seen (see `rest`).
        if ev.bound_active && input.feedback && !rest {
            let at_least = rp - input.measured_rad_s;
            e = if input.direction > 0.0 {
                e.max(at_least)
            } else {
                e.min(at_least)
            };
        }

        let wc = k.scheduled_bandwidth(r_abs);
        let ki_dt = wc * k.ki_dt_per_wc;
        let kp = wc * k.kp_per_wc;
        // A "too fast" error is not integrated while the shaft slows down to a lower reference
        // (see `slowing`) nor while the stall bound is active (the shaft is slowing between
        // edges and nothing says it is still faster than the model: the error held from the
        // last window is stale). Integrated for the seconds a window lasts at low speed, the
        // deceleration's error wound the duty below friction and the shaft stalled (4 -> 0.2
        // rad/s: 2 of 60 healthy plants faulted). It still acts proportionally.
        let stale_too_fast = (ev.bound_active || self.slowing) && e * input.direction < 0.0;
        // Bumpless gain change: the proportional jump is absorbed by the integral, except that
        // of a stale "too fast" error (above): the schedule lowers the gain with the reference
        // all the way down a step-down, and absorbing the deceleration's error moved it into
        // the integral for good, as integrating it would (4 -> 0.2 rad/s, family-60 p25: the
        // integral fell from 0.013 to 0.005 duty, below the material the shaft carried, and
        // the shaft crawled to a stop). The duty rises by the part not absorbed instead.
        if !stale_too_fast {
            self.integral += (self.kp_prev - kp) * e;
        }
        self.kp_prev = kp;

        // r != 0 here, so its sign is the commanded direction.
        let ff = (k.friction_duty + self.push + kick) * input.direction
            + led * k.duty_per_rad_s
            + input.extra_duty;
        let e_int = if stale_too_fast { 0.0 } else { e };
        let candidate_i = self.integral + ki_dt * e_int;
        let unlimited = ff + kp * e + candidate_i;
        let lim = k.duty_limit;
        let next = self.duty + clamp(clamp(unlimited, lim) - self.duty, k.slew_per_tick);
        // Conditional integration: keep the new integral only if the clamp or the slew limit
        // is not holding the output back in the direction the error pushes.
        // (This also bounds the integral: once the output sits at the clamp, the integral stops
        // growing toward it.)
        if (unlimited - next) * e <= 0.0 {
            self.integral = candidate_i;
        }
        // The kick is in the correction's history: the plant model (the reference through the
        // lag) does not know it, and a start's first window spans the speed it gave. Left out,
        // that speed read as a negative load at the start's reading and dropped the duty below
        // what the shaft needs (family-60 p02's rod: 0.227 for 0.235, 2 % settled at 3.2 s;
        // docs/control.md, "The kick in the start's first window"). Not with current sense:
        // there the kick lasts until the current shows the breakaway, so it held a shaft that
        // did not move and gave it no speed (in the history, 0 -> 1 rad/s on family-60 within
        // 5 % past it 100 -> 98.3 %).
        let kick_history = if input.torque_duty.is_none() {
            kick
        } else {
            0.0
        };
        self.correction_duty = next - ff + kick_history * input.direction;
        self.duty = next;
        next
    }
}

/// `x` limited to `[-lim, lim]` (`lim >= 0`); no panic path, unlike `f32::clamp`.
#[inline(always)]
fn clamp(x: f32, lim: f32) -> f32 {
    if x > lim {
        lim
    } else if x < -lim {
        -lim
    } else {
        x
    }
}

//! The loop's state, its rest, and what the controller reads of it; the step that moves it,
//! [`SpeedLoop::step`], is [`super`]'s.

use super::Breakaway;
use super::LoopConstants;
use crate::control::breakaway::BackEmf;

/// State of one axis's loop.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SpeedLoop {
    pub(super) integral: f32,
    pub(super) duty: f32,
    pub(super) model_rad_s: f32,
    pub(super) model_angle_rad: f32,
    pub(super) window_open: bool,
    pub(super) have_error: bool,
    pub(super) error: f32,
    pub(super) kp_prev: f32,
    pub(super) push: f32,
    pub(super) moved: bool,
    pub(super) kick_rad_s: f32,
    /// The speed the push has given the plant model (the push through the identified lag),
    /// rad/s, magnitude, and the angle it has turned it since the push began, rad: a crawling
    /// shaft follows them, and the crawl's reading takes both (`take_crawl_load`).
    pub(super) push_rad_s: f32,
    pub(super) push_angle_rad: f32,
    /// The kick's share the integral kept at the first edge, until the first measurement
    /// (duty, magnitude; see `kept_kick` in [`SpeedLoop::step`]).
    pub(super) kept_kick: f32,
    /// The model has been above the reference (the reference came down) since the start of
    /// the newest window: that window's "too fast" is the slowing down, not a load.
    pub(super) slowing: bool,
    /// Seconds since the model was last more than 2 % above the reference's magnitude.
    pub(super) model_down_quiet_s: f32,
    /// The reference's magnitude last tick, rad/s.
    pub(super) reference_abs_rad_s: f32,
    /// What the current says of this start (axes with current sense only).
    pub(super) breakaway: Breakaway,
    /// The duty applied last tick beyond the feedforward and the push: the feedback's (the
    /// clamp and the slew limit included) and the kick's, which the plant model does not
    /// know either.
    pub(super) correction_duty: f32,
    /// The speed that correction has given the plant model, rad/s (the correction through the
    /// identified lag), and its angle over the estimator's current window, rad.
    pub(super) correction_rad_s: f32,
    pub(super) correction_angle_rad: f32,
    /// The share of a load's steady speed deficit the shaft shows by now, since the loop left
    /// rest: a load that acts from the start slows the shaft through the identified lag,
    /// `1 - exp(-t / tau)` (a unit step through the plant model), and its integral over the
    /// estimator's current window, s (see `read_window`, window.rs).
    pub(super) load_lag: f32,
    pub(super) load_lag_angle: f32,
    /// What is left of the shaft's mismatch against its model at its first edge from rest,
    /// decaying through the identified lag (`exp(-t / tau)`), and its integral over the
    /// estimator's current window, s (see `read_second_window`, window.rs).
    pub(super) start_lag: f32,
    pub(super) start_lag_angle: f32,
    /// The start's first reading, `[shortfall, load share, mismatch share]` of its window,
    /// kept for the second (`read_second_window`), which is due while `second_reading` is set.
    pub(super) first_reading: [f32; 3],
    pub(super) second_reading: bool,
    /// The shaft started from rest (its first edge) and no window has been read since: the
    /// next one reads the load at once (see `step`).
    pub(super) start_reading: bool,
    /// The push started the shaft, so its first window is not read (`start_reading`): the
    /// second one is, once that window has closed.
    pub(super) late_reading: bool,
    /// The push has been on since the shaft was last at rest (the kick did not start it).
    pub(super) pushed: bool,
    /// The reference has come down since the loop started (see `quiet` in [`SpeedLoop::step`]).
    pub(super) stepped_down: bool,
    /// The current showed the breakaway in this step (see [`SpeedLoop::take_breakaway`]).
    pub(super) breakaway_news: bool,
    /// The back-EMF the current sense learned (`identified` 0: not given, the identified
    /// model's); set before each step (see [`SpeedLoop::set_back_emf`]).
    pub(super) emf: BackEmf,
}

impl SpeedLoop {
    /// At rest: zero output, zero integral.
    pub const REST: Self = Self {
        integral: 0.0,
        duty: 0.0,
        model_rad_s: 0.0,
        model_angle_rad: 0.0,
        window_open: false,
        have_error: false,
        error: 0.0,
        kp_prev: 0.0,
        push: 0.0,
        moved: false,
        kick_rad_s: 0.0,
        push_rad_s: 0.0,
        push_angle_rad: 0.0,
        kept_kick: 0.0,
        slowing: false,
        model_down_quiet_s: 0.0,
        reference_abs_rad_s: 0.0,
        breakaway: Breakaway::NONE,
        breakaway_news: false,
        emf: BackEmf::identified(0.0),
        correction_duty: 0.0,
        correction_rad_s: 0.0,
        correction_angle_rad: 0.0,
        load_lag: 0.0,
        load_lag_angle: 0.0,
        start_lag: 0.0,
        start_lag_angle: 0.0,
        first_reading: [0.0; 3],
        second_reading: false,
        start_reading: false,
        late_reading: false,
        pushed: false,
        stepped_down: false,
    };

    /// True once the loop has seen the shaft turn under its own motor since it started: an
    /// edge after the loop left rest (see `rest` in [`SpeedLoop::step`]), or, with current
    /// sense, the back-EMF of its breakaway (breakaway.rs; a shaft dragged backwards would
    /// raise the current, not lower it).
    pub fn turning(&self) -> bool {
        self.moved || self.breakaway.released()
    }

    /// The reference came down and the loop still compares windows that began before the
    /// model reached it (see the field of the same name): what the shaft does then is its
    /// deceleration, not a load.
    pub fn slowing(&self) -> bool {
        self.slowing
    }

    /// What the correction (the feedback's duty and the kick's beyond the feedforward) is
    /// still to add to the plant model's speed through the identified lag, rad/s: its steady
    /// speed less the speed it has given so far, that is the model's expected acceleration
    /// from it times `tau`.
    pub fn correction_to_come_rad_s(&self, k: &LoopConstants) -> f32 {
        self.correction_duty / k.duty_per_rad_s - self.correction_rad_s
    }

    /// The push has done its work (or is given up): it and the speed and angle it gave the
    /// plant model go.
    #[inline(always)]
    pub(super) fn end_push(&mut self) {
        self.push = 0.0;
        self.push_rad_s = 0.0;
        self.push_angle_rad = 0.0;
    }

    /// The plant model's speed (the reference through the identified lag), rad/s.
    pub fn model_rad_s(&self) -> f32 {
        self.model_rad_s
    }
    /// The last output duty.
    pub fn duty(&self) -> f32 {
        self.duty
    }
    /// The integral term (duty).
    pub fn integral(&self) -> f32 {
        self.integral
    }
    /// Back to rest (zero output, zero integral).
    pub fn reset(&mut self) {
        *self = Self::REST;
    }
}

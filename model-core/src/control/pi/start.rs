//! The loop's start from rest, out of the tick's common path where it can be: the crawl's and
//! the start's load readings, the current sense's samples (breakaway and back-EMF band), and
//! what the current tells the controller. The rules they follow are the module's "Breaking
//! stiction" ([`super`]).

use super::{
    CRAWL_READ_MIN_S, FUSED_BAND_SHARE, LoopConstants, LoopInput, PUSH_KEPT, STUCK_PITCHES,
    SpeedLoop, clamp,
};
use crate::control::breakaway::{BackEmf, KEPT_KICK_AHEAD_SHARE};

impl SpeedLoop {
    /// The first edge from rest (the loop's view, see `rest` in [`SpeedLoop::step`]): what
    /// started the shaft (the kick, or the push beyond it) held stiction and whatever load the
    /// model does not know; half of it stays in the integral, unless the current or the edge's
    /// timing shows that it was more than the shaft needed. `released`: the current showed the
    /// breakaway this tick; `travel_rad`: the model's travel since rest, the kick's included.
    #[inline(always)]
    pub(super) fn first_edge(
        &mut self,
        k: &LoopConstants,
        input: LoopInput,
        released: bool,
        travel_rad: f32,
        r_abs: f32,
    ) {
        if !released {
            // With current sense, a first edge that comes before the current confirmed
            // the breakaway, on a shaft whose back-EMF speed already keeps up with the
            // model's (above the fused band's lower edge): what started it was more than
            // it needed and no load holds it back, so as at the current's breakaway the
            // kick is not kept, only half of a push. Kept, a light rod that reached its
            // first tooth 35 ms into the start leapt 57 % past 0.5 rad/s (seed 6 p24). A
            // shaft behind the model (a loaded spin that slows after its first edge, or a
            // current per duty learned low) keeps it as before.
            let turning = input.torque_duty.is_some()
                && self.breakaway.speed_rad_s() > (1.0 - FUSED_BAND_SHARE) * self.model_rad_s.abs();
            // Without current sense, a rod's first edge that came before the model (the
            // kick's speed included) had turned a pitch does not show the shaft behind it:
            // the kick is not kept (half a push is). A light rod the kick ran to 1 rad/s
            // before its first tooth kept half of a breakaway duty commissioning read 2-3x
            // high until its first measurement: 20 % past 1 rad/s (seed 5 p44). Not the
            // spin: loaded with the bowl's material, spins then crawled and were pushed
            // (0 -> 0.5 rad/s within 5 % by 8 s two axes fewer on two families;
            // docs/control.md, "The rod's kept kick from rest").
            let early = input.early_edge_drops_kick
                && input.torque_duty.is_none()
                && travel_rad < k.stuck_angle_rad / STUCK_PITCHES;
            let started_by = if turning || early {
                self.push
            } else {
                self.push.max(k.kick_level(r_abs))
            };
            self.integral += PUSH_KEPT * started_by * input.direction;
            if started_by > self.push {
                self.kept_kick = PUSH_KEPT * started_by;
            }
            if input.torque_duty.is_some() {
                // The edge proves the breakaway: the back-EMF band holds the integral from
                // here to the first measurement, as after one the current confirmed. Left
                // unconfirmed, a spin whose first tooth came 10 ms before the third sample
                // above the threshold crawled at 0.2 of 0.5 rad/s with no band, until the
                // push drove it 50 % past (family-60 p10).
                self.breakaway.confirm();
            }
        }
        self.end_push();
        // The start's reading (`take_start_load`) is left out after a push: its first
        // window carries the leap of stiction the push overcame. Not when the current saw
        // the breakaway: the push ended there and the back-EMF band held the shaft near the
        // model to this edge, so the window reads the load. Left out, family-60 p13's
        // loaded spin (the push started it 2.5 s in) left the band phase at 0.37 of
        // 0.5 rad/s and the edges' loop took it into 5 % at 10.4 s (now 9.0 s).
        self.start_reading = !self.pushed || released;
        self.late_reading = !self.start_reading;
    }

    /// The integral takes the load read from a crawl window of `span_s` seconds whose model
    /// mean exceeded the measured mean by `sample` rad/s; the push ends. The push counts as
    /// the speed it gave the shaft through the identified lag over the window, not as its mean
    /// duty: the push comes late in the window, where the shaft has had least time to follow
    /// it, and read as a steady duty it stood for more speed than the window measured, a load
    /// read high
    /// (seed 4 p01's spin held 0.179 duty where 0.170 holds 1 rad/s, 3.3 % fast, 2 % at 3.16 s;
    /// now 2.39 s; docs/control.md, "The crawl's push in the correction"). A window shorter than
    /// [`CRAWL_READ_MIN_S`] was no crawl: half the push stays, as after the first edge. Rare
    /// (once per start of a loaded shaft), so kept out of the tick's common path; the choice
    /// is a product, not a branch (a branch here cost the common path two instructions, over
    /// the tick budget).
    #[cold]
    #[inline(never)]
    pub(super) fn take_crawl_load(
        &mut self,
        k: &LoopConstants,
        span_s: f32,
        sample: f32,
        direction: f32,
    ) {
        let reading = if span_s >= CRAWL_READ_MIN_S { 1.0 } else { 0.0 };
        let mean_push = self.push_angle_rad / span_s * k.duty_per_rad_s;
        self.integral += reading * (mean_push * direction + sample * k.duty_per_rad_s)
            + (1.0 - reading) * PUSH_KEPT * self.push * direction;
        // The push becomes the integral's, so the speed it has given the shaft becomes the
        // correction's: started from nothing, the correction's model ran behind a shaft that
        // had followed the push, and the next window read that lead as a smaller load (seed
        // 33 p11's spin: the integral fell from 0.044 to 0.035 duty, 2 % at 5.15 s, now
        // 2.60 s; docs/control.md, "The crawl's push in the correction").
        self.correction_rad_s += reading * self.push_rad_s * direction;
        self.end_push();
    }

    /// The first measurement of a start, over a window of at least [`START_READ_MIN_S`](super::START_READ_MIN_S): the
    /// integral takes the load it reads at once (the error the loop would otherwise remove at
    /// its bandwidth; how, below). What started the shaft (half the kick or the push,
    /// kept at its first edge so that a loaded shaft does not stick again) is then replaced by
    /// what the window shows the shaft needs. Left to the loop, an unloaded shaft ran on the
    /// kept kick at the scheduled bandwidth's pace: at 0.2 rad/s (0.19 rad/s of bandwidth, a
    /// 5 s time constant) the nominal rig's stiction leap to 0.52 rad/s was still 0.24 rad/s
    /// 13 s after the command. Before the dead time was modelled the held error did this
    /// job by accident (the integral ran on for the whole next window); the window's load
    /// reading does it on purpose. Only long windows (low speed, where the loop is slow and
    /// the shaft's lag is short against the window) are read; a short one through which the
    /// shaft still accelerates is left to the loop, as at the crawl's reading.
    ///
    /// The integral is set so that the correction this tick, the
    /// integral and the proportional part on `e = L - c`, is the load read, `L` as duty. The
    /// PI's zero cancels the plant's pole only from a state where the integral matches what
    /// the shaft already carries: a kick whose speed `c` still decays (a heavy rod, tau
    /// 0.5-0.7 s, read 0.7 s after its kick) left the integral at `L - c` and the rest to the
    /// loop's slow mode, at its bandwidth (about 1 rad/s at 1 rad/s): seed 8 p00's rod read
    /// `L` = 0.070 rad/s, took -0.009 duty and settled within 2 % at 5.1 s. Set so, the
    /// correction stays `L` while `c` comes to it through the shaft's own lag (the
    /// closed loop's modes are the plant's `1 / tau` and the bandwidth; this start excites
    /// only the first). With current sense too: the back-EMF band had been thought to hold
    /// the integral to the shaft up to here, and the integral took the reading's error on top
    /// of what it held; the band leaves a shaft that lags its model by its load alone, and
    /// the proportional part then drove a loaded spin past its target (family-60 p10's spin
    /// 4.8 % over 1 rad/s, 2 % settled at 3.9 s; docs/control.md, "A start read the same way
    /// with current sense").
    #[inline(always)]
    pub(super) fn take_start_load(&mut self, k: &LoopConstants, input: LoopInput, c: f32) {
        // `error` and `c` are signed speeds (the window's sample is the model's signed mean
        // less `direction` times the measured magnitude), as the integral is a signed duty:
        // no further `direction` (multiplied by it, a start in reverse took the reading with
        // the wrong sign; `a_loaded_shaft_that_crawls_takes_its_load_from_the_crawl_not_by_
        // overshooting` at -0.5 rad/s stopped the shaft once the reading set the integral).
        let kp = k.kp(k.scheduled_bandwidth(input.reference_rad_s.abs()));
        self.integral = self.error * k.duty_per_rad_s - kp * (self.error - c);
    }

    /// One current sample (see [`LoopInput::torque_duty`]): the breakaway watch, and between
    /// the breakaway and the first measurement the integral held to the back-EMF speed's band.
    /// Returns whether the current said the shaft broke away. Out of line: only axes with
    /// current sense pay for it.
    #[inline(never)]
    pub(super) fn sample_current(
        &mut self,
        k: &LoopConstants,
        input: LoopInput,
        torque_duty: f32,
        starting: bool,
        r_abs: f32,
    ) -> bool {
        let applied = self.duty * input.direction;
        let was_released = self.breakaway.released();
        let emf = if self.emf.identified > 0.0 {
            self.emf
        } else {
            BackEmf::identified(k.duty_per_rad_s)
        };
        let released = self.breakaway.sample(
            applied,
            torque_duty,
            (emf, k.friction_duty),
            (starting, starting),
            r_abs,
        );
        if released && !was_released && self.push != 0.0 {
            // The kick did not start it, the push did: load the model does not know holds the
            // shaft back (material), and half of the push stays in the integral as at the first
            // edge. Dropped to the feedforward, such shafts crawled until the expected-edge
            // watch faulted them (4 of 480 plants at 0 -> 0.5 rad/s).
            self.integral += PUSH_KEPT * self.push * input.direction;
        }
        if released && !was_released {
            self.breakaway_news = true;
        }
        if released {
            // The push has done its work.
            self.end_push();
        }
        if released && input.feedback && !input.measurement_valid && !self.slowing {
            let step = self.breakaway.fused_integral_step(
                (self.model_rad_s.abs(), r_abs),
                k.duty_per_rad_s,
                k.dt_s,
            );
            self.integral = clamp(self.integral + step * input.direction, k.duty_limit);
            if self.kept_kick > 0.0 {
                self.drop_kept_kick_ahead(input.direction);
            }
        }
        released
    }

    /// The kick kept at a first edge that came before the current confirmed the breakaway,
    /// on a shaft then behind its model (`first_edge`): kept so that a loaded shaft does not
    /// stick again. Once the back-EMF speed runs ahead of the model by more than
    /// [`KEPT_KICK_AHEAD_SHARE`], the shaft does not need it, and it goes before the first
    /// measurement would take it. Held to that measurement, a heavy rod (time constant 0.56 s)
    /// whose first tooth came 60 ms into the start ran on half a kick of 0.09 duty to 35 % past
    /// 0.5 rad/s (seed 34 p03; docs/control.md, "The kept kick the current shows is not
    /// needed"), and one read 14 % low 11.4 % past 1 rad/s (seed 52 p21; "The back-EMF read
    /// through the held ratio").
    #[cold]
    #[inline(never)]
    fn drop_kept_kick_ahead(&mut self, direction: f32) {
        if self.breakaway.speed_rad_s() > KEPT_KICK_AHEAD_SHARE * self.model_rad_s.abs() {
            self.integral -= self.kept_kick * direction;
            self.kept_kick = 0.0;
        }
    }

    /// The back-EMF the current sense learned at measured speeds
    /// ([`BackEmfScale`](crate::control::breakaway::BackEmfScale)), for the back-EMF speed of
    /// the next step; the controller sets it before each step on axes with current sense.
    pub fn set_back_emf(&mut self, emf: BackEmf) {
        self.emf = emf;
    }

    /// Whether the current showed the breakaway since the last call (once per start).
    pub fn take_breakaway(&mut self) -> bool {
        core::mem::replace(&mut self.breakaway_news, false)
    }

    /// The back-EMF speed the current shows, rad/s in the commanded direction (0 without
    /// current sense).
    pub fn back_emf_rad_s(&self) -> f32 {
        self.breakaway.speed_rad_s()
    }
}

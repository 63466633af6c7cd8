//! The breakaway seen in the motor current (issue 27 part 2): on an axis with current sense, the
//! back-EMF speed tells the loop that a shaft held by stiction has broken away, at once, where
//! the first edge may come a second later (12 pulses a revolution at 0.5 rad/s).
//!
//! The armature settles within a tick (`L / R` = 0.25 ms on the nominal motor, docs/model.md's
//! `L di/dt = V d - R i - k w`), so `i = (V d - k w) / R`: with `g = V / R` (times the sense
//! chain's gain; the supervisor's [`CurrentWatch`](super::supervisor::CurrentWatch) learns it,
//! and the offset, once, and the controller hands the loop `c = i / g`, the current as the duty
//! that drives it into a held shaft) the back-EMF speed is `w = (d - c) / (k / V)`. The loop's
//! `k / V` is learned where the edges measure the speed ([`BackEmfScale`]: commissioning's
//! steady steps, then every steady run); the identified `volts_per_rad_s / V` also holds the
//! viscous share (`k + R b / k`, 4.5 % on the nominal motor) and the identification's error,
//! and read through it the speed was 4 to 22 % low on the family. What is left is the current
//! per duty's error (a few percent of the current, a large share of it at low speed), so the
//! back-EMF speed serves for what a few percent do not change: the breakaway, and a dead band
//! around the model speed between the breakaway and the first valid measurement from the edges.

/// Weight of a new sample in the back-EMF speed's running mean (5 ms at 1 kHz: a tenth of a
/// nominal shaft's time constant; the 10 mA noise of one sample is 0.03 rad/s, 0.01 after it).
pub const SPEED_WEIGHT: f32 = 0.2;
/// The back-EMF speed, as a share of the reference, above which a shaft at rest has broken
/// away (a third of the way there: the kick's excess over friction is then spent).
pub const BREAKAWAY_SHARE: f32 = 0.3;
/// ... and never below this speed, rad/s (four times the filtered noise on the family's weakest
/// motor, while the reference ramps up from zero).
pub const BREAKAWAY_FLOOR_RAD_S: f32 = 0.05;
/// Consecutive samples above the threshold that confirm a breakaway.
pub const BREAKAWAY_CONFIRM: u8 = 3;
/// The dead band of the back-EMF speed around the model speed, as a share of it, inside which
/// the loop leaves the integral alone between the breakaway and the first measurement: wider
/// than the viscous share the back-EMF speed misses.
pub const FUSED_BAND_SHARE: f32 = 0.2;
/// The back-EMF speed, as a share of the model speed, above which the loop takes duty off
/// while the edges give no measurement: above the error of a current per duty not fitted in
/// this start (the supervisor's, up to 10 % off on the family: 0.1 rad/s at a duty of 0.15).
pub const FUSED_ABOVE_SHARE: f32 = 1.4;
/// The back-EMF speed, as a share of the model speed, above which a kick kept at the first
/// edge goes (`SpeedLoop`'s `drop_kept_kick_ahead`): read through the start's held ratio
/// ([`BackEmf`]) the back-EMF speed is the shaft's within a few percent, and a shaft 10 % ahead
/// of its model does not need the kick (at 1.2x seed 52 p21's rod kept it and ran 11.4 % past
/// 1 rad/s; at 1.1x it is within 1 %, and on the 27 families only two other axes moved,
/// both to less overshoot, from rest to 0.5 rad/s).
pub const KEPT_KICK_AHEAD_SHARE: f32 = 1.1;
/// The model speed's share of the reference from which the lower band applies.
pub const MODEL_THERE: f32 = 0.95;
/// Bandwidth of the integral on the back-EMF speed outside the band, rad/s (a loaded shaft that
/// crawls gets the duty it lacks within a second; slow against the plant's lag, so stable).
pub const FUSED_BANDWIDTH_RAD_S: f32 = 2.0;

/// The in-start fit of the held shaft's current per duty below the friction duty (see
/// [`Breakaway::sample`]) starts from the supervisor's `g` with this weight, duty^2 (as many
/// samples as ten at 0.03 duty): a light motor's duty passes the friction duty in ten ticks,
/// too few to fit alone; a heavy one's spends a hundred below it, and its fit then rules.
pub const FIT_PRIOR_DUTY2: f32 = 0.01;
/// Share of the identified friction duty below which a shaft is certainly held (stiction is at
/// least Coulomb friction, and material only adds to it): its current fits the held ratio.
pub const FIT_BELOW_FRICTION: f32 = 0.9;
/// Weight of a sample in the start's running mean of the current per duty `c / d` (100 ms at
/// 1 kHz: the 10 mA noise of a sample moves the mean by 0.6 mA, a few hundredths of a rad/s of
/// back-EMF speed). Its largest value over the start is the held shaft's ratio: the back-EMF
/// only lowers it (`c = h (d - e w)`), whatever load holds the shaft.
pub const RATIO_WEIGHT: f32 = 0.01;
/// The least duty whose current joins that mean (below it the ratio divides noise by little).
pub const RATIO_MIN_DUTY: f32 = 0.02;

/// The back-EMF is learned only from speeds the edges measure at or above this, rad/s: there
/// the back-EMF is most of the duty, so the current per duty's error (up to 25 % of the
/// current) moves it by a few percent at most; and the lowest speeds give windows of a second.
pub const SCALE_FROM_RAD_S: f32 = 1.0;
/// ... while the duty has stayed within this of its running mean for [`SCALE_HELD_S`]: a
/// shaft that accelerates is ahead of the edges' window mean (commissioning's reaction ramps
/// the spin's duty by 0.2 a second, 0.01 off its 50 ms mean: wound into the fit, that ramp
/// made it worse than the identified model).
pub const SCALE_DUTY_BAND: f32 = 0.003;
/// Seconds the duty must have held (see [`SCALE_DUTY_BAND`]).
pub const SCALE_HELD_S: f32 = 0.5;
/// Weight of a sample in the duty's running mean (50 ms at 1 kHz).
pub const SCALE_MEAN_WEIGHT: f32 = 0.02;
/// Samples of learning before the learned back-EMF replaces the identified model (a second:
/// the 10 mA noise of one sample averages out).
pub const SCALE_LEARNED_AFTER: u32 = 1000;
/// The learned back-EMF is kept between the identified `volts_per_rad_s / V` (which also holds
/// the viscous share: the back-EMF is below it) and that over this factor (a sense chain gone
/// wrong must not move the band far from the model). The families' viscous shares reach 43 %
/// of the slope (seed 52 p21's rod: back-EMF 0.70 of it); at 1.25 its reading was clamped
/// 14 % low.
pub const SCALE_RANGE: f32 = 1.6;

/// The back-EMF duty per rad/s as the current shows it where the edges measure the speed:
/// `d - c = e w` (least squares through zero over steady samples, commissioning's steps
/// first, then every steady run; `c` the current as the duty that drives it into a held
/// shaft, `w` the edges' speed). The identified `volts_per_rad_s` also holds the viscous share
/// and the identification's error: read through it, the back-EMF speed was 4 to 22 % low on
/// the family (docs/control.md, "The back-EMF learned at measured speeds"). A fit of the held
/// ratio beside it (`c = a (d - e w)`) was tried: the steps' duties are nearly in proportion
/// to their speeds, and it traded one for the other.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BackEmfScale {
    /// Sums over the learned samples of `w^2`, `(d - c) w` and `d w`, scaled by 1e-3.
    ww: f32,
    emf_w: f32,
    duty_w: f32,
    /// Running mean of the duty, and how long it has stayed near it, s.
    mean_duty: f32,
    held_s: f32,
    /// Samples learned from.
    learned: u32,
}

impl BackEmfScale {
    /// Nothing learned.
    pub const NONE: Self = Self {
        ww: 0.0,
        emf_w: 0.0,
        duty_w: 0.0,
        mean_duty: 0.0,
        held_s: 0.0,
        learned: 0,
    };

    /// One sample: `applied` duty and current `torque_duty` (both in the commanded direction,
    /// see [`Breakaway::sample`]) and the edges' speed `measured_rad_s` in that direction (0
    /// when there is no valid measurement), every `dt_s`.
    pub fn sample(&mut self, applied: f32, torque_duty: f32, measured_rad_s: f32, dt_s: f32) {
        if !(torque_duty.is_finite() && applied.is_finite() && measured_rad_s.is_finite()) {
            return;
        }
        self.mean_duty += (applied - self.mean_duty) * SCALE_MEAN_WEIGHT;
        self.held_s = if (applied - self.mean_duty).abs() <= SCALE_DUTY_BAND {
            self.held_s + dt_s
        } else {
            0.0
        };
        if self.held_s < SCALE_HELD_S || measured_rad_s < SCALE_FROM_RAD_S {
            return;
        }
        // Scaled so that hours of samples stay well inside f32.
        self.ww += 1e-3 * measured_rad_s * measured_rad_s;
        self.emf_w += 1e-3 * (applied - torque_duty) * measured_rad_s;
        self.duty_w += 1e-3 * applied * measured_rad_s;
        self.learned = self.learned.saturating_add(1);
    }

    /// What was learned of the back-EMF: once [`SCALE_LEARNED_AFTER`] samples taught it, the
    /// slopes of `d - c` and of `d` over the measured speed, else the `identified` slope.
    pub fn back_emf(&self, identified: f32) -> BackEmf {
        let learned = BackEmf {
            fitted: self.emf_w / self.ww,
            duty: self.duty_w / self.ww,
            identified,
        };
        if self.learned < SCALE_LEARNED_AFTER
            || self.ww <= 0.0
            || !(learned.fitted.is_finite() && learned.duty.is_finite())
        {
            return BackEmf::identified(identified);
        }
        learned
    }
}

/// The back-EMF duty per rad/s as far as the current sense has learned it ([`BackEmfScale`]),
/// to be read through the held ratio `h` a start measures ([`Breakaway::sample`]).
///
/// The current as the sense chain reads it is `c = h (d - e w)`: `h` the current per duty's
/// error (the supervisor's `g` is a mean over past starts, 8 % off on seed 52 p21's rod), the
/// same at every start. The learned samples hold it: `d - c = (1 - h) d + h e w`, so the slope
/// `fitted` of `d - c` is `(1 - h) duty + h e` with `duty` the slope of `d`. A start knows `h`
/// (the held shaft's current per duty) and reads the back-EMF as `(d - c / h) / e`: with
/// `fitted` for `e` a heavy rod read its speed 14 % low (seed 52 p21; `fitted` 0.120 against
/// the true 0.105 duty per rad/s) and ran 11.4 % past 1 rad/s on the half kick it kept.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BackEmf {
    /// Slope of `d - c` over the learned speeds, duty per rad/s.
    pub fitted: f32,
    /// Slope of `d` over the same speeds, duty per rad/s.
    pub duty: f32,
    /// The identified model's slope (`volts_per_rad_s / V`, the viscous share in it).
    pub identified: f32,
}

impl BackEmf {
    /// Nothing learned: the identified slope (which no held ratio changes: `duty` = `fitted`).
    pub const fn identified(identified: f32) -> Self {
        Self {
            fitted: identified,
            duty: identified,
            identified,
        }
    }

    /// The back-EMF duty per rad/s read through the held ratio `h` (1: none measured), kept
    /// within [`SCALE_RANGE`] below the identified slope (never above it: that one holds the
    /// viscous share too).
    pub fn duty_per_rad_s(&self, h: f32) -> f32 {
        let e = (self.fitted - (1.0 - h) * self.duty) / h;
        if !e.is_finite() || e > self.identified {
            self.identified
        } else if e < self.identified / SCALE_RANGE {
            self.identified / SCALE_RANGE
        } else {
            e
        }
    }
}

/// What the current says of one start.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Breakaway {
    /// The back-EMF speed's running mean, rad/s in the commanded direction.
    speed_rad_s: f32,
    /// A sample was taken since the loop started.
    sampled: bool,
    /// Consecutive samples above the breakaway threshold.
    above: u8,
    /// The current said the shaft broke away: kick and push are off.
    released: bool,
    /// Sums of `c d` and `d^2` over the held samples of this start (the fit's data).
    fit_cd: f32,
    fit_dd: f32,
    /// Running mean of `c / d` over this start, and its largest value (see [`RATIO_WEIGHT`]).
    ratio_mean: f32,
    ratio_max: f32,
}

impl Breakaway {
    /// Nothing seen.
    pub const NONE: Self = Self {
        speed_rad_s: 0.0,
        sampled: false,
        above: 0,
        released: false,
        fit_cd: 0.0,
        fit_dd: 0.0,
        ratio_mean: 0.0,
        ratio_max: 0.0,
    };

    /// One sample: `applied` duty and current `torque_duty` (both in the commanded direction,
    /// the current as the duty that drives it into a held shaft) over the last period, the
    /// identified `duty_per_rad_s` and `friction_duty`; while `starting` (at rest, not moved
    /// since the start) fits the held ratio, and while `watch` watches for the breakaway
    /// against the reference `r_abs` (`starting` and `watch`, in that order). Returns
    /// whether the shaft has broken away since the start.
    ///
    /// The supervisor's `g` is a mean over past starts of the largest window's ratio: a 2 %
    /// error reads as 0.05 rad/s of back-EMF at a duty of 0.4 (a heavy family plant's
    /// feedforward), more than the breakaway threshold while the reference ramps up. So while
    /// the duty is below [`FIT_BELOW_FRICTION`] of the friction duty (the shaft held for sure)
    /// the start fits `c = h d` (least squares through zero, from `h = 1`) and reads the
    /// current as `c / h`. A light shaft under material the model does not know is held far
    /// above that duty, where the fit has two or three samples and the prior rules (a `g` 26 %
    /// low when commissioning's starts broke it away below the duty that teaches `g`: seed 21
    /// p27's spin read -0.29 rad/s held, and its band drove it 30 % past 0.5 rad/s): `h` is
    /// at least the largest running mean of `c / d` this start (see [`RATIO_WEIGHT`]).
    pub fn sample(
        &mut self,
        applied: f32,
        torque_duty: f32,
        (emf, friction_duty): (BackEmf, f32),
        (starting, watch): (bool, bool),
        r_abs: f32,
    ) -> bool {
        if !(torque_duty.is_finite() && emf.identified > 0.0) {
            return self.released;
        }
        if starting
            && !self.released
            && applied > 0.0
            && applied <= FIT_BELOW_FRICTION * friction_duty
        {
            self.fit_cd += torque_duty * applied;
            self.fit_dd += applied * applied;
        }
        if starting && !self.released && applied >= RATIO_MIN_DUTY {
            self.ratio_mean += (torque_duty / applied - self.ratio_mean) * RATIO_WEIGHT;
            self.ratio_max = self.ratio_max.max(self.ratio_mean);
        }
        let h =
            ((self.fit_cd + FIT_PRIOR_DUTY2) / (self.fit_dd + FIT_PRIOR_DUTY2)).max(self.ratio_max);
        let h = if h > 0.5 { h } else { 1.0 };
        let w = (applied - torque_duty / h) / emf.duty_per_rad_s(h);
        if self.sampled {
            self.speed_rad_s += (w - self.speed_rad_s) * SPEED_WEIGHT;
        } else {
            self.speed_rad_s = w;
            self.sampled = true;
        }
        if watch && !self.released {
            let threshold = (BREAKAWAY_SHARE * r_abs).max(BREAKAWAY_FLOOR_RAD_S);
            // Below the friction duty the shaft is held for sure, whatever the current says:
            // there a back-EMF speed is the sense chain's offset and noise. The first sample
            // of a start, at zero duty, read -0.006 duty of current, 0.056 rad/s, above the
            // lowest speed's threshold (0.05): taken as a breakaway 3 ms into the start, it
            // ended the kick of a heavy rod whose feedforward alone (0.22 duty) could not
            // start it (0.33), the held ratio was never fitted, the band read the sense
            // chain's error as the model speed, and the expected-edge watch faulted the
            // healthy rod 7.5 s in (seed 31 p41 at 0.2 rad/s; docs/control.md, "A breakaway
            // below the friction duty").
            let may_turn = applied > FIT_BELOW_FRICTION * friction_duty;
            self.above = if may_turn && self.speed_rad_s > threshold {
                self.above.saturating_add(1)
            } else {
                0
            };
            self.released = self.above >= BREAKAWAY_CONFIRM;
        }
        self.released
    }

    /// The integral's change this tick (duty, in the commanded direction) between the breakaway
    /// and the first measurement from the edges (this start's fit holds the current's scale):
    /// the back-EMF speed held below [`FUSED_ABOVE_SHARE`] times the model speed `model_abs` (a
    /// shaft that leapt, brought back; the speed read is low if anything, by the viscous share,
    /// so this never slows a shaft at the model speed), and above `1 - FUSED_BAND_SHARE` of it
    /// once the model has reached [`MODEL_THERE`] of the reference `r_abs` (a loaded shaft that
    /// crawls gets the duty it lacks; a shaft still accelerating behind the model during a
    /// ramp, as at 0 -> 3 rad/s, is the edges' to judge).
    pub fn fused_integral_step(
        &self,
        (model_abs, r_abs): (f32, f32),
        duty_per_rad_s: f32,
        dt_s: f32,
    ) -> f32 {
        let lo = (1.0 - FUSED_BAND_SHARE) * model_abs;
        let hi = FUSED_ABOVE_SHARE * model_abs;
        let err = if self.speed_rad_s < lo && model_abs >= MODEL_THERE * r_abs {
            lo - self.speed_rad_s
        } else if self.speed_rad_s > hi {
            hi - self.speed_rad_s
        } else {
            0.0
        };
        FUSED_BANDWIDTH_RAD_S * dt_s * duty_per_rad_s * err
    }

    /// The first edge came before the current confirmed the breakaway (the back-EMF speed
    /// still below its threshold, or not yet for [`BREAKAWAY_CONFIRM`] samples): the edge
    /// proves it, and the band of [`Breakaway::fused_integral_step`] holds from here to the
    /// first measurement as it does after a breakaway the current saw.
    pub fn confirm(&mut self) {
        self.released = true;
    }

    /// The current showed the breakaway of this start.
    pub fn released(&self) -> bool {
        self.released
    }
    /// The back-EMF speed, rad/s in the commanded direction (0 before the first sample).
    pub fn speed_rad_s(&self) -> f32 {
        self.speed_rad_s
    }
}

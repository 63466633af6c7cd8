//! The once-per-revolution load of one axis, learned and fed forward.
//!
//! An eccentric bowl (a load off its axis) pulls with a torque that goes round with the shaft:
//! `T(theta) = T1 sin(theta + phi)`. The PI loop, sampling a few times a revolution and tuned to
//! the identified model, only reacts to the speed it already lost, so the true speed ripples at
//! the revolution (up to 5 % RMS at 1 rad/s on light spin axes, docs/control.md). Since the load
//! is a function of the angle, not of time, it can be learned once and given ahead of need.
//!
//! # What is learned
//! At each gap of the sensor wheel the identified model says what duty the shaft's motion
//! needed: `d = friction sign(w) + (Ke / V) (w + tau dw/dt)` (the first-order model the loop
//! runs, pi.rs), with `w` the gap's mean speed and `dw/dt` the central difference of the
//! neighbouring gaps' speeds. What the loop applied over the gap beyond that is the load's
//! share: `D_j = mean duty_j - d_j`, in duty. Over a whole revolution of contiguous gaps its
//! first Fourier harmonic at the gaps' middle angles, `D(theta) = a cos theta + b sin theta`, is
//! the once-per-revolution load (the mean belongs to the integral; higher harmonics are the
//! wheel's teeth and noise). Each revolution's `(a, b)` is averaged into the learned pair with
//! weight [`LEARN_WEIGHT`]; the mean over a gap of a sinusoid is `sinc(pi / N)` of its middle
//! value, which is divided out.
//!
//! It is a direct estimate, not an iteration on the error: what the feedforward already gives
//! is part of the applied duty, so the estimate does not depend on it and cannot wind up.
//!
//! # What is fed forward
//! `D(theta)` at the shaft's angle now: the angle of the last edge's tooth plus the plant
//! model's travel since (at most a pitch), from a start's first edge on. The angle is counted
//! in the wheel's gap index, so it means the same whichever way the shaft turns; a reversal
//! forgets the pattern.
//!
//! # When
//! Learned only at steady speed as the controller judges it (the reference unchanged and the
//! shaft within 10 % of the model) and at or below [`LEARN_BELOW_RAD_S`], from gaps measured
//! one pulse each and one edge per tick, with at least three teeth. Applied from the first learned revolution on, through set-point
//! changes (the load belongs to the angle, not to the speed), until the axis stops, reverses or
//! the tooth map starts its count afresh (a slipped count would put the pattern out of phase).
//!
//! # Before that: the load told from the wheel while commissioning
//! At one speed the wheel's own once-per-revolution pattern (a tooth angle error whose first
//! harmonic the tooth map leaves in, `h(theta)` in pitches, complex coefficient `P`) reads as a
//! load: the gaps' speed is `w (1 - h)` and their acceleration `-w^2 s h'` (`s = sin(2 pi / N) /
//! (2 pi / N)`, the central difference's gain), so the pattern found at speed `w` is
//! `D(w) = T + Ke/V w (1 - i tau s w) P` (coefficients `a + i b` of `a cos + b sin`): the load
//! `T` plus a wheel's share that grows with the speed along a curve the identified model gives.
//! Commissioning holds two duties on the spin, each for at least a whole revolution of gaps
//! after half its step time (commission.rs; not the rod, whose high step is the reaction's
//! reference); the last settled revolution of each is kept raw (the harmonics of the
//! duty, the gaps' speed and acceleration, [`LoadPattern::commission_tick`]), and once the model
//! is identified ([`LoadPattern::adopt`]) the two `D` give `T = (g2 D1 - g1 D2) / (g2 - g1)`,
//! `g = w (1 - i tau s w)`, when the high step is at least [`SEPARATE_SPEED_RATIO`] times the
//! low one's speed and each revolution's speed drifted by at most [`STEADY_DRIFT`]. That `T` is
//! fed forward from the first start until a pattern is learned in
//! closed loop, and kept through stops (the tooth map keeps its count through a stop too); a
//! reversal, a slipped count or a new commissioning forgets it.

use super::config::AxisConfig;
use super::const_trig::{cos_const, sin_const};
use super::estimator::{Gap, PulseSpeedEstimator};
use super::teeth::SLOWEST_LEARNED_REVOLUTION_S;

/// Weight of one revolution's estimate in the learned pattern after the first: about three
/// revolutions' memory (edge jitter of 0.1 ms leaves a per mille of the pattern's noise).
pub const LEARN_WEIGHT: f32 = 0.35;
/// Learned only at or below this speed, rad/s: where a revolution takes at least as long as
/// the slowest the tooth map learns from ([`SLOWEST_LEARNED_REVOLUTION_S`], 4 s). Above it the
/// wheel's own once-per-revolution pattern, which neither the tooth map nor this module can
/// tell from a load at one speed, reads as a load growing with the speed (its apparent speed
/// variation scales with `w`, its acceleration with `w^2`) while a true load's share of the
/// duty does not; learned at 2 and 3 rad/s on family-60 the pattern made the worst ripple
/// after a later step to 1 rad/s 7.98 % instead of 3.89 % (none learned) or 1.53 % (learned
/// at 1 rad/s). Below it the load is the larger part. What is learned below is applied at every
/// speed: the load belongs to the angle.
pub const LEARN_BELOW_RAD_S: f32 = core::f32::consts::TAU / SLOWEST_LEARNED_REVOLUTION_S;
/// The commissioning's high step must be at least this much faster than its low step for the
/// wheel's pattern and the load to be told apart.
pub const SEPARATE_SPEED_RATIO: f32 = 1.3;
/// A commissioning step's revolution is kept only if the speed at its first gap changed by
/// at most this share over the revolution (the shaft settled at the step's speed).
pub const STEADY_DRIFT: f32 = 0.03;
/// A revolution whose pattern is larger than this (duty, amplitude) is no eccentric load (a
/// stall, a hand on the bowl): not learned from.
pub const MAX_AMPLITUDE_DUTY: f32 = 0.3;

/// One gap's measurement, kept for the central difference.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Sample {
    index: u16,
    /// Mean speed over the gap, rad/s, signed (the commanded direction).
    speed_rad_s: f32,
    /// Mean duty applied over the gap, signed.
    duty: f32,
    /// The gap's middle, extended clock ticks.
    mid: u32,
}

/// One revolution's first harmonics (cos, sin) of the duty applied, the gaps' speeds and their
/// accelerations, raw, so that the load `duty - Ke/V (speed + tau accel)` can be formed with
/// whichever model holds when it is used (a commissioning step's, before the model is known).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Revolution {
    /// The revolution's mean speed, rad/s (0: none recorded).
    speed_rad_s: f32,
    /// cos and sin coefficients of the duty, the speed (rad/s) and the acceleration (rad/s^2).
    sums: [f32; 6],
}

/// The once-per-revolution load pattern of one axis (see the module's text).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadPattern {
    /// Identified model: duty per rad/s, and that times the time constant.
    duty_per_rad_s: f32,
    duty_s_per_rad_s: f32,
    /// cos and sin of half a gap's angle (a gap's middle is half a gap before its end), and
    /// `1 / sinc(pi / N)` (a gap's mean of a sinusoid to the value at its middle).
    half_cos: f32,
    half_sin: f32,
    mean_to_middle: f32,
    /// The learned pattern, duty: `a cos theta + b sin theta`.
    a: f32,
    b: f32,
    revolutions: u16,
    /// This revolution's sums (duty, speed, acceleration times cos and sin at each gap's
    /// middle), its gaps' speeds summed, and its gaps so far.
    sums: [f32; 6],
    speed_sum: f32,
    gaps: u16,
    /// The speed of this revolution's first gap, rad/s.
    first_speed_rad_s: f32,
    /// The commissioning step being learned from (0: none, 1: low, 2: high) and the last
    /// revolution of each step.
    step: u8,
    steps: [Revolution; 2],
    /// The load alone, from the two steps (the wheel's pattern taken out), duty: `a cos + b
    /// sin`; fed forward until a pattern is learned in closed loop.
    prior: [f32; 2],
    /// The last two gaps of an unbroken chain (`chain` of them valid), oldest first.
    last: [Sample; 2],
    chain: u8,
    /// Duty applied since the last gap ended, summed per tick.
    duty_sum: f32,
    duty_ticks: u32,
    /// The serial of the last gap seen, and the tooth map's learned revolutions then.
    seen_serial: u32,
    teeth_revs: u16,
}

impl LoadPattern {
    /// Nothing learned, for `axis` on a supply of `supply_v`.
    pub const fn new(axis: &AxisConfig, supply_v: f32) -> Self {
        let n = axis.pulses_per_rev;
        let half = if n >= 3 {
            core::f32::consts::PI / n as f32
        } else {
            0.0
        };
        let duty_per_rad_s = axis.model.volts_per_rad_s / supply_v;
        Self {
            duty_per_rad_s,
            duty_s_per_rad_s: duty_per_rad_s * axis.model.time_constant_s,
            half_cos: cos_const(half),
            half_sin: sin_const(half),
            mean_to_middle: if half > 0.0 {
                half / sin_const(half)
            } else {
                1.0
            },
            a: 0.0,
            b: 0.0,
            revolutions: 0,
            sums: [0.0; 6],
            speed_sum: 0.0,
            gaps: 0,
            first_speed_rad_s: 0.0,
            step: 0,
            steps: [Revolution {
                speed_rad_s: 0.0,
                sums: [0.0; 6],
            }; 2],
            prior: [0.0; 2],
            last: [Sample {
                index: 0,
                speed_rad_s: 0.0,
                duty: 0.0,
                mid: 0,
            }; 2],
            chain: 0,
            duty_sum: 0.0,
            duty_ticks: 0,
            seen_serial: 0,
            teeth_revs: 0,
        }
    }

    /// Forgets the pattern learned in closed loop (the axis stopped); the load found while
    /// commissioning is kept: the wheel's count goes on (the tooth map keeps it through a stop
    /// and says when it slipped).
    pub const fn forget(&mut self) {
        self.a = 0.0;
        self.b = 0.0;
        self.revolutions = 0;
        self.break_chain();
    }

    /// Forgets everything, the commissioning's load too (a reversal, a slipped count).
    pub const fn forget_all(&mut self) {
        self.forget();
        self.prior = [0.0; 2];
        self.steps = [Revolution {
            speed_rad_s: 0.0,
            sums: [0.0; 6],
        }; 2];
    }

    const fn break_chain(&mut self) {
        self.chain = 0;
        self.gaps = 0;
        self.sums = [0.0; 6];
        self.speed_sum = 0.0;
    }

    /// Takes over what `old` (the pattern before the configuration changed, same wheel)
    /// learned while commissioning and forms the load from it with this pattern's model.
    #[cold]
    #[inline(never)]
    pub fn adopt(&mut self, old: &LoadPattern) {
        if old.mean_to_middle != self.mean_to_middle {
            return;
        }
        self.steps = old.steps;
        self.teeth_revs = old.teeth_revs;
        self.seen_serial = old.seen_serial;
        self.prior = self.separate();
    }

    /// The load apart from the wheel, from the two commissioning steps (see the module's
    /// text): zero unless both were learned at clearly different speeds.
    fn separate(&self) -> [f32; 2] {
        let [lo, hi] = self.steps;
        let (w1, w2) = (lo.speed_rad_s, hi.speed_rad_s);
        if !(w1 > 0.0 && w2 >= SEPARATE_SPEED_RATIO * w1) {
            return [0.0; 2];
        }
        let (d1, d2) = (self.load_of(&lo), self.load_of(&hi));
        // g(w) = w (1 - i tau s w), s = sin(2 pi / N) / (2 pi / N) of the central difference.
        // sin(2h) / (2h) = cos h / (h / sin h), h half a gap.
        let diff_gain = self.half_cos / self.mean_to_middle;
        let ts = self.duty_s_per_rad_s / self.duty_per_rad_s * diff_gain;
        let g = |w: f32| [w, -ts * w * w];
        let (g1, g2) = (g(w1), g(w2));
        // T = (g2 D1 - g1 D2) / (g2 - g1).
        let num = [
            g2[0] * d1[0] - g2[1] * d1[1] - g1[0] * d2[0] + g1[1] * d2[1],
            g2[0] * d1[1] + g2[1] * d1[0] - g1[0] * d2[1] - g1[1] * d2[0],
        ];
        let den = [g2[0] - g1[0], g2[1] - g1[1]];
        let den2 = den[0] * den[0] + den[1] * den[1];
        let t = [
            (num[0] * den[0] + num[1] * den[1]) / den2,
            (num[1] * den[0] - num[0] * den[1]) / den2,
        ];
        let size = t[0] * t[0] + t[1] * t[1];
        if size.is_nan() || size > MAX_AMPLITUDE_DUTY * MAX_AMPLITUDE_DUTY {
            return [0.0; 2];
        }
        t
    }

    /// A revolution's load by this pattern's model, duty (cos, sin).
    fn load_of(&self, r: &Revolution) -> [f32; 2] {
        let s = &r.sums;
        [
            s[0] - self.duty_per_rad_s * s[2] - self.duty_s_per_rad_s * s[4],
            s[1] - self.duty_per_rad_s * s[3] - self.duty_s_per_rad_s * s[5],
        ]
    }

    /// One commissioning tick on the axis under test: `applied_duty` drove the shaft since the
    /// last tick, `step` is the step (1 low, 2 high, 0 none) it belonged to. The last whole
    /// revolution of each step is kept, raw.
    #[inline(never)]
    pub fn commission_tick(&mut self, est: &PulseSpeedEstimator, applied_duty: f32, step: u8) {
        if step != self.step {
            if step == 1 {
                // A new commissioning: nothing of an earlier one.
                self.forget_all();
            }
            self.break_chain();
            self.step = step;
        }
        self.observe(est, applied_duty, 1.0, step != 0, step);
    }

    /// Revolutions learned since the pattern was last forgotten.
    pub fn revolutions_learned(&self) -> u16 {
        self.revolutions
    }

    /// The amplitude of the pattern fed forward, duty: the one learned in closed loop, or
    /// before it the load found while commissioning.
    pub fn amplitude_duty(&self) -> f32 {
        let [a, b] = self.fed();
        libm::sqrtf(a * a + b * b)
    }

    /// The pattern fed forward, `(a, b)` of `a cos + b sin`, duty.
    fn fed(&self) -> [f32; 2] {
        if self.revolutions > 0 {
            [self.a, self.b]
        } else {
            self.prior
        }
    }

    /// One control tick, after the estimator's: `applied_duty` is the duty that drove the shaft
    /// since the previous tick, `direction` the commanded one (+1 or -1), `learn` whether the
    /// speed is steady, `model_rad_s` the plant model's speed (magnitude). Returns the duty to
    /// feed forward now (0 until a revolution is learned, and while the shaft is at rest).
    #[inline(always)]
    pub fn tick(
        &mut self,
        est: &PulseSpeedEstimator,
        applied_duty: f32,
        direction: f32,
        learn: bool,
        model_rad_s: f32,
    ) -> f32 {
        let slow = model_rad_s <= LEARN_BELOW_RAD_S;
        if !self.observe(est, applied_duty, direction, learn && slow, 0) {
            return 0.0;
        }
        let [a, b] = self.fed();
        // From the first edge on, not from the first measurement: the count runs through a
        // stop, so the first edge's tooth is known. Unfed until the first window closed, the
        // load's value at that angle went into the start's reading as a steady load and was
        // then given twice (seed 8 p24's spin at 1 rad/s: 2 % settled at 3.42 -> 2.17 s;
        // docs/control.md, "The eccentric load fed from the first edge").
        if (a == 0.0 && b == 0.0) || est.at_rest() {
            return 0.0;
        }
        let teeth = est.teeth();
        // The angle now: the last edge's tooth (the first edge from rest makes no gap, so not
        // `last_gap`), plus the model's travel since (at most a pitch), by a short series (the
        // pitch is at most 2 pi / 3).
        let (c, s) = teeth.tooth_cos_sin(teeth.index());
        let pitch = est.rad_per_pulse();
        let travel = est.since_edge_s() * model_rad_s;
        let phi = if travel < pitch { travel } else { pitch };
        let phi2 = phi * phi;
        let (cp, sp) = (1.0 - 0.5 * phi2, phi * (1.0 - phi2 / 6.0));
        a * (c * cp - s * sp) + b * (s * cp + c * sp)
    }

    /// Follows the gaps and learns from them when `learn` (a revolution goes to commissioning
    /// step `step`, 0: the loop's pattern); false while the wheel has too few teeth to learn
    /// from.
    #[inline(never)]
    fn observe(
        &mut self,
        est: &PulseSpeedEstimator,
        applied_duty: f32,
        direction: f32,
        learn: bool,
        step: u8,
    ) -> bool {
        let teeth = est.teeth();
        if teeth.teeth() < 3 {
            return false;
        }
        if teeth.revolutions_learned() < self.teeth_revs {
            // The tooth map started its count afresh: the index may have slipped.
            self.forget_all();
        }
        self.teeth_revs = teeth.revolutions_learned();
        self.duty_sum += applied_duty;
        self.duty_ticks += 1;
        let gap = est.last_gap();
        if gap.serial != self.seen_serial {
            let follows = gap.serial == self.seen_serial.wrapping_add(1);
            self.seen_serial = gap.serial;
            if learn && follows && gap.ticks > 0 && self.duty_ticks > 0 {
                self.on_gap(est, gap, direction, teeth.teeth(), step);
            } else {
                self.break_chain();
            }
            self.duty_sum = 0.0;
            self.duty_ticks = 0;
        } else if est.accepted_edges() != gap.serial {
            // An edge of more than one pulse (inferred missing ones): no gap to learn from.
            self.seen_serial = est.accepted_edges();
            self.break_chain();
            self.duty_sum = 0.0;
            self.duty_ticks = 0;
        }
        true
    }

    /// A gap that follows the last one, at steady speed.
    #[cold]
    #[inline(never)]
    fn on_gap(
        &mut self,
        est: &PulseSpeedEstimator,
        gap: Gap,
        direction: f32,
        teeth: u16,
        step: u8,
    ) {
        let dt_s = gap.ticks as f32 * est.s_per_tick();
        let new = Sample {
            index: gap.index,
            speed_rad_s: direction * gap.pitches * est.rad_per_pulse() / dt_s,
            duty: self.duty_sum / self.duty_ticks as f32,
            mid: gap.end.wrapping_sub(gap.ticks / 2),
        };
        if self.chain >= 2 {
            // The middle gap's load, by the central difference of its neighbours' speeds.
            let [old, mid] = self.last;
            let span_s = new.mid.wrapping_sub(old.mid) as f32 * est.s_per_tick();
            if span_s > 0.0 {
                let accel = (new.speed_rad_s - old.speed_rad_s) / span_s;
                // The middle gap's middle angle: its end tooth less half a gap. (The friction,
                // a constant, has no harmonic over a revolution.)
                let (c, s) = est.teeth().tooth_cos_sin(mid.index);
                let cm = c * self.half_cos + s * self.half_sin;
                let sm = s * self.half_cos - c * self.half_sin;
                for (k, v) in [mid.duty, mid.speed_rad_s, accel].into_iter().enumerate() {
                    self.sums[2 * k] += v * cm;
                    self.sums[2 * k + 1] += v * sm;
                }
                if self.gaps == 0 {
                    self.first_speed_rad_s = mid.speed_rad_s;
                }
                self.speed_sum += mid.speed_rad_s;
                self.gaps += 1;
                if self.gaps >= teeth {
                    // `new` ends at the revolution's first tooth again: the same gap a
                    // revolution later, so the difference is the speed's drift alone.
                    let drift = new.speed_rad_s - self.first_speed_rad_s;
                    self.end_revolution(teeth, step, drift);
                }
            }
        }
        self.last = [self.last[1], new];
        self.chain = if self.chain < 2 { self.chain + 1 } else { 2 };
    }

    /// A whole revolution of gaps summed: its harmonic goes into the pattern.
    fn end_revolution(&mut self, teeth: u16, step: u8, drift_rad_s: f32) {
        let scale = 2.0 * self.mean_to_middle / teeth as f32;
        let mut rev = Revolution {
            speed_rad_s: (self.speed_sum / teeth as f32).abs(),
            sums: self.sums,
        };
        for v in &mut rev.sums {
            *v *= scale;
        }
        self.gaps = 0;
        self.sums = [0.0; 6];
        self.speed_sum = 0.0;
        if let Some(slot) = self.steps.get_mut((step as usize).wrapping_sub(1)) {
            // Only a settled step: a shaft still approaching its speed (a slow axis half a
            // step in) leaks its trend into the harmonic by the model's error.
            if drift_rad_s.abs() <= STEADY_DRIFT * rev.speed_rad_s {
                *slot = rev;
            }
            return;
        }
        let [a, b] = self.load_of(&rev);
        // Also refuses NaN (a gap of no duration cannot reach here, but nothing is assumed).
        let size = a * a + b * b;
        if size.is_nan() || size > MAX_AMPLITUDE_DUTY * MAX_AMPLITUDE_DUTY {
            return;
        }
        if self.revolutions == 0 {
            (self.a, self.b) = (a, b);
        } else {
            self.a += LEARN_WEIGHT * (a - self.a);
            self.b += LEARN_WEIGHT * (b - self.b);
        }
        self.revolutions = self.revolutions.saturating_add(1);
    }
}

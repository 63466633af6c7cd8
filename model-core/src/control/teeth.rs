//! The sensor wheel's tooth offsets, learned while the speed is steady, so that a worn or
//! unevenly cut wheel does not read as speed ripple.
//!
//! A wheel whose tooth `j` sits `e_j` pitches off its nominal place makes the gap that ends at
//! that tooth `1 + e_j - e_(j-1)` pitches long; at a steady speed each pulse interval is then that
//! fraction of the mean interval, and a speed taken from one interval is off by the same
//! fraction (5 % with teeth 5 % of a pitch off: the loop chases it and the true speed ripples).
//! The edges are counted around the wheel (the index of each gap, modulo the teeth), and each
//! gap's length is learned as the fraction `f_j = N dt_j / (sum of the last N intervals)`, the
//! gap's share of the revolution that ends with it, averaged over the revolutions (the last
//! five or so, [`LEARN_WEIGHT`]). The estimator then counts each gap as `f_j` pitches instead of one.
//!
//! What it cannot tell apart at one speed: a once-per-revolution load (an eccentric bowl) makes
//! the true speed vary with the same period, and would be learned as part of the gaps' pattern,
//! hiding a real speed variation from the loop. So the pattern's once-per-revolution component
//! (its first Fourier harmonic) is left out of the correction: the loop keeps seeing, and
//! fighting, the eccentric load, while the rest of the tooth pattern (for random offsets of 12
//! teeth all but about a sixth of its power) no longer reads as ripple.
//!
//! Learning only runs at steady speed (a speed change inside the revolution would be learned as
//! a pattern) and on contiguous single-pulse gaps (an inferred missing pulse breaks the chain). A
//! wheel with more than [`MAX_TEETH`] teeth is not learned: its window spans several gaps anyway.
//!
//! The gap count must never slip: a reversal ([`ToothMap::forget`]) or a revolution whose learned
//! pattern fits worse than none (a lost edge shifted the count) starts learning afresh.

use super::const_trig::{cos_const, sin_const};

/// The most teeth whose offsets are learned.
pub const MAX_TEETH: usize = 64;

/// Weight of one revolution's measurement in the learned fraction once learned: the mean of
/// the revolutions so far until there are five, then an average over about five (it follows a
/// wheel that changes, and 0.1 ms of edge jitter leaves a few percent of its noise).
pub const LEARN_WEIGHT: f32 = 0.2;

/// The slowest revolution learned from, s. Slower, the loop's gain (scheduled by the pulse
/// rate) barely follows single gaps, so tooth offsets cost little ripple, while an eccentric
/// load's torque is a large share of the drive and bends the gaps' pattern with its harmonics:
/// learned, they would hide a real speed variation (measured on the test family at 0.5 rad/s).
pub const SLOWEST_LEARNED_REVOLUTION_S: f32 = 4.0;

/// A revolution whose gaps the pattern in use explains this much worse than no pattern means
/// the count slipped.
const SLIP_MISFIT_RATIO: f32 = 1.5;
/// Per gap, a squared misfit below which any fit is good: 0.1 % of a gap (edge jitter).
const MISFIT_FLOOR: f32 = 1e-6;

/// Revolutions learned before the fractions are used, and before a bad fit can reset them.
const WARM_UP_REVS: u16 = 2;

/// Learned gap lengths of one wheel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToothMap {
    teeth: u16,
    /// cos and sin of each gap's angle `2 pi j / teeth`, for the first harmonic.
    cos: [f32; MAX_TEETH],
    sin: [f32; MAX_TEETH],
    /// Index of the gap that ends at the last edge.
    index: u16,
    /// The last intervals, by gap index, ticks; `chain` of them are contiguous.
    intervals: [u32; MAX_TEETH],
    chain: u16,
    /// Sum of the `teeth` intervals in `intervals` once the chain is full (a revolution that
    /// does not fit in 32 bits of ticks is not learned).
    revolution_ticks: u32,
    /// Revolutions longer than this are not learned from ([`SLOWEST_LEARNED_REVOLUTION_S`]).
    slowest_revolution_ticks: u32,
    /// Learned length of each gap, pitches (1 = nominal).
    fraction: [f32; MAX_TEETH],
    /// `sum f_j (1, cos, sin)` over the revolution being learned, gap by gap as each is
    /// updated, so using the pattern never needs a loop over the wheel.
    next_sums: [f32; 3],
    /// The correction in use, from the last complete revolution's sums: gap `j` counts
    /// `scale f_j - harmonic_cos cos_j - harmonic_sin sin_j` pitches.
    scale: f32,
    harmonic_cos: f32,
    harmonic_sin: f32,
    /// This revolution's learning weight.
    weight: f32,
    revs_learned: u16,
    /// Over the current revolution: squared misfit of the pattern in use and of none.
    misfit_learned: f32,
    misfit_nominal: f32,
    gaps_this_rev: u16,
    /// Gaps counted but not yet learned from, oldest first: `(gap index, ticks)`, ticks 0 for
    /// a break in the chain. Learning runs in ticks without an edge ([`Self::learn_pending`]),
    /// so a tick that handles edges never also learns.
    pending: [(u16, u32); PENDING],
    pending_len: u8,
    /// The pattern's first harmonic is left in (the wheel's shaft may carry a
    /// once-per-revolution load: the spin's tilted bowl); false about the vertical.
    keeps_first_harmonic: bool,
}

/// Gaps that wait to be learned from; more than a few only wait when edges come in consecutive
/// ticks (then the chain restarts after them).
const PENDING: usize = 4;

impl ToothMap {
    /// A wheel of `pulses_per_rev` teeth timed by a clock of `ticks_per_s`, nothing learned.
    pub const fn new(pulses_per_rev: u16, ticks_per_s: f32) -> Self {
        let teeth = if (pulses_per_rev as usize) <= MAX_TEETH {
            pulses_per_rev
        } else {
            0
        };
        // The first harmonic is only told from the rest with at least 3 gaps.
        let (cos_gap, sin_gap) = if teeth >= 3 {
            let g = core::f32::consts::TAU / teeth as f32;
            (cos_const(g), sin_const(g))
        } else {
            (1.0, 0.0)
        };
        let mut cos = [0.0; MAX_TEETH];
        let mut sin = [0.0; MAX_TEETH];
        let (mut c, mut s) = (1.0f32, 0.0f32);
        let mut j = 0;
        while j < MAX_TEETH {
            cos[j] = c;
            sin[j] = s;
            (c, s) = (c * cos_gap - s * sin_gap, s * cos_gap + c * sin_gap);
            j += 1;
        }
        Self {
            teeth,
            cos,
            sin,
            index: 0,
            intervals: [0; MAX_TEETH],
            chain: 0,
            revolution_ticks: 0,
            slowest_revolution_ticks: (SLOWEST_LEARNED_REVOLUTION_S * ticks_per_s) as u32,
            fraction: [1.0; MAX_TEETH],
            next_sums: [0.0; 3],
            scale: 1.0,
            harmonic_cos: 0.0,
            harmonic_sin: 0.0,
            weight: 1.0,
            revs_learned: 0,
            misfit_learned: 0.0,
            misfit_nominal: 0.0,
            gaps_this_rev: 0,
            pending: [(0, 0); PENDING],
            pending_len: 0,
            keeps_first_harmonic: true,
        }
    }

    /// The map of a wheel on a shaft turning about the vertical (the precession): gravity
    /// puts no once-per-revolution torque on it, so the whole pattern, its first harmonic
    /// too, is the wheel's and is taken out (left in, the loop chases it and the rod's
    /// true speed ripples once per revolution, +/-2.5 % at 1 rad/s on family-60).
    pub const fn about_the_vertical(&mut self) {
        self.keeps_first_harmonic = false;
    }

    /// The map is learned: in use (its warm-up revolutions learned) and averaged over one
    /// revolution more (the first revolution counts whole, with its edge jitter: up to 1 ms,
    /// 1 % of a gap at 5 rad/s on 12 teeth), or it counts no wheel (too few teeth for the
    /// first harmonic, or too many to learn) and never will be.
    pub fn learned(&self) -> bool {
        self.teeth < 3 || self.revs_learned > WARM_UP_REVS
    }

    /// Forgets what was learned (the wheel turns the other way, or the count may have slipped).
    /// The wheel's geometry (its teeth, the harmonic's table) stays.
    pub fn forget(&mut self) {
        self.fraction = [1.0; MAX_TEETH];
        self.scale = 1.0;
        self.harmonic_cos = 0.0;
        self.harmonic_sin = 0.0;
        self.weight = 1.0;
        self.revs_learned = 0;
        self.pending_len = 0;
        self.break_chain();
    }

    /// The next interval does not follow the last one (or is not learned from): the chain,
    /// and the revolution being summed and judged, start again.
    fn break_chain(&mut self) {
        self.chain = 0;
        self.revolution_ticks = 0;
        self.next_sums = [0.0; 3];
        self.misfit_learned = 0.0;
        self.misfit_nominal = 0.0;
        self.gaps_this_rev = 0;
    }

    /// Teeth counted around the wheel (0: a wheel not counted, more than [`MAX_TEETH`]).
    pub fn teeth(&self) -> u16 {
        self.teeth
    }

    /// Index of the gap that ended at the last edge, counted around the wheel.
    pub fn index(&self) -> u16 {
        self.index
    }

    /// cos and sin of the angle `2 pi j / teeth` of tooth `j` (gap `j` ends there); (1, 0)
    /// outside the wheel.
    pub fn tooth_cos_sin(&self, j: u16) -> (f32, f32) {
        match (self.cos.get(j as usize), self.sin.get(j as usize)) {
            (Some(&c), Some(&s)) if j < self.teeth => (c, s),
            _ => (1.0, 0.0),
        }
    }

    /// Revolutions learned so far.
    pub fn revolutions_learned(&self) -> u16 {
        self.revs_learned
    }

    /// How many pitches gap `j` counts for: its learned length, scaled so the wheel is `n`
    /// pitches, less the pattern's first harmonic (1 before learning, and for unlearned
    /// wheels).
    pub fn fraction(&self, j: usize) -> f32 {
        if self.revs_learned < WARM_UP_REVS || j >= self.teeth as usize {
            return 1.0;
        }
        self.scale * self.fraction[j]
            - self.harmonic_cos * self.cos[j]
            - self.harmonic_sin * self.sin[j]
    }

    /// An edge `pulses` gaps after the previous one, `dt_ticks` after it (0: the first edge
    /// after rest, no interval). `learn`: the speed is steady. Returns how many pitches the shaft
    /// turned, by the learned gap lengths; the gap waits to be learned from.
    pub fn edge(&mut self, dt_ticks: u32, pulses: u32, learn: bool) -> f32 {
        let n = self.teeth as usize;
        if n < 2 {
            return pulses as f32;
        }
        let mut pitches = 0.0;
        for _ in 0..pulses.min(n as u32) {
            self.index = if self.index as usize + 1 >= n {
                0
            } else {
                self.index + 1
            };
            pitches += self.fraction(self.index as usize);
        }
        if pulses > n as u32 {
            pitches += (pulses - n as u32) as f32;
        }
        let sample = if learn && pulses == 1 {
            (self.index, dt_ticks)
        } else {
            (self.index, 0)
        };
        match self.pending.get_mut(self.pending_len as usize) {
            Some(slot) => {
                *slot = sample;
                self.pending_len += 1;
            }
            // Edges faster than the learning: the chain restarts after them.
            None => {
                self.pending = [(0, 0); PENDING];
                self.pending_len = 1;
            }
        }
        pitches
    }

    /// The last whole revolution's length, ticks, once the chain of learned gaps spans one
    /// (at a steady reference); tooth offsets and a once-per-revolution load cancel in it.
    pub fn revolution_ticks(&self) -> Option<u32> {
        if self.teeth >= 2 && self.chain == self.teeth && self.revolution_ticks > 0 {
            Some(self.revolution_ticks)
        } else {
            None
        }
    }

    /// Learns from the oldest waiting gap (the estimator calls this in ticks without an edge).
    pub fn learn_pending(&mut self) {
        let n = self.teeth as usize;
        if self.pending_len == 0 || n < 2 {
            return;
        }
        let (j, dt_ticks) = self.pending[0];
        self.pending.copy_within(1.., 0);
        self.pending_len -= 1;
        let j = j as usize;
        if dt_ticks == 0 || j >= n {
            self.break_chain();
            return;
        }
        let kept = if (self.chain as usize) < n {
            self.chain += 1;
            self.revolution_ticks
        } else {
            self.revolution_ticks - self.intervals[j]
        };
        let Some(total) = kept.checked_add(dt_ticks) else {
            self.break_chain();
            return;
        };
        self.revolution_ticks = total;
        self.intervals[j] = dt_ticks;
        if (self.chain as usize) == n && self.revolution_ticks <= self.slowest_revolution_ticks {
            self.learn(j, n, dt_ticks);
        }
    }

    fn learn(&mut self, j: usize, n: usize, dt_ticks: u32) {
        let measured = n as f32 * dt_ticks as f32 / self.revolution_ticks as f32;
        // How well the pattern in use and the nominal one explain this gap.
        let in_use = self.fraction(j);
        self.misfit_learned += (measured - in_use) * (measured - in_use);
        self.misfit_nominal += (measured - 1.0) * (measured - 1.0);
        self.fraction[j] += self.weight * (measured - self.fraction[j]);
        let f = self.fraction[j];
        self.next_sums[0] += f;
        self.next_sums[1] += f * self.cos[j];
        self.next_sums[2] += f * self.sin[j];
        self.gaps_this_rev += 1;
        if (self.gaps_this_rev as usize) < n {
            return;
        }
        // A revolution complete: every gap was updated once and summed after its update. A
        // slipped count fits about twice as badly as no pattern; the floor keeps a perfect
        // wheel (both misfits at rounding level) from looking slipped.
        let was_in_use = self.revs_learned >= WARM_UP_REVS;
        let slipped = was_in_use
            && self.misfit_learned
                > SLIP_MISFIT_RATIO * self.misfit_nominal + n as f32 * MISFIT_FLOOR;
        let [sum, sum_cos, sum_sin] = self.next_sums;
        self.next_sums = [0.0; 3];
        self.gaps_this_rev = 0;
        self.misfit_learned = 0.0;
        self.misfit_nominal = 0.0;
        if slipped {
            // The count slipped (or the wheel changed): start again.
            self.forget();
        } else if sum > 0.0 {
            // The wheel is n pitches: scale = n / sum. The first harmonic of the scaled
            // fractions is (2/n) scale (sum_cos cos_j + sum_sin sin_j): the constant part has
            // none (the cosines and sines over the wheel sum to zero).
            self.revs_learned = self.revs_learned.saturating_add(1);
            self.weight = (1.0 / (f32::from(self.revs_learned) + 1.0)).max(LEARN_WEIGHT);
            self.scale = n as f32 / sum;
            let h = if n >= 3 && self.keeps_first_harmonic {
                2.0 / n as f32 * self.scale
            } else {
                0.0
            };
            self.harmonic_cos = h * sum_cos;
            self.harmonic_sin = h * sum_sin;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 12-tooth wheel with offsets up to 5 % of a pitch at a steady 1000 ticks per pitch.
    fn offsets() -> [f32; 12] {
        [
            0.0, 0.05, -0.03, 0.02, -0.05, 0.04, 0.01, -0.02, 0.03, -0.04, 0.0, 0.05,
        ]
    }

    fn gap_ticks(e: &[f32; 12], j: usize) -> u32 {
        let prev = e[(j + 11) % 12];
        (1000.0 * (1.0 + e[j] - prev)).round() as u32
    }

    /// The gaps' true lengths, pitches: `1 + e_j - e_(j-1)`.
    fn gaps(e: &[f32; 12]) -> [f64; 12] {
        core::array::from_fn(|j| f64::from(1.0 + e[j] - e[(j + 11) % 12]))
    }

    /// The once-per-revolution part of the gap pattern at gap `j` (an independent f64 DFT).
    fn first_harmonic(g: &[f64; 12], j: usize) -> f64 {
        let w = core::f64::consts::TAU / 12.0;
        (0..12)
            .map(|k| (g[k] - 1.0) * ((j as f64 - k as f64) * w).cos())
            .sum::<f64>()
            * 2.0
            / 12.0
    }

    #[test]
    fn learns_the_gaps_but_leaves_the_once_per_revolution_part() {
        let e = offsets();
        let g = gaps(&e);
        let mut map = ToothMap::new(12, 1e6);
        let mut index = 0;
        let (mut worst, mut rms_learned, mut rms_plain) = (0.0f64, 0.0f64, 0.0f64);
        for rev in 0..12 {
            for _ in 0..12 {
                index = (index + 1) % 12;
                let dt = gap_ticks(&e, index);
                let pitches = f64::from(map.edge(dt, 1, true));
                map.learn_pending();
                // Speed from this one gap, in pitches per 1000 ticks (1 = the true speed).
                let speed = pitches * 1000.0 / f64::from(dt);
                if rev >= 8 {
                    let want = (g[index] - first_harmonic(&g, index)) / g[index];
                    worst = worst.max((speed - want).abs());
                    rms_learned += (speed - 1.0).powi(2);
                    rms_plain += (1000.0 / f64::from(dt) - 1.0).powi(2);
                }
            }
        }
        // Each gap counts as its true length less the first harmonic, to the ticks' rounding;
        // the one-gap reading's error is a fraction of the unlearned one.
        assert!(worst < 0.002, "{worst}");
        assert!(
            rms_learned < 0.6 * rms_plain,
            "{rms_learned} vs {rms_plain}"
        );
        assert!(map.revolutions_learned() >= 10);
    }

    #[test]
    fn the_revolution_is_the_last_whole_turn_of_gaps() {
        let e = offsets();
        let mut map = ToothMap::new(12, 1e6);
        let mut index = 0;
        let mut last = [0u32; 12];
        for k in 0..30u32 {
            index = (index + 1) % 12;
            // Slowing down: each gap 1 % longer than the one before.
            let dt = (gap_ticks(&e, index) as f64 * 1.01f64.powi(k as i32)).round() as u32;
            last[k as usize % 12] = dt;
            map.edge(dt, 1, true);
            map.learn_pending();
            let want = (k >= 11).then(|| last.iter().sum::<u32>());
            assert_eq!(map.revolution_ticks(), want, "edge {k}");
        }
        // A break in the chain (an edge not learned from) starts the revolution afresh.
        map.edge(1000, 1, false);
        map.learn_pending();
        assert_eq!(map.revolution_ticks(), None);
    }

    #[test]
    fn a_slipped_count_is_noticed_and_relearned() {
        let e = offsets();
        let mut map = ToothMap::new(12, 1e6);
        let mut index = 0;
        for _ in 0..8 * 12 {
            index = (index + 1) % 12;
            map.edge(gap_ticks(&e, index), 1, true);
            map.learn_pending();
        }
        let learned = map.revolutions_learned();
        // An edge lost without the estimator noticing: the wheel is one tooth ahead of the count.
        index = (index + 1) % 12;
        for _ in 0..3 * 12 {
            index = (index + 1) % 12;
            map.edge(gap_ticks(&e, index), 1, true);
            map.learn_pending();
        }
        assert!(
            map.revolutions_learned() < learned,
            "{} revolutions after the slip, {learned} before",
            map.revolutions_learned()
        );
    }

    #[test]
    fn unsteady_or_unlearnable_wheels_count_plain_pitches() {
        let mut map = ToothMap::new(12, 1e6);
        assert_eq!(map.edge(1000, 1, false), 1.0);
        assert_eq!(map.edge(2000, 2, true), 2.0);
        let mut big = ToothMap::new(200, 1e6);
        assert_eq!(big.edge(1000, 1, true), 1.0);
        let mut one = ToothMap::new(1, 1e6);
        assert_eq!(one.edge(1000, 1, true), 1.0);
        assert_eq!(ToothMap::new(12, 1e6).fraction(99), 1.0);
    }
}

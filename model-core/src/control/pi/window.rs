//! A closed window of the estimator, read against the plant model (the Smith predictor of
//! [`super`]'s "Structure"): the load the model does not know, and at a start the readings that
//! hand the integral what the shaft needs (the crawl's, the start's).

use super::{
    LoopConstants, LoopInput, PUSH_KEPT, SECOND_READING_CHANGE_SHARE,
    SECOND_READING_LESSER_MISMATCH_SHARE, SECOND_READING_MISMATCH_SHARE, START_READ_MIN_S,
    SpeedLoop,
};
use crate::control::estimator::WindowSample;

impl SpeedLoop {
    /// The window `w` closed with the model at `rp` and the correction's speed at `c` (rad/s);
    /// the model's and the correction's angles restart at its end.
    #[inline(always)]
    pub(super) fn read_window(
        &mut self,
        k: &LoopConstants,
        input: LoopInput,
        w: WindowSample,
        rp: f32,
        c: f32,
    ) {
        let model_mean = (self.model_angle_rad - rp * w.ago_s) / w.span_s;
        let sample = model_mean - input.direction * w.raw_speed_rad_s;
        let correction_mean = (self.correction_angle_rad - c * w.ago_s) / w.span_s;
        // A pushed start's second window (`late_reading`) is read as a first one: past
        // the leap its first window carried, it reads the load the loop would otherwise
        // close at its bandwidth, about 1 rad/s at 1 rad/s (seed 5 p11's spin: 2 % settled
        // at 3.95 -> 2.82 s; docs/control.md, "... a pushed start reads its second window").
        self.have_error &= !self.start_reading;
        if self.have_error {
            // A quiet shaft the push (`quiet` below) turned again: half of it stays, as
            // after a first edge from rest; the loop corrects the rest.
            if self.push != 0.0 {
                self.integral += PUSH_KEPT * self.push * input.direction;
                self.end_push();
            }
            // The load the model does not know, as the speed it costs: the window's
            // shortfall against the model *with* the correction applied through it.
            self.error += k.filter_weight * (sample + correction_mean - self.error);
            if self.second_reading {
                self.read_second_window(k, input, w, c, sample + correction_mean);
            }
        } else if self.push != 0.0 {
            // The first window after a crawl (no error then: no measurement) closed while
            // the push was on: the shaft slid through it under a known mean duty at a
            // measured mean speed, which reads the load the model does not know
            // (`d = ff(w) + load`, the plant's lag being short against a window). Through
            // the crawl the duty was the feedforward, the integral and the push: the load
            // is the integral, the push's mean, and the duty of the speed the model
            // expected but did not get. That is what the integral must hold; the push has
            // done its work, and the error starts afresh with the next window.
            self.take_crawl_load(k, w.span_s, sample, input.direction);
        } else {
            self.read_first_window(k, input, w, c, sample + correction_mean);
        }
        self.start_reading = self.late_reading;
        self.late_reading = false;
        self.model_angle_rad = rp * w.ago_s;
        self.correction_angle_rad = c * w.ago_s;
        self.load_lag_angle = self.load_lag * w.ago_s;
        self.start_lag_angle = self.start_lag * w.ago_s;
    }

    /// The first window read since the loop left rest (or lost its measurement), whose
    /// shortfall against the model with the correction is `shortfall` (rad/s): the error
    /// starts from the load it reads, and a start's reading hands it to the integral. A load
    /// acting from the start shows only the share of its steady deficit the shaft's lag has
    /// let through (`load_lag`), and the Smith predictor's `L` (a steady offset) read it short
    /// by that share: 0.8 of it in a heavy rod's first window (tau 0.52 s, window 0.55-1.27 s;
    /// seed 4 p00's rod read 0.198 rad/s, its loop settled at 0.26). The share is the window's
    /// mean of a unit load through the identified lag; counted from the loop's start, when the
    /// shaft may have started later, it is an upper bound, so the load read stays a lower
    /// bound of the lag model's (docs/control.md, "A load read through the shaft's lag"). With
    /// current sense too: the back-EMF band was thought to take the load in as it showed, but
    /// a heavy rod within the band lags its model by its load through its lag all the same
    /// (seed 3 p14's rod read 0.02 of its 0.24 rad/s and settled within 2 % at 4.4 s; docs/control.md,
    /// "A start read the same way with current sense"). Once per start, so out of the tick's
    /// common path.
    #[cold]
    #[inline(never)]
    fn read_first_window(
        &mut self,
        k: &LoopConstants,
        input: LoopInput,
        w: WindowSample,
        c: f32,
        shortfall: f32,
    ) {
        let [load_share, mismatch_share] = self.shares(w);
        self.error = shortfall / shown_share(load_share);
        self.have_error = true;
        if self.start_reading && w.span_s >= START_READ_MIN_S && input.feedback {
            self.first_reading = [shortfall, load_share, mismatch_share];
            self.second_reading = true;
            self.take_start_load(k, input, c);
        }
    }

    /// The start's second reading, at the window after the first (`shortfall` its shortfall
    /// against the model with the correction, rad/s). A start's shortfall is the load the model
    /// does not know, showing through the shaft's lag (the window's mean share `a` of it,
    /// `load_lag`), and the mismatch of the shaft against its model at its first edge, which
    /// decays through the same lag (share `b`, `start_lag`): the kick's leap, which the model
    /// (with the identified breakaway, 1.1-8x the true one) does not predict. The first window
    /// reads `s1 = a1 L + b1 D` and the second `s2 = a2 L + b2 D`: both together give `L =
    /// (s1 b2 - s2 b1) / (a1 b2 - a2 b1)`, where the first alone read `s1 / a1`. Seed 4 p19's
    /// heavy rod (time constant 0.40 s) ran ahead of its model until its first edge: its first
    /// window read 0.025 of a load of about 0.095 rad/s, the filtered error reached 0.055 at the
    /// second, the two together 0.083. The integral takes `L` as at the first reading
    /// (`take_start_load`). Only where the mismatch made up at least
    /// [`SECOND_READING_MISMATCH_SHARE`] of the first window, or at least
    /// [`SECOND_READING_LESSER_MISMATCH_SHARE`] where `L` moves the first window's reading by more
    /// than [`SECOND_READING_CHANGE_SHARE`] of the reference (docs/control.md, "The start's
    /// second reading"). Once per start, so out of the tick's common path.
    #[cold]
    #[inline(never)]
    fn read_second_window(
        &mut self,
        k: &LoopConstants,
        input: LoopInput,
        w: WindowSample,
        c: f32,
        shortfall: f32,
    ) {
        self.second_reading = false;
        let [s1, a1, b1] = self.first_reading;
        let [a2, b2] = self.shares(w);
        let det = a1 * b2 - a2 * b1;
        let load = (s1 * b2 - shortfall * b1) / det;
        // Where the mismatch made up less of the first window, the reading is taken only if it
        // moves the load the first window read by more than a window's noise.
        let moves = (load - s1 / shown_share(a1)).abs()
            > SECOND_READING_CHANGE_SHARE * input.reference_rad_s.abs();
        let mismatched = b1 > SECOND_READING_MISMATCH_SHARE
            || (b1 > SECOND_READING_LESSER_MISMATCH_SHARE && moves);
        if !(mismatched && det.abs() > 0.05 * a1 * b1.max(b2)) {
            return;
        }
        if load.is_finite() {
            self.error = load;
            if input.feedback && w.span_s >= START_READ_MIN_S {
                self.take_start_load(k, input, c);
            }
        }
    }

    /// The window's mean shares of a load acting since the loop left rest (`load_lag`) and of
    /// the start's mismatch (`start_lag`).
    #[inline(always)]
    fn shares(&self, w: WindowSample) -> [f32; 2] {
        [
            (self.load_lag_angle - self.load_lag * w.ago_s) / w.span_s,
            (self.start_lag_angle - self.start_lag * w.ago_s) / w.span_s,
        ]
    }
}

/// A window's mean share of a load's steady deficit the shaft showed (`load_lag`, from
/// [`SpeedLoop::shares`]) as the first reading divides by it: at most 1, at least a half, so
/// the reading is never more than doubled (the first window read comes a pitch after the first
/// edge, where the share of the heaviest rods, tau 0.7 s, is about 0.55).
#[inline(always)]
fn shown_share(share: f32) -> f32 {
    if share > 1.0 {
        1.0
    } else if share > 0.5 {
        share
    } else {
        0.5
    }
}

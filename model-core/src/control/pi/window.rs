//! A closed window of the estimator, read against the plant model (the Smith predictor of
//! [`super`]'s "Structure"): the load the model does not know, and at a start the readings that
//! hand the integral what the shaft needs (the crawl's, the start's).

use super::{LoopConstants, LoopInput, PUSH_KEPT, START_READ_MIN_S, SpeedLoop};
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
                self.push = 0.0;
                self.push_sum = 0.0;
            }
            // The load the model does not know, as the speed it costs: the window's
            // shortfall against the model *with* the correction applied through it.
            self.error += k.filter_weight * (sample + correction_mean - self.error);
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
        self.error = shortfall / self.load_shown_share(w);
        self.have_error = true;
        if self.start_reading && w.span_s >= START_READ_MIN_S && input.feedback {
            self.take_start_load(k, input, c);
        }
    }

    /// The mean over window `w` of the share of a load's steady deficit the shaft showed
    /// (`load_lag`), at least a half: the reading is never more than doubled (the first
    /// window read comes a pitch after the first edge, where the share of the heaviest rods,
    /// tau 0.7 s, is about 0.55).
    #[inline(always)]
    fn load_shown_share(&self, w: WindowSample) -> f32 {
        let share = (self.load_lag_angle - self.load_lag * w.ago_s) / w.span_s;
        if share > 1.0 {
            1.0
        } else if share > 0.5 {
            share
        } else {
            0.5
        }
    }
}

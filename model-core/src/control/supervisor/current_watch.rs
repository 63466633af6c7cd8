//! The current sense's watch (issue 27 part 2, the safety issue's trips): its offset and
//! current per duty learned from the samples, the back-EMF it shows, and the trips it raises
//! (over-current, more current than the duty drives, current where none is commanded).

/// Readings above this magnitude are ignored as broken, A.
pub const CURRENT_READING_LIMIT_A: f32 = 1000.0;
/// The least duty whose current teaches the current per duty: below it the sense chain's
/// offset and noise weigh too much.
pub const CURRENT_LEARN_MIN_DUTY: f32 = 0.05;
/// Samples at zero duty before the offset is trusted (and the zero-duty trip armed).
pub const CURRENT_OFFSET_SAMPLES: u16 = 32;
/// A coasting bridge's reading further than this from the learned offset is no offset: it is
/// never learned as one, A.
pub const CURRENT_OFFSET_LIMIT_A: f32 = 0.25;
/// The least half-width of the band a reading may stray from what the model says, A: above the
/// offset's drift and the noise of a sense chain (a VNH5019's CS into a 12-bit ADC: 10 mA).
pub const CURRENT_BAND_A: f32 = 0.05;
/// The band also spans this many times the noise learned at zero duty (mean absolute
/// deviation: uniform noise of +/-n has n / 2).
pub const CURRENT_BAND_NOISE: f32 = 6.0;
/// Absolute over-current: this many times the stall current at the duty limit (the current per
/// duty learned at rest, times the limit). A healthy bridge never exceeds the stall current
/// (`V d / R` with the shaft held); a shorted winding or a bridge shorted across the supply does.
pub const OVERCURRENT_MARGIN: f32 = 1.3;
/// The current may exceed what the model expects for the duty and a lower bound of the speed by
/// this share of the full-duty stall current (before it says the bridge drives harder than it
/// is told): the gain error of the learned current per duty and the viscous share of the
/// identified back-EMF constant stay inside.
pub const UNCOMMANDED_SHARE: f32 = 0.15;
/// The speed the back-EMF is credited with: this share of the smaller of the measured speed and
/// the plant model's (a slowing shaft's measurement lags; a shaft that slowed under material has
/// fallen below its model).
pub const BACK_EMF_SPEED_SHARE: f32 = 0.5;
/// The same share while the axis is steady (its reference unchanged for half a second and its
/// measurement within 10 % of the model): the measurement is then the speed, less tooth offsets.
pub const BACK_EMF_STEADY_SHARE: f32 = 0.9;
/// A watch that lost its edges blames the sensor (not a stall) when the back-EMF the current
/// shows is above this share of the model speed's back-EMF.
pub const TURNING_BACK_EMF_SHARE: f32 = 0.5;
/// Samples of a start from rest averaged together to learn the current per duty (the noise
/// of one sample is a tenth of the current at the least duty).
pub const START_WINDOW: usize = 4;
/// Weight of an edge's back-EMF in the turning shaft's reference.
const TURNING_WEIGHT: f32 = 0.2;
/// Weight of a new sample in the back-EMF's running mean (20 ms at 1 kHz).
const BACK_EMF_WEIGHT: f32 = 0.05;

/// What a current trip found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CurrentTrip {
    /// Above [`OVERCURRENT_MARGIN`] times the stall current at the duty limit.
    OverCurrent,
    /// More current than the duty drives at a lower bound of the speed: a bridge stuck on or
    /// shorted, or a shaft stopped dead under drive (its back-EMF gone).
    Uncommanded,
    /// More current than the duty drives even with the shaft held (at zero duty: any current
    /// outside the offset's band): only a bridge driving harder than it is told does that, and
    /// such a bridge cannot be trusted to stop when told.
    BridgeDriving,
}

/// One axis's current sense as the supervisor reads it: the offset and noise learned while the
/// bridge coasts, the current per duty (`V / R` through the sense chain's gain) learned while a
/// start drives a shaft still held by stiction, where `i = V d / R` (docs/model.md:
/// `L di/dt = u - R i - k w` settled, with `w = 0`), and the back-EMF's running mean that tells
/// a stalled shaft from a dead sensor. The start's fit stops taking samples once the current
/// falls below it (the back-EMF of a shaft that broke away) and is taken at the first edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurrentWatch {
    offset_a: f32,
    noise_a: f32,
    offset_samples: u16,
    amps_per_duty: f32,
    gain_samples: u16,
    /// A start may teach the current per duty: the bridge coasted since the last edge.
    start_armed: bool,
    /// The last [`START_WINDOW`] samples of this start at rest: currents and duties.
    window_i: [f32; START_WINDOW],
    window_d: [f32; START_WINDOW],
    /// Samples of this start at rest.
    start_samples: u16,
    /// The largest current per duty over a window of this start (0: none yet).
    start_best: f32,
    /// Running mean of `g |d| - i` (the back-EMF's share of the current), A.
    back_emf_a: f32,
    /// [`CurrentWatch::back_emf_a`] at the last edges of a steady shaft (edges prove it
    /// turned), A; None since the start.
    turning_back_emf_a: Option<f32>,
}

impl CurrentWatch {
    /// Nothing learned.
    pub const NEW: Self = Self {
        offset_a: 0.0,
        noise_a: 0.0,
        offset_samples: 0,
        amps_per_duty: 0.0,
        gain_samples: 0,
        start_armed: false,
        window_i: [0.0; START_WINDOW],
        window_d: [0.0; START_WINDOW],
        start_samples: 0,
        start_best: 0.0,
        back_emf_a: 0.0,
        turning_back_emf_a: None,
    };

    /// The learned offset, A.
    pub fn offset_a(&self) -> f32 {
        self.offset_a
    }
    /// The learned current per duty, A (0 until a start from rest taught it).
    pub fn amps_per_duty(&self) -> f32 {
        if self.gain_samples > 0 {
            self.amps_per_duty
        } else {
            0.0
        }
    }
    /// The half-width of the band around the model's current, A.
    pub fn band_a(&self) -> f32 {
        CURRENT_BAND_A + CURRENT_BAND_NOISE * self.noise_a
    }

    /// One sample: `reading_a` under the duty `applied` of the last period, the shaft turning
    /// (if at all) in `direction` (+1 or -1, the commanded one), at rest (no edge since it
    /// stopped) or not, its speed at least `speed_lo_rad_s` (0 if
    /// unknown) and the identified back-EMF per rad/s as a share of the supply,
    /// `emf_duty_per_rad_s`. Learns, then returns a trip, if any.
    #[allow(clippy::too_many_arguments)]
    pub fn sample(
        &mut self,
        reading_a: f32,
        applied: f32,
        direction: f32,
        at_rest: bool,
        speed_lo_rad_s: f32,
        emf_duty_per_rad_s: f32,
        duty_limit: f32,
    ) -> Option<CurrentTrip> {
        // No sense chain reads more than its ADC's full scale; a value beyond any motor's current
        // is a broken reading, not a current (and would overflow the running means).
        if !reading_a.is_finite() || reading_a.abs() > CURRENT_READING_LIMIT_A {
            return None;
        }
        let i = reading_a - self.offset_a;
        if applied == 0.0 || applied.is_nan() {
            self.take_start(true);
            let armed = self.offset_samples >= CURRENT_OFFSET_SAMPLES;
            if armed && i.abs() > self.band_a() {
                return Some(CurrentTrip::BridgeDriving);
            }
            if i.abs() < CURRENT_OFFSET_LIMIT_A || !armed {
                // Running means (the last 256 samples weigh most).
                let n = f32::from(self.offset_samples.min(255)) + 1.0;
                self.offset_a += i / n;
                let dev = (reading_a - self.offset_a).abs();
                self.noise_a += (dev - self.noise_a) / n;
                self.offset_samples = self.offset_samples.saturating_add(1);
            }
            return None;
        }
        // In the shaft's direction: a braking duty (against it) is negative, and so is the
        // current it and the back-EMF drive.
        let d = applied * direction;
        let i_dir = i * direction;
        if at_rest {
            self.learn_at_rest(i_dir, d);
        } else if self.start_armed || self.start_samples > 0 {
            self.take_start(false);
        }
        let g = self.amps_per_duty();
        if g <= 0.0 {
            return None;
        }
        self.back_emf_a += (g * d - i_dir - self.back_emf_a) * BACK_EMF_WEIGHT;
        let band = self.band_a();
        if i.abs() > OVERCURRENT_MARGIN * g * duty_limit + band {
            return Some(CurrentTrip::OverCurrent);
        }
        // `i = g (d - e w)` with `w >= 0` along the shaft's direction: the held shaft draws the
        // most, a turning one less by its back-EMF.
        let margin = UNCOMMANDED_SHARE * g + band;
        if i_dir > g * d + margin {
            return Some(CurrentTrip::BridgeDriving);
        }
        if i_dir > g * (d - emf_duty_per_rad_s * speed_lo_rad_s.max(0.0)) + margin {
            return Some(CurrentTrip::Uncommanded);
        }
        None
    }

    /// An edge came on a steady shaft: its back-EMF now is that of a turning shaft (the
    /// reference [`CurrentWatch::shaft_turns`] compares with; the current per duty's error
    /// cancels in the difference).
    pub fn note_turning(&mut self) {
        self.turning_back_emf_a = Some(match self.turning_back_emf_a {
            None => self.back_emf_a,
            Some(r) => r + (self.back_emf_a - r) * TURNING_WEIGHT,
        });
    }

    /// Whether the current says the shaft turns: its back-EMF fell from what it was at the
    /// last edges of the steady shaft by less than [`TURNING_BACK_EMF_SHARE`] of what
    /// `model_rad_s` gives (without such edges: the back-EMF itself above that share). None
    /// when no current per duty is known yet.
    pub fn shaft_turns(&self, model_rad_s: f32, emf_duty_per_rad_s: f32) -> Option<bool> {
        let g = self.amps_per_duty();
        if g <= 0.0 {
            return None;
        }
        let expected = g * emf_duty_per_rad_s * model_rad_s.abs();
        let reference = self.turning_back_emf_a.unwrap_or(expected);
        Some(self.back_emf_a > reference - (1.0 - TURNING_BACK_EMF_SHARE) * expected)
    }

    /// One sample of a shaft at rest under duty `d`, current `i_dir` in the drive's direction.
    fn learn_at_rest(&mut self, i_dir: f32, d: f32) {
        if !self.start_armed || d < CURRENT_LEARN_MIN_DUTY {
            return;
        }
        let k = usize::from(self.start_samples) % START_WINDOW;
        self.window_i[k] = i_dir;
        self.window_d[k] = d;
        self.start_samples = self.start_samples.saturating_add(1);
        if usize::from(self.start_samples) >= START_WINDOW {
            let i: f32 = self.window_i.iter().sum();
            let d: f32 = self.window_d.iter().sum();
            self.start_best = self.start_best.max(i / d);
        }
    }

    /// The start is over (an edge came, or the duty went to zero): its best window joins the
    /// current per duty (a running mean over the last 16 starts). While the shaft is held the
    /// current per duty is `V / R`; once it turns, its back-EMF only lowers it, so the largest
    /// window is the held shaft's (the inductance's first sample, too, only lowers it).
    fn take_start(&mut self, coasting: bool) {
        let fit = self.start_best;
        if fit > 0.0 && fit.is_finite() {
            let n = f32::from(self.gain_samples.min(15)) + 1.0;
            self.amps_per_duty += (fit - self.amps_per_duty) / n;
            self.gain_samples = self.gain_samples.saturating_add(1);
        }
        self.start_samples = 0;
        self.start_best = 0.0;
        // Only a start from a coasting bridge teaches: a shaft whose sensor died reads as at
        // rest too, but it turns.
        self.start_armed = coasting;
    }

    /// A fresh start: the back-EMF's mean restarts (the learned offset and gain stay).
    pub const fn restart(&mut self) {
        self.back_emf_a = 0.0;
        self.turning_back_emf_a = None;
    }
}

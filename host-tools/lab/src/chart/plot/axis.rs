//! The chart's axes: a data value mapped to the plotted coordinate (log axes as log10 on a linear
//! axis), a range and round ticks covering the data, the tick labels.

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};

use super::Scale;

/// Maps a data value to the plotted coordinate, or None if it cannot be drawn on this scale.
pub fn to_axis(scale: Scale, v: f64) -> Option<f64> {
    match scale {
        Scale::Linear if v.is_finite() => Some(v),
        Scale::Log if v.is_finite() && v > 0.0 => Some(v.log10()),
        _ => None,
    }
}

/// Axis range (in plotted coordinates) and tick positions.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
    /// Tick positions.
    pub ticks: Vec<f64>,
    /// Light grid lines between ticks (log axes: 2..9 times each decade).
    pub minor: Vec<f64>,
}

/// Our own coordinate: a linear map with exactly our ticks (plotters' key-point wrapper loses
/// the default label formatter).
impl Ranged for Axis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let f = (value - self.lo) / (self.hi - self.lo);
        let size = f64::from(limit.1 - limit.0);
        limit.0 + (f * size).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.max_num_points() == 0 {
            Vec::new()
        } else if hint.weight().allow_light_points() {
            // plotters draws light lines for the points not also in the bold set.
            let mut all = self.ticks.clone();
            all.extend(&self.minor);
            all
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

/// Chooses a range and ticks covering `values` (already in plotted coordinates).
pub fn axis_for(scale: Scale, values: &[f64]) -> Option<Axis> {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for &v in values {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    match scale {
        Scale::Log => {
            // Whole decades around the data; at least one decade.
            // A little room so points on a whole decade do not sit on the frame.
            let mut lo = (lo - 0.1).floor();
            let mut hi = (hi + 0.1).ceil();
            if hi - lo < 1.0 {
                lo -= 0.5;
                hi += 0.5;
                lo = lo.floor();
                hi = hi.ceil();
            }
            let step = ((hi - lo) / 12.0).ceil().max(1.0);
            let mut ticks = Vec::new();
            let mut t = lo;
            while t <= hi + 1e-9 {
                ticks.push(t);
                t += step;
            }
            let minor = if step == 1.0 && hi - lo <= 6.0 {
                (lo as i64..hi as i64)
                    .flat_map(|d| (2..10).map(move |m| d as f64 + f64::from(m).log10()))
                    .collect()
            } else {
                Vec::new()
            };
            Some(Axis {
                lo,
                hi,
                ticks,
                minor,
            })
        }
        Scale::Linear => {
            let span = if hi > lo { hi - lo } else { lo.abs().max(1.0) };
            let raw = span / 8.0;
            let mag = 10f64.powf(raw.log10().floor());
            let step = [1.0, 2.0, 2.5, 5.0, 10.0]
                .iter()
                .map(|m| m * mag)
                .find(|s| *s >= raw)
                .unwrap_or(10.0 * mag);
            let lo_t = (lo / step).floor() * step;
            let mut hi_t = (hi / step).ceil() * step;
            if hi_t <= lo_t {
                hi_t = lo_t + step;
            }
            let n = ((hi_t - lo_t) / step).round() as usize;
            let ticks = (0..=n).map(|i| lo_t + i as f64 * step).collect();
            Some(Axis {
                lo: lo_t,
                hi: hi_t,
                ticks,
                minor: Vec::new(),
            })
        }
    }
}

/// Share of the axis within which a marker line counts as on the frame.
const FRAME_SHARE: f64 = 0.03;

/// Chooses a range and ticks covering `values` and the marker `lines` (both in plotted
/// coordinates), with every line clear of the frame: the round range of the data alone often
/// ends exactly on a target (settling times up to 1.8 s and a 3 s target gave an axis ending at
/// 3), and a line drawn on the frame cannot be seen, nor can its label.
pub fn axis_clear_of(scale: Scale, values: &[f64], lines: &[f64]) -> Option<Axis> {
    let mut all: Vec<f64> = values.iter().chain(lines).copied().collect();
    let first = axis_for(scale, &all)?;
    let span = first.hi - first.lo;
    let room = 2.0 * FRAME_SHARE * span;
    let mut moved = false;
    for &l in lines {
        if first.hi - l < FRAME_SHARE * span {
            all.push(l + room);
            moved = true;
        }
        if l - first.lo < FRAME_SHARE * span {
            all.push(l - room);
            moved = true;
        }
    }
    if moved {
        axis_for(scale, &all)
    } else {
        Some(first)
    }
}

/// Formats a tick label for a plotted coordinate.
pub fn tick_label(scale: Scale, v: f64) -> String {
    match scale {
        Scale::Log => {
            let e = v.round() as i32;
            match e {
                0 => "1".to_string(),
                1 => "10".to_string(),
                _ => format!("1e{e}"),
            }
        }
        Scale::Linear => {
            let a = v.abs();
            if a == 0.0 {
                "0".to_string()
            } else if (1e-3..1e5).contains(&a) {
                // Enough decimals for the tick step, no trailing noise.
                let s = format!("{v:.4}");
                let s = s.trim_end_matches('0').trim_end_matches('.');
                s.to_string()
            } else {
                format!("{v:.1e}")
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_axis_covers_data_with_whole_decades() {
        let a = axis_for(Scale::Log, &[-6.3, -1.5]).unwrap();
        assert_eq!((a.lo, a.hi), (-7.0, -1.0));
        assert_eq!(a.ticks.first(), Some(&-7.0));
        assert_eq!(a.ticks.last(), Some(&-1.0));
    }

    #[test]
    fn linear_axis_ticks_are_round_and_cover_data() {
        let a = axis_for(Scale::Linear, &[0.013, 0.74]).unwrap();
        assert!(a.lo <= 0.013 && a.hi >= 0.74);
        let step = a.ticks[1] - a.ticks[0];
        assert!((step - 0.1).abs() < 1e-12, "step {step}");
    }

    /// A line on the data's round range's end moves the end out: settling times 0.97-1.8 s and
    /// a 3 s target gave an axis 0.5-3, the target on the frame.
    #[test]
    fn a_line_on_the_frame_moves_the_frame() {
        let data = [0.97, 1.2, 1.8];
        assert_eq!(axis_for(Scale::Linear, &[0.97, 1.8, 3.0]).unwrap().hi, 3.0);
        let a = axis_clear_of(Scale::Linear, &data, &[3.0]).unwrap();
        let span = a.hi - a.lo;
        assert!(a.hi - 3.0 >= FRAME_SHARE * span, "{a:?}");
        assert!(a.lo <= 0.97, "{a:?}");
        // At the bottom too, and on a log axis.
        let a = axis_clear_of(Scale::Linear, &data, &[0.0]).unwrap();
        assert!(0.0 - a.lo >= FRAME_SHARE * (a.hi - a.lo), "{a:?}");
        let a = axis_clear_of(Scale::Log, &[-1.5, -0.3], &[0.0]).unwrap();
        assert!(a.hi - 0.0 >= FRAME_SHARE * (a.hi - a.lo), "{a:?}");
        // A line well inside leaves the data's axis as it was.
        assert_eq!(
            axis_clear_of(Scale::Linear, &data, &[1.5]),
            axis_for(Scale::Linear, &data)
        );
    }

    #[test]
    fn tick_labels() {
        assert_eq!(tick_label(Scale::Log, -6.0), "1e-6");
        assert_eq!(tick_label(Scale::Log, 0.0), "1");
        assert_eq!(tick_label(Scale::Linear, 0.25), "0.25");
        assert_eq!(tick_label(Scale::Linear, 3.0), "3");
    }
}

//! A small line/scatter chart description, drawn to SVG and PNG with plotters.
//!
//! Why a description of our own instead of calling plotters from every chart: the charts share
//! log/linear axes, a legend panel beside the plot, gaps for points that do not exist (a particle
//! that never leaves has no residence time) and vertical marker lines (stability bounds), and each
//! must come out identically as SVG and PNG.
//!
//! Log axes are drawn by plotting log10 of the data on a linear axis with ticks at whole decades:
//! one code path for every axis combination, and tick labels we control ("1e-6").
//!
//! Fonts: the PNG needs glyphs. We use plotters' pure-Rust `ab_glyph` text renderer with DejaVu Sans
//! embedded at compile time from the `dejavu` crate, so a fresh machine without any system font
//! (and without fontconfig/freetype) draws the same PNG. The SVG names the family
//! "DejaVu Sans, sans-serif" and leaves rendering to the viewer.

use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::prelude::*;

/// How an axis maps data to the page.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// Linear.
    Linear,
    /// Base-10 logarithmic; values <= 0 cannot be drawn and leave a gap.
    Log,
}

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    /// A line through consecutive points, broken where a point is missing.
    Line,
    /// Dashed line.
    Dashed,
    /// Dashed line with small open circles at the points.
    DashedPoints,
    /// Filled circles only.
    Points,
    /// A line with filled circles at the points.
    LinePoints,
    /// Crosses only (used for "never leaves" markers).
    Crosses,
}

/// One named set of points.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend text.
    pub name: String,
    /// Data points; a non-finite coordinate (or a non-positive one on a log axis) is a gap.
    pub points: Vec<(f64, f64)>,
    /// Drawing style.
    pub mark: Mark,
    /// Index into the palette; series with the same index share a colour.
    pub color: usize,
}

/// A vertical line at a given x, labelled (for example a stability bound).
#[derive(Clone, Debug)]
pub struct VLine {
    /// Position on the x axis, in data units.
    pub x: f64,
    /// Label drawn beside the line.
    pub label: String,
    /// Palette index.
    pub color: usize,
}

/// A whole chart.
#[derive(Clone, Debug)]
pub struct Figure {
    /// Title above the plot.
    pub title: String,
    /// X axis description.
    pub x_label: String,
    /// Y axis description.
    pub y_label: String,
    /// X axis scale.
    pub x_scale: Scale,
    /// Y axis scale.
    pub y_scale: Scale,
    /// Data.
    pub series: Vec<Series>,
    /// Vertical marker lines.
    pub vlines: Vec<VLine>,
    /// Free text lines printed under the legend (how to read the chart).
    pub notes: Vec<String>,
}

/// Why a chart could not be drawn.
#[derive(Debug)]
pub enum PlotError {
    /// No series has a single drawable point, so there is no axis range to draw.
    NoData,
    /// The drawing backend failed (file not writable, encoder error); the text says what.
    Backend(String),
}

impl std::fmt::Display for PlotError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PlotError::NoData => write!(f, "chart has no drawable point"),
            PlotError::Backend(s) => write!(f, "drawing failed: {s}"),
        }
    }
}

impl std::error::Error for PlotError {}

/// Page size in pixels (both SVG and PNG).
const WIDTH: u32 = 1280;
/// Page height.
const HEIGHT: u32 = 760;
/// Width of the legend panel on the right.
const LEGEND_WIDTH: u32 = 360;
/// Font family name under which the embedded font is registered.
const FONT: &str = "DejaVu Sans, sans-serif";

/// A palette readable on white and distinguishable in print (Okabe-Ito plus a few).
const PALETTE: [RGBColor; 12] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(120, 120, 120),
    RGBColor(160, 40, 40),
    RGBColor(100, 60, 160),
    RGBColor(0, 60, 120),
    RGBColor(140, 140, 0),
];

fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are a valid TrueType font shipped by the crate; failing here would mean a
        // broken dependency, and text would then be missing rather than the program aborting.
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
        let _ = plotters::style::register_font(FONT, FontStyle::Bold, dejavu::sans::bold());
    });
}

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

impl Figure {
    /// Draws the figure as SVG to `path`.
    pub fn write_svg(&self, path: &Path) -> Result<(), PlotError> {
        register_font();
        let root = SVGBackend::new(path, (WIDTH, HEIGHT)).into_drawing_area();
        self.draw(&root)?;
        root.present()
            .map_err(|e| PlotError::Backend(format!("{}: {e}", path.display())))
    }

    /// Draws the figure as PNG to `path`.
    pub fn write_png(&self, path: &Path) -> Result<(), PlotError> {
        register_font();
        let root = BitMapBackend::new(path, (WIDTH, HEIGHT)).into_drawing_area();
        self.draw(&root)?;
        root.present()
            .map_err(|e| PlotError::Backend(format!("{}: {e}", path.display())))
    }

    /// Segments of each series in plotted coordinates, split at gaps.
    fn segments(&self, s: &Series) -> Vec<Vec<(f64, f64)>> {
        let mut out = Vec::new();
        let mut cur = Vec::new();
        for &(x, y) in &s.points {
            match (to_axis(self.x_scale, x), to_axis(self.y_scale, y)) {
                (Some(x), Some(y)) => cur.push((x, y)),
                _ => {
                    if !cur.is_empty() {
                        out.push(std::mem::take(&mut cur));
                    }
                }
            }
        }
        if !cur.is_empty() {
            out.push(cur);
        }
        out
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        let be = |e: DrawingAreaErrorKind<DB::ErrorType>| PlotError::Backend(e.to_string());
        root.fill(&WHITE).map_err(be)?;
        let segs: Vec<Vec<Vec<(f64, f64)>>> =
            self.series.iter().map(|s| self.segments(s)).collect();
        let xs: Vec<f64> = segs
            .iter()
            .flatten()
            .flatten()
            .map(|p| p.0)
            .chain(
                self.vlines
                    .iter()
                    .filter_map(|v| to_axis(self.x_scale, v.x)),
            )
            .collect();
        let ys: Vec<f64> = segs.iter().flatten().flatten().map(|p| p.1).collect();
        let xa = axis_for(self.x_scale, &xs).ok_or(PlotError::NoData)?;
        let ya = axis_for(self.y_scale, &ys).ok_or(PlotError::NoData)?;

        let (plot_area, legend_area) = root.split_horizontally(WIDTH - LEGEND_WIDTH);
        let xs_scale = self.x_scale;
        let ys_scale = self.y_scale;
        let x_fmt = move |v: &f64| tick_label(xs_scale, *v);
        let y_fmt = move |v: &f64| tick_label(ys_scale, *v);
        let mut chart = ChartBuilder::on(&plot_area)
            .caption(&self.title, (FONT, 22).into_font().style(FontStyle::Bold))
            .margin(14)
            .x_label_area_size(56)
            .y_label_area_size(84)
            .build_cartesian_2d(xa.clone(), ya.clone())
            .map_err(be)?;
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .x_label_formatter(&x_fmt)
            .y_label_formatter(&y_fmt)
            .label_style((FONT, 15))
            .axis_desc_style((FONT, 17))
            .light_line_style(RGBColor(242, 242, 242))
            .bold_line_style(RGBColor(225, 225, 225))
            .draw()
            .map_err(be)?;

        for v in &self.vlines {
            if let Some(x) = to_axis(self.x_scale, v.x) {
                chart
                    .draw_series(DashedLineSeries::new(
                        vec![(x, ya.lo), (x, ya.hi)],
                        6,
                        4,
                        colour(v.color).stroke_width(1),
                    ))
                    .map_err(be)?;
            }
        }

        for (s, parts) in self.series.iter().zip(&segs) {
            let c = colour(s.color);
            for part in parts {
                match s.mark {
                    Mark::Line | Mark::LinePoints => {
                        chart
                            .draw_series(LineSeries::new(part.clone(), c.stroke_width(2)))
                            .map_err(be)?;
                    }
                    Mark::Dashed | Mark::DashedPoints => {
                        chart
                            .draw_series(DashedLineSeries::new(
                                part.clone(),
                                8,
                                5,
                                c.stroke_width(2),
                            ))
                            .map_err(be)?;
                    }
                    Mark::Points | Mark::Crosses => {}
                }
                match s.mark {
                    Mark::Points | Mark::LinePoints => {
                        chart
                            .draw_series(part.iter().map(|&p| Circle::new(p, 4, c.filled())))
                            .map_err(be)?;
                    }
                    Mark::Crosses => {
                        chart
                            .draw_series(part.iter().map(|&p| Cross::new(p, 6, c.stroke_width(2))))
                            .map_err(be)?;
                    }
                    Mark::DashedPoints => {
                        chart
                            .draw_series(part.iter().map(|&p| Circle::new(p, 3, c.stroke_width(1))))
                            .map_err(be)?;
                    }
                    _ => {}
                }
            }
        }

        // The lines' labels over the data, staggered downwards from one step below the top
        // (a series along the top edge, such as a target, would cross the first one).
        for (i, v) in self.vlines.iter().enumerate() {
            if let Some(x) = to_axis(self.x_scale, v.x) {
                let label_y = ya.hi - (ya.hi - ya.lo) * 0.035 * (1 + i % 8) as f64;
                chart
                    .draw_series(std::iter::once(Text::new(
                        v.label.clone(),
                        (x, label_y),
                        (FONT, 13).into_font().color(&colour(v.color)),
                    )))
                    .map_err(be)?;
            }
        }

        self.draw_legend(&legend_area).map_err(be)
    }

    fn draw_legend<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let font = (FONT, 14).into_font();
        let line_h = 19;
        let mut y = 50;
        for s in &self.series {
            let c = colour(s.color);
            let (x0, x1, ym) = (8, 44, y + 8);
            match s.mark {
                Mark::Line | Mark::LinePoints => {
                    area.draw(&PathElement::new(
                        vec![(x0, ym), (x1, ym)],
                        c.stroke_width(2),
                    ))?;
                }
                Mark::Dashed | Mark::DashedPoints => {
                    area.draw(&PathElement::new(
                        vec![(x0, ym), (x0 + 14, ym)],
                        c.stroke_width(2),
                    ))?;
                    area.draw(&PathElement::new(
                        vec![(x0 + 22, ym), (x1, ym)],
                        c.stroke_width(2),
                    ))?;
                }
                _ => {}
            }
            match s.mark {
                Mark::Points | Mark::LinePoints => {
                    area.draw(&Circle::new(((x0 + x1) / 2, ym), 4, c.filled()))?;
                }
                Mark::Crosses => {
                    area.draw(&Cross::new(((x0 + x1) / 2, ym), 6, c.stroke_width(2)))?;
                }
                Mark::DashedPoints => {
                    area.draw(&Circle::new(((x0 + x1) / 2, ym), 3, c.stroke_width(1)))?;
                }
                _ => {}
            }
            area.draw(&Text::new(s.name.clone(), (52, y), font.clone()))?;
            y += line_h;
        }
        y += line_h / 2;
        let note_font = (FONT, 13).into_font().color(&RGBColor(60, 60, 60));
        for n in &self.notes {
            area.draw(&Text::new(n.clone(), (8, y), note_font.clone()))?;
            y += line_h - 2;
        }
        Ok(())
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

    #[test]
    fn gaps_split_lines() {
        let f = Figure {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            x_scale: Scale::Linear,
            y_scale: Scale::Log,
            series: vec![],
            vlines: vec![],
            notes: vec![],
        };
        let s = Series {
            name: "s".into(),
            points: vec![
                (0.0, 1.0),
                (1.0, f64::INFINITY),
                (2.0, 10.0),
                (3.0, 0.0),
                (4.0, 100.0),
            ],
            mark: Mark::Line,
            color: 0,
        };
        let segs = f.segments(&s);
        assert_eq!(
            segs,
            vec![vec![(0.0, 0.0)], vec![(2.0, 1.0)], vec![(4.0, 2.0)]]
        );
    }

    #[test]
    fn tick_labels() {
        assert_eq!(tick_label(Scale::Log, -6.0), "1e-6");
        assert_eq!(tick_label(Scale::Log, 0.0), "1");
        assert_eq!(tick_label(Scale::Linear, 0.25), "0.25");
        assert_eq!(tick_label(Scale::Linear, 3.0), "3");
    }

    fn sample() -> Figure {
        Figure {
            title: "Sample: y = x^2 and y = 1/x".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            x_scale: Scale::Log,
            y_scale: Scale::Log,
            series: vec![
                Series {
                    name: "x^2".into(),
                    points: (1..50).map(|i| (i as f64, (i * i) as f64)).collect(),
                    mark: Mark::LinePoints,
                    color: 0,
                },
                Series {
                    name: "1/x".into(),
                    points: (1..50).map(|i| (i as f64, 1.0 / i as f64)).collect(),
                    mark: Mark::Dashed,
                    color: 1,
                },
                Series {
                    name: "never".into(),
                    points: vec![(3.0, 1e-2)],
                    mark: Mark::Crosses,
                    color: 2,
                },
            ],
            vlines: vec![VLine {
                x: 10.0,
                label: "bound".into(),
                color: 6,
            }],
            notes: vec!["a note".into()],
        }
    }

    #[test]
    fn png_and_svg_are_written_with_text() {
        let dir = std::env::temp_dir().join(format!("bowl-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let png = dir.join("s.png");
        let svg = dir.join("s.svg");
        let f = sample();
        f.write_png(&png).unwrap();
        f.write_svg(&svg).unwrap();
        let bytes = std::fs::read(&png).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.contains("<svg") && text.contains("Sample: y = x^2"));
        assert!(text.contains("\n1e-2\n"), "log tick labels");
    }

    /// The topmost pixel row holding `rgb` in a PNG's plot area (left of the legend), if any.
    fn top_row_of(path: &Path, rgb: RGBColor) -> Option<usize> {
        let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        let bpp = info.line_size / info.width as usize;
        (0..info.height as usize).find(|&row| {
            buf[row * info.line_size..(row + 1) * info.line_size]
                .chunks(bpp)
                .take((WIDTH - LEGEND_WIDTH) as usize)
                .any(|p| p[0] == rgb.0 && p[1] == rgb.1 && p[2] == rgb.2)
        })
    }

    /// A noisy trace with sharp reversals (as a speed trace is) must not draw above its own
    /// maximum in the PNG (its topmost pixel may not rise above that of a horizontal line drawn
    /// at the data's maximum), and the PNG and the SVG draw it at the same height.
    #[test]
    fn png_lines_stay_within_the_data() {
        let n = 400;
        let trace: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let x = i as f64 * 0.05;
                let y = 2.6 + if i % 2 == 0 { 0.003 } else { -0.003 } * (1 + i % 7) as f64;
                (x, y)
            })
            .collect();
        let top = trace.iter().map(|p| p.1).fold(f64::MIN, f64::max);
        let f = Figure {
            title: "zigzag".into(),
            x_label: "t".into(),
            y_label: "w".into(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            series: vec![
                Series {
                    name: "trace".into(),
                    points: trace.clone(),
                    mark: Mark::Line,
                    color: 0,
                },
                Series {
                    name: "its maximum".into(),
                    points: vec![(0.0, top), (trace[n - 1].0, top)],
                    mark: Mark::Line,
                    color: 1,
                },
            ],
            vlines: vec![],
            notes: vec![],
        };
        let dir = std::env::temp_dir().join(format!("bowl-plot-spikes-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let png = dir.join("zigzag.png");
        let svg = dir.join("zigzag.svg");
        f.write_png(&png).unwrap();
        f.write_svg(&svg).unwrap();
        let trace_top = top_row_of(&png, colour(0)).expect("the trace is drawn");
        let max_top = top_row_of(&png, colour(1)).expect("the maximum is drawn");
        assert!(
            trace_top + 1 >= max_top,
            "the trace reaches pixel row {trace_top}, its maximum is drawn at row {max_top}"
        );
        // The SVG draws the same trace in the same pixel space: its highest point lies within
        // the stroke's half width and a pixel of rounding of the PNG's topmost trace pixel.
        let text = std::fs::read_to_string(&svg).unwrap();
        let c = colour(0);
        let stroke = format!("stroke=\"#{:02X}{:02X}{:02X}\"", c.0, c.1, c.2);
        let svg_top = text
            .split("<polyline")
            .skip(1)
            .filter(|e| e.contains(&stroke))
            .filter_map(|e| e.split("points=\"").nth(1)?.split('"').next())
            .flat_map(|pts| pts.split_whitespace())
            .filter_map(|xy| {
                let (x, y) = xy.split_once(',')?;
                let (x, y) = (x.parse::<f64>().ok()?, y.parse::<f64>().ok()?);
                // Left of the legend, whose sample line has the same stroke.
                (x < f64::from(WIDTH - LEGEND_WIDTH)).then_some(y)
            })
            .fold(f64::INFINITY, f64::min);
        assert!(svg_top.is_finite(), "no trace polyline in the SVG");
        assert!(
            (trace_top as f64 - svg_top).abs() <= 2.0,
            "PNG top row {trace_top}, SVG top {svg_top}"
        );
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn empty_figure_is_an_error_not_a_panic() {
        let mut f = sample();
        for s in &mut f.series {
            s.points = vec![(f64::NAN, 1.0), (1.0, -1.0)];
        }
        f.vlines.clear();
        let dir = std::env::temp_dir();
        let r = f.write_svg(&dir.join(format!("bowl-empty-{}.svg", std::process::id())));
        assert!(matches!(r, Err(PlotError::NoData)));
    }
}

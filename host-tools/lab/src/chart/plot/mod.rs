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
use plotters::prelude::*;

mod axis;
mod lines;

pub use axis::{Axis, axis_clear_of, axis_for, tick_label, to_axis};

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

/// A horizontal line at a given y across the whole plot, labelled on the line (for example a
/// target). The y axis keeps it clear of the frame.
#[derive(Clone, Debug)]
pub struct HLine {
    /// Position on the y axis, in data units.
    pub y: f64,
    /// Label drawn on the line, at its right end.
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
    /// Horizontal reference lines.
    pub hlines: Vec<HLine>,
    /// Free text lines printed under the legend (how to read the chart).
    pub notes: Vec<String>,
}

impl Figure {
    /// A figure on linear axes with no marker lines, its notes under the legend.
    pub fn linear(
        title: String,
        x_label: &str,
        y_label: &str,
        series: Vec<Series>,
        notes: &[&str],
    ) -> Self {
        Figure {
            title,
            x_label: x_label.into(),
            y_label: y_label.into(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            series,
            hlines: vec![],
            vlines: vec![],
            notes: notes.iter().map(|n| (*n).to_string()).collect(),
        }
    }

    /// A figure of the relative error in residence time T (y) against `x_label`'s measure (a
    /// cost or a step), both axes logarithmic, no marker lines, its notes under the legend.
    pub fn error_in_t(
        title: String,
        x_label: &str,
        series: Vec<Series>,
        notes: Vec<String>,
    ) -> Self {
        Figure {
            title,
            x_label: x_label.into(),
            y_label: "relative error in residence time T".into(),
            x_scale: Scale::Log,
            y_scale: Scale::Log,
            series,
            hlines: vec![],
            vlines: vec![],
            notes,
        }
    }
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

    /// The axes (x, y; plotted coordinates) covering the drawable points and the marker lines,
    /// each line clear of the frame.
    pub fn axes(&self) -> Result<(Axis, Axis), PlotError> {
        let segs: Vec<_> = self.series.iter().map(|s| self.segments(s)).collect();
        let points = || segs.iter().flatten().flatten();
        let xs: Vec<f64> = points().map(|p| p.0).collect();
        let ys: Vec<f64> = points().map(|p| p.1).collect();
        if xs.is_empty() {
            return Err(PlotError::NoData);
        }
        let vx: Vec<f64> = self
            .vlines
            .iter()
            .filter_map(|v| to_axis(self.x_scale, v.x))
            .collect();
        let hy: Vec<f64> = self
            .hlines
            .iter()
            .filter_map(|h| to_axis(self.y_scale, h.y))
            .collect();
        let xa = axis_clear_of(self.x_scale, &xs, &vx).ok_or(PlotError::NoData)?;
        let ya = axis_clear_of(self.y_scale, &ys, &hy).ok_or(PlotError::NoData)?;
        Ok((xa, ya))
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        let be = |e: DrawingAreaErrorKind<DB::ErrorType>| PlotError::Backend(e.to_string());
        root.fill(&WHITE).map_err(be)?;
        let segs: Vec<Vec<Vec<(f64, f64)>>> =
            self.series.iter().map(|s| self.segments(s)).collect();
        let (xa, ya) = self.axes()?;

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

        lines::draw_lines(self, &mut chart, &xa, &ya).map_err(be)?;

        for (s, parts) in self.series.iter().zip(&segs) {
            let c = colour(s.color);
            for part in parts {
                match s.mark {
                    Mark::Line | Mark::LinePoints => {
                        for path in strokes(part, |p| chart.backend_coord(p)) {
                            chart
                                .draw_series(LineSeries::new(path, c.stroke_width(2)))
                                .map_err(be)?;
                        }
                    }
                    // Stroke by stroke as the solid line: joined again, each split point would
                    // repeat and give the zero-length segment `strokes` removes.
                    Mark::Dashed | Mark::DashedPoints => {
                        for path in strokes(part, |p| chart.backend_coord(p)) {
                            chart
                                .draw_series(DashedLineSeries::new(path, 8, 5, c.stroke_width(2)))
                                .map_err(be)?;
                        }
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

        lines::draw_labels(self, &mut chart, &plot_area, &xa, &ya).map_err(be)?;

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

/// A line's points as the strokes to draw: one point per pixel (a run of samples on one pixel,
/// 2 250 telemetry frames across 800 pixels, gives zero-length segments), and a new stroke
/// wherever the line turns back by more than 120 degrees (a speed that steps down and is
/// corrected up within a pixel column). The bitmap backend joins a wide stroke's segments by
/// intersecting their edges, and two nearly opposite segments meet far away: a spike to the
/// plot's edge, seen in the demo's speed charts at a step. Neighbouring strokes share their end
/// point, so the line stays unbroken.
fn strokes(part: &[(f64, f64)], pixel: impl Fn(&(f64, f64)) -> (i32, i32)) -> Vec<Vec<(f64, f64)>> {
    let mut pts: Vec<((f64, f64), (i32, i32))> = Vec::with_capacity(part.len());
    for p in part {
        let px = pixel(p);
        if pts.last().is_some_and(|l| l.1 == px) {
            continue;
        }
        pts.push((*p, px));
    }
    let mut out = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    for (i, &(p, px)) in pts.iter().enumerate() {
        cur.push(p);
        let (Some(prev), Some(next)) = (i.checked_sub(1).map(|k| pts[k].1), pts.get(i + 1)) else {
            continue;
        };
        let a = (f64::from(px.0 - prev.0), f64::from(px.1 - prev.1));
        let b = (f64::from(next.1.0 - px.0), f64::from(next.1.1 - px.1));
        let dot = a.0 * b.0 + a.1 * b.1;
        let norms = (a.0.hypot(a.1) * b.0.hypot(b.1)).max(f64::MIN_POSITIVE);
        if dot / norms < -0.5 {
            out.push(std::mem::take(&mut cur));
            cur.push(p);
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

#[cfg(test)]
mod tests;

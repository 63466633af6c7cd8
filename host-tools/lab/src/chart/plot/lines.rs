//! The figure's marker lines: vertical ones (bounds, events) and horizontal ones (targets), each
//! drawn across the plot with its label.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{Axis, FONT, Figure, colour, to_axis};

type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<Axis, Axis>>;

/// Draws the lines themselves (under the data).
pub(super) fn draw_lines<DB: DrawingBackend>(
    fig: &Figure,
    chart: &mut Chart<'_, DB>,
    xa: &Axis,
    ya: &Axis,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    for v in &fig.vlines {
        if let Some(x) = to_axis(fig.x_scale, v.x) {
            chart.draw_series(DashedLineSeries::new(
                vec![(x, ya.lo), (x, ya.hi)],
                6,
                4,
                colour(v.color).stroke_width(1),
            ))?;
        }
    }
    for h in &fig.hlines {
        if let Some(y) = to_axis(fig.y_scale, h.y) {
            chart.draw_series(DashedLineSeries::new(
                vec![(xa.lo, y), (xa.hi, y)],
                8,
                5,
                colour(h.color).stroke_width(2),
            ))?;
        }
    }
    Ok(())
}

/// Draws the lines' labels (over the data).
pub(super) fn draw_labels<DB: DrawingBackend>(
    fig: &Figure,
    chart: &mut Chart<'_, DB>,
    plot_area: &DrawingArea<DB, Shift>,
    xa: &Axis,
    ya: &Axis,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    // Vertical lines' labels staggered downwards from one step below the top (a series along
    // the top edge, such as a target, would cross the first one). A label that would run past
    // the plot's right edge (into the legend) ends at its line instead of starting there.
    let right_px = chart.plotting_area().get_pixel_range().0.end;
    for (i, v) in fig.vlines.iter().enumerate() {
        if let Some(x) = to_axis(fig.x_scale, v.x) {
            let label_y = ya.hi - (ya.hi - ya.lo) * 0.035 * (1 + i % 8) as f64;
            let font = (FONT, 13).into_font().color(&colour(v.color));
            let width_px = plot_area
                .estimate_text_size(&v.label, &font)
                .map_or(0, |(w, _)| w as i32);
            let (label, font) = if chart.backend_coord(&(x, label_y)).0 + width_px > right_px {
                let anchor = Pos::new(HPos::Right, VPos::Top);
                (format!("{} ", v.label.trim()), font.pos(anchor))
            } else {
                (v.label.clone(), font)
            };
            chart.draw_series(std::iter::once(Text::new(label, (x, label_y), font)))?;
        }
    }
    // A horizontal line's label sits on the line at its right end, just above it, inside the
    // plot (the axis keeps the line clear of the frame, so there is room).
    for h in &fig.hlines {
        if let Some(y) = to_axis(fig.y_scale, h.y) {
            let font = (FONT, 13)
                .into_font()
                .color(&colour(h.color))
                .pos(Pos::new(HPos::Right, VPos::Bottom));
            let label = EmptyElement::at((xa.hi, y))
                + Text::new(h.label.trim().to_string(), (-6, -4), font);
            chart.plotting_area().draw(&label)?;
        }
    }
    Ok(())
}

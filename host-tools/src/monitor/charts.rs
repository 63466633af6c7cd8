//! The monitor's speed charts: the history of set and measured speed per axis against device
//! time, and its chart with numbered axes.

use std::collections::VecDeque;

use model_core::wire::Telemetry;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Borders, Chart, Dataset, GraphType};

/// Seconds of device time the charts show.
const WINDOW_S: f64 = 20.0;
/// The smallest speed span of a chart, rad/s: noise of a few mrad/s must not fill the height.
const MIN_SPAN_RAD_S: f64 = 1.0;

/// Speed history for the charts: (device time s, set, measured) per axis, rad/s.
pub struct History {
    pub axes: [VecDeque<(f64, f64, f64)>; 2],
}

impl History {
    pub fn push(&mut self, t: &Telemetry) {
        let now = f64::from(t.time_ms) / 1000.0;
        for (axis, m) in self.axes.iter_mut().zip([t.precession, t.spin]) {
            // A device restart starts the time axis again.
            if axis.back().is_some_and(|&(last, _, _)| now < last) {
                axis.clear();
            }
            axis.push_back((
                now,
                f64::from(m.set_mrad_s) / 1000.0,
                f64::from(m.measured_mrad_s) / 1000.0,
            ));
            while axis.front().is_some_and(|&(t0, _, _)| now - t0 > WINDOW_S) {
                axis.pop_front();
            }
        }
    }
}

/// One axis: set (yellow) and measured (cyan) speed against device time, numbered axes.
pub fn speed_chart(
    f: &mut ratatui::Frame,
    area: Rect,
    name: &str,
    points: &VecDeque<(f64, f64, f64)>,
    live: bool,
    ascii: bool,
) {
    let set: Vec<(f64, f64)> = points.iter().map(|&(t, s, _)| (t, s)).collect();
    let measured: Vec<(f64, f64)> = points.iter().map(|&(t, _, m)| (t, m)).collect();
    let t_end = points.back().map_or(WINDOW_S, |p| p.0.max(WINDOW_S));
    let t_start = t_end - WINDOW_S;
    let (lo, hi) = points
        .iter()
        .fold((0.0f64, 0.0f64), |(lo, hi), &(_, s, m)| {
            (lo.min(s).min(m), hi.max(s).max(m))
        });
    let span = (hi - lo).max(MIN_SPAN_RAD_S) * 1.1;
    let (y0, y1) = (lo.min(0.0), lo.min(0.0) + span);
    let dim = |c: Color| if live { c } else { Color::DarkGray };
    // In ASCII (see `glyphs`) one mark per cell, and a mark of its own for each line, so set
    // and measured differ without colour: dots (`.`) and blocks (`*`).
    let (set_marker, measured_marker, set_mark, measured_mark) = if ascii {
        (Marker::Dot, Marker::Block, " (.)", " (*)")
    } else {
        (Marker::Braille, Marker::Braille, "", "")
    };
    let datasets = vec![
        Dataset::default()
            .name("set")
            .marker(set_marker)
            .graph_type(GraphType::Line)
            .style(Style::default().fg(dim(Color::Yellow)))
            .data(&set),
        Dataset::default()
            .name("measured")
            .marker(measured_marker)
            .graph_type(GraphType::Line)
            .style(Style::default().fg(dim(Color::Cyan)))
            .data(&measured),
    ];
    let y_labels = [y0, (y0 + y1) / 2.0, y1].map(|v| format!("{v:.2}"));
    // The plot's columns: the frame's two, the y labels' and the axis line's are not in it.
    let y_label_width = y_labels.iter().map(String::len).max().unwrap_or(0) as u16;
    let plot_width = area.width.saturating_sub(2 + y_label_width + 1);
    // What the lines are and the units go in the frame's title: a legend or an axis title
    // inside the plot would be drawn over the newest samples at the right edge.
    let title = Line::from(vec![
        Span::raw(format!(" {name} rad/s: ")),
        Span::styled(
            format!("set{set_mark}"),
            Style::default().fg(dim(Color::Yellow)),
        ),
        Span::raw(", "),
        Span::styled(
            format!("measured{measured_mark}"),
            Style::default().fg(dim(Color::Cyan)),
        ),
        Span::raw(" "),
    ]);
    let chart = Chart::new(datasets)
        .block(Block::default().borders(Borders::ALL).title(title))
        .legend_position(None)
        // The unit on the last label, below the axis (device time, s).
        .x_axis(
            Axis::default()
                .bounds([t_start, t_end])
                .labels(super::fit::time_labels(t_start, t_end, plot_width)),
        )
        .y_axis(Axis::default().bounds([y0, y1]).labels(y_labels));
    f.render_widget(chart, area);
}

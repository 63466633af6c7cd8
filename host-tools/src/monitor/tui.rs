//! The monitor's terminal UI (ratatui + crossterm): live charts of set and measured speed per
//! axis against device time, the latest values, link and fault banners, counters, events and a
//! command line. Keys: `:` starts a command (Enter sends, Esc drops it), `p` or space pauses the
//! charts, `q` or Ctrl-C quits. The terminal is restored on every way out.

use std::collections::VecDeque;
use std::io::Stdout;
use std::time::Duration;

use anyhow::Result;
use crossterm::event::{self, Event, KeyCode, KeyEvent, KeyEventKind, KeyModifiers};
use crossterm::terminal::{
    EnterAlternateScreen, LeaveAlternateScreen, disable_raw_mode, enable_raw_mode,
};
use model_core::wire::{Decoder, FaultCode, Telemetry};
use ratatui::Terminal;
use ratatui::backend::CrosstermBackend;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Borders, Chart, Dataset, GraphType, Paragraph};

use super::view::{View, residence_text};

/// Seconds of device time the charts show.
const WINDOW_S: f64 = 20.0;
/// The smallest speed span of a chart, rad/s: noise of a few mrad/s must not fill the height.
const MIN_SPAN_RAD_S: f64 = 1.0;

/// What a key asked for.
pub enum Action {
    None,
    Quit,
    Send(String),
}

/// Speed history for the charts: (device time s, set, measured) per axis, rad/s.
struct History {
    axes: [VecDeque<(f64, f64, f64)>; 2],
}

impl History {
    fn push(&mut self, t: &Telemetry) {
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

/// The terminal in raw mode on the alternate screen, and what the UI alone keeps.
pub struct Tui {
    terminal: Terminal<CrosstermBackend<Stdout>>,
    history: History,
    paused: bool,
    /// The command being typed, when the command line is open.
    input: Option<String>,
}

impl Tui {
    pub fn start() -> Result<Tui> {
        enable_raw_mode()?;
        crossterm::execute!(std::io::stdout(), EnterAlternateScreen)?;
        let terminal = Terminal::new(CrosstermBackend::new(std::io::stdout()))?;
        Ok(Tui {
            terminal,
            history: History {
                axes: [VecDeque::new(), VecDeque::new()],
            },
            paused: false,
            input: None,
        })
    }

    pub fn on_telemetry(&mut self, t: &Telemetry) {
        if !self.paused {
            self.history.push(t);
        }
    }

    /// Handles the keys pressed since the last call (resizes are picked up by the next draw).
    pub fn keys(&mut self) -> Result<Action> {
        while event::poll(Duration::ZERO)? {
            if let Event::Key(key) = event::read()?
                && key.kind != KeyEventKind::Release
            {
                let action = self.key(key);
                if !matches!(action, Action::None) {
                    return Ok(action);
                }
            }
        }
        Ok(Action::None)
    }

    fn key(&mut self, key: KeyEvent) -> Action {
        if key.modifiers.contains(KeyModifiers::CONTROL) && key.code == KeyCode::Char('c') {
            return Action::Quit;
        }
        match (&mut self.input, key.code) {
            (Some(text), KeyCode::Enter) => {
                let text = std::mem::take(text);
                self.input = None;
                return Action::Send(text);
            }
            (Some(_), KeyCode::Esc) => self.input = None,
            (Some(text), KeyCode::Backspace) => {
                text.pop();
            }
            (Some(text), KeyCode::Char(c)) => text.push(c),
            (Some(_), _) => {}
            (None, KeyCode::Char('q')) => return Action::Quit,
            (None, KeyCode::Char('p') | KeyCode::Char(' ')) => self.paused = !self.paused,
            (None, KeyCode::Char(':') | KeyCode::Enter) => self.input = Some(String::new()),
            (None, _) => {}
        }
        Action::None
    }

    pub fn draw(&mut self, port: &str, view: &View, decoder: &Decoder, tools: usize) -> Result<()> {
        let (history, paused, input) = (&self.history, self.paused, &self.input);
        self.terminal.draw(|f| {
            let rows = Layout::vertical([
                Constraint::Length(1),
                Constraint::Length(1),
                Constraint::Min(8),
                Constraint::Length(5),
                Constraint::Length(1),
                Constraint::Length(4),
                Constraint::Length(1),
            ])
            .split(f.area());
            f.render_widget(banner(port, view, paused, tools), rows[0]);
            f.render_widget(fault_line(view), rows[1]);
            let charts = Layout::horizontal([Constraint::Ratio(1, 2), Constraint::Ratio(1, 2)])
                .split(rows[2]);
            let live = view.connected && view.latest.is_some();
            for (i, (name, area)) in ["precession w1", "spin w2"]
                .iter()
                .zip(charts.iter())
                .enumerate()
            {
                speed_chart(f, *area, name, &history.axes[i], live);
            }
            f.render_widget(values(view), rows[3]);
            f.render_widget(
                Paragraph::new(view.counters(decoder)).style(Style::default().fg(Color::Cyan)),
                rows[4],
            );
            let events: Vec<Line> = view
                .events
                .iter()
                .rev()
                .take(4)
                .map(|e| Line::from(e.as_str()))
                .collect();
            f.render_widget(
                Paragraph::new(events)
                    .block(Block::default().borders(Borders::TOP).title("events")),
                rows[5],
            );
            let prompt = match input {
                Some(text) => Line::from(vec![
                    Span::styled("command> ", Style::default().fg(Color::Yellow)),
                    Span::raw(text.as_str()),
                    Span::styled("_", Style::default().add_modifier(Modifier::SLOW_BLINK)),
                    Span::styled(
                        "   Enter send · Esc cancel",
                        Style::default().fg(Color::DarkGray),
                    ),
                ]),
                None => Line::from(Span::styled(
                    ": command (e.g. status, speed 1800 2100, start, stop) · p pause · q quit",
                    Style::default().fg(Color::DarkGray),
                )),
            };
            f.render_widget(Paragraph::new(prompt), rows[6]);
        })?;
        Ok(())
    }
}

impl Drop for Tui {
    fn drop(&mut self) {
        let _ = disable_raw_mode();
        let _ = crossterm::execute!(std::io::stdout(), LeaveAlternateScreen);
        let _ = self.terminal.show_cursor();
    }
}

/// The top line: port, link, rig state and fault, each impossible to miss when it matters.
fn banner<'a>(port: &'a str, view: &View, paused: bool, tools: usize) -> Paragraph<'a> {
    let alarm = Style::default()
        .fg(Color::White)
        .bg(Color::Red)
        .add_modifier(Modifier::BOLD);
    let mut spans = vec![Span::styled(
        format!(" bowl monitor {port} "),
        Style::default().add_modifier(Modifier::BOLD),
    )];
    if view.connected {
        spans.push(Span::styled(
            " LINK OK ",
            Style::default().fg(Color::Black).bg(Color::Green),
        ));
    } else {
        spans.push(Span::styled(
            " LINK LOST - reopening; the values below are old ",
            alarm,
        ));
    }
    if let Some(t) = view.latest.filter(|_| view.connected) {
        spans.push(Span::raw(format!(
            "  state {}  ",
            crate::words::state(t.state)
        )));
    }
    if paused {
        spans.push(Span::styled(
            " PAUSED ",
            Style::default().fg(Color::Black).bg(Color::Yellow),
        ));
    }
    if tools > 0 {
        spans.push(Span::raw(format!("  {tools} tool(s) connected")));
    }
    Paragraph::new(Line::from(spans))
}

/// A whole red line while the rig reports a fault (the motors are off until `clear`).
fn fault_line(view: &View) -> Paragraph<'static> {
    match view.latest.filter(|_| view.connected) {
        Some(t) if t.fault != FaultCode::None => Paragraph::new(format!(
            " FAULT {}: the rig stopped the motors. {}. Type `:clear` once the cause is fixed",
            t.fault.code(),
            crate::words::fault(t.fault)
        ))
        .style(
            Style::default()
                .fg(Color::White)
                .bg(Color::Red)
                .add_modifier(Modifier::BOLD),
        ),
        Some(_) => Paragraph::new(" no fault").style(Style::default().fg(Color::Green)),
        None => Paragraph::new(" fault: unknown (no current telemetry)")
            .style(Style::default().fg(Color::DarkGray)),
    }
}

/// One axis: set (yellow) and measured (cyan) speed against device time, numbered axes.
fn speed_chart(
    f: &mut ratatui::Frame,
    area: Rect,
    name: &str,
    points: &VecDeque<(f64, f64, f64)>,
    live: bool,
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
    let datasets = vec![
        Dataset::default()
            .name("set")
            .marker(Marker::Braille)
            .graph_type(GraphType::Line)
            .style(Style::default().fg(dim(Color::Yellow)))
            .data(&set),
        Dataset::default()
            .name("measured")
            .marker(Marker::Braille)
            .graph_type(GraphType::Line)
            .style(Style::default().fg(dim(Color::Cyan)))
            .data(&measured),
    ];
    let label = |v: f64| Span::raw(format!("{v:.2}"));
    let chart = Chart::new(datasets)
        .block(
            Block::default()
                .borders(Borders::ALL)
                .title(format!(" {name} ")),
        )
        .x_axis(
            Axis::default()
                .title("device time (s)")
                .bounds([t_start, t_end])
                .labels([
                    Span::raw(format!("{t_start:.0}")),
                    Span::raw(format!("{:.0}", (t_start + t_end) / 2.0)),
                    Span::raw(format!("{t_end:.0}")),
                ]),
        )
        .y_axis(
            Axis::default()
                .title("speed (rad/s)")
                .bounds([y0, y1])
                .labels([label(y0), label((y0 + y1) / 2.0), label(y1)]),
        );
    f.render_widget(chart, area);
}

/// The latest values; grey when the link is lost (they are then the last known, not current).
fn values(view: &View) -> Paragraph<'static> {
    let Some(t) = view.latest else {
        return Paragraph::new("no telemetry yet");
    };
    let style = if view.connected {
        Style::default()
    } else {
        Style::default()
            .fg(Color::DarkGray)
            .add_modifier(Modifier::CROSSED_OUT)
    };
    let mut lines = vec![Line::from(format!(
        "device time {:.3} s  seq {}   {:>13} {:>15} {:>8} {:>7}",
        f64::from(t.time_ms) / 1000.0,
        t.seq,
        "set rad/s",
        "measured rad/s",
        "duty %",
        "pulses"
    ))];
    for (name, m) in [("precession w1", t.precession), ("spin w2      ", t.spin)] {
        lines.push(Line::from(format!(
            "{name}                  {:>13.3} {:>15.3} {:>8.2} {:>7}",
            f64::from(m.set_mrad_s) / 1000.0,
            f64::from(m.measured_mrad_s) / 1000.0,
            f64::from(m.duty_bp) / 100.0,
            m.pulses
        )));
    }
    lines.push(Line::from(format!(
        "bowl speed (Eq. 2) {:.3} rad/s   residence flat {}   Coriolis {}",
        f64::from(t.bowl_mrad_s) / 1000.0,
        residence_text(t.residence_flat),
        residence_text(t.residence_coriolis)
    )));
    if !view.connected {
        lines.push(Line::from("(last values before the link was lost)"));
    }
    Paragraph::new(lines).style(style)
}

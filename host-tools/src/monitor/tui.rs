//! The monitor's terminal UI (ratatui + crossterm): live charts of set and measured speed per
//! axis against device time, the latest values, link and fault banners, counters, events and a
//! command line. Keys: `:` starts a command (Enter sends, Esc drops it, Up/Down bring back
//! earlier ones, Tab completes), `p` or space pauses the charts, `q` or Ctrl-C quits. The
//! terminal is restored on every way out.

use std::collections::VecDeque;
use std::io::Stdout;
use std::mem::ManuallyDrop;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use anyhow::Result;
use crossterm::event::{self, Event, KeyCode, KeyEvent, KeyEventKind, KeyModifiers};
use crossterm::terminal::{
    EnterAlternateScreen, LeaveAlternateScreen, disable_raw_mode, enable_raw_mode,
};
use model_core::wire::{Decoder, FaultCode, Telemetry};
use ratatui::Terminal;
use ratatui::backend::CrosstermBackend;
use ratatui::layout::{Constraint, Layout};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph};

use super::charts::{History, speed_chart};
use super::line_edit::LineEdit;
use super::view::{View, residence_text};
use super::wrap::{pack, wrap};

/// What a key asked for.
pub enum Action {
    None,
    Quit,
    Send(String),
}

/// The terminal in raw mode on the alternate screen, and what the UI alone keeps.
pub struct Tui {
    /// Never dropped: ratatui's drop, finding the cursor hidden, shows it and on failure (the
    /// terminal closed) prints to standard error, which then panics. [`Tui`]'s drop shows it.
    terminal: ManuallyDrop<Terminal<CrosstermBackend<Stdout>>>,
    history: History,
    paused: bool,
    /// Whether the command line is open.
    typing: bool,
    /// The command line's text and history.
    line: LineEdit,
    /// `NO_COLOR` is set (no-color.org): no colours; what a coloured background marked (the
    /// alarms, LINK OK, PAUSED) is drawn in reverse video instead, so it still stands out.
    no_color: bool,
    /// The locale has no UTF-8: the screen is drawn in ASCII ([`super::glyphs`]).
    ascii: bool,
    /// The terminal's events, read on a thread of their own ([`read_events`]).
    events: mpsc::Receiver<Event>,
}

/// Reads the terminal's events into `tx` until the UI is gone. On its own thread because a
/// terminal that closes (SIGHUP) makes crossterm's reader spin on the end of input without
/// returning: the monitor's loop must stay free to see the hangup and close its log.
fn read_events(tx: mpsc::Sender<Event>) {
    while let Ok(ev) = event::read() {
        if tx.send(ev).is_err() {
            break;
        }
    }
}

impl Tui {
    pub fn start() -> Result<Tui> {
        enable_raw_mode()?;
        crossterm::execute!(std::io::stdout(), EnterAlternateScreen)?;
        let terminal = Terminal::new(CrosstermBackend::new(std::io::stdout()))?;
        let (tx, events) = mpsc::channel();
        std::thread::spawn(move || read_events(tx));
        Ok(Tui {
            terminal: ManuallyDrop::new(terminal),
            history: History {
                axes: [VecDeque::new(), VecDeque::new()],
            },
            paused: false,
            typing: false,
            line: LineEdit::default(),
            no_color: std::env::var_os("NO_COLOR").is_some_and(|v| !v.is_empty()),
            ascii: !super::glyphs::utf8_locale(),
            events,
        })
    }

    pub fn on_telemetry(&mut self, t: &Telemetry) {
        if !self.paused {
            self.history.push(t);
        }
    }

    /// Handles the keys pressed since the last call (resizes are picked up by the next draw).
    pub fn keys(&mut self) -> Result<Action> {
        while let Ok(ev) = self.events.try_recv() {
            if let Event::Key(key) = ev
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
        let chord = key
            .modifiers
            .intersects(KeyModifiers::CONTROL | KeyModifiers::ALT);
        let code = match key.code {
            // A newline (the end of a pasted line; Enter on some terminals) is Enter.
            KeyCode::Char('j') if key.modifiers.contains(KeyModifiers::CONTROL) => KeyCode::Enter,
            // Other chords with a letter (Ctrl-U, Alt-B from habit) are no letter to type, nor
            // a key of the screen's (Ctrl-Q is not `q`). Symbols stay: AltGr sends Ctrl-Alt.
            KeyCode::Char(c) if chord && c.is_ascii_alphabetic() => return Action::None,
            code => code,
        };
        let line = &mut self.line;
        match (self.typing, code) {
            (true, KeyCode::Enter) => {
                self.typing = false;
                return Action::Send(line.take());
            }
            (true, KeyCode::Esc) => self.typing = false,
            (true, KeyCode::Backspace) => line.backspace(),
            (true, KeyCode::Up) => line.older(),
            (true, KeyCode::Down) => line.newer(),
            (true, KeyCode::Tab) => line.complete(),
            (true, KeyCode::Char(c)) => line.push(c),
            (true, _) => {}
            (false, KeyCode::Char('q')) => return Action::Quit,
            (false, KeyCode::Char('p') | KeyCode::Char(' ')) => self.paused = !self.paused,
            (false, KeyCode::Char(':') | KeyCode::Enter) => {
                self.typing = true;
                line.open();
            }
            // Up opens the command line on the last command, as in a shell.
            (false, KeyCode::Up) => {
                self.typing = true;
                line.open();
                line.older();
            }
            (false, _) => {}
        }
        Action::None
    }

    pub fn draw(&mut self, port: &str, view: &View, decoder: &Decoder, tools: usize) -> Result<()> {
        let (history, paused) = (&self.history, self.paused);
        let input = self.typing.then_some(&self.line);
        let silence = view.silence(Instant::now());
        let (no_color, ascii) = (self.no_color, self.ascii);
        self.terminal.draw(|f| {
            // Laid out at least MIN_WIDTH wide: a narrower terminal gets the words of
            // fit::too_small, never the screen cut at its edge.
            let width = usize::from(f.area().width.max(super::fit::MIN_WIDTH));
            // The fault line and the events are wrapped to the width, never cut: the end of a
            // fault line says what to do.
            let (fault_text, fault_style) = fault_line(view, silence.is_some());
            let fault_rows = wrap(&fault_text, width);
            // The newest event whole (up to EVENT_ROWS_MAX rows), then older ones while they fit.
            let newest = view.events.back().map_or(0, |e| wrap(e, width).len());
            let event_space = newest.clamp(EVENT_ROWS, EVENT_ROWS_MAX);
            let mut event_rows = Vec::new();
            for e in view.events.iter().rev() {
                let mut lines = wrap(e, width);
                if event_rows.len() + lines.len() > event_space && !event_rows.is_empty() {
                    break;
                }
                lines.truncate(event_space);
                event_rows.extend(lines);
            }
            let banner_rows = banner(port, view, silence, paused, tools, width);
            let live = view.connected && silence.is_none() && view.latest.is_some();
            let (value_lines, value_style) = values(view, live, width);
            let counters: Vec<Line> = wrap(&view.counters(decoder), width)
                .into_iter()
                .map(Line::from)
                .collect();
            let must = banner_rows.len() + fault_rows.len() + value_lines.len() + 1;
            if let Some(words) = super::fit::too_small(f.area().width, f.area().height, must) {
                let mut lines: Vec<Line> = words.into_iter().map(Line::from).collect();
                // What is being typed stays in sight, on the last row if there is one spare.
                if input.is_some() && lines.len() < usize::from(f.area().height) {
                    let columns = usize::from(f.area().width);
                    lines.resize(usize::from(f.area().height) - 1, Line::default());
                    lines.push(super::prompt::line(input, columns));
                }
                f.render_widget(Paragraph::new(lines), f.area());
                if ascii {
                    super::glyphs::to_ascii(f.buffer_mut());
                }
                return;
            }
            // In a small terminal the charts give way first, never the banner or the fault.
            let heights = super::fit::rows(
                f.area().height,
                banner_rows.len(),
                fault_rows.len(),
                value_lines.len(),
                counters.len(),
                event_space + 1,
            );
            let rows = Layout::vertical(heights.map(Constraint::Length)).split(f.area());
            f.render_widget(Paragraph::new(banner_rows), rows[0]);
            let fault_lines: Vec<Line> = fault_rows.into_iter().map(Line::from).collect();
            f.render_widget(Paragraph::new(fault_lines).style(fault_style), rows[1]);
            let charts = Layout::horizontal([Constraint::Ratio(1, 2), Constraint::Ratio(1, 2)])
                .split(rows[2]);
            for (i, (name, area)) in ["precession w1", "spin w2"]
                .iter()
                .zip(charts.iter())
                .enumerate()
            {
                speed_chart(f, *area, name, &history.axes[i], live, ascii);
            }
            f.render_widget(Paragraph::new(value_lines).style(value_style), rows[3]);
            f.render_widget(
                Paragraph::new(counters).style(Style::default().fg(Color::Cyan)),
                rows[4],
            );
            let events: Vec<Line> = event_rows.into_iter().map(Line::from).collect();
            f.render_widget(
                Paragraph::new(events)
                    .block(Block::default().borders(Borders::TOP).title("events")),
                rows[5],
            );
            let prompt = super::prompt::line(input, width);
            f.render_widget(Paragraph::new(prompt), rows[6]);
            if no_color {
                for cell in &mut f.buffer_mut().content {
                    if cell.bg != Color::Reset {
                        cell.modifier |= Modifier::REVERSED;
                    }
                    (cell.fg, cell.bg) = (Color::Reset, Color::Reset);
                }
            }
            if ascii {
                super::glyphs::to_ascii(f.buffer_mut());
            }
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
fn banner(
    port: &str,
    view: &View,
    silence: Option<Duration>,
    paused: bool,
    tools: usize,
    width: usize,
) -> Vec<Line<'static>> {
    let alarm = Style::default()
        .fg(Color::White)
        .bg(Color::Red)
        .add_modifier(Modifier::BOLD);
    let mut spans = vec![Span::styled(
        // A long path (a link in a deep directory) is shortened, so the link and the state
        // stay on the first rows and the banner leaves the screen to the rest.
        format!(
            " bowl monitor {} ",
            super::wrap::shorten(port, width.saturating_sub(30).max(12))
        ),
        Style::default().add_modifier(Modifier::BOLD),
    )];
    if let Some(quiet) = silence.filter(|_| view.connected) {
        // The port is open but nothing comes: LINK OK would be a lie.
        spans.push(Span::styled(
            format!(
                " no telemetry for {:.0} s - the values below are old ",
                quiet.as_secs_f64()
            ),
            alarm,
        ));
    } else if view.connected {
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
    if let Some(t) = view.latest.filter(|_| view.connected && silence.is_none()) {
        spans.push(Span::raw(format!("  state {}  ", t.state.words())));
    }
    // Board conditions the rig reported (defaults instead of the saved parameters, the
    // internal oscillator): on the banner for as long as they hold, not only as an event.
    if let Some(words) = view
        .board_flags
        .and_then(rig_client::lines::status_flag_words)
        .filter(|_| view.connected)
    {
        spans.push(Span::styled(
            format!(" board: {words} "),
            Style::default().fg(Color::Black).bg(Color::Yellow),
        ));
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
    pack(spans, width)
}

/// How many rows the events get (the newest first, each wrapped) ...
const EVENT_ROWS: usize = 4;
/// ... and at most, for a long newest event (a refusal that lists every parameter name).
const EVENT_ROWS_MAX: usize = 8;

/// The fault line's text and style: red while the rig reports a fault (the motors are off until
/// `clear`), unknown while no current telemetry comes (`stale`: overdue).
fn fault_line(view: &View, stale: bool) -> (String, Style) {
    match view.latest.filter(|_| view.connected && !stale) {
        Some(t) if t.fault != FaultCode::None => (
            format!(
                " FAULT {}: the rig stopped the motors. {}. Type `:clear` once the cause is fixed",
                t.fault.code(),
                t.fault.words()
            ),
            Style::default()
                .fg(Color::White)
                .bg(Color::Red)
                .add_modifier(Modifier::BOLD),
        ),
        Some(_) => (" no fault".into(), Style::default().fg(Color::Green)),
        None => (
            " fault: unknown (no current telemetry)".into(),
            Style::default().fg(Color::DarkGray),
        ),
    }
}

/// The widest line of the values' table: narrower screens get them as sentences, wrapped.
const VALUES_TABLE_WIDTH: usize = 82;

/// The latest values in lines no wider than `width`, and their style: grey when they are not
/// current (`live` false: the link is lost or no telemetry came for a while: they are then the
/// last known).
fn values(view: &View, live: bool, width: usize) -> (Vec<Line<'static>>, Style) {
    let Some(t) = view.latest else {
        return (vec![Line::from("no telemetry yet")], Style::default());
    };
    let style = if live {
        Style::default()
    } else {
        Style::default()
            .fg(Color::DarkGray)
            .add_modifier(Modifier::CROSSED_OUT)
    };
    let mut lines = Vec::new();
    let axes = [("precession w1", t.precession), ("spin w2      ", t.spin)];
    if width >= VALUES_TABLE_WIDTH {
        lines.push(format!(
            "device time {:.3} s  seq {}   {:>13} {:>15} {:>8} {:>7}",
            f64::from(t.time_ms) / 1000.0,
            t.seq,
            "set rad/s",
            "measured rad/s",
            "duty %",
            "pulses"
        ));
        for (name, m) in axes {
            lines.push(format!(
                "{name}                  {:>13.3} {:>15.3} {:>8.2} {:>7}",
                f64::from(m.set_mrad_s) / 1000.0,
                f64::from(m.measured_mrad_s) / 1000.0,
                f64::from(m.duty_bp) / 100.0,
                m.pulses
            ));
        }
    } else {
        lines.push(format!(
            "device time {:.3} s  seq {}",
            f64::from(t.time_ms) / 1000.0,
            t.seq
        ));
        for (name, m) in axes {
            lines.push(format!(
                "{}: set {:.3} measured {:.3} rad/s, duty {:.2} %, pulses {}",
                name.trim_end(),
                f64::from(m.set_mrad_s) / 1000.0,
                f64::from(m.measured_mrad_s) / 1000.0,
                f64::from(m.duty_bp) / 100.0,
                m.pulses
            ));
        }
    }
    lines.push(format!(
        "bowl speed (Eq. 2) {:.3} rad/s   residence flat {}   Coriolis {}",
        f64::from(t.bowl_mrad_s) / 1000.0,
        residence_text(t.residence_flat),
        residence_text(t.residence_coriolis)
    ));
    if !view.connected {
        lines.push("(last values before the link was lost)".into());
    } else if !live {
        lines.push("(last values before the telemetry stopped)".into());
    }
    let rows = lines.iter().flat_map(|l| wrap(l, width)).map(Line::from);
    (rows.collect(), style)
}

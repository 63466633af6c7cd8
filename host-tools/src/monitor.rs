//! `bowl monitor PORT`: live view of the rig's telemetry, CSV log keyed on device time, counters
//! of good, corrupt and missing frames; reopens the port after an unplug and keeps logging.
//!
//! On a terminal it draws a dashboard (latest values and trend lines, ANSI escapes only); with
//! `--plain` or when stdout is not a terminal it prints one line per second instead. It only
//! listens: it never writes to the port, so it cannot disturb the rig.

use std::collections::VecDeque;
use std::fs::{File, OpenOptions};
use std::io::{BufWriter, IsTerminal, Write};
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use model_core::wire::{Decoder, Frame, Hello, Residence, Telemetry};
use serde_json::json;

use crate::replay::stats_json;
use crate::send::describe;
use crate::serial::{Port, ReadOutcome};
use crate::telemetry_csv;

/// Flags of `bowl monitor`.
#[derive(clap::Args)]
pub struct Args {
    /// The serial port or pseudo-terminal of the rig.
    port: String,
    /// Baud rate.
    #[arg(long, default_value_t = 115_200)]
    baud: u32,
    /// Append the telemetry to this CSV file (header written when the file is new).
    #[arg(long)]
    log: Option<PathBuf>,
    /// Stop after this many seconds (default: run until interrupted).
    #[arg(long)]
    seconds: Option<f64>,
    /// One text line per second instead of the dashboard.
    #[arg(long)]
    plain: bool,
}

/// How many points a trend line keeps (one per redraw, 5 per second: 12 s).
const TREND_LEN: usize = 60;
const REDRAW: Duration = Duration::from_millis(200);
const REOPEN_EVERY: Duration = Duration::from_millis(250);

struct Trend {
    name: &'static str,
    points: VecDeque<f64>,
}

impl Trend {
    fn new(name: &'static str) -> Self {
        Self {
            name,
            points: VecDeque::with_capacity(TREND_LEN),
        }
    }

    fn push(&mut self, v: f64) {
        if self.points.len() == TREND_LEN {
            self.points.pop_front();
        }
        self.points.push_back(v);
    }

    /// A sparkline of the points, scaled between their min and max.
    fn sparkline(&self) -> String {
        const BARS: [char; 8] = ['▁', '▂', '▃', '▄', '▅', '▆', '▇', '█'];
        let finite = self.points.iter().copied().filter(|v| v.is_finite());
        let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        self.points
            .iter()
            .map(|&v| {
                if !v.is_finite() {
                    ' '
                } else if hi - lo < 1e-12 {
                    BARS[3]
                } else {
                    BARS[(((v - lo) / (hi - lo)) * 7.0).round().clamp(0.0, 7.0) as usize]
                }
            })
            .collect()
    }
}

fn residence_s(r: Residence) -> f64 {
    match r {
        Residence::Ms(ms) => f64::from(ms) / 1000.0,
        _ => f64::NAN,
    }
}

fn residence_text(r: Residence) -> String {
    match r {
        Residence::Ms(ms) => format!("{:.3} s", f64::from(ms) / 1000.0),
        Residence::NeverLeaves => "never leaves".into(),
        Residence::Unavailable => "-".into(),
    }
}

/// What the live view shows; also drawn by `bowl demo`.
pub(crate) struct View {
    latest: Option<Telemetry>,
    hello: Option<Hello>,
    events: VecDeque<String>,
    trends: [Trend; 5],
    reconnects: u64,
    connected: bool,
    logged_rows: u64,
}

impl View {
    pub(crate) fn new() -> Self {
        View {
            latest: None,
            hello: None,
            events: VecDeque::new(),
            trends: [
                Trend::new("w1 rad/s"),
                Trend::new("w2 rad/s"),
                Trend::new("bowl rad/s"),
                Trend::new("T flat s"),
                Trend::new("T Coriolis s"),
            ],
            reconnects: 0,
            connected: false,
            logged_rows: 0,
        }
    }

    /// Takes in one decoded frame (the CSV log is the caller's).
    pub(crate) fn on_frame(&mut self, plain: bool, frame: &Frame) {
        match frame {
            Frame::Telemetry(t) => self.latest = Some(*t),
            Frame::Hello(h) => {
                self.hello = Some(*h);
                self.event(
                    plain,
                    format!(
                        "rig booted: reset cause {:?}, reset count {}",
                        h.reset_cause, h.reset_count
                    ),
                );
            }
            other => self.event(plain, format!("answer: {}", describe(other))),
        }
    }

    pub(crate) fn set_connected(&mut self, connected: bool) {
        self.connected = connected;
    }

    pub(crate) fn event(&mut self, plain: bool, text: String) {
        if plain {
            println!("{text}");
        }
        if self.events.len() == 5 {
            self.events.pop_front();
        }
        self.events.push_back(text);
    }

    pub(crate) fn sample_trends(&mut self) {
        if let Some(t) = self.latest {
            let values = [
                f64::from(t.precession.measured_mrad_s) / 1000.0,
                f64::from(t.spin.measured_mrad_s) / 1000.0,
                f64::from(t.bowl_mrad_s) / 1000.0,
                residence_s(t.residence_flat),
                residence_s(t.residence_coriolis),
            ];
            for (trend, v) in self.trends.iter_mut().zip(values) {
                trend.push(v);
            }
        }
    }

    fn counters(&self, d: &Decoder) -> String {
        let s = d.stats();
        format!(
            "frames ok {}  corrupt {}  missing {}  bytes skipped {}  reconnects {}",
            s.frames_ok, s.frames_corrupt, s.frames_missing, s.bytes_skipped, self.reconnects
        )
    }

    pub(crate) fn plain_line(&self, d: &Decoder) -> String {
        let values = match self.latest {
            Some(t) => format!(
                "t={:.3}s seq={} state={:?} fault={:?} w1={:.3}/{:.3} w2={:.3}/{:.3} rad/s bowl={:.3} rad/s T_flat={} T_cor={}",
                f64::from(t.time_ms) / 1000.0,
                t.seq,
                t.state,
                t.fault,
                f64::from(t.precession.measured_mrad_s) / 1000.0,
                f64::from(t.precession.set_mrad_s) / 1000.0,
                f64::from(t.spin.measured_mrad_s) / 1000.0,
                f64::from(t.spin.set_mrad_s) / 1000.0,
                f64::from(t.bowl_mrad_s) / 1000.0,
                residence_text(t.residence_flat),
                residence_text(t.residence_coriolis),
            ),
            None => "no telemetry yet".into(),
        };
        format!("{values} | {}", self.counters(d))
    }

    pub(crate) fn dashboard(&self, port: &str, d: &Decoder) -> String {
        let mut s = String::from("\x1b[H\x1b[2J");
        let link = if self.connected {
            "connected"
        } else {
            "REOPENING"
        };
        s += &format!("bowl monitor  {port}  [{link}]\n\n");
        match self.latest {
            Some(t) => {
                s += &format!(
                    "device time {:>12.3} s   seq {:>5}   state {:?}   fault {:?}\n\n",
                    f64::from(t.time_ms) / 1000.0,
                    t.seq,
                    t.state,
                    t.fault
                );
                s += "              set rad/s  measured rad/s   duty %   pulses\n";
                for (name, m) in [("precession w1", t.precession), ("spin       w2", t.spin)] {
                    s += &format!(
                        "{name} {:>10.3} {:>15.3} {:>8.2} {:>8}\n",
                        f64::from(m.set_mrad_s) / 1000.0,
                        f64::from(m.measured_mrad_s) / 1000.0,
                        f64::from(m.duty_bp) / 100.0,
                        m.pulses
                    );
                }
                s += &format!(
                    "\nbowl speed (Eq. 2) {:.3} rad/s   residence flat {}   Coriolis {}\n\n",
                    f64::from(t.bowl_mrad_s) / 1000.0,
                    residence_text(t.residence_flat),
                    residence_text(t.residence_coriolis)
                );
            }
            None => s += "no telemetry yet\n\n",
        }
        for trend in &self.trends {
            s += &format!("{:<16} {}\n", trend.name, trend.sparkline());
        }
        if let Some(h) = self.hello {
            s += &format!(
                "\nlast boot: reset cause {:?}, reset count {}\n",
                h.reset_cause, h.reset_count
            );
        }
        s += &format!("\n{}\n", self.counters(d));
        for e in &self.events {
            s += &format!("  {e}\n");
        }
        s
    }
}

fn open_log(path: &PathBuf) -> Result<BufWriter<File>> {
    let is_new = std::fs::metadata(path)
        .map(|m| m.len() == 0)
        .unwrap_or(true);
    let file = OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .with_context(|| format!("cannot open the log {}", path.display()))?;
    let mut w = BufWriter::new(file);
    if is_new {
        writeln!(w, "{}", telemetry_csv::HEADER)?;
    }
    Ok(w)
}

/// Runs `bowl monitor`.
pub fn run(args: &Args) -> Result<()> {
    crate::serial::baud_rate(args.baud)?;
    crate::serial::check_path(&args.port)?;
    let plain = args.plain || !std::io::stdout().is_terminal();
    let mut log = args.log.as_ref().map(open_log).transpose()?;
    let started = Instant::now();
    let deadline = args
        .seconds
        .map(|s| started + Duration::from_secs_f64(s.max(0.0)));
    let mut decoder = Decoder::new();
    let mut view = View::new();
    let mut port: Option<Port> = None;
    let mut last_open_try: Option<Instant> = None;
    let mut next_redraw = Instant::now();
    let mut next_plain = Instant::now() + Duration::from_secs(1);
    let mut buf = [0u8; 4096];
    let mut ever_connected = false;

    while deadline.is_none_or(|d| Instant::now() < d) {
        if port.is_none() && last_open_try.is_none_or(|t| t.elapsed() >= REOPEN_EVERY) {
            last_open_try = Some(Instant::now());
            match Port::open(&args.port, args.baud) {
                Ok(p) => {
                    port = Some(p);
                    view.set_connected(true);
                    if ever_connected {
                        view.reconnects += 1;
                        view.event(plain, format!("port {} reopened", args.port));
                    } else {
                        view.event(plain, format!("port {} open", args.port));
                    }
                    ever_connected = true;
                }
                Err(e) if !ever_connected && last_open_try == Some(started) => {
                    view.event(plain, format!("waiting for {}: {e:#}", args.port));
                }
                Err(_) => {}
            }
        }
        let outcome = match port.as_mut() {
            Some(p) => p.read(&mut buf, Duration::from_millis(20))?,
            None => {
                std::thread::sleep(Duration::from_millis(20));
                ReadOutcome::Timeout
            }
        };
        match outcome {
            ReadOutcome::Data(n) => {
                for &b in &buf[..n] {
                    // Damaged frames are counted by the decoder (corrupt, oversize, truncated).
                    if let Some(Ok(frame)) = decoder.push(b) {
                        if let (Frame::Telemetry(t), Some(w)) = (&frame, log.as_mut()) {
                            telemetry_csv::write_row(w, decoder.stats().restarts, t)?;
                            view.logged_rows += 1;
                        }
                        view.on_frame(plain, &frame);
                    }
                }
            }
            ReadOutcome::Timeout => {}
            ReadOutcome::Gone => {
                port = None;
                view.set_connected(false);
                decoder.finish();
                view.event(plain, format!("port {} lost; reopening", args.port));
            }
        }
        let now = Instant::now();
        if now >= next_redraw {
            next_redraw = now + REDRAW;
            view.sample_trends();
            if let Some(w) = log.as_mut() {
                w.flush().context("writing the log")?;
            }
            if !plain {
                print!("{}", view.dashboard(&args.port, &decoder));
                std::io::stdout().flush()?;
            }
        }
        if plain && now >= next_plain {
            next_plain = now + Duration::from_secs(1);
            println!("{}", view.plain_line(&decoder));
        }
    }
    if let Some(w) = log.as_mut() {
        w.flush().context("writing the log")?;
    }
    let mut summary = stats_json(decoder.stats());
    summary["reconnects"] = json!(view.reconnects);
    summary["logged_rows"] = json!(view.logged_rows);
    println!("{summary}");
    if !ever_connected {
        return Err(crate::exit_code::LinkError(format!(
            "no telemetry: {} never appeared or could not be opened in {:.0} s",
            args.port,
            started.elapsed().as_secs_f64()
        ))
        .into());
    }
    Ok(())
}

//! What the live view knows (latest telemetry, boot, events, link) and its text forms: the plain
//! line of `bowl monitor --plain` and the ANSI dashboard `bowl demo` draws.

// The ANSI dashboard and the pseudo-terminal serve the demo, which needs a Unix system.
#![cfg_attr(not(unix), allow(dead_code, unused_imports))]

use std::collections::VecDeque;
use std::io::Write;
use std::time::{Duration, Instant};

use model_core::wire::{Decoder, FaultCode, Frame, Hello, Residence, Telemetry};

use rig_client::lines::describe;

/// How many points a trend line keeps (one per redraw, 5 per second: 12 s).
const TREND_LEN: usize = 60;

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

    /// A sparkline of the points and the range it spans, `[lo .. hi]`. The range is the
    /// points' own, widened to at least `MIN_SPAN` (1 unit) about its middle, so a few thousandths
    /// of noise stay a flat line instead of filling the height. In `ascii` (a locale without
    /// UTF-8, see `glyphs`) the bars are characters that sit ever higher in the line.
    fn sparkline(&self, ascii: bool) -> String {
        const BARS: [char; 8] = ['▁', '▂', '▃', '▄', '▅', '▆', '▇', '█'];
        const ASCII_BARS: [char; 8] = ['_', '.', ',', '-', '=', '~', '^', '\''];
        let bars = if ascii { ASCII_BARS } else { BARS };
        const MIN_SPAN: f64 = 1.0;
        let finite = self.points.iter().copied().filter(|v| v.is_finite());
        let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        if !(lo.is_finite() && hi.is_finite()) {
            return "(no values)".into();
        }
        let (lo, hi) = if hi - lo < MIN_SPAN {
            let mid = 0.5 * (lo + hi);
            (mid - 0.5 * MIN_SPAN, mid + 0.5 * MIN_SPAN)
        } else {
            (lo, hi)
        };
        let line: String = self
            .points
            .iter()
            .map(|&v| {
                if v.is_finite() {
                    bars[(((v - lo) / (hi - lo)) * 7.0).round().clamp(0.0, 7.0) as usize]
                } else {
                    ' '
                }
            })
            .collect();
        format!("{line} [{lo:.2} .. {hi:.2}]")
    }
}

fn residence_s(r: Residence) -> f64 {
    match r {
        Residence::Ms(ms) => f64::from(ms) / 1000.0,
        _ => f64::NAN,
    }
}

pub(crate) fn residence_text(r: Residence) -> String {
    match r {
        Residence::Ms(ms) => format!("{:.3} s", f64::from(ms) / 1000.0),
        Residence::NeverLeaves => "never leaves".into(),
        Residence::Unavailable => "-".into(),
    }
}

/// What the live view shows; also drawn by `bowl demo`.
pub(crate) struct View {
    pub(crate) latest: Option<Telemetry>,
    hello: Option<Hello>,
    pub(crate) events: VecDeque<String>,
    trends: [Trend; 5],
    pub(crate) reconnects: u64,
    /// Lines the rig got and could not read (`rig_client::lines::unread_by_rig`).
    pub(crate) unread_by_rig: u64,
    pub(crate) connected: bool,
    pub(crate) logged_rows: u64,
    /// When the latest telemetry frame arrived (or the port was opened, before the first).
    heard_at: Instant,
    /// Device time between the last two telemetry frames, ms (0 until two have come).
    period_ms: u32,
    /// Telemetry frames taken in.
    pub(crate) telemetry_frames: u64,
    /// The board conditions the rig's STATUS reported (`wire::status_flags` bits), once asked.
    pub(crate) board_flags: Option<u8>,
    /// The fault the telemetry reported last (each change is said once, as an event).
    fault: FaultCode,
}

/// Telemetry is overdue after this many frame periods without a frame ...
const STALE_PERIODS: u32 = 3;
/// ... and never sooner than this: a USB serial adapter delivers in bursts of up to ~20 ms and
/// a busy PC can pause the monitor for a few tenths of a second, which must not read as a rig
/// gone quiet at 50 frames/s.
const STALE_FLOOR: Duration = Duration::from_millis(500);

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
            unread_by_rig: 0,
            connected: false,
            logged_rows: 0,
            heard_at: Instant::now(),
            period_ms: 0,
            telemetry_frames: 0,
            board_flags: None,
            fault: FaultCode::None,
        }
    }

    /// How long no telemetry has arrived, once that is longer than [`STALE_PERIODS`] frame
    /// periods (at least [`STALE_FLOOR`]; before the period is known, 1 s): then LINK OK would
    /// be a lie, the values are old. `None` while frames arrive, and while the port is lost
    /// (that is said already).
    pub(crate) fn silence(&self, now: Instant) -> Option<Duration> {
        let quiet = now.saturating_duration_since(self.heard_at);
        let limit = match self.period_ms {
            0 => Duration::from_secs(1),
            ms => (Duration::from_millis(u64::from(ms)) * STALE_PERIODS).max(STALE_FLOOR),
        };
        (self.connected && quiet > limit).then_some(quiet)
    }

    /// Takes in one decoded frame (the CSV log is the caller's).
    pub(crate) fn on_frame(&mut self, plain: bool, frame: &Frame) {
        match frame {
            Frame::Telemetry(t) => {
                if let Some(last) = self.latest {
                    // The period the rig sends at now (it changes with TELEM_HZ); a jump of
                    // more than 10 s is a gap or a restart, not a period.
                    let dt = t.time_ms.wrapping_sub(last.time_ms);
                    if (1..=10_000).contains(&dt) && t.seq == last.seq.wrapping_add(1) {
                        self.period_ms = dt;
                    }
                }
                // A fault said as it comes and goes: one cleared within a second (`clear` from
                // another console, a script) never reached a plain line or stayed on the screen,
                // and the motors were found stopped with no word why.
                let before = self.fault;
                self.fault = t.fault;
                if t.fault != before {
                    let text = match t.fault {
                        FaultCode::None => format!(
                            "fault cleared (it was: {}); the motors stay off until `start`",
                            before.words()
                        ),
                        now => format!(
                            "FAULT {}: {}: the rig stopped the motors; `clear` once the cause \
                             is fixed",
                            now.code(),
                            now.words()
                        ),
                    };
                    self.event(plain, text);
                }
                self.latest = Some(*t);
                self.heard_at = Instant::now();
                self.telemetry_frames += 1;
            }
            Frame::Hello(h) => {
                self.hello = Some(*h);
                // A reset ends a fault without a `clear`: the boot is said, not a clearing.
                self.fault = FaultCode::None;
                self.event(
                    plain,
                    format!(
                        "rig booted: reset cause {}, reset count {}",
                        h.reset_cause.words(),
                        h.reset_count
                    ),
                );
            }
            // Gate events and the like: what the rig says of itself, no answer to anything.
            other => self.event(plain, describe(other)),
        }
    }

    /// The rig could not read a line it got: counted and said each time. Before, its answer
    /// (`$R1,0,UNREADABLE`, id 0) was passed over as another tool's, and a frame of ours
    /// garbled on the way to the rig went unsaid. The rig answers only lines the PC sends (a
    /// heartbeat a second, the commands), so these come no faster than that.
    pub(crate) fn unread_by_rig(&mut self, plain: bool) {
        self.unread_by_rig += 1;
        let text = format!(
            "{}; {} so far",
            rig_client::lines::UNREAD_BY_RIG,
            self.unread_by_rig
        );
        self.event(plain, text);
    }

    pub(crate) fn set_connected(&mut self, connected: bool) {
        self.connected = connected;
        if connected {
            // A port just (re)opened: silence is counted from now.
            self.heard_at = Instant::now();
        }
    }

    pub(crate) fn event(&mut self, plain: bool, text: String) {
        if plain {
            // Not a panic when the terminal is gone (SIGHUP): the monitor's next status line
            // fails instead, and ends it with its log closed.
            let _ = writeln!(std::io::stdout(), "{text}");
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

    pub(crate) fn counters(&self, d: &Decoder) -> String {
        let s = d.stats();
        format!(
            "frames ok {}  corrupt {}  missing {}  bytes skipped {}  reconnects {}  \
             unread by the rig {}",
            s.frames_ok,
            s.frames_corrupt,
            s.frames_missing,
            s.bytes_skipped,
            self.reconnects,
            self.unread_by_rig
        )
    }

    pub(crate) fn plain_line(&self, d: &Decoder) -> String {
        let values = match self.latest {
            Some(t) => format!(
                "t={:.3}s seq={} state={} fault={} w1={:.3}/{:.3} w2={:.3}/{:.3} rad/s bowl={:.3} rad/s T_flat={} T_cor={}",
                f64::from(t.time_ms) / 1000.0,
                t.seq,
                t.state.words(),
                t.fault.words(),
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
        if !self.connected {
            // The old values would read as current: say the link is down instead.
            return format!("LINK LOST: no values | {}", self.counters(d));
        }
        if let Some(quiet) = self.silence(Instant::now()) {
            return format!(
                "NO TELEMETRY for {:.1} s: no values | {}",
                quiet.as_secs_f64(),
                self.counters(d)
            );
        }
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
                    "device time {:>12.3} s   seq {:>5}   state {}   fault: {}\n\n",
                    f64::from(t.time_ms) / 1000.0,
                    t.seq,
                    t.state.words(),
                    t.fault.words()
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
        let ascii = !super::glyphs::utf8_locale();
        for trend in &self.trends {
            s += &format!("{:<16} {}\n", trend.name, trend.sparkline(ascii));
        }
        if let Some(h) = self.hello {
            s += &format!(
                "\nlast boot: reset cause {}, reset count {}\n",
                h.reset_cause.words(),
                h.reset_count
            );
        }
        s += &format!("\n{}\n", self.counters(d));
        for e in &self.events {
            s += &format!("  {e}\n");
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trend(values: impl IntoIterator<Item = f64>) -> Trend {
        let mut t = Trend::new("w1 rad/s");
        for v in values {
            t.push(v);
        }
        t
    }

    /// +-5 mrad/s of noise on 1.8 rad/s is a flat line with its range written beside it; a
    /// real ramp fills the height.
    #[test]
    fn sparklines_say_their_range_and_do_not_magnify_noise() {
        let noisy = trend((0..40).map(|i| 1.8 + if i % 2 == 0 { 0.005 } else { -0.005 }));
        let line = noisy.sparkline(false);
        let bars: std::collections::BTreeSet<char> =
            line.chars().take_while(|c| *c != ' ').collect();
        assert!(bars.len() <= 2, "{line}");
        assert!(line.ends_with("[1.30 .. 2.30]"), "{line}");
        let ramp = trend((0..=30).map(|i| f64::from(i) * 0.1));
        let line = ramp.sparkline(false);
        assert!(line.starts_with('▁') && line.contains('█'), "{line}");
        assert!(line.ends_with("[0.00 .. 3.00]"), "{line}");
        // The same ramp without UTF-8: ASCII from the bottom of the line to its top.
        let line = ramp.sparkline(true);
        assert!(line.is_ascii(), "{line}");
        assert!(line.starts_with("__") && line.contains("^''' ["), "{line}");
    }
}

//! The demo's side of the link: one serial port, one decoder. Every frame the rig sends is
//! taken in here: telemetry goes to the live view (the monitor's), the CSV log and the record;
//! answers are matched to the commands by request id; anything else is shown as an event.
//! Time is the rig's: every wait is measured on the device time in the telemetry, so the same
//! script runs in real time, faster, or on an emulated board.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow, bail};
use model_core::wire::{Command, DecodeStats, Decoder, Frame, Hello, Telemetry};

use crate::monitor::View;
use rig_client::lines::{command_line, describe, explain};
use rig_client::request::Request;
use rig_client::serial::{Port, ReadOutcome};
use rig_client::telemetry_csv;

/// One command the script sent and what came back.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CommandRecord {
    /// What the step was for.
    pub step: String,
    /// The command words as sent.
    pub command: String,
    /// The rig accepted it.
    pub accepted: bool,
    /// The answer, for people.
    pub answer: String,
    /// Device time of the last telemetry frame before the answer: the command took effect
    /// at or after it (within one telemetry period).
    pub at_ms: Option<u32>,
}

/// An answer frame (matched to its request by the request loop's rule) and the device time of
/// the last telemetry frame before it in the stream.
struct Answer {
    frame: Frame,
    after_ms: Option<u32>,
}

/// Everything the session saw.
#[derive(Default)]
pub struct Record {
    /// Every telemetry frame, in arrival order.
    pub telemetry: Vec<Telemetry>,
    /// Commands in the order sent.
    pub commands: Vec<CommandRecord>,
    /// The boot announcement.
    pub hello: Option<Hello>,
    /// Lines shown as events (step log), with device time.
    pub log: Vec<String>,
}

/// The session: port, decoder, view, log, record.
pub struct Session {
    port: Port,
    label: String,
    decoder: Decoder,
    view: View,
    plain: bool,
    csv: BufWriter<File>,
    /// What was seen so far.
    pub record: Record,
    next_id: u16,
    ping_ids: Vec<u16>,
    last_ping_ms: Option<u32>,
    next_redraw: Instant,
    next_plain_ms: u32,
    plain_every_ms: u32,
    last_frame_at: Instant,
    /// Raised by Ctrl-C or SIGTERM ([`crate::interrupt::flag`]).
    interrupt: &'static AtomicBool,
    /// The interruption ended the script (once: the STOP after it still goes through).
    interrupted: bool,
}

/// How long the rig may stay silent (wall time) before the session gives up.
const SILENCE_LIMIT: Duration = Duration::from_secs(10);
/// How long to wait (wall time) for the answer to a command.
const ANSWER_TIMEOUT: Duration = Duration::from_secs(3);
/// Heartbeat period on device time (the rig faults on host silence if told to).
const PING_EVERY_MS: u32 = 1000;

impl Session {
    /// Opens the port and the CSV log.
    pub fn open(
        port: &str,
        label: String,
        plain: bool,
        csv_path: &std::path::Path,
        interrupt: &'static AtomicBool,
    ) -> Result<Self> {
        let port_handle = Port::open(port, model_core::wire::DEFAULT_BAUD)?;
        let mut csv = BufWriter::new(
            File::create(csv_path)
                .with_context(|| format!("cannot create {}", csv_path.display()))?,
        );
        writeln!(csv, "{}", telemetry_csv::HEADER)?;
        let mut view = View::new();
        view.set_connected(true);
        Ok(Self {
            port: port_handle,
            label,
            decoder: Decoder::new(),
            view,
            plain,
            csv,
            record: Record::default(),
            next_id: 1,
            ping_ids: Vec::new(),
            last_ping_ms: None,
            next_redraw: Instant::now(),
            next_plain_ms: 0,
            plain_every_ms: 2000,
            last_frame_at: Instant::now(),
            interrupt,
            interrupted: false,
        })
    }

    /// Device time of the latest telemetry frame.
    pub fn now_ms(&self) -> Option<u32> {
        self.record.telemetry.last().map(|t| t.time_ms)
    }

    /// The latest telemetry frame.
    pub fn latest(&self) -> Option<&Telemetry> {
        self.record.telemetry.last()
    }

    /// Shows a step line: printed at once in plain mode, in the dashboard's event list otherwise,
    /// and kept for the end.
    pub fn event(&mut self, text: String) {
        self.event_at(self.now_ms(), text);
    }

    /// As [`Session::event`], stamped with the device time `at_ms`.
    fn event_at(&mut self, at_ms: Option<u32>, text: String) {
        let stamp = match at_ms {
            Some(ms) => format!("[t={:>7.3} s] ", f64::from(ms) / 1000.0),
            None => "[t=   -    ] ".into(),
        };
        let line = format!("{stamp}{text}");
        self.record.log.push(line.clone());
        self.view.event(self.plain, line);
    }

    /// Whether Ctrl-C (or SIGTERM) ended the script.
    pub fn interrupted(&self) -> bool {
        self.interrupted
    }

    /// Reads what is there (waiting at most `wait`), handles every frame, redraws. Ctrl-C ends
    /// the step under way with an error, once: the script then stops the motors through here.
    fn pump(&mut self, wait: Duration) -> Result<Vec<Answer>> {
        if !self.interrupted && self.interrupt.load(Ordering::SeqCst) {
            self.interrupted = true;
            bail!("interrupted (Ctrl-C)");
        }
        let mut answers = Vec::new();
        let mut buf = [0u8; 4096];
        match self.port.read(&mut buf, wait)? {
            ReadOutcome::Data(n) => {
                for &b in &buf[..n] {
                    // Damaged frames are counted by the decoder and shown in the counters.
                    if let Some(Ok(frame)) = self.decoder.push(b) {
                        self.take(frame, &mut answers)?;
                    }
                }
            }
            ReadOutcome::Timeout => {}
            ReadOutcome::Gone => bail!("the rig's port went away"),
        }
        // Before the first frame the caller's boot limit applies instead.
        if self.now_ms().is_some() && self.last_frame_at.elapsed() > SILENCE_LIMIT {
            bail!("the rig sent nothing for {} s", SILENCE_LIMIT.as_secs());
        }
        self.heartbeat()?;
        self.draw()?;
        Ok(answers)
    }

    fn take(&mut self, frame: Frame, answers: &mut Vec<Answer>) -> Result<()> {
        self.last_frame_at = Instant::now();
        match frame {
            Frame::Telemetry(t) => {
                telemetry_csv::write_row(
                    &mut self.csv,
                    self.decoder.stats().restarts,
                    &t,
                    Some(std::time::SystemTime::now()),
                )?;
                self.record.telemetry.push(t);
                self.view.on_frame(self.plain, &frame);
            }
            Frame::Hello(h) => {
                self.record.hello = Some(h);
                self.view.on_frame(self.plain, &frame);
            }
            other => match other.answer_id() {
                Some(id) if self.ping_ids.contains(&id) => {
                    self.ping_ids.retain(|&p| p != id);
                    if matches!(other, Frame::Reject { .. }) {
                        self.event(format!("heartbeat refused: {}", describe(&other)));
                    }
                }
                Some(_) => answers.push(Answer {
                    frame: other,
                    after_ms: self.now_ms(),
                }),
                None => self.event(format!("unexpected frame: {}", describe(&other))),
            },
        }
        Ok(())
    }

    fn heartbeat(&mut self) -> Result<()> {
        let Some(now) = self.now_ms() else {
            return Ok(());
        };
        if self
            .last_ping_ms
            .is_some_and(|t| now.wrapping_sub(t) < PING_EVERY_MS)
        {
            return Ok(());
        }
        self.last_ping_ms = Some(now);
        let id = self.fresh_id();
        let mut ping = Request::new(id, Command::Ping)
            .map_err(|r| anyhow!("PING rejected locally: {}", r.token()))?;
        self.ping_ids.push(id);
        if self.ping_ids.len() > 16 {
            // Unanswered heartbeats: shown, not piled up.
            self.ping_ids.remove(0);
        }
        // Sent once: the next heartbeat is the resend.
        let line = ping.due(Instant::now()).unwrap_or_default();
        Ok(self.port.write_all(line)?)
    }

    fn draw(&mut self) -> Result<()> {
        if self.plain {
            if let Some(now) = self.now_ms()
                && now >= self.next_plain_ms
            {
                self.next_plain_ms = now - now % self.plain_every_ms + self.plain_every_ms;
                println!("  {}", self.view.plain_line(&self.decoder));
            }
            return Ok(());
        }
        let now = Instant::now();
        if now >= self.next_redraw {
            self.next_redraw = now + Duration::from_millis(200);
            self.view.sample_trends();
            print!("{}", self.view.dashboard(&self.label, &self.decoder));
            std::io::stdout().flush()?;
        }
        Ok(())
    }

    fn fresh_id(&mut self) -> u16 {
        let id = self.next_id;
        self.next_id = self.next_id.wrapping_add(1).max(1);
        id
    }

    /// Sends one command (`words` as for `bowl send`) and waits for its answer. A rejection is
    /// recorded and returned as `Ok(false)`; no answer at all is an error.
    pub fn command(&mut self, step: &str, words: &[&str]) -> Result<bool> {
        let (accepted, _) = self.command_answer(step, words)?;
        Ok(accepted)
    }

    /// As [`Session::command`], also returning the answer frame.
    pub fn command_answer(&mut self, step: &str, words: &[&str]) -> Result<(bool, Frame)> {
        let id = self.fresh_id();
        let owned: Vec<String> = words.iter().map(|w| w.to_string()).collect();
        let text = owned.join(" ");
        let line = command_line(id, &owned).map_err(|r| {
            anyhow!(
                "{step}: `{text}` rejected locally: {} - {}",
                r.token(),
                explain(r)
            )
        })?;
        let mut request = Request::from_line(line)
            .ok_or_else(|| anyhow!("{step}: `{text}` is not a command line (a bug in bowl)"))?;
        let deadline = Instant::now() + ANSWER_TIMEOUT;
        loop {
            // The one request loop's schedule: sent now, and again with the same id every
            // 200 ms until the answer comes (the rig carries a copy out once).
            if let Some(line) = request.due(Instant::now()) {
                self.port.write_all(line)?;
            }
            let answers = self.pump(Duration::from_millis(10))?;
            if let Some(Answer {
                frame, after_ms, ..
            }) = answers.into_iter().find(|a| request.answered_by(&a.frame))
            {
                let accepted = !matches!(frame, Frame::Reject { .. });
                let answer = match frame {
                    // Nineteen values: kept whole in the summary, short here.
                    Frame::Params { id, values } => {
                        format!("params (id {id}): {} values", values.len())
                    }
                    _ => describe(&frame),
                };
                self.record.commands.push(CommandRecord {
                    step: step.to_string(),
                    command: text.clone(),
                    accepted,
                    answer: answer.clone(),
                    at_ms: after_ms,
                });
                self.event_at(after_ms, format!("{step}: {text} -> {answer}"));
                return Ok((accepted, frame));
            }
            if Instant::now() >= deadline {
                bail!("{step}: no answer to `{text}` within {ANSWER_TIMEOUT:?}");
            }
        }
    }

    /// Waits for the first telemetry frame (the rig is up).
    pub fn wait_first_telemetry(&mut self, limit: Duration) -> Result<()> {
        let deadline = Instant::now() + limit;
        self.last_frame_at = Instant::now();
        while self.now_ms().is_none() {
            if Instant::now() >= deadline {
                bail!("no telemetry from the rig within {limit:?}");
            }
            self.pump(Duration::from_millis(20))?;
        }
        Ok(())
    }

    /// Runs for `dt_ms` of device time.
    pub fn wait_ms(&mut self, dt_ms: u32) -> Result<()> {
        self.wait_for(dt_ms, |_| false).map(|_| ())
    }

    /// Runs until `done` holds for a telemetry frame (returns its device time) or `max_ms` of
    /// device time pass (returns `None`).
    pub fn wait_for(
        &mut self,
        max_ms: u32,
        mut done: impl FnMut(&Telemetry) -> bool,
    ) -> Result<Option<u32>> {
        let start = self.now_ms().ok_or_else(|| anyhow!("no telemetry yet"))?;
        let mut seen = self.record.telemetry.len();
        loop {
            self.pump(Duration::from_millis(10))?;
            while seen < self.record.telemetry.len() {
                let t = self.record.telemetry[seen];
                seen += 1;
                if done(&t) {
                    return Ok(Some(t.time_ms));
                }
                if t.time_ms.wrapping_sub(start) >= max_ms {
                    return Ok(None);
                }
            }
        }
    }

    /// Flushes the CSV log; in dashboard mode draws the last state once more.
    pub fn finish(mut self) -> Result<(Record, DecodeStats)> {
        self.csv.flush().context("writing the telemetry log")?;
        if !self.plain {
            self.next_redraw = Instant::now();
            self.draw()?;
        } else {
            println!("  {}", self.view.plain_line(&self.decoder));
        }
        let stats = *self.decoder.stats();
        Ok((self.record, stats))
    }
}

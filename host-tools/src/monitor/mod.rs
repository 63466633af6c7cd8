//! `bowl monitor PORT`: the rig engineer's console. Live view of the telemetry (a terminal UI,
//! or one text line per second with `--plain` or when stdout is not a terminal), CSV log keyed on
//! device time, frame counters; reopens the port after an unplug and keeps logging.
//!
//! It holds the port exclusively and serves a local socket ([`rig_client::relay`]) through which
//! `bowl send`, `bowl commission` and scripts reach the rig meanwhile. Commands can also be typed
//! into the monitor itself (the UI's command line, or stdin lines in plain mode).

mod backlog;
mod charts;
mod commands;
mod fit;
mod glyphs;
mod line_edit;
mod log_file;
mod prompt;
mod tui;
mod view;
mod wrap;

pub(crate) use view::View;

use std::fs::File;
use std::io::{BufRead, BufWriter, IsTerminal, Write};
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::sync::mpsc;
use std::time::{Duration, Instant, SystemTime};

use anyhow::{Context, Result};
use model_core::wire::{Decoder, Frame, FrameError};
use serde_json::json;

use commands::Commands;
use log_file::open_log;
use rig_client::decode_stats::stats_json;
use rig_client::relay::Relay;
use rig_client::serial::{Holder, Port, ReadOutcome, other_holders, shared_port_warning};
use rig_client::telemetry_csv;
use rig_client::unreadable::LineTap;
use tui::{Action, Tui};

/// Flags of `bowl monitor`.
#[derive(clap::Args)]
pub struct Args {
    /// The serial port or pseudo-terminal of the rig (`bowl ports` lists them).
    port: String,
    /// Baud rate (any rate the port supports).
    #[arg(long, default_value_t = 115_200, value_parser = clap::value_parser!(u32).range(50..=12_000_000))]
    baud: u32,
    /// Append the telemetry to this CSV file (header written when the file is new).
    #[arg(long, value_parser = crate::cmd::file_to_write)]
    log: Option<PathBuf>,
    /// Stop after this many seconds (default: run until interrupted).
    #[arg(long)]
    seconds: Option<f64>,
    /// One text line per second instead of the terminal UI (also when stdout is not a terminal).
    #[arg(long)]
    plain: bool,
}

const REDRAW: Duration = Duration::from_millis(100);
const REOPEN_EVERY: Duration = Duration::from_millis(250);

/// Lines typed on stdin (plain mode), read on their own thread.
fn stdin_lines() -> mpsc::Receiver<String> {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in std::io::stdin().lock().lines() {
            let Ok(line) = line else { break };
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    rx
}

/// Runs `bowl monitor`.
/// How often the monitor looks for programs that read the port beside it (a scan of `/proc`: a
/// few milliseconds).
const HOLDER_CHECK_EVERY: Duration = Duration::from_secs(5);

/// Who else had the port open when last looked, so each change is said once.
#[derive(Default)]
struct SharedPort {
    seen: Vec<Holder>,
}

impl SharedPort {
    /// Looks again; the words to show when the set of other holders changed.
    fn check(&mut self, port: &str) -> Option<String> {
        let now = other_holders(port);
        if now == self.seen {
            return None;
        }
        let text = shared_port_warning(port, &now)
            .unwrap_or_else(|| format!("{port} is no longer open in another program"));
        self.seen = now;
        Some(text)
    }
}

/// Heartbeat period, well inside the rig's default link-loss timeout (3 s).
const HEARTBEAT_EVERY: Duration = Duration::from_secs(1);
/// The heartbeat's command id: other tools match answers by id and kind and never wait for it.
const HEARTBEAT_ID: u16 = u16::MAX;
/// The id of the monitor's own STATUS (asked when the port opens and after each rig restart, for
/// the board conditions only STATUS carries: the parameters' source, the clock).
const STATUS_ID: u16 = u16::MAX - 1;
/// Asked again this often until answered.
const STATUS_AGAIN_EVERY: Duration = Duration::from_secs(2);

pub fn run(args: &Args) -> Result<()> {
    if let Some(s) = args.seconds
        && !(s.is_finite() && s >= 0.0)
    {
        return Err(crate::exit_code::usage(format!(
            "--seconds {s}: give how long to watch, 0 s or more (leave it out to watch until \
             interrupted)"
        )));
    }
    // The UI needs a screen and a keyboard; without either it prints lines, and so it does on
    // a terminal that says it cannot move the cursor (TERM=dumb: an editor's shell buffer).
    let dumb = std::env::var_os("TERM").is_some_and(|t| t == "dumb");
    let plain =
        args.plain || dumb || !std::io::stdout().is_terminal() || !std::io::stdin().is_terminal();
    // In the UI, Ctrl-C arrives as a key; this catches it in plain mode, and SIGTERM and SIGHUP
    // (the terminal closed) in both: the loop ends, so the terminal is given back and the log
    // gets `monitor end`.
    let interrupted = crate::interrupt::flag_with_hangup();
    crate::interrupt::closed_pipe_as_error();
    // Served only while the port is held: a lost port's name may soon be another device's.
    // Asked first, so a second monitor is told that one runs (not only that the port is busy).
    let mut relay = Some(Relay::serve(&args.port)?);
    // The port is checked before anything is drawn: a wrong path is an error, not a wait.
    let first = Port::open(&args.port, args.baud)?;
    let mut log = args.log.as_ref().map(open_log).transpose()?;
    let started = Instant::now();
    let deadline = args
        .seconds
        .map(|s| started + Duration::from_secs_f64(s.max(0.0)));
    let mut decoder = Decoder::new();
    let mut tap = LineTap::default();
    let mut other_version_said = false;
    let mut view = View::new();
    let mut commands = Commands::new(&args.port);
    let mut port = Some(first);
    let mut backlog = backlog::Backlog::default();
    backlog.opened();
    view.set_connected(true);
    view.event(plain, format!("port {} open", args.port));
    let link_event = |log: &mut Option<BufWriter<File>>, boot: u64, what: &str| -> Result<()> {
        if let Some(w) = log.as_mut() {
            telemetry_csv::write_event(w, boot, Some(SystemTime::now()), what)?;
        }
        Ok(())
    };
    link_event(&mut log, 0, "port open")?;
    let mut tui = if plain { None } else { Some(Tui::start()?) };
    let typed = if plain { Some(stdin_lines()) } else { None };
    let mut last_open_try = Instant::now();
    let mut last_heartbeat = Instant::now();
    let mut next_redraw = Instant::now();
    let mut next_plain = Instant::now() + Duration::from_secs(1);
    let mut buf = [0u8; 4096];
    // An open gap in the telemetry: since when nothing came, and the frame count then.
    let mut gap: Option<(Instant, u64)> = None;
    let mut holders = SharedPort::default();
    // When to ask the rig's STATUS next (None: answered).
    let mut status_due = Some(Instant::now());
    let mut next_holder_check = Instant::now();
    // The latest telemetry's (boot, device ms): where a gate event sits on the device clock.
    let mut latest: Option<(u64, u32)> = None;

    // The loop in a closure, so that every way out of it (an error too: a terminal that is
    // gone fails the next draw) passes through the end below and the log gets `monitor end`.
    let watched = (|| -> Result<()> {
        while deadline.is_none_or(|d| Instant::now() < d) && !interrupted.load(Ordering::SeqCst) {
            if port.is_none() && last_open_try.elapsed() >= REOPEN_EVERY {
                last_open_try = Instant::now();
                if let Ok(p) = Port::open(&args.port, args.baud) {
                    port = Some(p);
                    relay = match Relay::serve(&args.port) {
                        Ok(r) => Some(r),
                        Err(e) => {
                            view.event(plain, format!("other tools cannot reach the rig: {e:#}"));
                            None
                        }
                    };
                    view.set_connected(true);
                    view.reconnects += 1;
                    view.event(plain, format!("port {} reopened", args.port));
                    backlog.opened();
                    status_due = Some(Instant::now());
                    link_event(&mut log, decoder.stats().restarts, "port reopened")?;
                }
            }
            let outcome = match port.as_mut() {
                Some(p) => p.read(&mut buf, Duration::from_millis(10))?,
                None => {
                    std::thread::sleep(Duration::from_millis(10));
                    ReadOutcome::Timeout
                }
            };
            match outcome {
                ReadOutcome::Data(n) => {
                    if let Some(r) = relay.as_mut() {
                        r.broadcast(&buf[..n]);
                    }
                    for &b in &buf[..n] {
                        // Damaged frames are counted by the decoder (corrupt, oversize, truncated).
                        let restarts = decoder.stats().restarts;
                        tap.push(b);
                        let frame = match decoder.push(b) {
                            Some(Ok(frame)) => frame,
                            Some(Err(e)) => {
                                // Intact but unreadable here (another version, an unknown word):
                                // shown as it came, never taken for silence.
                                if let Some(u) = tap.unreadable_answer(e) {
                                    view.event(plain, commands.on_unreadable(&u));
                                } else if e == FrameError::UnsupportedVersion && !other_version_said
                                {
                                    // Telemetry in another protocol version: every frame would
                                    // count as malformed with no word why. Said once.
                                    other_version_said = true;
                                    view.event(
                                        plain,
                                        format!(
                                            "the rig sends another protocol version than this \
                                             bowl reads (1): `{}`; update whichever is older",
                                            tap.text()
                                        ),
                                    );
                                }
                                continue;
                            }
                            None => continue,
                        };
                        if decoder.stats().restarts > restarts {
                            // The held rows are of the boot before: the new clock cannot date them.
                            if let Some(w) = log.as_mut() {
                                view.logged_rows += backlog.release(w, None)?;
                            }
                            link_event(&mut log, decoder.stats().restarts, "device restart")?;
                        }
                        let boot = decoder.stats().restarts;
                        if let (Frame::Event(e), Some(w)) = (&frame, log.as_mut()) {
                            if backlog.pending() {
                                backlog.hold_gate(boot, *e);
                            } else {
                                let near = latest.filter(|(b, _)| *b == boot).map(|(_, ms)| ms);
                                telemetry_csv::write_gate_event(
                                    w,
                                    boot,
                                    Some(SystemTime::now()),
                                    e,
                                    near,
                                )?;
                            }
                        }
                        if let Frame::Telemetry(t) = &frame {
                            latest = Some((boot, t.time_ms));
                            if let Some(w) = log.as_mut() {
                                if backlog.holding() {
                                    backlog.hold_row(boot, *t);
                                } else {
                                    let now = SystemTime::now();
                                    view.logged_rows += backlog.release(w, Some((boot, t, now)))?;
                                    telemetry_csv::write_row(w, boot, t, Some(now))?;
                                    view.logged_rows += 1;
                                }
                            }
                            if let Some(ui) = tui.as_mut() {
                                ui.on_telemetry(t);
                            }
                        }
                        match &frame {
                            Frame::Hello(_) => status_due = Some(Instant::now()),
                            Frame::Status { id, status } if *id == STATUS_ID => {
                                status_due = None;
                                if view.board_flags != Some(status.flags) {
                                    view.board_flags = Some(status.flags);
                                    if let Some(words) =
                                        rig_client::lines::status_flag_words(status.flags)
                                    {
                                        let text = format!("the rig reports: {words}");
                                        view.event(plain, text.clone());
                                        link_event(&mut log, decoder.stats().restarts, &text)?;
                                    }
                                }
                                continue;
                            }
                            _ => {}
                        }
                        match commands.on_frame(&frame) {
                            Some(text) => view.event(plain, text),
                            // No tool's answer: said here, or no one would.
                            None if rig_client::lines::unread_by_rig(&frame) => {
                                view.unread_by_rig(plain);
                                let boot = decoder.stats().restarts;
                                link_event(&mut log, boot, rig_client::lines::UNREAD_BY_RIG)?;
                            }
                            // Answers to other tools' commands are theirs to report.
                            None if frame.answer_id().is_some() => {}
                            None => view.on_frame(plain, &frame),
                        }
                    }
                }
                ReadOutcome::Timeout => backlog.quiet(),
                ReadOutcome::Gone => {
                    if let Some(w) = log.as_mut() {
                        view.logged_rows += backlog.release(w, None)?;
                    }
                    port = None;
                    relay = None;
                    view.set_connected(false);
                    decoder.finish();
                    view.event(plain, format!("port {} lost; reopening", args.port));
                    for text in commands.link_lost() {
                        view.event(plain, text);
                    }
                    link_event(&mut log, decoder.stats().restarts, "link lost")?;
                }
            }
            // Telemetry overdue, and back: said on the screen and marked in the log (so a chart of
            // the log breaks its lines across the gap).
            match gap {
                None => {
                    if let Some(quiet) = view.silence(Instant::now()) {
                        gap = Some((Instant::now() - quiet, view.telemetry_frames));
                        view.event(
                            plain,
                            format!(
                                "no telemetry for {:.1} s: the port is open but the rig sends no \
                                 frames (TELEM_HZ 0? a reset? a loose cable?); the values shown are old",
                                quiet.as_secs_f64()
                            ),
                        );
                        link_event(&mut log, decoder.stats().restarts, "no telemetry")?;
                    }
                }
                Some((from, frames)) if view.telemetry_frames > frames => {
                    gap = None;
                    let text = format!(
                        "telemetry again after {:.1} s",
                        from.elapsed().as_secs_f64()
                    );
                    view.event(plain, text.clone());
                    link_event(&mut log, decoder.stats().restarts, &text)?;
                }
                Some(_) => {}
            }
            if port.is_some() && Instant::now() >= next_holder_check {
                next_holder_check = Instant::now() + HOLDER_CHECK_EVERY;
                if let Some(text) = holders.check(&args.port) {
                    view.event(plain, text.clone());
                    link_event(&mut log, decoder.stats().restarts, &text)?;
                }
            }
            let mut outgoing = relay.as_mut().map(Relay::poll).unwrap_or_default();
            let mut typed_now: Vec<String> = typed.iter().flat_map(|rx| rx.try_iter()).collect();
            if let Some(ui) = tui.as_mut() {
                match ui.keys()? {
                    Action::Quit => break,
                    Action::Send(text) => typed_now.push(text),
                    Action::None => {}
                }
            }
            for text in typed_now {
                match commands.submit(&text, port.is_some()) {
                    Ok(line) => outgoing.push(line),
                    Err(why) => view.event(plain, why),
                }
            }
            let (resend, gave_up) = commands.due();
            outgoing.extend(resend);
            // The rig's link-loss watchdog (LINK_TIMEOUT_MS) needs bytes from the PC: the monitor,
            // the one program holding the port, keeps the link alive while it watches.
            if port.is_some() && last_heartbeat.elapsed() >= HEARTBEAT_EVERY {
                last_heartbeat = Instant::now();
                if let Ok(line) =
                    rig_client::lines::command_line(HEARTBEAT_ID, &["PING".to_string()])
                {
                    outgoing.push(line);
                }
            }
            if port.is_some() && status_due.is_some_and(|due| Instant::now() >= due) {
                status_due = Some(Instant::now() + STATUS_AGAIN_EVERY);
                if let Ok(line) =
                    rig_client::lines::command_line(STATUS_ID, &["STATUS".to_string()])
                {
                    outgoing.push(line);
                }
            }
            for text in gave_up {
                view.event(plain, text);
            }
            if let Some(p) = port.as_mut() {
                for line in &outgoing {
                    if let Err(e) = p.write_all(line) {
                        view.event(plain, format!("{e}"));
                    }
                }
            } else if !outgoing.is_empty() {
                view.event(plain, "not sent: the link is lost".into());
            }
            let now = Instant::now();
            if now >= next_redraw {
                next_redraw = now + REDRAW;
                if let Some(w) = log.as_mut() {
                    w.flush().context("writing the log")?;
                }
                if let Some(ui) = tui.as_mut() {
                    let tools = relay.as_ref().map_or(0, Relay::client_count);
                    ui.draw(&args.port, &view, &decoder, tools)?;
                }
            }
            if plain && now >= next_plain {
                next_plain = now + Duration::from_secs(1);
                // An error, not a panic, when the terminal is gone: the log is still closed.
                writeln!(std::io::stdout(), "{}", view.plain_line(&decoder))?;
            }
        }
        Ok(())
    })();
    // Leave the alternate screen first, so the summary stays on the terminal.
    drop(tui);
    let ended = (|| -> Result<()> {
        if let Some(w) = log.as_mut() {
            view.logged_rows += backlog.release(w, None)?;
        }
        link_event(&mut log, decoder.stats().restarts, "monitor end")?;
        if let Some(w) = log.as_mut() {
            w.flush().context("writing the log")?;
        }
        Ok(())
    })();
    if crate::interrupt::hung_up() {
        // The terminal closed: nobody reads the summary, and its errors were its going.
        return ended;
    }
    // The loop's error first: it is why the monitor ended.
    watched.and(ended)?;
    let mut summary = stats_json(decoder.stats());
    summary["reconnects"] = json!(view.reconnects);
    summary["unread_by_rig"] = json!(view.unread_by_rig);
    summary["logged_rows"] = json!(view.logged_rows);
    writeln!(std::io::stdout(), "{summary}")?;
    Ok(())
}

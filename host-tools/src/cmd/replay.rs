//! `bowl replay FILE [--csv OUT]`: decode a raw byte capture of the rig's serial output and print
//! one JSON line of statistics (and the decoding speed) on stdout.

use std::fs::File;
use std::io::{BufWriter, Read, Write};
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use model_core::wire::{Decoder, Frame};

use rig_client::decode_stats::stats_json;
use rig_client::telemetry_csv;
use serde_json::json;

use crate::exit_code::usage;

/// Flags of `bowl replay`.
#[derive(clap::Args)]
pub struct Args {
    /// The raw capture (the bytes exactly as they came off the serial line).
    file: PathBuf,
    /// Write the decoded telemetry as CSV, keyed on device time.
    #[arg(long, value_parser = crate::cmd::file_to_write)]
    csv: Option<PathBuf>,
}

/// CPU time of this thread, s (0 if the clock cannot be read).
#[cfg(not(unix))]
fn thread_cpu_seconds() -> f64 {
    0.0
}

/// CPU time of this thread, s (0 if the clock cannot be read).
#[cfg(unix)]
fn thread_cpu_seconds() -> f64 {
    use nix::time::{ClockId, clock_gettime};
    clock_gettime(ClockId::CLOCK_THREAD_CPUTIME_ID)
        .map(|t| t.tv_sec() as f64 + t.tv_nsec() as f64 * 1e-9)
        .unwrap_or(0.0)
}

/// Gaps in a capture's telemetry, judged as the monitor judges them live: no frame for three
/// frame periods (at least [`GAP_FLOOR_MS`]) is a gap, marked in the CSV with the monitor's own
/// words at the device times it began and ended, so `bowl chart log` breaks its lines there.
#[derive(Default)]
struct Gaps {
    /// The last frame: boot, device time, sequence number.
    last: Option<(u64, u32, u16)>,
    /// The frame period, from the last two frames that followed each other with none lost.
    period_ms: Option<u32>,
}

/// The shortest silence called a gap (the monitor's floor).
const GAP_FLOOR_MS: u32 = 500;

impl Gaps {
    /// A telemetry frame arrived: the (device time, words) of the gap it ends, if any.
    fn on_frame(&mut self, boot: u64, time_ms: u32, seq: u16) -> Option<[(u32, String); 2]> {
        let last = self.last.replace((boot, time_ms, seq));
        let (last_boot, last_ms, last_seq) = last?;
        if last_boot != boot || time_ms < last_ms {
            // A restart: the device clock began again; the restart is its own event.
            self.period_ms = None;
            return None;
        }
        let dt = time_ms - last_ms;
        let gap = self
            .period_ms
            .filter(|&p| dt > (3 * p).max(GAP_FLOOR_MS))
            .map(|p| {
                [
                    (last_ms + p, "no telemetry".to_string()),
                    (
                        time_ms,
                        format!(
                            "telemetry again after {:.1} s",
                            f64::from(time_ms - last_ms - p) / 1000.0
                        ),
                    ),
                ]
            });
        if seq == last_seq.wrapping_add(1) && dt > 0 {
            self.period_ms = Some(dt);
        }
        gap
    }
}

/// Read size of the streaming replay: the capture is never held whole, whatever its size.
const CHUNK_BYTES: usize = 1 << 16;

/// Runs `bowl replay`: reads the capture in chunks into one decoder (constant memory).
pub fn run(args: &Args) -> Result<()> {
    // Checked before the open: a serial port never ends, so the decode would wait forever.
    refuse_a_port(&args.file)?;
    let mut file =
        File::open(&args.file).with_context(|| format!("cannot read {}", args.file.display()))?;
    if args.file.is_dir() {
        bail!(
            "cannot read {}: it is a directory, not a capture",
            args.file.display()
        );
    }
    // Writing the CSV over the capture would empty it before it is read (a typo that lost
    // the user's recording).
    if let Some(path) = &args.csv
        && same_file(path, &args.file)
    {
        bail!(
            "--csv {} is the capture being read: it would be overwritten before it is decoded; \
             give another file name for the CSV",
            path.display()
        );
    }
    if let Some(path) = &args.csv {
        refuse_a_live_log(path)?;
    }
    // A replay writes the whole decode each time (appending would repeat its rows), unlike the
    // monitor's live log, which appends: say so when a file was there.
    let replaced = args
        .csv
        .as_ref()
        .filter(|p| p.metadata().is_ok_and(|m| m.is_file() && m.len() > 0));
    let mut csv = match &args.csv {
        Some(path) => {
            let mut w = BufWriter::new(
                File::create(path).with_context(|| format!("cannot create {}", path.display()))?,
            );
            writeln!(w, "{}", telemetry_csv::HEADER)?;
            Some(w)
        }
        None => None,
    };
    let mut telemetry = 0u64;
    // The latest telemetry's (boot, device ms): where a gate event sits on the device clock.
    let mut latest: Option<(u64, u32)> = None;
    let mut gaps = Gaps::default();
    let mut csv_error = None;
    let started = Instant::now();
    let cpu_started = thread_cpu_seconds();
    let mut decoder = Decoder::new();
    let mut chunk = vec![0u8; CHUNK_BYTES];
    loop {
        let n = match file.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => {
                return Err(e).with_context(|| format!("cannot read {}", args.file.display()));
            }
        };
        decoder.push_slice(&chunk[..n], |r, stats| {
            let written = match (r, csv.as_mut()) {
                (Ok(Frame::Telemetry(t)), w) => {
                    telemetry += 1;
                    latest = Some((stats.restarts, t.time_ms));
                    let gap = gaps.on_frame(stats.restarts, t.time_ms, t.seq);
                    w.map(|w| {
                        for (at_ms, what) in gap.iter().flatten() {
                            telemetry_csv::write_device_event(w, stats.restarts, *at_ms, what)?;
                        }
                        telemetry_csv::write_row(w, stats.restarts, &t, None)
                    })
                }
                // Gate events are logged too: nothing the rig sends is dropped.
                (Ok(Frame::Event(e)), Some(w)) => {
                    let near = latest.filter(|(boot, _)| *boot == stats.restarts);
                    Some(telemetry_csv::write_gate_event(
                        w,
                        stats.restarts,
                        None,
                        &e,
                        near.map(|(_, ms)| ms),
                    ))
                }
                _ => None,
            };
            if let Some(Err(e)) = written
                && csv_error.is_none()
            {
                csv_error = Some(e);
            }
        });
    }
    decoder.finish();
    let stats = *decoder.stats();
    let seconds = started.elapsed().as_secs_f64();
    let cpu_seconds = thread_cpu_seconds() - cpu_started;
    if let Some(e) = csv_error {
        return Err(e.context("writing the CSV"));
    }
    if let Some(mut w) = csv {
        w.flush().context("writing the CSV")?;
    }
    if let Some(path) = replaced {
        eprintln!(
            "note: {} existed and was replaced by this decode (`bowl monitor --log` appends; \
             `bowl replay --csv` writes the whole file)",
            path.display()
        );
    }
    let mut out = stats_json(&stats);
    out["telemetry_frames"] = json!(telemetry);
    out["decode_seconds"] = json!(seconds);
    out["decode_mb_s"] = json!(if seconds > 0.0 {
        stats.bytes as f64 / 1e6 / seconds
    } else {
        0.0
    });
    // On a shared machine the wall-clock figure depends on the load; the CPU-time one does not.
    out["decode_cpu_seconds"] = json!(cpu_seconds);
    out["decode_mb_per_cpu_s"] = json!(if cpu_seconds > 0.0 {
        stats.bytes as f64 / 1e6 / cpu_seconds
    } else {
        0.0
    });
    println!("{out}");
    // Nothing decoded: not a capture of the rig's output (or one the line ruined). Said, and a
    // failure, so a script does not go on with zero frames.
    if stats.frames_ok == 0 {
        let file = args.file.display();
        if stats.bytes == 0 {
            bail!("{file} is empty: a capture holds the bytes the rig sent");
        }
        // A telemetry log given for its capture: the decode is done already; say what reads it.
        if telemetry_csv::log_kind(&args.file) != telemetry_csv::LogKind::Other {
            return Err(usage(format!(
                "{file} is a telemetry log (the CSV `bowl monitor --log` or `bowl replay --csv` \
                 writes), decoded already, not a capture of the rig's raw bytes: draw it with \
                 `bowl chart log --csv {file} --out run.svg`"
            )));
        }
        let damaged = if stats.frames_corrupt > 0 {
            format!(
                "; {} frame candidates, every one damaged (a wrong baud rate or a broken line?)",
                stats.frames_corrupt
            )
        } else {
            String::new()
        };
        bail!(
            "{file} is not a capture of the rig's output: none of its {} bytes forms a frame{damaged}. \
             A capture is the raw bytes from the rig's serial port, as `bowl serve --capture` or a \
             serial logger writes them",
            stats.bytes
        );
    }
    Ok(())
}

/// Refuses a serial port or terminal (a character device) as the capture: its bytes never
/// end, so a replay of it would print nothing, forever. Watching a port live is the monitor's job.
fn refuse_a_port(path: &std::path::Path) -> Result<()> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if std::fs::metadata(path).is_ok_and(|m| m.file_type().is_char_device()) {
            let p = path.display();
            return Err(usage(format!(
                "{p} is a serial port or terminal, not a capture file: `bowl replay` decodes a \
                 recorded capture and would wait forever on a port; to watch the rig and log its \
                 telemetry use `bowl monitor {p} --log run.csv` (then `bowl chart log --csv \
                 run.csv`)"
            )));
        }
    }
    #[cfg(not(unix))]
    let _ = path;
    Ok(())
}

/// Refuses to replace a log written live (`bowl monitor --log`, the demo's telemetry.csv): its
/// PC times are made once, and a monitor still writing it would append its rows after the
/// decode's. A replay's own CSV is made again from its capture, so that one is replaced.
fn refuse_a_live_log(path: &std::path::Path) -> Result<()> {
    let p = path.display();
    let held = File::open(path)
        .is_ok_and(|f| matches!(f.try_lock_shared(), Err(std::fs::TryLockError::WouldBlock)));
    let why = if held {
        "a `bowl monitor` is writing it now (its `--log`)"
    } else if telemetry_csv::log_kind(path) == telemetry_csv::LogKind::Live {
        "it was logged live (`bowl monitor --log`, or a demo's telemetry.csv): its rows carry the \
         PC's clock, which no capture holds"
    } else {
        return Ok(());
    };
    Err(usage(format!(
        "--csv {p}: {why}, so replacing it with this decode would lose those rows; it was left \
         as it is. Give a new file name for the decode (e.g. --csv replay.csv)"
    )))
}

/// Whether `a` names the existing file `b` (the same path, or another path to it).
fn same_file(a: &std::path::Path, b: &std::path::Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

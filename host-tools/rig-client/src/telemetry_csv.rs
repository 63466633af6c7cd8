//! The CSV form of telemetry, shared by `bowl replay --csv`, `bowl monitor --log` and the demo:
//! one row per telemetry frame, keyed on (boot, device time); the values stay the wire's scaled
//! integers, with the unit in each column name. Two columns close each row: `host_time_utc`, the
//! PC's wall clock when the frame arrived (ISO 8601, UTC, milliseconds; empty when replaying a
//! capture, which holds no PC time), and `event`: empty for telemetry, or what happened on the
//! link (`port open`, `link lost`, `port reopened`, `device restart`, `monitor end`), on a row of
//! its own with the telemetry columns empty, so a gap in the data shows its cause.

use std::io::Write;
use std::time::SystemTime;

use anyhow::Result;
use model_core::wire::{Residence, Telemetry};

/// The header line.
pub const HEADER: &str = "boot,device_time_ms,seq,state,fault,\
prec_set_mrad_s,prec_measured_mrad_s,prec_duty_bp,prec_pulses,\
spin_set_mrad_s,spin_measured_mrad_s,spin_duty_bp,spin_pulses,\
bowl_mrad_s,residence_flat_ms,residence_coriolis_ms,host_time_utc,event";

/// Telemetry columns between `boot` and `host_time_utc`.
const TELEMETRY_COLUMNS: usize = 15;

fn residence(r: Residence) -> String {
    match r {
        Residence::Ms(ms) => ms.to_string(),
        Residence::NeverLeaves => "never".to_string(),
        Residence::Unavailable => String::new(),
    }
}

/// `2026-11-25T02:44:26.123Z` for a wall-clock time (empty before 1970).
pub fn utc(t: SystemTime) -> String {
    let Ok(d) = t.duration_since(SystemTime::UNIX_EPOCH) else {
        return String::new();
    };
    let secs = d.as_secs();
    let (days, rem) = (secs / 86_400, secs % 86_400);
    // Civil date from days since 1970-01-01 (proleptic Gregorian, H. Hinnant's algorithm).
    let z = days as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1_460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}.{:03}Z",
        rem / 3_600,
        rem / 60 % 60,
        rem % 60,
        d.subsec_millis()
    )
}

/// Writes one telemetry row. `boot` counts the device restarts seen before this frame, so the
/// key stays unique when the device time starts again from zero; `host` is when it arrived.
pub fn write_row(
    out: &mut impl Write,
    boot: u64,
    t: &Telemetry,
    host: Option<SystemTime>,
) -> Result<()> {
    writeln!(
        out,
        "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},",
        boot,
        t.time_ms,
        t.seq,
        t.state.token(),
        t.fault.token(),
        t.precession.set_mrad_s,
        t.precession.measured_mrad_s,
        t.precession.duty_bp,
        t.precession.pulses,
        t.spin.set_mrad_s,
        t.spin.measured_mrad_s,
        t.spin.duty_bp,
        t.spin.pulses,
        t.bowl_mrad_s,
        residence(t.residence_flat),
        residence(t.residence_coriolis),
        host.map(utc).unwrap_or_default(),
    )?;
    Ok(())
}

/// An event's words as one CSV cell (RFC 4180): quoted, with its quotes doubled, when it holds
/// a comma, a quote or a line end (a warning in words has commas), so a spreadsheet and
/// [`LogReader`] read it as the one `event` cell, not as extra columns.
fn event_cell(event: &str) -> std::borrow::Cow<'_, str> {
    if event.contains([',', '"', '\r', '\n']) {
        format!("\"{}\"", event.replace('"', "\"\"")).into()
    } else {
        event.into()
    }
}

/// Writes an event's row (a link event, a gate event): `boot`, empty telemetry columns, the
/// PC's time if known and the event.
pub fn write_event(
    out: &mut impl Write,
    boot: u64,
    host: Option<SystemTime>,
    event: &str,
) -> Result<()> {
    writeln!(
        out,
        "{boot},{}{},{}",
        ",".repeat(TELEMETRY_COLUMNS),
        host.map(utc).unwrap_or_default(),
        event_cell(event)
    )?;
    Ok(())
}

/// Writes an event the device's clock dates (a gap found in a capture, which holds no PC time):
/// `boot`, the device time, the other columns empty, the event.
pub fn write_device_event(
    out: &mut impl Write,
    boot: u64,
    device_time_ms: u32,
    event: &str,
) -> Result<()> {
    writeln!(
        out,
        "{boot},{device_time_ms}{},{}",
        ",".repeat(TELEMETRY_COLUMNS),
        event_cell(event)
    )?;
    Ok(())
}

/// A telemetry log opened for reading (`bowl monitor --log`, `bowl replay --csv`, the demo's
/// telemetry.csv): its records, and its columns found by name.
pub struct LogReader {
    /// The records after the header (flexible: event rows are shorter in old logs).
    pub reader: csv::Reader<std::fs::File>,
    header: csv::StringRecord,
    path: std::path::PathBuf,
}

impl LogReader {
    /// Opens `path` and reads its header.
    pub fn open(path: &std::path::Path) -> Result<Self> {
        use anyhow::Context as _;
        // A directory opens like a file on Unix and fails only at the first read, without
        // its name: said here, with it.
        if path.is_dir() {
            anyhow::bail!(
                "{} is a directory, not a telemetry log (a CSV file)",
                path.display()
            );
        }
        let mut reader = csv::ReaderBuilder::new()
            .flexible(true)
            .from_path(path)
            .with_context(|| format!("cannot open {}", path.display()))?;
        let header = reader
            .headers()
            .with_context(|| format!("cannot read the header of {}", path.display()))?
            .clone();
        Ok(Self {
            reader,
            header,
            path: path.to_path_buf(),
        })
    }

    /// The index of column `name`, or an error that says what file is expected.
    pub fn column(&self, name: &str) -> Result<usize> {
        self.optional(name).ok_or_else(|| {
            anyhow::anyhow!(
                "{}: no `{name}` column: is this a telemetry log (bowl monitor --log, bowl \
                 replay --csv, the demo's telemetry.csv)?",
                self.path.display()
            )
        })
    }

    /// The index of column `name`, if the log has it.
    pub fn optional(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h == name)
    }

    /// The column names, in order.
    pub fn names(&self) -> Vec<String> {
        self.header.iter().map(str::to_string).collect()
    }
}

/// A gate event's device time in ms on the telemetry's clock. The gates count microseconds,
/// which wrap every 71.6 minutes, the telemetry milliseconds, which wrap after 49.7 days: after
/// a boot's first 71.6 minutes a gate's own count no longer says where it sits among the rows.
/// It is placed from `telemetry_ms`, a telemetry frame of the same boot near it (the latest
/// before it; within 35 minutes either way, half the microseconds' wrap); without one, from its
/// own count (right within a boot's first 71.6 minutes).
pub fn gate_device_ms(time_us: u32, telemetry_ms: Option<u32>) -> f64 {
    let Some(t) = telemetry_ms else {
        return f64::from(time_us) / 1000.0;
    };
    let t_us = (u64::from(t) * 1000) as u32;
    // The signed distance from that frame to the gate, in the wrapping microsecond count.
    let ahead_us = time_us.wrapping_sub(t_us) as i32;
    f64::from(t) + f64::from(ahead_us) / 1000.0
}

/// Writes a gate event's row: as [`write_event`], with the event's device time in ms
/// ([`gate_device_ms`] from `telemetry_ms`, the latest telemetry of the same boot) in
/// `device_time_ms`, so a chart places it on the telemetry's time axis.
pub fn write_gate_event(
    out: &mut impl Write,
    boot: u64,
    host: Option<SystemTime>,
    e: &model_core::wire::GateEvent,
    telemetry_ms: Option<u32>,
) -> Result<()> {
    writeln!(
        out,
        "{boot},{:.3}{}{},{}",
        gate_device_ms(e.time_us, telemetry_ms),
        ",".repeat(TELEMETRY_COLUMNS),
        host.map(utc).unwrap_or_default(),
        gate_event_text(e)
    )?;
    Ok(())
}

/// What an existing file is, as far as a telemetry log goes: read from its first 64 KiB (a day's
/// log is hundreds of MB).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LogKind {
    /// Not a telemetry log (no such header), or not readable.
    Other,
    /// A telemetry log decoded from a capture (`bowl replay --csv`): no PC times, so a replay
    /// of its capture makes it again.
    Decoded,
    /// A log written live (`bowl monitor --log`, the demo's telemetry.csv): its rows carry the
    /// PC's clock, which nothing can make again.
    Live,
}

/// What the file at `path` is ([`LogKind`]).
pub fn log_kind(path: &std::path::Path) -> LogKind {
    use std::io::Read as _;
    let mut head = Vec::new();
    let read = std::fs::File::open(path).and_then(|f| f.take(1 << 16).read_to_end(&mut head));
    if read.is_err() {
        return LogKind::Other;
    }
    let mut reader = csv::ReaderBuilder::new()
        .flexible(true)
        .from_reader(head.as_slice());
    let host = match reader.headers() {
        Ok(h) if h.iter().eq(HEADER.split(',')) => TELEMETRY_COLUMNS + 1,
        _ => return LogKind::Other,
    };
    // The last record read may be cut at 64 KiB: its host time, if any, is still a host time.
    let live = reader
        .records()
        .map_while(Result::ok)
        .any(|r| r.get(host).is_some_and(|t| !t.is_empty()));
    if live {
        LogKind::Live
    } else {
        LogKind::Decoded
    }
}

/// A gate event in words, for the log's event column and the console: `release gate at
/// 5000123 us (boot 0)`.
pub fn gate_event_text(e: &model_core::wire::GateEvent) -> String {
    let gate = match e.kind {
        model_core::wire::GateKind::Release => "release",
        model_core::wire::GateKind::Exit => "exit",
    };
    format!("{gate} gate at {} us (boot {})", e.time_us, e.boot)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn utc_dates_match_known_instants() {
        let at = |s: u64, ms: u64| SystemTime::UNIX_EPOCH + Duration::from_millis(s * 1000 + ms);
        assert_eq!(utc(at(0, 0)), "1970-01-01T00:00:00.000Z");
        // `date -u -d @951782400`: the leap day of 2000.
        assert_eq!(utc(at(951_782_400, 5)), "2000-02-29T00:00:00.005Z");
        assert_eq!(utc(at(1_764_038_666, 123)), "2025-11-25T02:44:26.123Z");
        assert_eq!(utc(at(4_102_444_799, 999)), "2099-12-31T23:59:59.999Z");
    }

    #[test]
    fn event_rows_have_as_many_fields_as_the_header() {
        let mut out = Vec::new();
        write_event(&mut out, 2, Some(SystemTime::UNIX_EPOCH), "link lost").unwrap();
        let line = String::from_utf8(out).unwrap();
        assert_eq!(
            line.trim_end().split(',').count(),
            HEADER.split(',').count(),
            "{line}"
        );
        assert!(line.starts_with("2,") && line.trim_end().ends_with(",link lost"));
    }

    /// A gate 4300.5 s after boot (past the microseconds' wrap at 4294.967 s) sits at 4300.5 s
    /// among the telemetry, not at the 5.5 s its own count reads; before the wrap, and without
    /// telemetry, its own count is it.
    #[test]
    fn a_gate_after_the_microsecond_wrap_sits_among_its_telemetry() {
        let wrap_us = 1u64 << 32;
        let time_us = (4_300_500_000u64 - wrap_us) as u32;
        assert_eq!(time_us, 5_532_704);
        assert_eq!(gate_device_ms(time_us, Some(4_300_000)), 4_300_500.0);
        // The latest frame may be just after the gate (a late row): a negative distance.
        assert_eq!(gate_device_ms(time_us, Some(4_300_520)), 4_300_500.0);
        assert_eq!(gate_device_ms(5_000_123, Some(4_990)), 5_000.123);
        assert_eq!(gate_device_ms(5_000_123, None), 5_000.123);
    }

    /// A replay's CSV (no PC times) and a live log (a `port open` row with the PC's time) are
    /// told apart; a results file and a missing file are neither.
    #[test]
    fn live_logs_are_told_from_decoded_ones() {
        let dir = std::env::temp_dir().join(format!("bowl-log-kind-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (mut decoded, mut live) = (format!("{HEADER}\n").into_bytes(), Vec::new());
        live.extend_from_slice(&decoded);
        write_device_event(&mut decoded, 1, 5000, "no telemetry").unwrap();
        write_event(&mut live, 0, Some(SystemTime::UNIX_EPOCH), "port open").unwrap();
        for (name, text, kind) in [
            ("decoded.csv", decoded, LogKind::Decoded),
            ("live.csv", live, LogKind::Live),
            ("results.csv", b"run,t_s\n1,2.5\n".to_vec(), LogKind::Other),
        ] {
            std::fs::write(dir.join(name), text).unwrap();
            assert_eq!(log_kind(&dir.join(name)), kind, "{name}");
        }
        assert_eq!(log_kind(&dir.join("missing.csv")), LogKind::Other);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// An event in words with commas and quotes (the monitor's warning about another program
    /// on the port) stays one cell: a CSV reader gets the header's column count and the words
    /// back whole.
    #[test]
    fn an_event_with_commas_is_one_cell() {
        let words = "warning: /dev/pts/3 is also open in picocom (pid 42), which does not lock \
                     it: it takes some of the rig's bytes, so frames go \"missing\"";
        let mut out = Vec::new();
        write_event(&mut out, 0, Some(SystemTime::UNIX_EPOCH), words).unwrap();
        write_device_event(&mut out, 0, 5000, words).unwrap();
        let text = format!("{HEADER}\n{}", String::from_utf8(out).unwrap());
        let mut reader = csv::Reader::from_reader(text.as_bytes());
        let columns = reader.headers().unwrap().len();
        let rows: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
        assert_eq!(rows.len(), 2);
        for row in rows {
            assert_eq!(row.len(), columns, "{row:?}");
            assert_eq!(&row[columns - 1], words);
        }
    }
}

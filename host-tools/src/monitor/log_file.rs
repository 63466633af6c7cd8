//! The monitor's `--log` file: opened to append to, checked to be a telemetry log of this
//! bowl and held against a second monitor.

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Read, Seek, SeekFrom, Write};
use std::path::PathBuf;

use anyhow::{Context, Result};
use rig_client::telemetry_csv;

/// Opens the log to append to it: a new or empty file gets the header; an existing one must be
/// a log with these very columns (appending telemetry to another CSV, a results file say,
/// would spoil it, and rows under an older header would sit in the wrong columns).
pub(super) fn open_log(path: &PathBuf) -> Result<BufWriter<File>> {
    let mut file = OpenOptions::new()
        .create(true)
        .append(true)
        .read(true)
        .open(path)
        .with_context(|| format!("cannot open the log {}", path.display()))?;
    // Held while the monitor runs: a second monitor's rows (another rig's) would be mixed into
    // this one's, a row cut in two where their buffers met. A file system without locks
    // does without.
    if let Err(std::fs::TryLockError::WouldBlock) = file.try_lock() {
        return Err(crate::exit_code::usage(format!(
            "--log {}: another `bowl monitor` is writing to this log, and the rows of two \
             monitors would be mixed in it; give each monitor a log of its own",
            path.display()
        )));
    }
    let len = file.metadata().map(|m| m.len()).unwrap_or(0);
    // The header line and the last byte are all that is read: a day's log is hundreds of MB.
    let mut head = Vec::new();
    let mut last = [b'\n'];
    (|| -> std::io::Result<()> {
        (&mut file)
            .take(telemetry_csv::HEADER.len() as u64 + 2)
            .read_to_end(&mut head)?;
        if len > 0 {
            file.seek(SeekFrom::Start(len - 1))?;
            file.read_exact(&mut last)?;
        }
        Ok(())
    })()
    .with_context(|| format!("cannot read the log {}", path.display()))?;
    let mut w = BufWriter::new(file);
    if len == 0 {
        writeln!(w, "{}", telemetry_csv::HEADER)?;
        return Ok(w);
    }
    let first = head.split(|&b| b == b'\n').next().unwrap_or_default();
    if first.strip_suffix(b"\r").unwrap_or(first) != telemetry_csv::HEADER.as_bytes() {
        return Err(crate::exit_code::usage(format!(
            "--log {}: the file exists and is not a telemetry log with this bowl's columns (its \
             first line is not the header `bowl monitor --log` writes), so nothing was appended \
             to it; give a new file name (or an earlier log of this bowl to go on with)",
            path.display()
        )));
    }
    // A log whose last row was cut off (the PC lost power mid-write): the next row starts on
    // a line of its own, not glued to the stub.
    if last != [b'\n'] {
        writeln!(w)?;
    }
    Ok(w)
}
